"""``import tumble`` on a read-only install with no writable HOME (issue 18): Numba's cache falls back to a
temporary directory with one warning, instead of failing the import."""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "tumble"

PROBE = """
import warnings
warnings.simplefilter("always")
with warnings.catch_warnings(record=True) as caught:
    import tumble
    import numba
    print(tumble.attitude.to_rotvec([1.0, 0.0, 0.0, 0.0]).tolist())  # runs compiled, cached code
print(len(caught), numba.config.CACHE_DIR)
for w in caught:
    print(w.category.__name__, w.message)
"""


def test_import_on_a_read_only_package_without_home_falls_back_to_a_temporary_cache():
    root = tempfile.mkdtemp(prefix="tumble-readonly-")
    try:
        os.chmod(root, 0o755)
        shutil.copytree(SRC, Path(root) / "tumble", ignore=shutil.ignore_patterns("__pycache__"))
        for directory, _, _ in os.walk(root):
            # no cache beside the sources: read-only modes, and (as root writes through modes) a plain file
            # where each __pycache__ directory would be made
            if directory != root:
                (Path(directory) / "__pycache__").touch()
            os.chmod(directory, 0o555)
        env = {k: v for k, v in os.environ.items() if k not in ("HOME", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
        env["PYTHONPATH"] = root
        env["HOME"] = "/dev/null/home"  # no home directory can be made there, not even by root
        result = subprocess.run([sys.executable, "-c", PROBE], env=env, cwd="/", capture_output=True, text=True,
                                timeout=120)
    finally:
        for directory, _, _ in os.walk(root):
            os.chmod(directory, 0o755)
        shutil.rmtree(root)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == "[0.0, 0.0, 0.0]"
    count, cache = lines[1].split(" ", 1)
    assert count == "1" and "tumble-numba-cache-" in cache
    assert lines[2].startswith("RuntimeWarning tumble: neither the package directory nor the user's cache")
    shutil.rmtree(cache, ignore_errors=True)
