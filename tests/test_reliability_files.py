"""Results written atomically under signals, stale temporary files, concurrent writers (issue 18)."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tumble.trajectory import write_atomic

SRC = Path(__file__).resolve().parents[1] / "src"


def test_stale_temporary_siblings_of_killed_runs_are_removed(tmp_path):
    stale = [tmp_path / ".out.txt.0a1b2c3d.tmp", tmp_path / ".out.txt.ffffffff.tmp"]  # the writer's own pattern
    others = [tmp_path / ".other.txt.0a1b2c3d.tmp",  # another output's
              tmp_path / ".out.txt.html.0a1b2c3d.tmp",  # the file out.txt.html's, whose name begins with out.txt
              tmp_path / ".out.txt.k2j3.tmp"]  # not a name the writer makes
    for p in [*stale, *others]:
        p.write_text("partial")
    write_atomic(tmp_path / "out.txt", lambda tmp: Path(tmp).write_text("done"))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([p.name for p in others] + ["out.txt"])
    assert (tmp_path / "out.txt").read_text() == "done"


def test_a_second_writer_to_the_same_path_is_refused_and_the_first_wins(tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("old")
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    first = subprocess.Popen([sys.executable, "-c", WRITER, str(out)], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True, env=env)  # a writer at work, holding the lock
    try:
        assert first.stdout.readline() == "writing\n"
        with pytest.raises(FileExistsError, match=r"out.txt: another process is writing it now"):
            write_atomic(out, lambda tmp: Path(tmp).write_text("second"))
        assert out.read_text() == "old"
        first.stdin.write("done\n")  # the first writer finishes
        first.stdin.close()
        assert first.wait(timeout=120) == 0
    finally:
        first.kill()
        first.wait()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"] and out.read_text() == "first"


WRITER = """
import signal, sys, time
from pathlib import Path
from tumble.trajectory import write_atomic

# Ctrl-C raises KeyboardInterrupt, as in a terminal, even where this process was started with SIGINT ignored
# (a shell's background job, as CI may run the suite)
signal.signal(signal.SIGINT, signal.default_int_handler)

def write(tmp):
    Path(tmp).write_text("partial")
    print("writing", flush=True)
    if sys.stdin.readline() != "done\\n":  # until told (an interrupt test signals it first)
        time.sleep(60)
    Path(tmp).write_text("first")

write_atomic(sys.argv[1], write)
"""


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, -signal.SIGINT)])
def test_a_run_interrupted_while_writing_leaves_no_temporary_file(tmp_path, sig, code):
    out = tmp_path / "out.txt"
    out.write_text("old")
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    child = subprocess.Popen([sys.executable, "-c", WRITER, str(out)], stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert child.stdout.readline() == "writing\n"
        child.send_signal(sig)
        assert child.wait(timeout=120) == code  # SIGINT: KeyboardInterrupt, then Python dies of SIGINT
    finally:
        child.kill()
        child.wait()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"] and out.read_text() == "old"
