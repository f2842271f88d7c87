"""Serial chains through tumble.simulate (power balance, torque laws, batches, files, docs) and the `tumble robot` CLI."""

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import tumble
from tumble import ValidationError, robot
from tumble.cli.robot import app

from helpers import read_by

# The tests here compile or share the robot's kernels (tumble.kernels.featherstone and the chain model's
# integrators, ~50 CPU s on a cold Numba cache); the robot's modules run on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

ROBOTS = tumble.examples.directory() / "robots"
DOCS = Path(__file__).resolve().parents[2] / "docs" / "robot.md"
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
    q, qd = run.joint_position, run.joint_velocity
    return robot.kinetic_energy(chain, q, qd) + robot.potential_energy(chain, q)


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_power_balance_under_a_constant_torque(puma):
    """d/dt (T + V) = q̇ · τ, so for a constant τ: E(t) − E(0) = τ · (q(t) − q(0))."""
    run = tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=TORQUE, method="dop853", rtol=1e-12, atol=1e-12)
    assert run.joint_position.shape == (6, 6) and run.info["n_steps"] > 0
    work = (run.joint_position - Q0) @ TORQUE
    assert np.abs(work).max() > 1.0  # the torque does work: the test can fail
    np.testing.assert_allclose(energy(puma, run) - energy(puma, run)[0], work, rtol=0, atol=ENERGY_TOL)
    # the integrated work W = ∫ τ·q̇ dt is the closed form τ·Δq, and the trajectory's energy is T + V
    np.testing.assert_allclose(run.work, work, rtol=0, atol=ENERGY_TOL)
    np.testing.assert_allclose(run.energy, energy(puma, run), rtol=0, atol=1e-13)  # the same kernel: rounding


@pytest.mark.slow  # shares the compiled dop853 of the test above (one compiled model type for every chain)
@pytest.mark.parametrize("name", ["planar_2link.toml", "puma560.toml", "panda.toml", "panda.urdf"])
def test_power_balance_on_every_example_robot(name):
    """E(t) − E(0) = τ · (q(t) − q(0)) for τ = 0.8 g(q0) from a random state (measured ≤ 3e-13 J on E ≤ 99 J)."""
    chain = robot.load(ROBOTS / name)
    rng = np.random.default_rng(4)
    q0, qd0 = rng.uniform(-1.0, 1.0, chain.dof), rng.uniform(-0.5, 0.5, chain.dof)
    tau = 0.8 * robot.gravity_torques(chain, q0)
    run = tumble.simulate(chain, q0=q0, qd0=qd0, t=T, torque=tau, method="dop853", rtol=1e-12, atol=1e-12)
    work = (run.joint_position - q0) @ tau
    assert np.abs(work).max() > 1.0  # the torque does work: the test can fail
    e = energy(chain, run)
    np.testing.assert_allclose(e - e[0], work, rtol=0, atol=ENERGY_TOL)


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_rk4_converges_at_fourth_order(puma):
    """Errors against dop853 at rtol 1e-12 fall by 2⁴ = 16 when dt halves (measured 15.4 from dt = 5 ms)."""
    exact = tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=TORQUE, method="dop853", rtol=1e-12,
                            atol=1e-12).joint_position
    errors = [np.abs(tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=TORQUE, method="rk4", dt=dt).joint_position
                     - exact).max() for dt in (0.005, 0.0025)]
    assert 14.0 < errors[0] / errors[1] < 18.0


@pytest.mark.slow  # compiles the integrators for the chain model (~20 s with a cold cache)
def test_torque_laws_agree(puma):
    """The same constant torque as an array and as a Python function: the same arithmetic, bitwise."""
    runs = [tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=law, method="rk4", dt=0.01)
            for law in (TORQUE, lambda t, q, qd: TORQUE)]
    np.testing.assert_array_equal(runs[1].joint_position, runs[0].joint_position)
    # the applied torques at the samples and their work: bitwise too (the bound 1e-12 would allow rounding)
    np.testing.assert_array_equal(runs[1].joint_torque, runs[0].joint_torque)
    np.testing.assert_array_equal(runs[0].joint_torque, np.broadcast_to(TORQUE, (len(T), 6)))
    np.testing.assert_array_equal(runs[1].work, runs[0].work)
    assert runs[0].info["torque"].startswith("array(") and runs[1].info["torque"] == "Python function <lambda>"
    # the function sees the time: a torque that grows moves the arm elsewhere
    ramp = tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=lambda t, q, qd: (1.0 + t) * TORQUE, method="rk4",
                           dt=0.01)
    assert np.abs(ramp.joint_position[-1] - runs[0].joint_position[-1]).max() > 0.1
    np.testing.assert_allclose(ramp.joint_torque, (1.0 + T)[:, None] * TORQUE, rtol=1e-15, atol=0)
    with pytest.raises(ValidationError, match=r"torque: the function <lambda>\(t, q, qd\) must return 6 finite"):
        tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=lambda t, q, qd: np.zeros(2), method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"torque: must be None, a callable f\(t, q, qd\) -> \(6,\) or"):
        tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=np.zeros((6, 6)), method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"torque: a SerialChain takes joint torques .*not a body torque"):
        tumble.simulate(puma, q0=Q0, t=T, torque=tumble.torques.ConstantBody([0.0, 0.0, 1.0]), method="rk4",
                        dt=0.01)


@pytest.mark.parametrize(("method", "needs"), [("cf4", "the body rate of its attitude quaternion"),
                                               ("splitting2", "a rigid body without torque"),
                                               ("exact", "the closed-form motion of a free rigid body")])
def test_methods_a_chain_cannot_use_are_refused_naming_those_that_work(puma, method, needs):
    """A chain has no attitude: the one message of integrate.check_method, naming rk4 and dop853."""
    with pytest.raises(ValidationError) as refused:
        tumble.simulate(puma, q0=Q0, t=T, **read_by(method, dt=0.01))
    message = str(refused.value)
    assert message.startswith(f"method: {method!r} needs {needs}")
    assert message.endswith("which a SerialChain is not; methods for it: 'rk4', 'dop853'")


def test_initial_state_by_name(puma):
    """q0 (the joint vector, not a quaternion) is required; qd0 defaults to rest; other names are refused."""
    with pytest.raises(ValidationError, match=r"q0: a SerialChain needs it: initial joint coordinates"):
        tumble.simulate(puma, t=T, method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"omega0: a SerialChain has no initial state 'omega0'"):
        tumble.simulate(puma, [0.0, 0.0, 1.0], q0=Q0, t=T, method="rk4", dt=0.01)
    with pytest.raises(ValidationError, match=r"qd0: must have shape \(…, 6\)"):
        tumble.simulate(puma, q0=Q0, qd0=np.zeros(4), t=T, method="rk4", dt=0.01)


# Power balance E(t) − W(t) = E(0) on every example robot. The scale is the largest energy that changes
# form on the run, S = max(ptp T, ptp V, ptp W) (J). dop853 at rtol = atol = 1e-12 keeps the balance to a
# measured ≤ 2.6e-13 S (the PUMA falling freely: 1.1e-11 J of S = 40 J); 1e-10 S leaves room for other
# platforms' rounding while a wrong power term (an O(1) fraction of W) fails by ten orders of magnitude.
# rk4's residual is its truncation error, O(dt⁴): measured ≤ 2.1e-11 S at dt = 0.5 ms (PUMA, free fall), under
# the same 1e-10 S; halving dt divides it by 2⁴ (measured 15.8-16.0), which a modelling error would not do.
BALANCE_TOL = 1e-10


def _balance(chain, run):
    """``(max |E − W − E(0)|, S)``, with E recomputed by tumble.robot.dynamics (not the trajectory's own)."""
    q, qd = run.joint_position, run.joint_velocity
    kinetic, potential = robot.kinetic_energy(chain, q, qd), robot.potential_energy(chain, q)
    residual = chain.invariants(run)["energy_minus_work"]
    np.testing.assert_allclose(residual, kinetic + potential - run.work, rtol=0, atol=1e-13)
    scale = max(np.ptp(kinetic), np.ptp(potential), np.ptp(run.work))
    return np.abs(residual - residual[0]).max(), scale


@pytest.mark.slow  # compiles dop853 and rk4 for the chain model with a Python torque law
@pytest.mark.parametrize("name", ["planar_2link.toml", "puma560.toml", "panda.toml", "panda.urdf"])
@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_power_balance_along_dop853_and_rk4(name, method):
    """|E − W − E(0)| ≤ 1e-10 S, falling freely and under a torque law that depends on t and q."""
    chain = robot.load(ROBOTS / name)
    rng = np.random.default_rng(4)
    q0, qd0 = rng.uniform(-1.0, 1.0, chain.dof), rng.uniform(-0.5, 0.5, chain.dof)
    options = dict(rtol=1e-12, atol=1e-12) if method == "dop853" else dict(dt=5e-4)

    def breathing(t, q, qd):  # a partial gravity compensation that breathes: work from t and from q
        return (0.8 + 0.2 * np.cos(3.0 * t)) * robot.gravity_torques(chain, q)

    for torque in (None, breathing):
        run = tumble.simulate(chain, q0=q0, qd0=qd0, t=T, torque=torque, method=method, **options)
        residual, scale = _balance(chain, run)
        assert scale > 1.0  # energy changes form: the balance can fail
        assert (np.abs(run.work).max() > 1.0) == (torque is not None)
        assert residual <= BALANCE_TOL * scale, (torque, residual, scale)
    if method == "rk4":  # the residual is rk4's truncation error: fourth order in dt
        coarse = tumble.simulate(chain, q0=q0, qd0=qd0, t=T, method="rk4", dt=1e-3)
        fine = tumble.simulate(chain, q0=q0, qd0=qd0, t=T, method="rk4", dt=5e-4)
        assert 14.0 < _balance(chain, coarse)[0] / _balance(chain, fine)[0] < 18.0


@pytest.mark.slow  # compiles the parallel batch integrator
def test_batch_equals_single_runs_and_saves(puma, tmp_path):
    q0 = np.stack([Q0, -Q0, 0.5 * Q0])
    run = tumble.simulate(puma, q0=q0, qd0=np.zeros_like(q0), t=T, method="rk4", dt=0.01)
    one = tumble.simulate(puma, q0=q0[1], qd0=np.zeros(6), t=T, method="rk4", dt=0.01)
    assert run.joint_position.shape == (6, 3, 6)
    np.testing.assert_array_equal(run.joint_position[:, 1], one.joint_position)
    path = tmp_path / "puma.nc"
    run.save(path)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        np.testing.assert_array_equal(ds["joint_position"].values, run.joint_position)
        assert ds.attrs["solver_joint_names"].split(", ") == list(puma.joint_names)
    assert [p.name for p in tmp_path.iterdir()] == ["puma.nc"]  # no temporary file left


@pytest.mark.slow  # shares the compiled rk4 of the chain model
def test_a_robot_trajectory_saves_loads_and_plots(puma, tmp_path):
    """A chain has no single attitude: q = omega = inertia = None; the joint motion is in the extras."""
    run = tumble.simulate(puma, q0=Q0, qd0=QD0, t=T, torque=lambda t, q, qd: np.cos(t) * TORQUE, method="rk4",
                          dt=0.01)
    assert isinstance(run, tumble.Trajectory) and run.model == "SerialChain" and run.batch_size is None
    assert run.q is None and run.omega is None and run.inertia is None
    units = {name: (e.dims, e.units) for name, e in run.extras.items()}
    assert units == {"joint_position": (("joint",), "rad or m"), "joint_velocity": (("joint",), "rad/s or m/s"),
                     "joint_torque": (("joint",), "N m or N"), "work": ((), "J"), "beyond_limits": ((), "1")}
    assert run.info["robot"] == "PUMA 560" and run.info["gravity_z"] == -9.81
    path = tmp_path / "puma.nc"
    run.save(path)
    back = tumble.load(path)
    for name in ("t", "energy"):
        np.testing.assert_array_equal(getattr(back, name), getattr(run, name))
    assert back.extras.keys() == run.extras.keys()
    for name, extra in run.extras.items():
        np.testing.assert_array_equal(back.extras[name].data, extra.data)  # bitwise
        assert back.extras[name]._replace(data=None) == extra._replace(data=None)
    assert (back.q, back.method, back.model, back.info) == (None, run.method, run.model, run.info)
    figure = run.plot()
    assert [ax.get_title(loc="left") for ax in figure.axes][::2] == ["(a) joint position", "(c) joint velocity"]


@pytest.mark.slow  # shares the compiled rk4 of the chain model
def test_gravity_is_the_chains(puma):
    """Without gravity or torque an arm at rest stays at rest; with_gravity(g) is the chain under g."""
    still = tumble.simulate(puma.with_gravity((0.0, 0.0, 0.0)), q0=Q0, t=T, method="rk4", dt=0.01)
    np.testing.assert_array_equal(still.joint_position, np.broadcast_to(Q0, (len(T), 6)))
    np.testing.assert_array_equal(still.energy, np.zeros(len(T)))
    moon = puma.with_gravity((0.0, 0.0, -1.62))
    np.testing.assert_array_equal(moon.params, puma.params)
    assert moon.gravity.tolist() == [0.0, 0.0, -1.62] and moon.name == puma.name
    np.testing.assert_allclose(robot.gravity_torques(moon, Q0), robot.gravity_torques(puma, Q0) * 1.62 / 9.81,
                               rtol=1e-13, atol=1e-15)


@pytest.mark.slow  # compiles dop853 for the chain model (shared with the power-balance test)
def test_demo_writes_its_files_and_keeps_the_energy(tmp_path):
    """The Panda falling for 2 s: energy E ≈ 94 J kept to a measured 6e-12 J (tolerance 1e-10 J, see above)."""
    from tumble.viz.robot import demo_robot

    summary = demo_robot(tmp_path, tumble.examples.directory() / "robots" / "panda.urdf")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot_fall.nc", "robot_fall.png"]
    assert summary["max_energy_drift_J"] < ENERGY_TOL
    assert summary["energy_scale_J"] > 50.0
    # the model has no joint stops: the arm leaves its joint limits, and the demo says when
    assert summary["leaves_joint_limits_s"] == pytest.approx(0.37)


@pytest.mark.slow  # shares the compiled dop853 and rk4 of the chain model
def test_docs_python_blocks_run_as_scripts(tmp_path, monkeypatch):
    """Every Python block of docs/robot.md runs as written, from an empty folder (files through
    tumble.examples.path and the installed example-robot-data, not paths relative to the repository)."""
    monkeypatch.chdir(tmp_path)
    blocks = re.findall(r"```python\n(.*?)```", DOCS.read_text(encoding="utf-8"), re.S)
    assert len(blocks) == 5
    spaces = []
    for k, code in enumerate(blocks):
        assert "…" not in code
        namespace: dict = {}
        exec(compile(code, f"{DOCS}, Python block {k}", "exec"), namespace)  # the project's own text
        spaces.append(namespace)
    # the simulation block's claim: the power balance holds below 1e-13 J (measured 2.5e-14 J)
    balance = spaces[2]["balance"]
    assert np.abs(balance - balance[0]).max() < 1e-13


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
