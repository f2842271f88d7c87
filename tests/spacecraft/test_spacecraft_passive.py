"""Gravity-gradient equilibria, libration frequencies and stability regions; the major-axis rule."""

import math

import numpy as np
import pytest

import tumble
from tumble.scenario import load_scenario
from tumble.spacecraft import passive
from tumble.viz.passive import gravity_gradient_stability_figure
from tumble.spacecraft.orbit import Orbit, attitude_in_lvlh, lvlh_quaternion
from tumble.torques import GravityGradient

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

ORBIT = Orbit.circular(700e3)
N = ORBIT.mean_motion
# Body axes: 1 roll (along-track), 2 pitch (minus orbit normal), 3 yaw (nadir).
LAGRANGE = (300.0, 400.0, 200.0)         # k_R = 2/3, k_Y = 1/2
DEBRA_DELP = (151.51515151515152, 100.0, 103.03030303030303)  # k_R = -0.02, k_Y = -0.5
PITCH_UNSTABLE = (200.0, 100.0, 300.0)   # I1 < I3
ROLL_YAW_UNSTABLE = (100.0, 98.0, 10.0)  # k_R = 0.88, k_Y = -0.2: k_R k_Y < 0

# The LVLH-held attitude stays put to 1e-12 rad over 5 orbits at rtol = 1e-11
# (measured: 4e-14); the deviation is integration error, the start is exact.
EQUILIBRIUM_TOL = 1e-12
# Frequencies from zero crossings of a single-mode libration (largest angle
# 1e-3 rad) over 6 orbits against the linear theory: the nonlinear shift is
# O(amplitude²) ~ 1e-7 and the interpolation error of the crossings is below
# that. Measured: pitch 2.5e-7 (the pendulum shift (2θ₀)²/16 of
# θ̈ ∝ −sin 2θ), roll/yaw modes 2e-9 and 1.8e-7.
FREQUENCY_RTOL = 1e-6


def simulate_libration(moments, angles=(0.0, 0.0, 0.0), rates=(0.0, 0.0, 0.0), *, orbits=5.0, samples=3001):
    """Simulate a body starting at roll/pitch/yaw ``angles`` and their rates relative to LVLH (rad, rad/s)."""
    roll, pitch, yaw = angles
    droll, dpitch, dyaw = rates
    q_lvlh_b = tumble.attitude.from_euler("ZYX", [yaw, pitch, roll])
    # body rate relative to LVLH from the 3-2-1 Euler-angle rates, plus the LVLH rate (0, -n, 0)
    w_rel = np.array([droll - dyaw * math.sin(pitch),
                      dpitch * math.cos(roll) + dyaw * math.cos(pitch) * math.sin(roll),
                      -dpitch * math.sin(roll) + dyaw * math.cos(pitch) * math.cos(roll)])
    omega0 = w_rel + tumble.attitude.rotate_inverse(q_lvlh_b, [0.0, -N, 0.0])
    q0 = tumble.attitude.multiply(lvlh_quaternion(*ORBIT.state(0.0)), q_lvlh_b)
    inertia = np.diag(moments)
    t = np.linspace(0.0, orbits * ORBIT.period, samples)
    traj = tumble.simulate(inertia, omega0, q0=q0, t=t, rtol=1e-11, atol=1e-14,
                           torque=GravityGradient(ORBIT, inertia))
    return t, attitude_in_lvlh(traj, ORBIT)


def zero_crossing_frequency(t, x):
    """Angular frequency (rad/s) of an oscillation from the times of its zero crossings (linear interpolation)."""
    k = np.flatnonzero(np.signbit(x[1:]) != np.signbit(x[:-1]))
    crossings = t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
    half_period = np.polyfit(np.arange(crossings.size), crossings, 1)[0]
    return math.pi / half_period


@pytest.mark.slow  # the first simulation compiles dop853 with a torque program (~20 s cold)
def test_lvlh_attitude_is_an_equilibrium():
    t, rel = simulate_libration(LAGRANGE)
    deviation = np.max(np.abs([rel.roll, rel.pitch, rel.yaw]))
    assert deviation < EQUILIBRIUM_TOL


@pytest.mark.slow
def test_pitch_libration_frequency():
    s = passive.gravity_gradient_stability(LAGRANGE)
    expected = N * math.sqrt(3 * (LAGRANGE[0] - LAGRANGE[2]) / LAGRANGE[1])
    assert math.isclose(s.pitch_frequency * N, expected, rel_tol=1e-15)
    t, rel = simulate_libration(LAGRANGE, angles=(0.0, 1e-3, 0.0), orbits=6.0)
    assert np.max(np.abs(rel.roll)) + np.max(np.abs(rel.yaw)) < EQUILIBRIUM_TOL  # planar: no roll, no yaw
    assert math.isclose(zero_crossing_frequency(t, rel.pitch), expected, rel_tol=FREQUENCY_RTOL)


@pytest.mark.slow
@pytest.mark.parametrize("mode", [0, 1])
def test_roll_yaw_mode_frequencies(mode):
    """Each root of s⁴ + (1 + 3k_R + k_R k_Y) n² s² + 4 k_R k_Y n⁴ = 0, excited alone, is the measured frequency.

    Mode ω: roll φ = A cos ωt, yaw ψ = B sin ωt with B = A (4n² k_R − ω²) / (n (1 − k_R) ω)
    (from the linearised roll equation φ̈ − n(1 − k_R) ψ̇ + 4n² k_R φ = 0, Wie ch. 6).
    """
    s = passive.gravity_gradient_stability(LAGRANGE)
    i1, i2, i3 = LAGRANGE
    kr, ky = (i2 - i3) / i1, (i2 - i1) / i3
    w = s.roll_yaw_frequencies[mode] * N
    assert math.isclose(w**4 - (1 + 3 * kr + kr * ky) * N**2 * w**2 + 4 * kr * ky * N**4, 0.0,
                        abs_tol=1e-14 * w**4)
    amplitude = 1e-4  # the slow mode's yaw is ~10x its roll: 1e-3 rad, still linear
    b = amplitude * (4 * N**2 * kr - w**2) / (N * (1 - kr) * w)
    t, rel = simulate_libration(LAGRANGE, angles=(amplitude, 0.0, 0.0), rates=(0.0, 0.0, b * w), orbits=6.0)
    assert math.isclose(zero_crossing_frequency(t, rel.roll), w, rel_tol=FREQUENCY_RTOL)
    assert math.isclose(np.max(np.abs(rel.yaw)), abs(b), rel_tol=1e-5)  # the mode's yaw amplitude (3e-7 measured)


@pytest.mark.parametrize("moments, region, pitch, roll_yaw", [
    (LAGRANGE, "Lagrange", True, True),
    (DEBRA_DELP, "DeBra-Delp", True, True),
    (PITCH_UNSTABLE, "unstable", False, False),
    (ROLL_YAW_UNSTABLE, "unstable", True, False),
    ((100.0, 80.0, 95.0), "unstable", True, False),  # k_R, k_Y < 0 outside the DeBra-Delp sliver
])
def test_gravity_gradient_classification(moments, region, pitch, roll_yaw):
    s = passive.gravity_gradient_stability(moments)
    assert (s.region, s.pitch_stable, s.roll_yaw_stable, s.stable) == (region, pitch, roll_yaw, pitch and roll_yaw)
    i1, i2, i3 = moments
    assert (s.k_roll, s.k_yaw) == ((i2 - i3) / i1, (i2 - i1) / i3)


# Stable: a 1e-3 rad start stays within 5e-3 rad over 8 orbits (measured peak:
# 1.6e-3 rad Lagrange, 3.6e-3 DeBra-Delp). Unstable: it exceeds 0.1 rad
# (measured: 3.1 rad, a tumble, in both unstable cases).
STABLE_BOUND, DIVERGED = 5e-3, 0.1


@pytest.mark.slow
@pytest.mark.parametrize("moments", [LAGRANGE, DEBRA_DELP, PITCH_UNSTABLE, ROLL_YAW_UNSTABLE])
def test_classification_agrees_with_simulation(moments):
    t, rel = simulate_libration(moments, angles=(1e-3, 1e-3, 1e-3), orbits=8.0, samples=801)
    peak = np.max(np.abs([rel.roll, rel.pitch, rel.yaw]))
    if passive.gravity_gradient_stability(moments).stable:
        assert peak < STABLE_BOUND
    else:
        assert peak > DIVERGED


def test_gravity_gradient_stability_refuses_non_principal_axes():
    with pytest.raises(tumble.ValidationError, match="principal"):
        passive.gravity_gradient_stability([[300.0, 1.0, 0.0], [1.0, 400.0, 0.0], [0.0, 0.0, 200.0]])
    with pytest.raises(tumble.ValidationError, match="inertia"):
        passive.gravity_gradient_stability([1.0, 2.0])


def test_stability_figure_places_the_spacecraft():
    fig = gravity_gradient_stability_figure(LAGRANGE)
    (star,) = [line for line in fig.axes[0].lines if line.get_marker() == "*"]
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (2 / 3, 0.5)
    assert "Lagrange" in star.get_label()


# --- the major-axis rule ------------------------------------------------------------------------------


@pytest.mark.parametrize("axis, role, rigid, dissipative", [
    ([0.0, 0.0, 2.0], "major", "stable", True),
    ([0.0, -1.0, 0.0], "intermediate", "unstable", False),
    ([1.0, 0.0, 0.0], "minor", "stable", False),
])
def test_major_axis_rule(axis, role, rigid, dissipative):
    s = passive.spin_stability(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), axis)
    assert (s.role, s.rigid, s.with_dissipation) == (role, rigid, dissipative)
    assert s.moment == float(np.argmax(np.abs(axis)) + 1)


def test_major_axis_rule_rotated_body_and_symmetric_tops():
    rot = tumble.attitude.to_matrix(tumble.attitude.from_euler("ZYX", [0.3, 0.2, -0.4]))
    body = tumble.RigidBody(rot @ np.diag([1.0, 2.0, 3.0]) @ rot.T)
    assert passive.spin_stability(body, rot[:, 2]).with_dissipation
    assert passive.spin_stability(body, rot[:, 0]).role == "minor"
    oblate = tumble.RigidBody(np.diag([1.0, 1.0, 1.5]))
    assert passive.spin_stability(oblate, [1.0, 1.0, 0.0])[1:] == ("minor", "neutral", False)
    prolate = tumble.RigidBody(np.diag([0.4, 1.0, 1.0]))  # Explorer 1's shape: spin about the long axis
    assert passive.spin_stability(prolate, [1.0, 0.0, 0.0])[1:] == ("minor", "stable", False)
    assert passive.spin_stability(prolate, [0.0, 1.0, 1.0])[1:] == ("major", "neutral", True)
    with pytest.raises(tumble.ValidationError, match="principal axis"):
        passive.spin_stability(body, [1.0, 1.0, 0.0])


@pytest.mark.slow
def test_gravity_gradient_example_librates_about_lvlh():
    """examples/spacecraft/gravity_gradient.toml: released 5° off in pitch, it stays within 6° of LVLH for
    10 orbits (measured largest angle 5.26°: the roll/yaw coupling adds a little to the initial offsets)."""
    path = tumble.examples.directory() / "spacecraft" / "gravity_gradient.toml"
    problem = load_scenario(path).build()
    rel = attitude_in_lvlh(problem.simulate(), problem.torque.orbit)
    assert math.radians(5.0) <= np.max(np.abs([rel.roll, rel.pitch, rel.yaw])) < math.radians(6.0)
