"""Spacecraft scenario files: the examples run, bad files are refused naming the key."""

from pathlib import Path

import numpy as np
import pytest

from tumble import attitude
from tumble.scenario import ScenarioError, load, parse, run_scenario
from tumble.spacecraft.figure import spacecraft_figure

# Every test here compiles a spacecraft model type on first use (30–40 s with a cold Numba cache
# on 2 shared cores, under 1 s warm).
pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).parent.parent / "examples" / "spacecraft"


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
    (("samples = 3", "samples = 3\n[solver]\nmethod = \"cf4\"\ndt = 0.1"), "solver.method", "for a spacecraft"),
])
def test_bad_scenarios_name_the_key(edit, where, rule):
    text = GOOD.replace(*edit)
    with pytest.raises(ScenarioError) as info:
        parse(text, source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems


# The craft of tests/test_spacecraft_wheels.py::test_hub_plus_wheels_equals_total_inertia, as scenario files:
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
    """The craft's total inertia about its centre of mass, summed independently of tumble.body: the
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
