"""Reliability of the command line (issue 18): every bad input is one ``error:`` line and exit code 2.

A corpus of bad inputs, each through the command that reads it; the trajectory file the ``info`` cases
damage comes from a 2-step rk4 run of a torque-free RigidBody (a compiled specialization the suite builds).
"""

import os

import h5py
import numpy as np
import pytest
from helpers import assert_one_line_error
import xarray as xr
from typer.testing import CliRunner

import tumble
from tumble.cli import app

runner = CliRunner()

SCENARIO = "[body]\nmoments = [1.0, 2.0, 3.0]\n[initial]\nomega = [0.1, 1.0, 0.1]\n[time]\nstop = {stop}\nsamples = 3\n"


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])




@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """A trajectory file of 3 samples written by tumble."""
    path = tmp_path_factory.mktemp("traj") / "run.nc"
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    tumble.simulate(body, [0.1, 1.0, 0.1], t=[0.0, 0.5, 1.0], method="rk4", dt=0.5).save(path)
    return path


def _altered(saved, tmp_path, name, change):
    ds = xr.load_dataset(saved, engine="h5netcdf")
    ds[name].values[...] = change(ds[name].values)
    path = tmp_path / f"{name}.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    return path


# -- tumble run ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("text, message, code", [
    (SCENARIO.format(stop=1.0) + '[solver]\nmethod = "rk4"\ndt = 1e-300\n', "max_steps: the run needs 1e+300 steps",
     2),
    (SCENARIO.format(stop=1e308) + '[solver]\nmethod = "rk4"\ndt = 1.0\n', "max_steps: the run needs 1e+308 steps", 2),
    # the integrator gives up (a tumble.SolverError): exit 2 too, after 1000 steps instead of 1e8
    (SCENARIO.format(stop=1e300) + '[solver]\nmethod = "dop853"\n', "max_steps: the run would need", 2),
    ("a = " + "{b = " * 1000 + "1" + "}" * 1000 + "\n", "bad.toml: ", 2),
], ids=["dt 1e-300", "stop 1e308", "dop853 stop 1e300", "1000-deep inline table"])
def test_run_refuses_bad_scenarios_in_one_line(tmp_path, text, message, code):
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    result = invoke("run", bad, "-o", tmp_path / "out.nc")
    assert_one_line_error(result, message, code)
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


def test_run_refuses_a_scenario_that_is_not_utf8(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"name = \"\xff\xfe\"\n")
    assert_one_line_error(invoke("run", bad, "-o", tmp_path / "out.nc"), "bad.toml")


# -- tumble info --------------------------------------------------------------------------------------


def test_info_reads_the_undamaged_file(saved):
    result = invoke("info", saved)
    assert result.exit_code == 0 and "0 to 1 s, 3 samples" in result.stdout


@pytest.mark.parametrize("damage, message", [
    ("junk", "not a readable tumble trajectory"),
    ("truncated", "not a readable tumble trajectory"),
    ("directory", "not a readable Zarr store"),  # a directory is read as a sweep's store
    ("fifo", "not a regular file"),
    ("missing", "not a readable tumble trajectory"),
    ("not a trajectory", "not a tumble trajectory (missing time, q, omega, inertia)"),
    ("q off the unit sphere", "q: must be unit quaternions (||q| - 1| <= 1e-09), |q[1]| = 0.99999818"),
    ("negative inertia", "inertia: must be positive semi-definite"),
    ("nan omega", "omega: must be finite"),
    ("1e12 elements declared", "variables: the 1 variable(s) it declares need 7.3 TiB (8e+12 bytes), more than half "
                               "this machine's memory"),
])
def test_info_refuses_damaged_and_hostile_files_in_one_line(saved, tmp_path, damage, message):
    path = tmp_path / "bad.nc"
    if damage == "junk":
        path.write_text("not netcdf")
    elif damage == "truncated":
        path.write_bytes(saved.read_bytes()[:2000])
    elif damage == "directory":
        path.mkdir()
    elif damage == "fifo":
        os.mkfifo(path)  # opening it would block for ever
    elif damage == "not a trajectory":
        xr.Dataset({"x": ("n", np.zeros(3))}).to_netcdf(path, engine="h5netcdf")
    elif damage == "q off the unit sphere":
        path = _altered(saved, tmp_path, "q", lambda q: np.where(np.arange(3)[:, None] == 1, q * 0.99999818, q))
    elif damage == "negative inertia":
        path = _altered(saved, tmp_path, "inertia", lambda inertia: -inertia)
    elif damage == "nan omega":
        path = _altered(saved, tmp_path, "omega", lambda omega: omega * np.nan)
    elif damage == "1e12 elements declared":
        with h5py.File(path, "w") as f:  # a few kB on disk, chunked and never written
            f.create_dataset("time", shape=(10**12,), dtype="f8", chunks=(1024,))
    result = invoke("info", path)
    assert_one_line_error(result, message)
    assert f"{path}: " in result.stderr


# -- tumble robot torques -----------------------------------------------------------------------------


@pytest.mark.parametrize("name, content, message", [
    ("bad.toml", b"name = \"\xff\"\n", "bad.toml"),
    ("bad.urdf", b'<robot name="r"><link name="base"/><link name="a"><inertial><mass value="1"/><mass value="2"/>'
                 b'<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j1" '
                 b'type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>',
     "link 'a' <inertial>: has 2 <mass> elements; at most one is allowed"),
    ("deep.toml", b"a = " + b"[" * 1000 + b"]" * 1000 + b"\n", "deep.toml"),
])
def test_robot_torques_refuses_bad_robot_files_in_one_line(tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    assert_one_line_error(invoke("robot", "torques", path, "--q", "0"), message)


# -- tumble demo --------------------------------------------------------------------------------------


@pytest.mark.parametrize("duration, message", [
    ("1e12", "--duration: the samples of 1e+12 s (200 per second) need 31.3 PiB (3.5e+16 bytes)"),
    ("1e308", "--duration: the samples of 1e+308 s (200 per second) need an unbounded amount (more than 1.8e308"),
    ("nan", "--duration: must be a finite number > 0"),
])
def test_demo_racket_refuses_durations_it_cannot_hold_saying_the_bytes(tmp_path, duration, message):
    result = invoke("demo", "racket", "--duration", duration, "-o", tmp_path)
    assert_one_line_error(result, message)
    assert list(tmp_path.iterdir()) == []
