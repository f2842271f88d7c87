"""Scenario kinds of the models beyond the rigid body and the spacecraft: flexible, slosh, variable, human,
gyroscope, robot. Each example file runs as tumble.simulate of the same model built in Python (bitwise), with
its physics; bad files are refused naming the key; `tumble run` runs one example of each kind."""

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tumble
from tumble import flexible, robot, slosh
from tumble.rigid_body import RigidBody
from tumble.cli import app
from tumble.ins import GimbaledGyro
from tumble.viz.ins import DEMO_GYRO
from tumble.scenario import ScenarioError, load, parse
from tumble.variable import Human, Motion, VariableBody, diver

from helpers import assert_same_run

# Every test here compiles the integrators of several model kinds on a cold Numba cache (tens of CPU s).
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = tumble.examples.directory()
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

# Every example of the new kinds, with its kind.
KIND_EXAMPLES = {
    "flexible/solar_array_slew.toml": "flexible",
    "slosh/minor_axis_spinner.toml": "slosh",
    "variable/skater.toml": "variable",
    "human/twisting_somersault.toml": "human",
    "gyroscope/imbalance_drift.toml": "gyroscope",
    "gyroscope/gimbaled_precession.toml": "gyroscope",
    "robot/planar_2link_torque.toml": "robot",
    "robot/panda_fall.toml": "robot",
}

# The 30° slew of examples/flexible/solar_array_slew.toml: the torque table is this profile.
SLEW = dict(angle=math.radians(30.0), duration=40.0, inertia=3000.0, ramp=0.4)
PANDA_Q0 = [0.0, -0.2, 0.0, -1.2, 0.0, 1.0, 0.7]


def same_model_in_python(name: str):
    """The model, initial state and run options of example ``name``, written here in Python from the numbers
    of the file: ``tumble.simulate(model, t=t, **rest)``."""
    if name == "flexible/solar_array_slew.toml":
        model = flexible.FlexibleBody(RigidBody(np.diag([2000.0, 1500.0, 3000.0])), [
            flexible.Mode(2 * math.pi * 0.2, 0.003, [0.0, 0.0, 25.0]),
            flexible.Mode(2 * math.pi * 1.1, 0.005, [0.0, 0.0, 8.0])])
        return model, dict(t=np.linspace(0.0, 60.0, 601), omega0=np.zeros(3), eta0=np.zeros(2),
                           eta_rate0=np.zeros(2), torque=flexible.slew_torque([0.0, 0.0, 1.0], **SLEW),
                           method="dop853", rtol=1e-10, atol=1e-10)
    if name == "slosh/minor_axis_spinner.toml":
        return slosh.DEMO_BODY, dict(t=np.linspace(0.0, 100.0, 201), omega0=[0.035, 0.0, 2.0],
                                     direction0=[1.0, 0.0, 0.0], rate0=np.zeros(3), method="dop853", rtol=1e-10,
                                     atol=1e-10)
    if name == "variable/skater.toml":
        times = np.arange(13) * 0.25
        moments = np.interp(times, [0.0, 1.0, 2.0, 3.0], [3.0, 3.0, 1.0, 1.0])  # I_zz: 3 → 1 between 1 and 2 s
        transverse = moments + 9.0                                            # I_xx = I_yy: 12 → 10
        inertia = [np.diag([a, a, c]) for a, c in zip(transverse, moments)]
        return VariableBody(times, inertia), dict(t=np.linspace(0.0, 3.0, 61), omega0=[0.0, 0.0, 2.0],
                                                  method="dop853", rtol=1e-10, atol=1e-12)
    if name == "human/twisting_somersault.toml":
        angles = {"left_shoulder_abduction": Motion(math.pi, [(0.2, 0.6, 0.0)]),
                  "right_shoulder_abduction": Motion(math.pi)}
        model = Human.de_leva(73.0, 1.741).moving(angles, t_span=(0.0, 2.0), dt=0.002)
        return model, dict(t=np.linspace(0.0, 2.0, 801), omega0=[5.059499652298716, 0.0, 0.0], method="dop853",
                           rtol=1e-10, atol=1e-10)
    if name == "gyroscope/imbalance_drift.toml":
        gyro = replace(DEMO_GYRO, spin_friction=2e-3)
        return gyro, dict(t=np.linspace(0.0, 5.0, 101), precession_rate0=gyro.steady_precession_rate,
                          method="dop853", rtol=1e-12, atol=1e-12)
    if name == "gyroscope/gimbaled_precession.toml":
        gyro = GimbaledGyro(2e-3, 1.5e-3, inner_gimbal=(4e-4, 5e-4, 3e-4), outer_gimbal=1e-3, inner_torque=0.0196)
        return gyro, dict(t=np.linspace(0.0, 2.0, 201), spin=500.0, theta0=math.pi / 2,
                          phi_dot0=gyro.precession_rate(500.0), method="dop853", rtol=1e-12, atol=1e-12)
    if name == "robot/planar_2link_torque.toml":
        chain = robot.load(EXAMPLES / "robots" / "planar_2link.toml")
        return chain, dict(t=np.linspace(0.0, 3.0, 301), q0=[-math.pi / 2, 0.0], qd0=np.zeros(2),
                           torque=np.array([5.0, 0.0]), method="rk4", dt=1e-3)
    if name == "robot/panda_fall.toml":
        return robot.load(EXAMPLES / "robots" / "panda.urdf"), dict(t=np.linspace(0.0, 2.0, 401), q0=PANDA_Q0,
                                                                     method="dop853", rtol=1e-12, atol=1e-12)
    raise AssertionError(name)


@pytest.fixture(scope="module")
def runs():
    """Each example loaded and run once for the module: name → (scenario, trajectory)."""
    loaded = {name: load(EXAMPLES / name) for name in KIND_EXAMPLES}
    return {name: (scenario, scenario.run()) for name, scenario in loaded.items()}


# --------------------------------------------------------------------------
# The examples
# --------------------------------------------------------------------------


def test_every_example_of_the_new_kinds_is_listed():
    listed = {EXAMPLES / name for name in KIND_EXAMPLES}
    found = {path for kind in set(KIND_EXAMPLES.values()) for path in (EXAMPLES / kind).glob("*.toml")}
    assert found == listed


@pytest.mark.parametrize("name", KIND_EXAMPLES)
def test_example_is_simulate_of_the_same_model_built_in_python(name, runs):
    scenario, traj = runs[name]
    assert scenario.kind == KIND_EXAMPLES[name]
    model, options = same_model_in_python(name)
    problem = scenario.build()
    assert type(problem.model) is type(model) and problem.t[-1] == scenario.time.stop
    assert_same_run(traj, tumble.simulate(model, **options))


@pytest.mark.parametrize("name", KIND_EXAMPLES)
def test_the_kind_of_an_example_follows_from_its_table(name):
    text = (EXAMPLES / name).read_text(encoding="utf-8")
    without = re.sub(r'(?m)^kind = ".*"\n', "", text, count=1)  # the top-level kind comes before any table
    assert without != text  # every example says its kind, and its marker table says the same
    assert parse(without, source=str(EXAMPLES / name)).kind == KIND_EXAMPLES[name]


def test_flexible_example_torque_is_the_slew_profile_and_leaves_no_momentum(runs):
    scenario, traj = runs["flexible/solar_array_slew.toml"]
    torque, profile = scenario.build().torque, flexible.slew_torque([0.0, 0.0, 1.0], **SLEW)
    np.testing.assert_array_equal(torque.t, profile.t)
    np.testing.assert_array_equal(torque.torque, profile.torque)  # the file's peak is the profile's, to the bit
    # The bang-bang impulse ∫τ dt is zero: after 40 s the total inertial momentum (hub + array) returns to 0.
    # dop853 at 1e-10 leaves 2.3e-13 N m s of a peak of 78.5 N m s (measured); 1e-10 of the peak is allowed.
    h = np.linalg.norm(traj.momentum_inertial, axis=-1)
    assert h[traj.t >= 40.0].max() < 1e-10 * h.max()
    # the rigid body turns by exactly 30°: the slew angle of the hub's trajectory ends within its jitter,
    # 125 arcsec (measured peak after the manoeuvre, demo_flexible's figure)
    assert abs(flexible.slew_angle(traj.q[-1]) - SLEW["angle"]) < math.radians(130.0 / 3600.0)


def test_slosh_example_keeps_its_momentum_loses_energy_and_nutates_more(runs):
    scenario, traj = runs["slosh/minor_axis_spinner.toml"]
    h = traj.momentum_norm
    # hinge friction is internal: |H| is kept (measured 2.3e-12 over 100 s at rtol 1e-10)
    assert np.abs(h / h[0] - 1.0).max() < 1e-10
    # and dissipates: dT/dt = -μ l² d |ν|² ≤ 0 at every sample (measured steps ≤ -3.6e-7 of T)
    assert np.all(np.diff(traj.energy) < 0.0)
    angle = scenario.nutation_angle(traj)
    # H(0) = I_B ω + μ r × (ω × r), r = b + l s = (0.8, 0, 0) m, μ = 60·900/960 kg: (21, 0, 600 + 72) N m s
    assert angle[0] == pytest.approx(math.atan2(21.0, 672.0), rel=1e-12)
    assert angle[-1] > 3.0 * angle[0]  # the minor-axis spinner is unstable (1.79° → 6.79° measured)


def test_skater_spins_up_as_the_inertia_falls(runs):
    _, traj = runs["variable/skater.toml"]
    # L = I_zz(t) ω_z = 3 kg m² × 2 rad/s: kept exactly (the state holds L_N; measured 0.0 difference)
    np.testing.assert_allclose(traj.angular_momentum, np.tile([0.0, 0.0, 6.0], (traj.t.size, 1)), rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(traj.omega[-1], [0.0, 0.0, 6.0], rtol=1e-12)  # I_zz = 1 kg m² at the end
    assert traj.energy[-1] == pytest.approx(18.0, rel=1e-12)  # L²/(2 I): 6 J → 18 J, the work of the arms


def test_human_example_is_the_twisting_somersault_of_the_diver_module(runs):
    scenario, traj = runs["human/twisting_somersault.toml"]
    np.testing.assert_allclose(traj.momentum_inertial[0], [80.0, 0.0, 0.0], rtol=1e-15, atol=1e-12)
    dive = diver.twisting_somersault()
    # the same run but for ω_z(0): -2.2e-33 rad/s there (the rounding of I⁻¹L), 0 in the file
    np.testing.assert_allclose(traj.q, dive.trajectory.q, rtol=0, atol=1e-15)
    angles = diver.orientation_angles(traj.q, traj.momentum_inertial[0])
    assert angles.somersaults == pytest.approx(1.76, abs=0.005) and angles.twists == pytest.approx(2.99, abs=0.005)
    rows = dict(scenario.rows(traj))
    assert rows["turns"] == "+1.76 somersaults, +2.986 twists (Yeadon's angles about L)"


def test_gyroscope_examples_follow_their_precession_laws(runs):
    scenario, traj = runs["gyroscope/imbalance_drift.toml"]
    gyro = scenario.model
    assert scenario.initial.precession_rate == gyro.steady_precession_rate  # the file starts steady precession
    axis = gyro.axis(traj)
    spin = gyro.spin - gyro.spin_friction * traj.t / gyro.spin_inertia  # 100 → 95 rad/s
    np.testing.assert_allclose(axis.spin, spin, rtol=1e-12)
    law = gyro.imbalance_torque / gyro.spin_friction * np.log(gyro.spin / spin)
    # adiabatic law φ = (m g l / τ_f) ln(ω_s0 / ω_s): measured 2.6e-7 of the final azimuth (0.50 rad) at
    # ε = τ I_t / (I_s ω_s)² = 7.4e-4 (the nutation it neglects)
    np.testing.assert_allclose(axis.phi, law, rtol=0, atol=1e-6 * law[-1])

    scenario, traj = runs["gyroscope/gimbaled_precession.toml"]
    # exact steady precession at τ_θ / (I_s ω₃) = 0.0196 rad/s: measured 1.2e-15 relative, tilt constant to
    # 2e-15 rad
    assert np.polyfit(traj.t, traj.phi, 1)[0] == pytest.approx(0.0196, rel=1e-10)
    assert np.ptp(traj.theta) < 1e-12


def test_robot_examples_keep_the_energy_balance(runs):
    _, traj = runs["robot/planar_2link_torque.toml"]
    balance = traj.energy - traj.work
    # E − W = E(0) along the exact motion; rk4 at dt = 1 ms: measured 8.5e-12 J with W = 3.2 J exchanged
    assert np.abs(balance - balance[0]).max() < 1e-10
    assert traj.work.max() > 3.0
    _, traj = runs["robot/panda_fall.toml"]
    # no torque: T + V is kept; dop853 at 1e-12: measured 6e-12 J of 94 J (docs/robot.md: 1e-10 J)
    assert np.abs(traj.energy - traj.energy[0]).max() < 1e-10


def test_docs_show_an_example_of_each_kind_as_it_is():
    docs = (ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8")
    shown = dict(re.findall(r"```toml\n# examples/(\S+)\n(.*?)```", docs, flags=re.S))
    new = {name: text for name, text in shown.items() if name in KIND_EXAMPLES}
    assert {KIND_EXAMPLES[name] for name in new} == set(KIND_EXAMPLES.values())
    for name, text in new.items():
        assert text == (EXAMPLES / name).read_text(encoding="utf-8"), name


# --------------------------------------------------------------------------
# Figures and summary rows
# --------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "panel"), [
    ("flexible/solar_array_slew.toml", "(d) jitter after the manoeuvre"),   # flexible.slew_figure
    ("slosh/minor_axis_spinner.toml", "(b) kinetic energy (hub + slosh mass)"),  # slosh.nutation_figure
    ("human/twisting_somersault.toml", "somersault φ and twist ψ (Yeadon's angles about L)"),  # figure_dive
    ("variable/skater.toml", "(b) drift of energy and momentum"),            # Trajectory.plot
    ("gyroscope/gimbaled_precession.toml", "(b) drift of energy and momentum"),
    ("robot/panda_fall.toml", "(a) joint position"),
])
def test_each_kind_draws_its_figure(name, panel, runs):
    scenario, traj = runs[name]
    figure = scenario.figure(traj)
    titles = [ax.get_title(loc) for ax in figure.axes for loc in ("center", "left")]
    assert any(title.startswith(panel) for title in titles), titles


def test_a_flexible_run_that_is_not_a_slew_about_z_is_plotted_as_a_trajectory():
    text = (EXAMPLES / "flexible/solar_array_slew.toml").read_text(encoding="utf-8")
    scenario = parse(text.replace("omega = [0.0, 0.0, 0.0]", "omega = [0.01, 0.0, 0.0]")
                     .replace("stop = 60.0", "stop = 1.0"), source="tilted.toml")
    figure = scenario.figure(scenario.run())
    assert figure.axes[0].get_title(loc="left") == "(a) body rates"


def test_rows_of_each_kind(runs):
    assert dict(runs["flexible/solar_array_slew.toml"][0].rows(runs["flexible/solar_array_slew.toml"][1]))[
        "modes"].startswith("|eta| (kg^1/2 m) of mode 1: peak 0.0789")
    rows = dict(runs["robot/panda_fall.toml"][0].rows(runs["robot/panda_fall.toml"][1]))
    assert rows["limits"] == "joint4 leaves its range at t = 0.37 s (not enforced)"  # as demo_robot's figure says
    rows = dict(runs["gyroscope/gimbaled_precession.toml"][0].rows(runs["gyroscope/gimbaled_precession.toml"][1]))
    assert rows["precession"].startswith("mean 0.0196 rad/s")


# --------------------------------------------------------------------------
# Bad files: refused naming the key, before anything is integrated
# --------------------------------------------------------------------------

# (example, text replaced, replacement, key of the problem); "+" appends the replacement.
BAD = [
    # flexible
    ("flexible/solar_array_slew.toml", "frequency = 1.2566370614359172", "frequency = -1.0",
     "flexible.mode[0].frequency"),
    ("flexible/solar_array_slew.toml", "damping = 0.003", "dampng = 0.003", "flexible.mode[0].dampng"),
    ("flexible/solar_array_slew.toml", "participation = [0.0, 0.0, 25.0]", "participation = [0.0, 0.0, 60.0]",
     "flexible.mode"),
    ("flexible/solar_array_slew.toml", "eta = [0.0, 0.0]", "eta = [0.0]", "initial.eta"),
    # slosh
    ("slosh/minor_axis_spinner.toml", "mass = 900.0", "", "body"),
    ("slosh/minor_axis_spinner.toml", "length = 0.6", "length = 0.0", "slosh.pendulum.length"),
    ("slosh/minor_axis_spinner.toml", "direction = [1.0, 0.0, 0.0]", "", "initial.direction"),
    ("slosh/minor_axis_spinner.toml", "spin_axis = [0.0, 0.0, 1.0]", "spin_axis = [0.0, 0.0, 0.0]",
     "slosh.spin_axis"),
    # variable
    ("variable/skater.toml", "[variable]", "[variable]\ninertia = [[[1, 0, 0], [0, 1, 0], [0, 0, 1]]]", "variable"),
    ("variable/skater.toml", "0.75, 1.0,", "1.0, 0.75,", "variable.times"),
    ("variable/skater.toml", "[12.0, 12.0, 3.0], [11.5, 11.5, 2.5]", "[12.0, 12.0, 3.0], [1.0, 1.0, 2.5]",
     "variable.moments[5]"),
    ("variable/skater.toml", "stop = 3.0", "stop = 4.0", "time"),
    # human
    ("human/twisting_somersault.toml", "[human.angles.left_shoulder_abduction]",
     "[human.angles.left_shoulder_abductio]", "human.angles.left_shoulder_abductio"),
    ("human/twisting_somersault.toml", "begin = 0.2, end = 0.6", "begin = 0.6, end = 0.2",
     "human.angles.left_shoulder_abduction.moves[0]"),
    ("human/twisting_somersault.toml", "mass = 73.0", "mass = -73.0", "human.mass"),
    ("human/twisting_somersault.toml", "[initial]", "+[[torque]]\nkind = 'constant_body'\nvalue = [0, 0, 1]\n",
     "torque"),
    # gyroscope
    ("gyroscope/imbalance_drift.toml", 'suspension = "pivot"', 'suspension = "gimballed"', "gyroscope.suspension"),
    ("gyroscope/imbalance_drift.toml", "spin = 100.0", "", "gyroscope.spin"),
    ("gyroscope/imbalance_drift.toml", "spin_inertia = 2e-3", "spin_inertia = 0.0", "gyroscope.spin_inertia"),
    ("gyroscope/imbalance_drift.toml", "precession_rate = 0.0980665", "spin = 100.0", "initial.spin"),
    ("gyroscope/gimbaled_precession.toml", "spin = 500.0", "", "initial.spin"),
    ("gyroscope/gimbaled_precession.toml", "inner_gimbal = [4e-4, 5e-4, 3e-4]", "inner_gimbal = [4e-4, -5e-4, 3e-4]",
     "gyroscope.inner_gimbal[1]"),
    # robot
    ("robot/planar_2link_torque.toml", 'file = "../robots/planar_2link.toml"', 'file = "../robots/nowhere.toml"',
     "robot.file"),
    ("robot/planar_2link_torque.toml", "q = [-1.5707963267948966, 0.0]", "q = [-1.5707963267948966]", "initial.q"),
    ("robot/planar_2link_torque.toml", "torque = [5.0, 0.0]", "torque = [5.0, 0.0, 0.0]", "robot.torque"),
    ("robot/planar_2link_torque.toml", "[robot]", "[robot]\ngravity = [0.0, -9.81]", "robot.gravity"),
    ("robot/panda_fall.toml", 'file = "../robots/panda.urdf"', 'file = "../robots/panda.sdf"', "robot.file"),
    ("robot/panda_fall.toml", 'method = "dop853"\nrtol = 1e-12\natol = 1e-12', 'method = "cf4"\ndt = 0.01',
     "solver.method"),  # tumble.simulate's one check of method and model: a chain has no attitude for cf4
]


def bad_text(name, old, new):
    """Example ``name`` with ``old`` replaced by ``new``, or with ``new[1:]`` appended when ``new`` starts with +."""
    text = (EXAMPLES / name).read_text(encoding="utf-8")
    assert old in text
    if new.startswith("+"):
        return text + new[1:]
    return text.replace(old, new, 1)


@pytest.mark.parametrize(("name", "old", "new", "key"), BAD, ids=[f"{b[0].split('/')[0]}-{b[3]}" for b in BAD])
def test_a_bad_file_is_refused_naming_the_key(name, old, new, key):
    source = str(EXAMPLES / name.split("/")[0] / "case.toml")  # a robot file is found next to the examples
    with pytest.raises(ScenarioError) as info:
        parse(bad_text(name, old, new), source=source).run()
    assert info.value.field == key, str(info.value)
    assert str(info.value).startswith(f"{source}: {key}: ")


def test_the_kinds_per_bad_file():
    kinds = [name.split("/")[0] for name, *_ in BAD]
    assert {kind: kinds.count(kind) for kind in kinds} == {"flexible": 4, "slosh": 4, "variable": 4, "human": 4,
                                                          "gyroscope": 6, "robot": 6}


def test_an_initial_state_the_rotor_does_not_have_names_the_keys_it_takes():
    text = bad_text("gyroscope/imbalance_drift.toml", "precession_rate = 0.0980665", "theta = 1.0")
    with pytest.raises(ScenarioError) as info:
        parse(text, source="gyro.toml").build()
    assert str(info.value) == ("gyro.toml: initial.theta: not an initial state of a Gyroscope, which takes: "
                               "precession_rate")


# --------------------------------------------------------------------------
# tumble run
# --------------------------------------------------------------------------

runner = CliRunner()
ONE_OF_EACH_KIND = ["flexible/solar_array_slew.toml", "slosh/minor_axis_spinner.toml", "variable/skater.toml",
                    "human/twisting_somersault.toml", "gyroscope/gimbaled_precession.toml",
                    "robot/planar_2link_torque.toml"]


@pytest.mark.parametrize("name", ONE_OF_EACH_KIND)
def test_tumble_run_writes_the_trajectory_and_the_figure(name, tmp_path, runs):
    out, png = tmp_path / "out.nc", tmp_path / "out.png"
    result = runner.invoke(app, ["run", str(EXAMPLES / name), "-o", str(out), "--plot", str(png), "--quiet"])
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:8] == PNG_MAGIC
    saved, traj = tumble.load(out), runs[name][1]
    np.testing.assert_array_equal(saved.energy, traj.energy)
    for label, value in runs[name][0].rows(traj):
        assert f"{label} {value}" in " ".join(result.stdout.split())


@pytest.mark.parametrize("name", ONE_OF_EACH_KIND)
def test_tumble_run_writes_nothing_for_a_bad_file(name, tmp_path):
    _, old, new, key = next(b for b in BAD if b[0] == name)
    bad = tmp_path / "bad.toml"
    bad.write_text(bad_text(name, old, new).replace("../robots/", f"{EXAMPLES / 'robots'}/"), encoding="utf-8")
    result = runner.invoke(app, ["run", str(bad), "-o", str(tmp_path / "out.nc"), "--plot", str(tmp_path / "o.png")])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith(f"error: {bad}: {key}: ")
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]
