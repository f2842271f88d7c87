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
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from helpers import assert_one_line_error
import xarray as xr
from typer.testing import CliRunner

import tumble
from tumble._files import MAX_INPUT_BYTES, read_input, write_atomic, write_atomic_all
from tumble._validate import ValidationError
from tumble.cli import app
from tumble.trajectory import Extra, Trajectory
from tumble.viz.viewer._frames import MAX_FRAMES, check_budget

runner = CliRunner()

SCENARIO = ("[body]\nmoments = [1.0, 2.0, 3.0]\n[initial]\nomega = [0.1, 1.0, 0.1]\n[time]\nstop = 1.0\n"
            "samples = 3\n[solver]\nmethod = \"rk4\"\ndt = 0.5\n")


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])




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
    # only its old spelling (until 0.5) names the files: a deprecation line, then the refusal
    out = tmp_path / "r.html"
    out.write_text("old results")
    result = invoke("demo", "racket", "-o", out, "--plot", tmp_path / "r.png")
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr.splitlines()[1:] == [f"error: --plot's viewer page: {str(out)!r} is the same file as "
                                              "--output; give each output its own name"]
    assert listing(tmp_path) == {"r.html": b"old results"}


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
        path, beside = tmp_path / name, tmp_path / name.replace(".", "_")  # beside: its big file or device node
        beside.mkdir()
        _special(path, node, beside)
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


# -- 5. a full disk ------------------------------------------------------------------------------------


@pytest.mark.slow  # a fresh process importing tumble: some 10 s on 2 busy cores
def test_a_full_disk_is_one_error_line_and_the_old_results_stay(tmp_path):
    with tmpfs(tmp_path / "small", "size=64k") as small:
        scenario = small / "s.toml"  # 2001 samples: a NetCDF file of some 300 kB, past the 64 kB
        scenario.write_text(SCENARIO.replace("samples = 3", "samples = 2001").replace("dt = 0.5", "dt = 0.0005"))
        out = small / "out.nc"
        out.write_text("old results")
        env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
        done = subprocess.run([sys.executable, "-m", "tumble", "run", str(scenario), "-o", str(out)],
                              capture_output=True, text=True, env=env, timeout=300)
        assert (done.returncode, done.stdout) == (2, ""), done.stderr  # it died of SIGSEGV (-11)
        assert done.stderr == f"error: [Errno 28] No space left on device: {str(out)!r}\n"
        assert listing(small) == {"s.toml": scenario.read_bytes(), "out.nc": b"old results"}


# -- 9, 10, 11. result files: honest readings, named refusals -----------------------------------------


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    """A real saved result: 5 samples of rk4 on a torque-free RigidBody, and a vector extra."""
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    run = tumble.simulate(body, [0.1, 1.0, 0.1], t=np.linspace(0.0, 1.0, 5), method="rk4", dt=0.25)
    traj = Trajectory(run.t, run.q, run.omega, run.inertia, run.method, run.info,
                      {"wheel_speed": Extra(np.arange(10.0).reshape(5, 2), ("wheel",), "rad/s", "wheel rates")},
                      model="RigidBody")
    path = tmp_path_factory.mktemp("result") / "run.nc"
    traj.save(path)
    return path, traj


def _edited(saved: Path, path: Path, change) -> None:
    """``saved`` read with xarray (times as stored), changed by ``change(ds)``, written to ``path``."""
    ds = change(xr.load_dataset(saved, engine="h5netcdf", decode_times=False))
    ds.to_netcdf(path, engine="h5netcdf")


def _flipped(saved: Path, path: Path, variable: str | None) -> None:
    """``saved`` with one bit changed: in the first chunk of ``variable``'s data, or in the HDF5 signature."""
    offset = 0
    if variable is not None:
        with h5py.File(saved) as f:
            offset = f[variable].id.get_chunk_info(0).byte_offset + 3
    raw = bytearray(saved.read_bytes())
    raw[offset] ^= 0x10
    path.write_bytes(bytes(raw))


def _units(name, units):
    def change(ds):
        ds[name].attrs["units"] = units
        return ds
    return change


UNREADABLE = "not a readable tumble trajectory"
DAMAGES = {
    "empty": (lambda saved, path: path.write_bytes(b""), UNREADABLE),
    "truncated to 100 bytes": (lambda saved, path: path.write_bytes(saved.read_bytes()[:100]), UNREADABLE),
    "half of it": (lambda saved, path: path.write_bytes(saved.read_bytes()[:saved.stat().st_size // 2]),
                   UNREADABLE),
    "last byte cut": (lambda saved, path: path.write_bytes(saved.read_bytes()[:-1]), UNREADABLE),
    "signature bit": (lambda saved, path: _flipped(saved, path, None), UNREADABLE),
    **{f"bit of {name}": ((lambda name: lambda saved, path: _flipped(saved, path, name))(name),
                          "filter returned failure during read")  # the Fletcher-32 checksum
       for name in ("time", "q", "omega", "inertia", "wheel_speed")},
    **{f"{name} deleted": ((lambda name: lambda saved, path: _edited(saved, path, lambda ds: ds.drop_vars(name)))(name),
                           f"not a tumble trajectory (missing {name})") for name in ("time", "q", "omega", "inertia")},
    "q on 4 times of another dimension": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(
        q=ds.q.isel(time=slice(0, 4)).rename(time="t2"))), "Dimensions {'time'} do not exist"),
    "omega's axis renamed": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(
        omega=ds.omega.rename(axis="ax"))), "ax: must hold real numbers, got <U1 values"),
    "omega as strings": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(omega=ds.omega.astype(str))),
                         "omega: must hold real numbers, got <U"),
    "omega complex": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(omega=ds.omega * (1 + 1e-3j))),
                      "omega: must hold real numbers, got complex128 values"),
    "omega in deg/s": (lambda saved, path: _edited(saved, path, _units("omega", "deg/s")),
                       "omega: units must be 'rad/s' (as tumble writes them), got 'deg/s'"),
    "time in furlongs": (lambda saved, path: _edited(saved, path, _units("time", "furlongs")),
                         "time: units must be a unit of time"),
    "extra NaN": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(wheel_speed=ds.wheel_speed * np.nan)),
                  "wheel_speed: must be finite (found nan at index (0, 0))"),
    "extra inf": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(wheel_speed=ds.wheel_speed / 0.0)),
                  "wheel_speed: must be finite (found nan at index (0, 0))"),
    "times out of order": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign_coords(
        time=ds.time.values[[0, 2, 1, 3, 4]])), "t: must be strictly increasing or strictly decreasing"),
    "component labels twice": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign_coords(
        component=["w", "w", "y", "z"])), "InvalidIndexError"),
    "rates of 1e160 rad/s": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign(omega=ds.omega * 1e160)),
                             "energy: must be finite (found inf at index 0)"),
    "solver setting an array": (lambda saved, path: _edited(saved, path, lambda ds: ds.assign_attrs(
        solver_dt=np.array([0.25, 0.5]))), "info['dt']: must be a float, an int or a string, got ndarray"),
}


@pytest.mark.parametrize("damage", list(DAMAGES))
def test_a_damaged_result_is_refused_by_name_by_load_info_and_view(result, tmp_path, damage):
    saved, _ = result
    make, message = DAMAGES[damage]
    path = tmp_path / "bad.nc"
    make(saved, path)
    with pytest.raises(ValidationError, match=re.escape(message)) as refusal:
        tumble.load(path)
    assert str(refusal.value).startswith(f"{path}: ")
    assert_one_line_error(invoke("info", path), f"{path}: ")
    assert_one_line_error(invoke("view", path, "-o", tmp_path / "bad.html"), f"traj: {str(path)!r} is not")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.nc"]


@pytest.mark.parametrize("units, seconds", [("s", 1.0), ("seconds since 2000-01-01 00:00:00", 1.0),
                                            ("ms", 1e-3), ("hours", 3600.0)])
def test_time_is_read_in_seconds_from_its_units(result, tmp_path, units, seconds):
    saved, traj = result
    _edited(saved, tmp_path / "t.nc", _units("time", units))
    back = tumble.load(tmp_path / "t.nc")
    np.testing.assert_array_equal(back.t, traj.t * seconds)  # 0, 0.25, ... s: exact in binary
    np.testing.assert_array_equal(back.omega, traj.omega)


def test_a_saved_result_reads_back_bit_for_bit_with_its_checksums(result):
    saved, traj = result
    back = tumble.load(saved)
    for name in ("t", "q", "omega", "inertia", "wheel_speed"):
        np.testing.assert_array_equal(getattr(back, name), getattr(traj, name))
    with h5py.File(saved) as f:
        assert all(f[name].fletcher32 for name in ("time", "q", "omega", "inertia", "wheel_speed"))


def test_info_prints_files_tumble_writes_an_empty_batch_and_a_string_setting(tmp_path):
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    tumble.simulate(body, np.zeros((0, 3)), t=[0.0, 0.5, 1.0], method="rk4", dt=0.5).save(tmp_path / "empty.nc")
    result = invoke("info", tmp_path / "empty.nc")
    assert result.exit_code == 0, result.stderr
    assert "bodies    0 (batch)" in result.stdout and "drift     energy n/a, |L| n/a, L_I n/a" in result.stdout
    run = tumble.simulate(body, [0.1, 1.0, 0.1], t=[0.0, 0.5, 1.0], method="rk4", dt=0.5)
    Trajectory(run.t, run.q, run.omega, run.inertia, "rk4", {"dt": "half a second"}).save(tmp_path / "s.nc")
    result = invoke("info", tmp_path / "s.nc")
    assert result.exit_code == 0, result.stderr
    assert "method    rk4 (dt half a second)" in result.stdout


# -- 7. the viewer's frame budget is bounded ----------------------------------------------------------


def test_view_refuses_a_frame_budget_past_the_bound(result, tmp_path):
    saved, _ = result
    assert check_budget(MAX_FRAMES) == MAX_FRAMES == 100_000
    assert_one_line_error(invoke("view", saved, "-o", tmp_path / "v.html", "--frames", MAX_FRAMES + 1),
                          f"frames: must be at most 100000 (a page of about 80 MB; a browser animates no more), "
                          f"got {MAX_FRAMES + 1}")
    assert list(tmp_path.iterdir()) == []


def test_demo_top_checks_its_three_files_before_it_runs(tmp_path):
    os.mkfifo(tmp_path / "top.png")
    assert_one_line_error(invoke("demo", "top", "-o", tmp_path),
                          f"--output: {str(tmp_path / 'top.png')!r} is a FIFO")
    assert listing(tmp_path) == {"top.png": stat.S_IFIFO}
