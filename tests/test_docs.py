"""Every example of the documentation runs: each fenced ``python`` block of README.md and docs/*.md, and
each ``tumble`` command of their shell blocks, from an empty temporary directory per page.

Rules (docs/README.md, "Examples that run"):

* A page's blocks run in order in one new directory; each Python block in a namespace of its own (a
  block never continues another), as ``python block.py`` would run it. Shell lines that start with
  ``tumble`` (or ``python -m tumble``, ``$ `` prompts allowed) run through the CLI in this process; other
  shell lines (pip, pytest, scripts of the repository) are not run, but for ``mkdir DIR``.
* A ``toml`` block whose first line is ``# NAME.toml`` is a file the page's commands read: it is written
  there before the next block runs. (``# examples/NAME.toml`` shows an installed example file, which
  ``tumble examples copy examples`` puts there; tests/scenario/test_scenario*.py check that the two agree.)
* A Python block that starts a local Dask cluster (``tumble.sweep(...)``, ``sweep_scenario(...)`` or
  ``local_cluster(...)`` without ``workers=0``) must guard its entry point with ``if __name__ ==
  "__main__":``, and runs as a script in a new Python process (``python block.py``): the cluster's
  worker processes import the script, which ``exec`` inside pytest would not show.
* ``<!-- docs-test: skip: REASON -->`` just before a block leaves it out (a GPU, a cluster address, a
  listing of signatures); such blocks are few and counted here. ``<!-- docs-test: exit N -->`` before a
  shell block says its commands exit with N, and every ``error:`` line it shows is checked.
* A number a Python block prints and states in the comment of that ``print`` line is checked (see
  :func:`claims`): ``# 2.98632`` to the digits given; ``# ~1e-14`` as at most ten times that; ``# below
  1e-13`` as at most that; figures at the level of rounding (under 1e-12) as bounds, since their last
  digits depend on the machine's floating point.

Each page is one test, so pytest-xdist spreads the pages over the workers; the compiled kernels the
examples use are those the rest of the suite compiles (Numba's disk cache is shared).
"""

from __future__ import annotations

import builtins
import io
import math
import os
import pickle
import re
import shlex
import subprocess
import sys
import warnings
from contextlib import redirect_stdout
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from typer.testing import CliRunner

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# Most blocks a page may leave out, over all pages (the issue: "marked explicitly, and few").
MOST_SKIPPED = 4

FENCE = re.compile(r"(?P<mark><!-- docs-test: (?P<rule>[^>]*?) -->\n)?```(?P<lang>[\w-]*)\n(?P<body>.*?)^```",
                   re.M | re.S)
COMMAND = re.compile(r"^(?:\$ )?(?:python3? -m )?tumble(?: |$)(?P<args>.*)$")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?j?", re.I)
ROUNDING = 1e-12   # claimed figures smaller than this are rounding errors: checked as bounds (10x)
# A call that starts a local Dask cluster unless given workers=0; the guard the script then needs.
CLUSTER = re.compile(r"\b(?:tumble\.sweep|sweep_scenario|local_cluster|LocalCluster)\(")
GUARD = re.compile(r'^if __name__ == "__main__":', re.M)


def blocks(page: Path) -> list[dict]:
    """The fenced blocks of a page, in order: language, body, the rule of a docs-test mark, line number and
    the heading (``## ...``) the block is under."""
    text = page.read_text(encoding="utf-8")
    headings = [(m.start(), m[0]) for m in re.finditer(r"^#+ .*$", re.sub(r"```.*?```", _blank, text, flags=re.S),
                                                          flags=re.M)]
    return [dict(lang=m["lang"], body=m["body"], rule=m["rule"], line=text.count("\n", 0, m.start("lang")) + 1,
                 heading=next((h for at, h in reversed(headings) if at < m.start()), ""))
            for m in FENCE.finditer(text)]


def _blank(block: re.Match) -> str:
    """A fenced block with its text blanked (same length), so that its ``# comments`` are not headings."""
    return re.sub(r"[^\n]", " ", block[0])


# -- claims in comments ---------------------------------------------------------------------------------


def claims(comment: str) -> tuple[str, list[str]] | None:
    """What the comment of a ``print`` line claims: ``("bound", [x])``, ``("equal", [numbers...])``,
    ``("text", [fragments...])``, or None when it claims no figure."""
    comment = comment.strip()
    if m := re.match(r"~\s*(\S+)", comment):
        return "bound", [str(10 * float(m[1]))]
    if m := re.match(r"below (\S+)", comment):
        return "bound", [m[1]]
    if re.match(r"[\[(]?[-+]?\d[\d.eE+-]*j?(?=[\s\]),]|$)", comment):
        if comment[0] in "[(":      # a bracketed array, tuple or complex number
            closing = {"[": "]", "(": ")"}[comment[0]]
            return "equal", NUMBER.findall(comment[: comment.index(closing) + 1])
        leading = []
        for token in comment.split():
            if not NUMBER.fullmatch(token):
                break
            leading.append(token)
        return "equal", leading
    if m := re.match(r"[^=]*? = ([-+]?\d[\d.eE+-]*)", comment):
        return "equal", [m[1]]
    if m := re.match(r'"([^"]+)"', comment):                 # a string, quoted
        return "text", [m[1]]
    said = comment.split(": ", 1)[-1]
    if re.match(r"[A-Za-z_]\w*\(", said) or "..." in said:     # a repr, or a message given in part
        return "text", [f.strip() for f in said.split("...") if len(f.strip()) > 8]
    return None


def numbers(values) -> list[float]:
    """The numbers printed: numbers, arrays, tuples (a shape) and the numbers written in strings, in order."""
    out: list[float] = []
    for value in values:
        if isinstance(value, str):
            out += [complex(n).imag if n.lower().endswith("j") else float(n) for n in NUMBER.findall(value)]
        elif isinstance(value, (tuple, list)) and all(isinstance(v, (int, float, np.number)) for v in value):
            out += [float(v) for v in value]
        else:
            array = np.asarray(value)
            if array.dtype.kind in "biuf":
                out += array.astype(float).ravel().tolist()
            elif array.dtype.kind == "c":
                out += [x for z in array.ravel() for x in (z.real, z.imag)]
    return out


def check(claim: tuple[str, list[str]], printed: list, where: str) -> None:
    kind, wanted = claim
    if kind == "text":
        text = " ".join(str(v) for v in printed)
        for fragment in wanted:
            assert fragment in text, f"{where}: printed {text!r}, the comment says {fragment!r}"
        return
    got = numbers(printed)
    if kind == "bound":
        assert got and max(abs(v) for v in got) <= float(wanted[0]), f"{where}: printed {got}, claimed <= {wanted[0]}"
        return
    claimed = [complex(w).imag if w.lower().endswith("j") else float(w) for w in wanted]
    assert len(got) == len(claimed), f"{where}: printed {got}, the comment gives {wanted}"
    for value, text, c in zip(got, wanted, claimed):
        if abs(c) < ROUNDING:
            assert abs(value) <= 10 * max(abs(c), ROUNDING / 10), f"{where}: printed {value}, claimed ~{text}"
            continue
        mantissa = re.sub(r"e.*|j", "", text.lower()).lstrip("+-")
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        exponent = int(re.search(r"e([-+]?\d+)", text.lower())[1]) if "e" in text.lower() else 0
        half_unit = 0.5 * 10.0 ** (exponent - decimals)        # half a unit in the last digit given
        assert abs(value - c) <= half_unit * (1 + 1e-9), f"{where}: printed {value}, the docs say {text}"


def instrument(code: str, record) -> str:
    """Route each single-line ``print(...)  # claim`` through ``__print__(line, ...)``, which records it."""
    lines = code.splitlines()
    for k, line in enumerate(lines):
        m = re.match(r"(\s*)print\((.*)\)\s*#(.*)$", line)
        if m and claims(m[3]) is not None and m[2].count("(") == m[2].count(")"):
            lines[k] = f"{m[1]}__print__({k}, {m[2]})"
            record[k] = claims(m[3])
    return "\n".join(lines) + "\n"


# -- running a page ------------------------------------------------------------------------------------------


def run_python(code: str, where: str, page: Path) -> dict:
    """Run one block as a script, and check the figures its comments claim; returns its namespace."""
    wanted: dict = {}
    source = instrument(code, wanted)
    printed: dict = {}

    def __print__(line, *values, **kwargs):
        printed[line] = values
        builtins.print(*values, **kwargs)

    namespace = {"__name__": "__main__", "__file__": str(page), "__print__": __print__}
    with redirect_stdout(io.StringIO()), warnings.catch_warnings():
        exec(compile(source, f"{page.name}:{where}", "exec"), namespace)   # the project's own docs
    for line, claim in wanted.items():
        check(claim, printed[line], f"{page.name}:{where} line {line + 1}")
    return namespace


def starts_a_cluster(code: str) -> bool:
    return bool(CLUSTER.search(code)) and "workers=0" not in code


# What a script block's prelude records: each checked print's values, pickled to PRINTED at exit.
SCRIPT_PRELUDE = """\
import atexit as __atexit, builtins as __builtins, pickle as __pickle
__printed = {}
def __print__(line, *values, **kwargs):
    __printed[line] = values
    __builtins.print(*values, **kwargs)
def __save():
    with open(%r, "wb") as f:
        __pickle.dump(__printed, f)
__atexit.register(__save)
"""


def run_script(code: str, where: str, page: Path, directory: Path) -> None:
    """Run one block as ``python block.py`` in ``directory`` (a new process, ``__main__`` its own), and check the
    figures its comments claim."""
    assert GUARD.search(code), f"{page.name}:{where}: a block that starts a local cluster needs `if __name__ == " \
                               '"__main__":` (its worker processes import the script)'
    wanted: dict = {}
    script, printed = directory / f"{page.stem}_{where.split()[-1]}.py", directory / "printed.pickle"
    script.write_text(SCRIPT_PRELUDE % str(printed) + instrument(code, wanted), encoding="utf-8")
    source = str(Path(__file__).resolve().parents[1] / "src")
    env = {**os.environ, "PYTHONPATH": source + os.pathsep + os.environ.get("PYTHONPATH", "")}
    result = subprocess.run([sys.executable, str(script)], cwd=directory, env=env, capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, f"{page.name}:{where} exited {result.returncode}:\n{result.stderr[-3000:]}"
    values = pickle.loads(printed.read_bytes())
    printed.unlink()
    script.unlink()
    for line, claim in wanted.items():
        check(claim, values[line], f"{page.name}:{where} line {line + 1}")


def run_shell(body: str, lang: str, rule: str | None, where: str) -> None:
    from tumble.cli import app

    exit_code = int(rule.split()[1]) if rule and rule.startswith("exit") else 0
    output = ""
    prompted = lang == "console" or any(line.startswith("$ ") for line in body.splitlines())
    for line in body.splitlines():
        if prompted and not line.startswith("$ "):    # a block with prompts shows output after its commands
            continue
        if line.startswith("$ mkdir ") or line.startswith("mkdir "):     # a directory a command writes in
            Path(line.split()[-1]).mkdir(parents=True)
            continue
        m = COMMAND.match(line.strip())
        if not m:
            continue
        result = CliRunner().invoke(app, shlex.split(m["args"], comments=True))
        output += result.output
        assert result.exit_code == exit_code, f"{where}: `{line}` exited {result.exit_code}:\n{result.output}"
    for shown in (line for line in body.splitlines() if line.startswith("error: ")):
        assert shown in output, f"{where}: the docs show {shown!r}; the command printed:\n{output}"


# -- what some blocks keep beyond their printed figures (page, heading): checks on the block's namespace ------


def _ten_lines(namespace, directory):
    code = next(b["body"] for b in blocks(ROOT / "README.md") if b["heading"] == "## Ten lines of Python")
    assert len([line for line in code.splitlines() if line.strip()]) <= 12
    assert (directory / "box.nc").stat().st_size > 0
    assert (directory / "box.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _front_door(namespace, directory):
    # the undamped panel keeps hub + panel energy: rk4 at dt = 0.01 s over 60 s, measured 3.4e-11
    flex = namespace["flex"]
    assert flex.model == "FlexibleBody" and np.ptp(flex.energy) / flex.energy[0] <= 1e-9
    # the falling arm keeps E - W: dop853 at its default tolerances, measured 4.0e-11 J
    assert np.ptp(namespace["arm"].invariants(namespace["fall"])["energy_minus_work"]) <= 1e-9
    run = namespace["run"]
    assert run.model == "Spacecraft" and run.wheel_speed.shape == (61, 3)


def _exact_motion(namespace, directory):
    assert namespace["exact"].method == "exact"


FOLLOW_UP = {("README.md", "## Ten lines of Python"): _ten_lines,
             ("README.md", "## One front door for every model"): _front_door,
             ("README.md", "## Exact motion, stability and the heavy top"): _exact_motion}


#: The pages whose examples compile model kinds other than the rigid body's, the rigid body's parallel batch
#: driver (free_body, integrators), or run demos, sweeps or the CLI's commands: seconds to two minutes of CPU
#: each on a cold Numba cache (the README's: 126 CPU s, measured).
SLOW_PAGES = {"README.md", *(f"docs/{name}.md" for name in (
    "chaos", "cli", "diver", "estimation", "flexible", "fluid", "frames", "free_body", "gpu", "ins", "integrators",
    "limits", "passive_stability", "robot", "scenarios", "slosh", "spacecraft", "spacecraft_environment",
    "stability", "sweeps", "variable_inertia", "viewer"))}


def _page_id(page):
    return page.relative_to(ROOT).as_posix()


@pytest.mark.parametrize("page", [pytest.param(page, marks=pytest.mark.slow) if _page_id(page) in SLOW_PAGES else page
                                  for page in PAGES], ids=_page_id)
def test_every_example_of_the_page_runs(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for block in blocks(page):
        where = f"block at line {block['line']}"
        rule = block["rule"]
        if rule and rule.startswith("skip"):
            continue
        if block["lang"] == "python" and starts_a_cluster(block["body"]):
            run_script(block["body"], where, page, tmp_path)
        elif block["lang"] == "python":
            namespace = run_python(block["body"], where, page)
            if (page.name, block["heading"]) in FOLLOW_UP:
                FOLLOW_UP[page.name, block["heading"]](namespace, tmp_path)
            plt.close("all")
        elif block["lang"] in ("bash", "console", "sh", "shell", ""):
            run_shell(block["body"], block["lang"], rule, f"{page.name}:{where}")
        elif block["lang"] == "toml" and (m := re.match(r"# (?!examples/)(\S+\.toml)\n", block["body"])):
            (tmp_path / m[1]).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / m[1]).write_text(block["body"], encoding="utf-8")


def test_blocks_left_out_are_few_and_say_why():
    skipped = [(page.name, b["line"], b["rule"]) for page in PAGES for b in blocks(page)
               if b["rule"] and b["rule"].startswith("skip")]
    assert len(skipped) <= MOST_SKIPPED, skipped
    for name, line, rule in skipped:
        assert re.match(r"skip: \S.{8,}", rule), f"{name}:{line}: a skipped block says why ('skip: REASON')"


def test_claims_are_read_from_comments():
    # the parser of claims, on the forms the docs use
    assert claims("2K/λ = 2.98632 s between flips") == ("equal", ["2.98632"])
    assert claims("1.76 2.99 8.9e-16") == ("equal", ["1.76", "2.99", "8.9e-16"])
    assert claims("(0.0128+0.9697j) 1/s: unstable") == ("equal", ["0.0128", "+0.9697j"])
    assert claims("[0, 0, 37.30] rad/s: 6 × 5.72/0.92") == ("equal", ["0", "0", "37.30"])
    assert claims("~1e-14") == ("bound", [str(10 * 1e-14)])
    assert claims("below 1e-13 J") == ("bound", ["1e-13"])
    assert claims("the 99th percentile, rad") is None
    assert claims('"rigid" (inferred: the file has no [spacecraft] table)') == ("text", ["rigid"])
    assert claims("the model: RigidBody(moments=[1, 2, 3] kg m^2)") == ("text", ["RigidBody(moments=[1, 2, 3] kg m^2)"])
    check(("equal", ["1.76"]), [1.7649], "here")
    with pytest.raises(AssertionError):
        check(("equal", ["1.76"]), [1.7651], "here")
    assert math.isclose(sum(numbers([np.array([1.0, 2.0]), (3, 4), "x 5.5 y"])), 15.5)


def test_a_block_that_starts_a_cluster_is_run_as_a_script_and_needs_the_guard(tmp_path):
    # exec inside pytest could not show the missing guard: spawned workers import the script, not pytest
    unguarded = "import tumble\nds = tumble.sweep(body, dispersions, samples=10, t=t)\n"
    assert starts_a_cluster(unguarded) and not starts_a_cluster(unguarded.replace("t=t", "t=t, workers=0"))
    assert starts_a_cluster("cluster = tumble.sweeps.local_cluster(2)\n")
    assert not starts_a_cluster("tumble.sweeps.Normal(0, 1)")
    with pytest.raises(AssertionError, match='needs `if __name__ == "__main__":`'):
        run_script(unguarded, "block at line 1", ROOT / "README.md", tmp_path)
    run_script('import math\nif __name__ == "__main__":\n    print(math.pi)  # 3.14159\n', "block at line 1",
               ROOT / "README.md", tmp_path)
    with pytest.raises(AssertionError, match=r"line 3: printed 3\.14159265\d*, the docs say 3\.1415\n"):
        run_script('import math\nif __name__ == "__main__":\n    print(math.pi)  # 3.1415\n', "block at line 1",
                   ROOT / "README.md", tmp_path)
