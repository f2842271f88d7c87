"""Modules renamed in 0.4 keep their old names until tumble 0.5: importing one, or a name from it, gives the new
module's very object, with one DeprecationWarning per old module that names its replacement; an object pickled
under the old module path loads.

The spellings run in a new Python process (``sys.executable``), since an import changes the process for good;
before each one the process forgets the old names it imported (``sys.modules`` and the attribute of the parent
package), as a process that never imported them but has loaded the new modules.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

SPELLINGS = textwrap.dedent("""
    import importlib, json, sys, warnings
    import tumble

    def forget(old):
        for name in [name for name in sys.modules if name == old or name.startswith(old + ".")]:
            del sys.modules[name]
        parent, _, child = old.rpartition(".")
        vars(sys.modules[parent]).pop(child, None)

    results = {}
    for code, olds, news, check in json.loads(sys.argv[1]):
        for old in olds:
            forget(old)
        for new in news:
            importlib.import_module(new)
        namespace = {"tumble": tumble}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            exec(code, namespace)
        said = [[str(w.message), w.filename] for w in caught if w.category is DeprecationWarning]
        results[code] = [bool(eval(check, namespace)), said]
    print(json.dumps(results))
""")


def _said(*renames: tuple[str, str]) -> list[str]:
    return [f"{old} is deprecated and will be removed in tumble 0.5: use {new}" for old, new in renames]


def _pickled_under(old: str, new: str, value: str) -> str:
    """Code that pickles ``value`` (protocol 2, whose globals are text), names the module ``old`` in place of
    ``new`` (as a pickle written before the rename does), and loads it back as ``got``."""
    return (f"import pickle\ndata = pickle.dumps({value}, protocol=2)\n"
            f"assert b'c{new}\\n' in data\n"
            f"got = pickle.loads(data.replace(b'c{new}\\n', b'c{old}\\n'))\nwant = {value}")


FRAMES = ("tumble.frames", "tumble.axisymmetric")
ANALYSIS = ("tumble.analysis", "tumble.measure")
VIEWER = ("tumble.viewer", "tumble.viz.viewer")
BODY = ("tumble.body", "tumble.rigid_body")
RIGID = ("tumble.rigid", "tumble.rigid_model")
PRISM = "tumble.RigidBody([[2.0, 0, 0], [0, 2.0, 0], [0, 0, 3.0]])"

#: (code that binds ``got``, the old modules it imports, the new ones, the check, the warnings it gives)
CASES = [
    ("import tumble.frames\ngot = tumble.frames", [FRAMES[0]], [FRAMES[1]], "got is tumble.axisymmetric",
     _said(FRAMES)),
    ("from tumble.frames import AxisymmetricBody as got", [FRAMES[0]], [FRAMES[1]],
     "got is tumble.axisymmetric.AxisymmetricBody", _said(FRAMES)),
    ("got = tumble.analysis.lyapunov_exponents", [ANALYSIS[0]], [ANALYSIS[1]],
     "got is tumble.measure.lyapunov_exponents", _said(ANALYSIS)),
    ("from tumble.analysis import poincare_section as got", [ANALYSIS[0]], [ANALYSIS[1]],
     "got is tumble.measure.poincare_section", _said(ANALYSIS)),
    ("from tumble.analysis._flips import flip_times as got", [ANALYSIS[0]], [ANALYSIS[1]],
     "got is tumble.measure.flip_times", _said(ANALYSIS, (f"{ANALYSIS[0]}._flips", f"{ANALYSIS[1]}._flips"))),
    ("import tumble.viewer\ngot = tumble.viewer.write_html", [VIEWER[0]], [VIEWER[1]],
     "got is tumble.viz.viewer.write_html", _said(VIEWER)),
    ("from tumble import viewer as got", [VIEWER[0]], [VIEWER[1]], "got is tumble.viz.viewer", _said(VIEWER)),
    ("from tumble.viewer.scenes import rigid as got", [VIEWER[0]], [f"{VIEWER[1]}.scenes.rigid"],
     "got is tumble.viz.viewer.scenes.rigid", _said(VIEWER, (f"{VIEWER[0]}.scenes", f"{VIEWER[1]}.scenes"))),
    ("from tumble.body import RigidBody as got", [BODY[0]], [BODY[1]], "got is tumble.RigidBody", _said(BODY)),
    ("got = tumble.body.principal_axes", [BODY[0]], [BODY[1]], "got is tumble.rigid_body.principal_axes",
     _said(BODY)),
    (_pickled_under(*BODY, PRISM), [BODY[0]], [BODY[1]], "type(got) is tumble.RigidBody and got == want",
     _said(BODY)),
    ("from tumble.rigid import RigidBodies as got", [RIGID[0]], [RIGID[1]], "got is tumble.rigid_model.RigidBodies",
     _said(RIGID)),
    ("import tumble.rigid\ngot = tumble.rigid.RigidBodies", [RIGID[0]], [RIGID[1]],
     "got is tumble.rigid_model.RigidBodies", _said(RIGID)),
    (_pickled_under(*RIGID, f"tumble.as_model({PRISM})"), [RIGID[0]], [RIGID[1]],
     "type(got) is tumble.rigid_model.RigidBodies and (got.inertia == want.inertia).all()", _said(RIGID)),
]


@pytest.fixture(scope="module")
def spelled() -> dict[str, list]:
    """Each case's code -> [its check, the DeprecationWarnings it gave], from one new process."""
    cases = json.dumps([case[:4] for case in CASES])
    out = subprocess.run([sys.executable, "-c", SPELLINGS, cases], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.splitlines()[-1])


@pytest.mark.parametrize(("code", "said"), [(case[0], case[4]) for case in CASES],
                         ids=[case[0].splitlines()[-1] if "pickle" not in case[0] else "pickle " + case[1][0]
                              for case in CASES])
def test_an_old_module_name_gives_the_new_module_with_a_warning_naming_it(spelled, code, said):
    same, warned = spelled[code]
    assert same
    # `from tumble import viewer` reads the attribute twice (the import system's hasattr, then the name): the
    # same warning twice; each at the line of the code that spelled the old name
    assert sorted({message for message, _ in warned}) == sorted(said) and len(warned) <= 2 * len(said)
    assert {where for _, where in warned} == {"<string>"}


def test_a_name_that_no_module_had_is_still_a_module_not_found_error():
    out = subprocess.run([sys.executable, "-c", "import tumble.frames_of_reference"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 1
    assert out.stderr.splitlines()[-1] == "ModuleNotFoundError: No module named 'tumble.frames_of_reference'"
