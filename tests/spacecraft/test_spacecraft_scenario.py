"""Spacecraft scenario files: the examples run, the tables build the spacecraft of the Python API (bitwise the
same run), bad files are refused naming the key."""

import re
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import attitude, torques
from tumble.rigid_body import RigidBody
from tumble.scenario import ScenarioError, load, parse, run_scenario
from tumble.spacecraft import (CMGCluster, MRPFeedback, QuaternionPD, ReactionWheel, Spacecraft, SphericalDamper,
                               WheelTorques, pyramid_wheels)
from tumble.viz.spacecraft import spacecraft_figure

from helpers import assert_same_run

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = tumble.examples.directory() / "spacecraft"


def test_slew_example_reaches_its_target():
    traj = run_scenario(EXAMPLES / "slew_wheels.toml")
    target = attitude.from_euler("ZYX", [60.0, 0.0, 0.0], degrees=True)
    error = np.degrees(attitude.relative_angle(traj.q[-1], target))
    assert error < 1e-4                                   # measured 1.3e-6 deg after 150 s
    # the slew-rate limit of 0.02 rad/s holds (to the overshoot of one 0.5 s control sample)
    assert np.linalg.norm(traj.omega, axis=-1).max() < 0.02 * 1.01
    assert traj.info["control_period"] == 0.5
    fig = spacecraft_figure(traj, target=target)
    assert len(fig.axes) == 4


@pytest.mark.parametrize("name", ["cmg_slew", "thruster_pwpf"])
def test_examples_load_and_run(name):
    traj = run_scenario(EXAMPLES / f"{name}.toml")
    assert np.all(np.isfinite(traj.q))
    # both hold their target to better than 1 degree at the end (measured 2e-4 and 0.44 deg)
    scenario = load(EXAMPLES / f"{name}.toml")
    pd = scenario.spacecraft.controller[0]
    target = pd.target_euler.quaternion() if pd.target_euler is not None else attitude.identity()
    assert np.degrees(attitude.relative_angle(traj.q[-1], target)) < 1.0


GOOD = """
[spacecraft]
moments = [1.0, 2.0, 2.5]
[spacecraft.wheel_pyramid]
inertia = 0.01
[[spacecraft.controller]]
kind = "rate_damping"
time_constant = 5.0
[initial]
omega = [0.1, 0.0, 0.0]
[time]
stop = 1.0
samples = 3
"""


@pytest.mark.parametrize("edit, where, rule", [
    (("moments = [1.0, 2.0, 2.5]", "moments = [1.0, 2.0, 2.5]\ninertia = [[1,0,0],[0,1,0],[0,0,1]]"),
     "spacecraft", "give exactly one of inertia, moments (the total, wheels included) or hub"),
    (("time_constant = 5.0", "time_constant = -5.0"), "spacecraft.controller[0].time_constant", "must be > 0"),
    (("kind = \"rate_damping\"", "kind = \"lqr\""), "spacecraft.controller[0].kind", "must be one of"),
    (("inertia = 0.01", "inertia = 0.01\nspin = 3"), "spacecraft.wheel_pyramid.spin", "unknown key"),
    (("moments = [1.0, 2.0, 2.5]", "moments = [1.0, 2.0, 5.0]"), "spacecraft.moments", "triangle"),
    (("samples = 3", "samples = 3\n[solver]\nmethod = \"splitting2\"\ndt = 0.1"), "solver.method",
     "which a Spacecraft is not"),  # tumble.simulate's one check of method and model
])
def test_bad_scenarios_name_the_key(edit, where, rule):
    text = GOOD.replace(*edit)
    with pytest.raises(ScenarioError) as info:
        parse(text, source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems


# The craft of tests/spacecraft/test_spacecraft_wheels.py::test_hub_plus_wheels_equals_total_inertia, as scenario files:
# described by its hub (without the wheels) plus each wheel's mass properties, or by its total inertia.
HUB = """
[spacecraft.hub]
moments = [9.0, 11.0, 7.5]
mass = 100.0
com = [0.01, 0.0, -0.02]
"""
WHEELS = "".join(f"""
[[spacecraft.wheels]]
axis = {axis}
inertia = 0.05
mass = 2.0
position = {position}
transverse_inertia = 0.011
""" for axis, position in [("[1, 0, 0]", "[0.3, 0.0, 0.0]"), ("[0, 1, 0]", "[0.0, 0.3, 0.0]"),
                            ("[0, 0, 1]", "[0.0, 0.0, 0.3]")])
REST = """
[[spacecraft.controller]]
kind = "quaternion_pd"
natural_frequency = 0.3
damping_ratio = 0.8
target = [0.9, 0.2, -0.15, 0.35]
[initial]
omega = [0.05, -0.02, 0.03]
[time]
stop = 5.0
step = 1.0
[solver]
dt = 0.05
"""


def _total_inertia():
    """The craft's total inertia about its centre of mass, summed independently of tumble.rigid_body: the
    rotors' I_s a aᵀ + I_t (E − a aᵀ) and the parallel-axis terms m (|c|² E − c cᵀ)."""
    masses = np.array([100.0, 2.0, 2.0, 2.0])
    coms = np.array([[0.01, 0.0, -0.02], [0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.3]])
    com = masses @ coms / masses.sum()
    total = np.diag([9.0, 11.0, 7.5]) + sum(
        0.05 * np.outer(a, a) + 0.011 * (np.eye(3) - np.outer(a, a)) for a in np.eye(3))
    for m, c in zip(masses, coms - com):
        total = total + m * (c @ c * np.eye(3) - np.outer(c, c))
    return total


def test_hub_description_gives_the_motion_of_the_total_inertia():
    total = _total_inertia()
    given = "[spacecraft]\ninertia = " + repr(total.tolist()) + "\n"   # repr: the floats round-trip exactly
    hub = parse(HUB + WHEELS + REST).run()
    tot = parse(given + WHEELS + REST).run()
    # the composite of the hub table equals the independent sum (measured: 1.5e-19 of max |J|)
    np.testing.assert_allclose(hub.inertia, total, rtol=1e-14)
    # and the motion (a 29° turn in 5 s) is the same, to the tolerance of the Python test
    # (measured: q, omega and wheel speeds bit-identical)
    np.testing.assert_allclose(hub.q, tot.q, rtol=0, atol=1e-13)
    np.testing.assert_allclose(hub.omega, tot.omega, rtol=0, atol=1e-13)
    np.testing.assert_allclose(hub.extras["wheel_speed"].data, tot.extras["wheel_speed"].data, rtol=0, atol=1e-12)


@pytest.mark.parametrize("text, where, rule", [
    # both descriptions, or neither
    ("[spacecraft]\nmoments = [1.0, 2.0, 2.5]\n" + HUB + WHEELS + REST, "spacecraft", "got moments and hub"),
    ("[spacecraft]\n" + WHEELS + REST, "spacecraft", "give exactly one of inertia, moments"),
    # the hub table: one of inertia or moments, a mass, no unknown keys, a valid tensor
    (HUB.replace("moments = [9.0, 11.0, 7.5]", "moments = [9.0, 11.0, 7.5]\ninertia = [[9,0,0],[0,11,0],[0,0,7.5]]")
     + WHEELS + REST, "spacecraft.hub", "give exactly one of inertia or moments"),
    (HUB.replace("mass = 100.0\n", "") + WHEELS + REST, "spacecraft.hub.mass", "missing required key"),
    (HUB.replace("mass = 100.0", "mass = 0.0") + WHEELS + REST, "spacecraft.hub.mass", "must be > 0"),
    (HUB.replace("mass = 100.0", "mass = 100.0\nspin = 1.0") + WHEELS + REST, "spacecraft.hub.spin", "unknown key"),
    (HUB.replace("[9.0, 11.0, 7.5]", "[9.0, 11.0, 30.0]") + WHEELS + REST, "spacecraft.hub.moments", "triangle"),
    # with a hub, every wheel needs its mass properties, given together
    (HUB + WHEELS.replace("mass = 2.0\n", "", 1) + REST, "spacecraft.wheels[0].mass",
     "give mass, position and transverse_inertia together"),
    (HUB + WHEELS.replace("mass = 2.0\nposition = [0.0, 0.3, 0.0]\ntransverse_inertia = 0.011\n", "") + REST,
     "spacecraft.wheels[1].mass", "every wheel needs mass, position and transverse_inertia"),
    (HUB + "[spacecraft.wheel_pyramid]\ninertia = 0.02\n" + REST, "spacecraft.wheel_pyramid.mass",
     "every wheel needs mass"),
])
def test_bad_hub_descriptions_name_the_key(text, where, rule):
    with pytest.raises(ScenarioError) as info:
        parse(text, source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems


# ---------------------------------------------------------------------------------------------------------
# examples/spacecraft/mrp_disturbance.toml: MRP feedback with its integral term against a disturbance torque
# ---------------------------------------------------------------------------------------------------------

MRP_EXAMPLE = EXAMPLES / "mrp_disturbance.toml"
K_GAIN, P_GAIN, KI = 10.0, 150.0, 3e-5                 # N m, N m s, 1/(N m s)
DISTURBANCE = np.array([0.005, -0.003, 0.002])         # N m, body axes
SIGMA0 = np.array([0.1, 0.2, -0.3])


def _mrp(q):
    """The MRP σ = q_v/(1 + q_w) of the shorter rotation (q_w ≥ 0) of unit quaternions ``q`` (..., 4)."""
    q = q * np.where(q[..., :1] < 0.0, -1.0, 1.0)
    return q[..., 1:] / (1.0 + q[..., :1])


def _mrp_craft(ki):
    """The spacecraft of the example, written here with the Python API from the numbers of the issue."""
    return Spacecraft(inertia=np.diag([900.0, 800.0, 600.0]),
                      wheels=[ReactionWheel(axis=axis, inertia=0.1) for axis in np.eye(3)],
                      controller=MRPFeedback(K=K_GAIN, P=P_GAIN, Ki=ki, target=[1.0, 0.0, 0.0, 0.0]))


@pytest.fixture(scope="module")
def mrp_run():
    return run_scenario(MRP_EXAMPLE)


def test_mrp_example_is_simulate_of_the_same_spacecraft_built_in_python(mrp_run):
    scenario = load(MRP_EXAMPLE)
    assert scenario.kind == "spacecraft" and isinstance(scenario.model, Spacecraft)
    q0 = [0.86, 0.2, 0.4, -0.6]                        # the file's [1 - |σ|², 2σ], normalised by simulate
    np.testing.assert_allclose(_mrp(attitude.normalize(q0)), SIGMA0, rtol=0, atol=1e-16)   # σ₀ of the issue
    reference = tumble.simulate(_mrp_craft(KI), omega0=[0.01, -0.01, 0.005], q0=q0,
                                attitude_error_integral0=np.zeros(3), t=np.linspace(0.0, 3600.0, 361),
                                method="dop853", rtol=1e-12, atol=1e-12, torque=torques.ConstantBody(DISTURBANCE))
    assert_same_run(mrp_run, reference)
    assert mrp_run.info == reference.info


# After 3600 s the slowest closed-loop transient (time constant 114 s, tests/spacecraft/test_spacecraft_control.py) has
# decayed by e^-31 of |σ₀| = 0.37: what remains is dop853's error at rtol = atol = 1e-12. Measured at the end:
# |σ| = 4.6e-14, max |ω_k| = 1.4e-15 rad/s, P K_I K ∫σ dt = L to 1.1e-10 relative; the limits are those of
# tests/spacecraft/test_spacecraft_control.py (σ, ω 1e-11; the integral 1e-9 relative).
def test_mrp_example_settles_with_the_integral_term_holding_the_disturbance(mrp_run):
    sigma = _mrp(mrp_run.q[-1])
    assert np.linalg.norm(sigma) < 1e-11
    assert np.abs(mrp_run.omega[-1]).max() < 1e-11
    np.testing.assert_allclose(P_GAIN * KI * K_GAIN * mrp_run.attitude_error_integral[-1], DISTURBANCE, rtol=1e-9)
    np.testing.assert_allclose(mrp_run.external_torque, np.broadcast_to(DISTURBANCE, (361, 3)), rtol=1e-15)
    # the settling is the integral term's: the same file without it settles where K σ = L (|σ| = 6.2e-4, reached
    # to 3e-19 at the end, measured), the attitude error the integral term removes
    text = MRP_EXAMPLE.read_text(encoding="utf-8")
    without = re.sub(r"(?m)^(Ki|attitude_error_integral) = .*\n", "", text)
    assert without.count("\n") == text.count("\n") - 2
    proportional = parse(without).run()
    np.testing.assert_allclose(_mrp(proportional.q[-1]), DISTURBANCE / K_GAIN, rtol=0, atol=1e-11)
    assert "attitude_error_integral" not in proportional.extras


def test_mrp_example_figure_and_rows(mrp_run):
    scenario = load(MRP_EXAMPLE)
    assert np.array_equal(scenario.target(), attitude.identity())
    assert len(scenario.figure(mrp_run).axes) == 4
    rows = dict(scenario.rows(mrp_run))
    angle = np.degrees(attitude.relative_angle(mrp_run.q[-1], attitude.identity()))
    assert rows["target"] == f"final angle to the target {angle:.3g} deg" and angle < 1e-9


def test_docs_show_the_mrp_example_as_it_is():
    docs = (ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8")
    shown = dict(re.findall(r"```toml\n# examples/(\S+)\n(.*?)```", docs, flags=re.S))
    assert shown["spacecraft/mrp_disturbance.toml"] == MRP_EXAMPLE.read_text(encoding="utf-8")


# ---------------------------------------------------------------------------------------------------------
# The tables of the parts added with the front door: each file is tumble.simulate of the spacecraft written
# with the Python API, bit for bit
# ---------------------------------------------------------------------------------------------------------

WHEEL_TABLE = """
[spacecraft]
moments = [10.0, 12.0, 8.0]
""" + "".join(f"""
[[spacecraft.wheels]]
axis = {axis}
inertia = 0.05
max_torque = 0.02
""" for axis in ("[1, 0, 0]", "[0, 1, 0]", "[0, 0, 1]")) + """
[[spacecraft.controller]]
kind = "wheel_torques"
times = [0.0, 1.0, 2.0]
torques = [[0.01, 0.0, -0.005], [0.0, 0.03, 0.0], [0.0, 0.0, 0.0]]
interpolation = "previous"

[initial]
omega = [0.01, 0.0, 0.0]
wheel_speeds = [1.0, -2.0, 0.0]

[time]
stop = 3.0
step = 0.5

[solver]
dt = 0.05
"""

MRP_TABLE = """
[spacecraft]
inertia = [[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]]

[spacecraft.wheel_pyramid]
inertia = 0.02

[[spacecraft.controller]]
kind = "mrp_feedback"
K = 0.5
P = [[3.0, 0.1, 0.0], [0.1, 3.0, 0.0], [0.0, 0.0, 2.5]]
Ki = 1e-3
target_euler = { seq = "ZYX", angles = [30.0, -10.0, 5.0] }

[[spacecraft.controller]]
kind = "wheel_torques"
torques = [0.001, -0.001, 0.0, 0.0005]

[[torque]]
kind = "tabulated"
frame = "inertial"
times = [0.0, 2.0]
values = [[0.0, 0.001, 0.0], [0.002, 0.0, 0.0]]

[initial]
omega = [0.0, 0.01, 0.0]
euler = { seq = "XYZ", angles = [5.0, 0.0, -3.0] }
attitude_error_integral = [0.1, -0.2, 0.05]

[time]
stop = 4.0
samples = 9

[solver]
method = "dop853"
rtol = 1e-10
atol = 1e-10
"""

DAMPER_TABLE = """
[spacecraft.hub]
moments = [9.0, 11.0, 7.5]
mass = 100.0

[spacecraft.cmgs]
momentum = 0.5
steering = "generalised"
dither_phases = [0.0, 1.0, 2.0]

[spacecraft.damper]
inertia = 0.2
damping = 0.05

[[spacecraft.controller]]
kind = "quaternion_pd"
natural_frequency = 0.3
target = [0.9, 0.2, -0.15, 0.35]

[[torque]]
kind = "constant_body"
value = [0.0, 0.0, 0.002]

[initial]
omega = [0.05, -0.02, 0.03]
gimbal_angles = [0.1, 0.0, -0.1, 0.0]
damper_omega = [0.0, 0.0, 0.1]

[time]
stop = 3.0
step = 0.5
"""


def _python_run(name):
    """The spacecraft of the table ``name`` and the arguments of its run, written with the Python API."""
    if name == "wheel_torques":
        craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]),
                           wheels=[ReactionWheel(axis=axis, inertia=0.05, max_torque=0.02) for axis in np.eye(3)],
                           controller=WheelTorques([[0.01, 0.0, -0.005], [0.0, 0.03, 0.0], [0.0, 0.0, 0.0]],
                                                   t=[0.0, 1.0, 2.0], interpolation="previous"))
        return craft, dict(omega0=[0.01, 0.0, 0.0], wheel_speeds0=[1.0, -2.0, 0.0], t=np.linspace(0.0, 3.0, 7),
                           method="rk4", dt=0.05)
    if name == "mrp_feedback":
        p = np.array([[3.0, 0.1, 0.0], [0.1, 3.0, 0.0], [0.0, 0.0, 2.5]])
        target = attitude.from_euler("ZYX", [30.0, -10.0, 5.0], degrees=True)
        craft = Spacecraft(inertia=np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]]),
                           wheels=pyramid_wheels(0.02),
                           controller=[MRPFeedback(K=0.5, P=p, Ki=1e-3, target=target),
                                       WheelTorques([0.001, -0.001, 0.0, 0.0005])])
        return craft, dict(omega0=[0.0, 0.01, 0.0], q0=attitude.from_euler("XYZ", [5.0, 0.0, -3.0], degrees=True),
                           attitude_error_integral0=[0.1, -0.2, 0.05], t=np.linspace(0.0, 4.0, 9),
                           method="dop853", rtol=1e-10, atol=1e-10,
                           torque=torques.Tabulated([0.0, 2.0], [[0.0, 0.001, 0.0], [0.002, 0.0, 0.0]],
                                                    frame="inertial"))
    craft = Spacecraft(hub=RigidBody(np.diag([9.0, 11.0, 7.5]), mass=100.0),
                       cmgs=CMGCluster.pyramid(0.5).generalised(dither_phases=(0.0, 1.0, 2.0)),
                       damper=SphericalDamper(0.2, 0.05),
                       controller=QuaternionPD(0.3, target=[0.9, 0.2, -0.15, 0.35]))
    return craft, dict(omega0=[0.05, -0.02, 0.03], gimbal_angles0=[0.1, 0.0, -0.1, 0.0],
                       damper_omega0=[0.0, 0.0, 0.1], t=np.linspace(0.0, 3.0, 7), method="rk4", dt=0.1,
                       torque=torques.ConstantBody([0.0, 0.0, 0.002]))


TABLES = {"wheel_torques": WHEEL_TABLE, "mrp_feedback": MRP_TABLE, "damper_and_generalised_cmgs": DAMPER_TABLE}


@pytest.mark.parametrize("name", TABLES)
def test_tables_build_the_spacecraft_of_the_python_api(name):
    craft, options = _python_run(name)
    traj = parse(TABLES[name]).run()
    assert_same_run(traj, tumble.simulate(craft, **options))
    model = parse(TABLES[name]).model
    if name == "damper_and_generalised_cmgs":
        assert model.cmgs.dither == 0.01 and model.cmgs.dither_phases == (0.0, 1.0, 2.0)   # Wie's ε₀, the file's φ
        assert np.abs(traj.damper_omega[0] - [0.0, 0.0, 0.1]).max() == 0.0
    else:
        assert traj.wheel_torque.shape == (len(traj), len(model.wheels))


def test_singularity_robust_steering_is_the_default_and_takes_no_dither():
    text = DAMPER_TABLE.replace('steering = "generalised"\ndither_phases = [0.0, 1.0, 2.0]\n', "")
    assert parse(text).model.cmgs.dither == 0.0


# The MRP example with one edit each (old, new), and the key and rule of the refusal.
MRP_BAD = [
    ("Ki = 3e-5 ", "Ki = 3e-5\nKd = 1.0 ", "spacecraft.controller[0].Kd", "unknown key"),
    ("K = 10.0 ", "K = 0.0 ", "spacecraft.controller[0].K", "must be > 0"),
    ("K = 10.0 ", "K = -10.0 ", "spacecraft.controller[0].K", "must be > 0"),
    ("P = 150.0", "P = [[150.0, 200.0, 0.0], [200.0, 150.0, 0.0], [0.0, 0.0, 150.0]]", "spacecraft.controller[0].P",
     "symmetric positive-definite"),
    ("P = 150.0", "P = [[150.0, 0.0], [0.0, 150.0]]", "spacecraft.controller[0].P[0]", "at least 3 entries"),
    ("Ki = 3e-5 ", "Ki = -3e-5 ", "spacecraft.controller[0].Ki", "must be > 0"),
    ("target = [1.0, 0.0, 0.0, 0.0]", 'target = [1.0, 0.0, 0.0, 0.0]\ntarget_euler = { seq = "ZYX", angles = '
     "[10.0, 0.0, 0.0] }", "spacecraft.controller[0].target_euler", "not both"),
    ("target = [1.0, 0.0, 0.0, 0.0]", "target = [0.0, 0.0, 0.0, 0.0]", "spacecraft.controller[0].target",
     "non-zero quaternion"),
    ("[[torque]]\n", '[[spacecraft.controller]]\nkind = "wheel_torques"\ntorques = [0.01, 0.02]\n\n[[torque]]\n',
     "spacecraft.controller", "WheelTorques gives 2 motor torques for 3 wheels"),
    ("[[torque]]\n", '[[spacecraft.controller]]\nkind = "wheel_torques"\ntimes = [0.0, 1.0]\n'
     "torques = [[0.01, 0.0, 0.0]]\n\n[[torque]]\n", "spacecraft.controller[1].torques", "must have shape (len(t)"),
    ("[[torque]]\n", '[[spacecraft.controller]]\nkind = "wheel_torques"\ntorques = [0.0, 0.0, 0.0]\n'
     'interpolation = "previous"\n\n[[torque]]\n', "spacecraft.controller[1].interpolation", "only with times"),
    ("[[torque]]\n", '[[spacecraft.controller]]\nkind = "wheel_torques"\ntimes = [0.0, 0.0]\n'
     "torques = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n\n[[torque]]\n", "spacecraft.controller[1].times",
     "strictly increasing"),
    ("[[torque]]\n", "[spacecraft.damper]\ninertia = 0.5\ndamping = -0.1\n\n[[torque]]\n",
     "spacecraft.damper.damping", "must be > 0"),
    ("[[torque]]\n", "[spacecraft.damper]\ninertia = 0.5\n\n[[torque]]\n", "spacecraft.damper.damping",
     "missing required key"),
    ("[[torque]]\n", "[spacecraft.cmgs]\nmomentum = 1.0\ndither = 0.01\n\n[[torque]]\n", "spacecraft.cmgs.dither",
     'only with steering = "generalised"'),
    ("[[torque]]\n", '[spacecraft.cmgs]\nmomentum = 1.0\nsteering = "generalised"\ndither = 0.6\n\n[[torque]]\n',
     "spacecraft.cmgs.dither", "must be < 0.5"),
    ("value = [0.005, -0.003, 0.002]", "value = [0.005, -0.003]", "torque[0].value", "at least 3 entries"),
    ('kind = "constant_body"', 'kind = "solar_pressure"', "torque[0].kind", "must be one of"),
    ("attitude_error_integral = [0.0, 0.0, 0.0]", "damper_omega = [0.0, 0.0, 0.0]", "initial.damper_omega",
     "no initial state 'damper_omega0'"),
    ("Ki = 3e-5 ", "", "initial.attitude_error_integral", "no initial state 'attitude_error_integral0'"),
    ("moments = [900.0, 800.0, 600.0]", "moments = [900.0, 800.0, 600.0]\ngravity_gradient = true\n\n"
     "[spacecraft.orbit]\naltitude = 700e3", "torque[1].kind", "the gravity gradient is already on"),
]


@pytest.mark.parametrize("old, new, where, rule", MRP_BAD, ids=[bad[2] for bad in MRP_BAD])
def test_bad_tables_are_refused_naming_the_file_and_key(old, new, where, rule):
    text = MRP_EXAMPLE.read_text(encoding="utf-8")
    assert text.count(old) == 1, old
    text = text.replace(old, new)
    if where == "torque[1].kind":
        text += '\n[[torque]]\nkind = "gravity_gradient"\n\n[torque.orbit]\naltitude = 700e3\n'
    with pytest.raises(ScenarioError) as info:
        parse(text, source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems
    assert str(info.value).startswith(f"craft.toml: {where}: ")
