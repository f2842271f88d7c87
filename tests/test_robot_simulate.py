"""tumble.robot.simulate (power balance, torque laws, batches, files) and the `tumble robot` CLI."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from tumble import ValidationError, robot
from tumble.robot.cli import app
from tumble.robot.simulate import simulate

ROBOTS = Path(__file__).resolve().parents[1] / "examples" / "robots"
Q0 = np.array([0.1, 0.5, -0.3, 0.2, 0.4, -0.1])
QD0 = np.array([0.3, -0.2, 0.4, 0.5, -0.6, 0.7])
TORQUE = np.array([2.0, 30.0, 5.0, 0.1, -0.05, 0.02])  # N·m: about the PUMA's gravity load
T = np.linspace(0.0, 0.5, 6)
# dop853 at rtol = atol = 1e-12 keeps the energy balance of the PUMA (E from 27
# to 39 J, work 12 J) to a measured 7e-13 J over 0.5 s; 1e-10 J leaves a margin
# for other platforms' rounding while a wrong term (≥ 1e-4 J) still fails.
ENERGY_TOL = 1e-10


@pytest.fixture(scope="module")
def puma():
    return robot.load(ROBOTS / "puma560.toml")


def energy(chain, run):
    return robot.kinetic_energy(chain, run.q, run.qd) + robot.potential_energy(chain, run.q)


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_power_balance_under_a_constant_torque(puma):
    """d/dt (T + V) = q̇ · τ, so for a constant τ: E(t) − E(0) = τ · (q(t) − q(0))."""
    run = simulate(puma, Q0, QD0, t=T, torque=TORQUE, method="dop853", rtol=1e-12, atol=1e-12)
    assert run.q.shape == (6, 6) and run.info["n_steps"] > 0
    work = (run.q - Q0) @ TORQUE
    assert np.abs(work).max() > 1.0  # the torque does work: the test can fail
    np.testing.assert_allclose(energy(puma, run) - energy(puma, run)[0], work, rtol=0, atol=ENERGY_TOL)


@pytest.mark.slow  # shares the compiled dop853 of the test above (one compiled model type for every chain)
@pytest.mark.parametrize("name", ["planar_2link.toml", "puma560.toml", "panda.toml", "panda.urdf"])
def test_power_balance_on_every_example_robot(name):
    """E(t) − E(0) = τ · (q(t) − q(0)) for τ = 0.8 g(q0) from a random state (measured ≤ 3e-13 J on E ≤ 99 J)."""
    chain = robot.load(ROBOTS / name)
    rng = np.random.default_rng(4)
    q0, qd0 = rng.uniform(-1.0, 1.0, chain.dof), rng.uniform(-0.5, 0.5, chain.dof)
    tau = 0.8 * robot.gravity_torques(chain, q0)
    run = simulate(chain, q0, qd0, t=T, torque=tau, method="dop853", rtol=1e-12, atol=1e-12)
    work = (run.q - q0) @ tau
    assert np.abs(work).max() > 1.0  # the torque does work: the test can fail
    e = energy(chain, run)
    np.testing.assert_allclose(e - e[0], work, rtol=0, atol=ENERGY_TOL)


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_rk4_converges_at_fourth_order(puma):
    """Errors against dop853 at rtol 1e-12 fall by 2⁴ = 16 when dt halves (measured 15.4 from dt = 5 ms)."""
    exact = simulate(puma, Q0, QD0, t=T, torque=TORQUE, method="dop853", rtol=1e-12, atol=1e-12).q
    errors = [np.abs(simulate(puma, Q0, QD0, t=T, torque=TORQUE, method="rk4", dt=dt).q - exact).max()
              for dt in (0.005, 0.0025)]
    assert 14.0 < errors[0] / errors[1] < 18.0


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_torque_laws_agree(puma):
    """The same constant torque as an array and as a Python function: the same arithmetic, bitwise."""
    runs = [simulate(puma, Q0, QD0, t=T, torque=law, method="rk4", dt=0.01)
            for law in (TORQUE, lambda t, q, qd: TORQUE)]
    np.testing.assert_array_equal(runs[1].q, runs[0].q)
    # the function sees the time: a torque that grows moves the arm elsewhere
    ramp = simulate(puma, Q0, QD0, t=T, torque=lambda t, q, qd: (1.0 + t) * TORQUE, method="rk4", dt=0.01)
    assert np.abs(ramp.q[-1] - runs[0].q[-1]).max() > 0.1
    with pytest.raises(ValidationError, match=r"torque: the function <lambda>\(t, q, qd\) must return 6 finite"):
        simulate(puma, Q0, QD0, t=T, torque=lambda t, q, qd: np.zeros(2), method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"torque: must be None, a callable f\(t, q, qd\) -> \(6,\) or"):
        simulate(puma, Q0, QD0, t=T, torque=np.zeros((6, 6)), method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"method: must be one of \('rk4', 'dop853'\)"):
        simulate(puma, Q0, QD0, t=T, method="cf4", dt=0.01)


@pytest.mark.slow  # compiles the parallel batch integrator
def test_batch_equals_single_runs_and_saves(puma, tmp_path):
    q0 = np.stack([Q0, -Q0, 0.5 * Q0])
    run = simulate(puma, q0, np.zeros_like(q0), t=T, method="rk4", dt=0.01)
    one = simulate(puma, q0[1], np.zeros(6), t=T, method="rk4", dt=0.01)
    assert run.q.shape == (6, 3, 6)
    np.testing.assert_array_equal(run.q[:, 1], one.q)
    path = tmp_path / "puma.nc"
    run.save(path)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        np.testing.assert_array_equal(ds["q"].values, run.q)
        assert list(ds["joint"].values) == list(puma.joint_names)
    assert [p.name for p in tmp_path.iterdir()] == ["puma.nc"]  # no temporary file left


@pytest.mark.slow  # compiles dop853 for the chain model (shared with the power-balance test)
def test_demo_writes_its_files_and_keeps_the_energy(tmp_path):
    """The Panda falling for 2 s: energy E ≈ 94 J kept to a measured 5e-12 J (tolerance 1e-10 J, see above)."""
    from tumble.robot.demo import demo_robot

    summary = demo_robot(tmp_path, Path(__file__).resolve().parents[1] / "examples" / "robots" / "panda.urdf")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot_fall.nc", "robot_fall.png"]
    assert summary["max_energy_drift_J"] < ENERGY_TOL
    assert summary["energy_scale_J"] > 50.0


# -- the CLI ------------------------------------------------------------------------------

runner = CliRunner()


def test_cli_prints_the_gravity_load_of_the_puma():
    qn = "0, 0.7853981633974483, 3.141592653589793, 0, 0.7853981633974483, 0"
    result = runner.invoke(app, ["torques", str(ROBOTS / "puma560.toml"), "--q", qn, "--mass-matrix"])
    assert result.exit_code == 0, result.output
    assert "shoulder" in result.stdout and "tau =  31.6398803784 N m" in result.stdout
    assert "mass matrix M(q):" in result.stdout


def test_cli_reads_urdf_and_refuses_bad_input():
    ok = runner.invoke(app, ["torques", str(ROBOTS / "panda.urdf"), "--q", "0 0 0 -1.5 0 1.5 0",
                             "--qd", "1 0 0 0 0 0 0", "--gravity", "0,0,0"])
    assert ok.exit_code == 0, ok.output
    assert ok.stdout.count("tau =") == 7
    bad = runner.invoke(app, ["torques", str(ROBOTS / "panda.urdf"), "--q", "0 0 0"])
    assert bad.exit_code == 2
    assert "error: --q: must be 7 finite numbers" in bad.output
    missing = runner.invoke(app, ["torques", str(ROBOTS / "nothing.toml"), "--q", "0"])
    assert missing.exit_code == 2 and "error:" in missing.output
