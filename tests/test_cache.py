"""Compiled code keyed on content (tumble/_cache.py): an edit of any source compiled into a function makes its
cached code stale, an edit of the layers above the compiled code does not, and the key stays in the user's
NUMBA_CACHE_DIR."""

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tumble import _cache

SRC = Path(__file__).resolve().parents[1] / "src" / "tumble"

# attitude.to_rotvec runs attitude._to_rotvec_loop, compiled with _quat.qlog in it: the rotation vector of a
# rotation by 1 rad about x
PROBE = """
import math, tumble
print(tumble.attitude.to_rotvec([math.cos(0.5), math.sin(0.5), 0.0, 0.0]).round(12).tolist())
"""
QLOG_RETURN = "    return (k * qx, k * qy, k * qz)\n"


def _run(root: Path, cache: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(root), "NUMBA_CACHE_DIR": str(cache), "NUMBA_DEBUG_CACHE": "1"}
    done = subprocess.run([sys.executable, "-c", PROBE], env=env, cwd=root, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return done


@pytest.mark.slow
def test_an_edit_of_an_inlined_kernel_recompiles_its_callers_and_an_edit_of_the_cli_recompiles_nothing(tmp_path):
    root, cache = tmp_path / "src", tmp_path / "cache"
    shutil.copytree(SRC, root / "tumble", ignore=shutil.ignore_patterns("__pycache__"))
    first = _run(root, cache)
    assert first.stdout.splitlines()[-1] == "[1.0, 0.0, 0.0]"
    assert "[cache] data saved" in first.stdout
    assert list(cache.rglob("attitude._to_rotvec_loop-*.nbi")), "the cache is not in NUMBA_CACHE_DIR"

    # qlog scaled by 2, in _quat.py; attitude.py, which holds the cached caller, is unchanged (Numba's own stamp,
    # a hash of the caller's file, would load the stale loop and print [1.0, 0.0, 0.0] again)
    quat = root / "tumble" / "_quat.py"
    source = quat.read_text()
    assert source.count(QLOG_RETURN) == 1
    quat.write_text(source.replace(QLOG_RETURN, "    return (2.0 * k * qx, 2.0 * k * qy, 2.0 * k * qz)\n"))
    edited = _run(root, cache)
    assert edited.stdout.splitlines()[-1] == "[2.0, 0.0, 0.0]"

    # the CLI is no part of any compiled function: editing it loads everything from the cache
    with open(root / "tumble" / "cli" / "main.py", "a") as cli:
        cli.write("\n# an edit\n")
    unchanged = _run(root, cache)
    assert unchanged.stdout.splitlines()[-1] == "[2.0, 0.0, 0.0]"
    assert "[cache] data loaded" in unchanged.stdout and "[cache] data saved" not in unchanged.stdout


# Adds to a cache index one more signature, an object of a class of a module that the test then deletes: the
# index of a tumble version with a model kind this one does not have.
REWRITE = """
import pickle, sys
from tumble_gone_kind import GoneModel
with open(sys.argv[1], "rb") as f:
    version = pickle.load(f)
    stamp, overloads = pickle.loads(f.read())
overloads[(GoneModel,)] = "gone.nbc"
with open(sys.argv[1], "wb") as f:
    pickle.dump(version, f, protocol=-1)
    f.write(pickle.dumps((stamp, overloads), protocol=-1))
"""


@pytest.mark.slow
def test_an_index_naming_a_class_that_is_gone_is_stale_not_an_error(tmp_path):
    # a cache outlives the sources it was compiled from (a git branch, an upgrade or a downgrade): Numba
    # unpickles an index before it checks its stamp, and a class the index names that is no longer there raised
    # ModuleNotFoundError at every call; the function compiles again instead, and its index is rewritten
    cache, gone = tmp_path / "cache", tmp_path / "gone"
    assert _run(SRC.parent, cache).stdout.splitlines()[-1] == "[1.0, 0.0, 0.0]"
    (index,) = cache.rglob("attitude._to_rotvec_loop-*.nbi")
    gone.mkdir()
    (gone / "tumble_gone_kind.py").write_text("class GoneModel:\n    pass\n")
    subprocess.run([sys.executable, "-c", REWRITE, str(index)], env={**os.environ, "PYTHONPATH": str(gone)},
                   check=True, timeout=60)
    shutil.rmtree(gone)
    assert b"tumble_gone_kind" in index.read_bytes()
    again = _run(SRC.parent, cache)
    assert again.stdout.splitlines()[-1] == "[1.0, 0.0, 0.0]"
    assert "[cache] data saved" in again.stdout
    assert b"tumble_gone_kind" not in index.read_bytes()
    third = _run(SRC.parent, cache)
    assert "[cache] data loaded" in third.stdout and "[cache] data saved" not in third.stdout


def test_the_key_is_the_content_of_the_compiled_sources_and_the_compiler_versions(tmp_path):
    root = tmp_path / "tumble"
    shutil.copytree(SRC, root, ignore=shutil.ignore_patterns("__pycache__"))
    key = _cache.content_key.__wrapped__(root)
    assert key == _cache.content_key.__wrapped__(SRC)  # the content, not the place or the file times
    os.utime(root / "_quat.py", (0, 0))
    assert _cache.content_key.__wrapped__(root) == key
    (root / "viz" / "top.py").write_text("# edited\n")
    assert _cache.content_key.__wrapped__(root) == key
    (root / "kernels" / "rigid.py").write_text("# edited\n")
    assert _cache.content_key.__wrapped__(root) != key


# -- the layers left out of the key ------------------------------------------------------------------------

# what makes compiled code: Numba's decorators and tumble's own (_protocol.implements, the spacecraft kernels'
# inline)
COMPILING = {"njit", "jit", "overload", "overload_method", "overload_attribute", "register_jitable", "intrinsic",
             "generated_jit", "vectorize", "guvectorize", "cfunc", "stencil", "jitclass", "implements", "inline"}


def _module_name(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _module_level_imports(path: Path) -> set[str]:
    """The modules ``path`` imports outside functions (what its globals can hold), relative imports resolved."""
    module = _module_name(path)
    package = (module if path.name == "__init__.py" else module.rpartition(".")[0]).split(".")
    found: set[str] = set()
    nodes = list(ast.parse(path.read_text()).body)
    while nodes:
        node = nodes.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = ".".join(package[:len(package) - node.level + 1] + [node.module or ""]).strip(".") \
                if node.level else node.module
            found |= {base} | {f"{base}.{alias.name}" for alias in node.names}
        nodes.extend(ast.iter_child_nodes(node))
    return found


def _names(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    return ({node.id for node in ast.walk(tree) if isinstance(node, ast.Name)}
            | {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)})


def test_the_layers_left_out_of_the_key_compile_nothing_and_no_compiled_module_imports_them():
    covered = set(_cache.sources(SRC))
    left_out = [path for path in SRC.rglob("*.py") if path not in covered and "__pycache__" not in path.parts]
    assert left_out and all(path.relative_to(SRC).parts[0] in _cache.UNCOMPILED for path in left_out)
    left_out_modules = {_module_name(path) for path in left_out}
    for path in left_out:
        assert not _names(path) & COMPILING, f"{path.relative_to(SRC)} compiles code: it must be in the key"
        assert not {name for name in _module_level_imports(path) if name.split(".")[0] == "numba"}, path
    for path in covered:
        reached = {name for name in _module_level_imports(path)
                   if any(name == module or name.startswith(module + ".") for module in left_out_modules)}
        if path == SRC / "__init__.py":  # `import tumble` fills Trajectory's table of views (Python functions only)
            reached -= {"tumble.viz", "tumble.viz.trajectory"}
        assert not reached, f"{path.relative_to(SRC)} imports {reached}: they must be in the key"


@pytest.mark.slow
def test_cache_info_counts_the_compiled_functions_and_cache_clear_removes_them(tmp_path):
    cache = tmp_path / "cache"
    _run(SRC.parent, cache)  # compiles attitude.to_rotvec's loop into the empty NUMBA_CACHE_DIR
    env = {**os.environ, "PYTHONPATH": str(SRC.parent), "NUMBA_CACHE_DIR": str(cache)}

    def tumble_cache(command):
        done = subprocess.run([sys.executable, "-m", "tumble", "cache", command], env=env, capture_output=True,
                              text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        return dict(line.split(None, 1) for line in done.stdout.splitlines())

    indexes = list(cache.rglob("*.nbi"))
    data = list(cache.rglob("*.nbc"))
    assert indexes and data
    info = tumble_cache("info")
    assert info["cache"] == str(cache) and info["key"] == _cache.content_key()
    assert info["functions"] == str(len(indexes))
    assert tumble_cache("clear")["removed"].startswith(f"{len(indexes) + len(data)} files, ")
    assert not list(cache.rglob("*.nb[ic]"))
    assert tumble_cache("info")["functions"] == "0"


# The robots' inverse and forward dynamics (tumble.kernels.featherstone) over 200 random states, as the bytes'
# SHA-256, then whether the two batch kernels were compiled or loaded from the cache.
DYNAMICS = """
import hashlib
import numpy as np
import tumble
from tumble import robot
from tumble.kernels import featherstone

rng = np.random.default_rng(3)
for name in ("puma560.toml", "panda.toml"):
    chain = robot.load(tumble.examples.directory() / "robots" / name)
    q, qd, x = (rng.normal(size=(200, chain.dof)) for _ in range(3))
    for tau in (robot.rnea(chain, q, qd, x), robot.forward_dynamics(chain, q, qd, x)):
        print(name, hashlib.sha256(np.ascontiguousarray(tau).tobytes()).hexdigest())
for kernel in (featherstone.rnea_batch, featherstone.aba_batch):
    print(kernel.__name__, sum(kernel.stats.cache_misses.values()), "compiled", sum(kernel.stats.cache_hits.values()),
          "loaded")
"""


@pytest.mark.slow
def test_code_loaded_from_the_cache_gives_the_freshly_compiled_results_bit_for_bit(tmp_path):
    # Before the featherstone kernels stopped contracting a·b + c into fused multiply-adds, each copy of a
    # function (in its own module, and inlined again in each caller's) rounded differently, and which copy ran
    # depended on what the JIT had linked first: the PUMA's RNEA and ABA differed in the last bits here.
    env = {**os.environ, "PYTHONPATH": str(SRC.parent), "NUMBA_CACHE_DIR": str(tmp_path)}

    def run():
        done = subprocess.run([sys.executable, "-c", DYNAMICS], env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        return done.stdout.splitlines()

    fresh, loaded = run(), run()
    assert fresh[-2:] == ["rnea_batch 1 compiled 0 loaded", "aba_batch 1 compiled 0 loaded"]
    assert loaded[-2:] == ["rnea_batch 0 compiled 1 loaded", "aba_batch 0 compiled 1 loaded"]
    assert len(fresh) == 6 and loaded[:4] == fresh[:4]
