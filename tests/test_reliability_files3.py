"""Reliability of files, round 3 (issue 34): no output lost or replaced wrongly, bounded inputs, honest results.

Outputs: every output of a command is checked before anything runs (a new name or a regular file, in a
writable directory, one file each) and all are renamed together at the end. Inputs: one reader for every
document, a regular file of bounded size. Result files: ``tumble.load``, ``tumble info`` and ``tumble view``
refuse a damaged or edited file by name. Symbolic links, FIFOs and device nodes are made in ``tmp_path``
(a device node only as root); the real ``/dev`` is never touched.
"""

import contextlib
import os
import re
import stat
import subprocess
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tumble._files import MAX_INPUT_BYTES, read_input, write_atomic, write_atomic_all
from tumble._validate import ValidationError
from tumble.cli import app

runner = CliRunner()

SCENARIO = ("[body]\nmoments = [1.0, 2.0, 3.0]\n[initial]\nomega = [0.1, 1.0, 0.1]\n[time]\nstop = 1.0\n"
            "samples = 3\n[solver]\nmethod = \"rk4\"\ndt = 0.5\n")


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def assert_one_line_error(result, message, code=2):
    """Exit ``code``, nothing on stdout, one ``error:`` line holding ``message``, no traceback."""
    assert result.exit_code == code, (result.exit_code, result.stderr, result.exception)
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], result.stderr
    assert "Traceback" not in result.stderr


def listing(directory: Path) -> dict:
    """Each entry of ``directory``: its kind and, for a regular file, its bytes (a symlink: its target)."""
    out = {}
    for p in directory.iterdir():
        mode = p.lstat().st_mode
        out[p.name] = (p.read_bytes() if stat.S_ISREG(mode) else f"-> {os.readlink(p)}" if stat.S_ISLNK(mode)
                       else stat.S_IFMT(mode))
    return out


@pytest.fixture
def scenario(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO)
    return path


@contextlib.contextmanager
def tmpfs(path: Path, options: str):
    """A tmpfs mounted at ``path`` with ``options`` (root only; the test is skipped where mounting is refused)."""
    path.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here ({done.stderr.decode().strip() or done.returncode})")
    try:
        yield path
    finally:
        subprocess.run(["umount", str(path)], check=True)


# -- 1. all outputs of a command together -------------------------------------------------------------


def test_a_failing_write_leaves_every_output_of_the_group_as_it_was(tmp_path):
    first, second = tmp_path / "out.nc", tmp_path / "out.png"
    first.write_text("old results")

    def fail(tmp):
        Path(tmp).write_text("half a figure")
        raise OSError("cannot write the figure")

    with pytest.raises(OSError, match="cannot write the figure"):
        write_atomic_all([(first, lambda tmp: Path(tmp).write_text("new results")), (second, fail)])
    assert listing(tmp_path) == {"out.nc": b"old results"}  # not replaced, no temporary, no lock


def test_run_with_a_plot_that_cannot_be_written_keeps_the_old_results(tmp_path, scenario):
    out, plot = tmp_path / "out.nc", tmp_path / "plot.png"
    out.write_text("old results")
    os.mkfifo(plot)
    assert_one_line_error(invoke("run", scenario, "-o", out, "--plot", plot),
                          f"--plot: {str(plot)!r} is a FIFO; an output must be a new name or a regular file")
    assert listing(tmp_path) == {"s.toml": SCENARIO.encode(), "out.nc": b"old results", "plot.png": stat.S_IFIFO}


# -- 2. a demo's outputs that are one file ------------------------------------------------------------


def test_demo_racket_refuses_a_viewer_page_onto_its_results(tmp_path):
    out = tmp_path / "r.html"
    out.write_text("old results")
    assert_one_line_error(invoke("demo", "racket", "-o", out, "--plot", tmp_path / "r.png"),
                          f"--plot's viewer page: {str(out)!r} is the same file as --output")
    assert listing(tmp_path) == {"r.html": b"old results"}


def test_demo_polhode_refuses_an_html_figure_that_its_page_would_replace(tmp_path):
    assert_one_line_error(invoke("demo", "polhode", "-o", tmp_path / "p.html"),
                          "--output's viewer page: ")
    assert listing(tmp_path) == {}


# -- 3. outputs that are not regular files, or one file twice ------------------------------------------


@pytest.mark.parametrize("node", ["symlink", "fifo", "device", "directory"])
def test_an_output_that_is_not_a_regular_file_is_refused_and_left_alone(tmp_path, scenario, node):
    out = tmp_path / "out.nc"
    target = tmp_path / "target.nc"
    target.write_text("kept")
    if node == "symlink":
        out.symlink_to(target)
    elif node == "fifo":
        os.mkfifo(out)
    elif node == "device":
        if os.geteuid() != 0:
            pytest.skip("making a device node needs root")
        os.mknod(out, stat.S_IFCHR | 0o600, os.makedev(1, 3))  # a null device of our own, in tmp_path
    else:
        out.mkdir()
    kind = {"symlink": "a symbolic link", "fifo": "a FIFO", "device": "a character device",
            "directory": "a directory"}[node]
    before = listing(tmp_path)
    assert_one_line_error(invoke("run", scenario, "-o", out), f"--output: {str(out)!r} is {kind}")
    with pytest.raises(ValidationError, match=f"is {kind}; an output must be a new name or a regular file"):
        write_atomic(out, lambda tmp: Path(tmp).write_text("replaced"))
    assert listing(tmp_path) == before


def test_two_outputs_of_one_command_that_are_one_file_are_refused(tmp_path, scenario):
    out = tmp_path / "out.nc"
    out.write_text("old results")
    os.link(out, tmp_path / "hard.png")
    for plot, name in [(tmp_path / "sub" / ".." / "out.nc", "sub/../out.nc"), (tmp_path / "hard.png", "hard.png")]:
        (tmp_path / "sub").mkdir(exist_ok=True)
        assert_one_line_error(invoke("run", scenario, "-o", out, "--plot", plot),
                              f"--plot: {str(plot)!r} is the same file as --output")
    assert_one_line_error(invoke("run", scenario, "-o", scenario), "--output: ")
    with pytest.raises(ValidationError, match="is the same file as"):
        write_atomic_all([(out, lambda tmp: None), (tmp_path / "." / "out.nc", lambda tmp: None)])
    assert (out.read_text(), sorted(p.name for p in tmp_path.iterdir())) == (
        "old results", ["hard.png", "out.nc", "s.toml", "sub"])


# -- 4. the temporaries of another file are not stale ones ---------------------------------------------


def test_writing_a_file_keeps_the_live_temporary_of_a_file_whose_name_begins_with_its_name(tmp_path):
    out, page = tmp_path / "out.nc", tmp_path / "out.nc.html"

    def write_page(tmp):  # while the page is being written, out.nc is written (another thread, process...)
        Path(tmp).write_text("page, first half")
        write_atomic(out, lambda tmp_out: Path(tmp_out).write_text("results"))
        with open(tmp, "a") as fh:  # the page's temporary is still there to finish
            fh.write(", second half")

    write_atomic(page, write_page)
    assert listing(tmp_path) == {"out.nc": b"results", "out.nc.html": b"page, first half, second half"}


# -- 8. an unwritable place is named as such ---------------------------------------------------------


def test_a_read_only_file_system_is_named_not_taken_for_another_writer(tmp_path, scenario):
    with tmpfs(tmp_path / "ro", "size=64k,ro") as ro:
        with pytest.raises(PermissionError, match=r"cannot write in directory .* \(read-only file system\)"):
            write_atomic(ro / "out.txt", lambda tmp: Path(tmp).write_text("x"))
        assert_one_line_error(invoke("run", scenario, "-o", ro / "out.nc"),
                              f"--output: cannot write in directory {str(ro)!r} (read-only file system)")
        assert list(ro.iterdir()) == []


# -- 6. one reader for every input document: a regular file of bounded size ---------------------------


def _special(path: Path, node: str, tmp_path: Path) -> None:
    """Make ``path`` a FIFO (no writer: a reader would wait for ever), or a symbolic link to a sparse
    regular file one byte past the bound (no disk used) or to a character device (``/dev/zero``'s numbers,
    a node of our own in tmp_path; root only)."""
    if node == "fifo":
        os.mkfifo(path)
    elif node == "too large":
        big = tmp_path / "big"
        with open(big, "wb") as fh:
            fh.truncate(MAX_INPUT_BYTES + 1)
        path.symlink_to(big)
    else:
        if os.geteuid() != 0:
            pytest.skip("making a device node needs root")
        os.mknod(tmp_path / "zero", stat.S_IFCHR | 0o600, os.makedev(1, 5))
        path.symlink_to(tmp_path / "zero")


RULES = {"fifo": "not a regular file (a FIFO)", "too large": f"larger than {MAX_INPUT_BYTES} bytes",
         "device": "not a regular file (a character device)"}


@pytest.mark.parametrize("node", list(RULES))
def test_scenario_and_robot_files_are_refused_unless_regular_and_bounded(tmp_path, node):
    for name, args in [("s.toml", ("run", "{}", "-o", tmp_path / "out.nc")),
                       ("arm.toml", ("robot", "torques", "{}", "--q", "0")),
                       ("arm.urdf", ("robot", "torques", "{}", "--q", "0"))]:
        path = tmp_path / name
        (tmp_path / name.replace(".", "_")).mkdir()
        _special(path, node, tmp_path / name.replace(".", "_"))
        assert_one_line_error(invoke(*(str(path) if a == "{}" else a for a in args)), f"{path}: {RULES[node]}")
    assert not (tmp_path / "out.nc").exists()


@pytest.mark.parametrize("node", list(RULES))
def test_ins_csv_tables_are_refused_unless_regular_and_bounded(tmp_path, node):
    from tumble.ins import read_csv

    _special(tmp_path / "imu.csv", node, tmp_path)
    with pytest.raises(ValidationError, match=re.escape(f"imu.csv: {RULES[node]}")):
        read_csv(tmp_path / "imu.csv")


def test_read_input_reads_a_regular_file_through_a_symbolic_link(tmp_path):
    (tmp_path / "a.toml").write_bytes(b"x = 1\n")
    (tmp_path / "link.toml").symlink_to(tmp_path / "a.toml")
    assert read_input(tmp_path / "link.toml") == b"x = 1\n"
    with pytest.raises(ValidationError, match="larger than 5 bytes"):
        read_input(tmp_path / "link.toml", limit=5)
