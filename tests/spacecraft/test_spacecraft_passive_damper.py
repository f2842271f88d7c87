"""A hub with a spherical viscous damper: invariants, the energy-sink estimate, the Explorer 1 flat spin."""

import math
import re

import numpy as np
import pytest

import tumble
from tumble.scenario import ScenarioError, load_scenario, parse_scenario
from tumble.spacecraft import Spacecraft
from tumble.spacecraft import damper as d
from tumble.spacecraft import passive
from tumble.viz.passive import demo_explorer1

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

# A scaled Explorer 1: prolate hub (spin axis z the minor axis), damper 2 % of
# the transverse moment, tuned for the spin (time constant 87 s instead of
# Explorer 1's minutes, so the run is short).
HUB = tumble.RigidBody(np.diag([1.0, 1.0, 0.4]))
J, SPIN, THETA0 = 0.02, 2.0, 0.01
I_S, I_T = 0.4 + J, 1.0 + J  # moments with the sphere locked to the hub
DAMPER = d.SphericalDamper.tuned(J, I_S, I_T, SPIN)
CRAFT = Spacecraft(hub=HUB, damper=DAMPER)  # the hub without the sphere, and the sphere
T = np.linspace(0.0, 1500.0, 3001)

# dop853 at rtol = atol = 1e-12 over 1500 s (5000 steps): |L| drifts by 7e-13
# and the inertial vector L by 3.4e-12 of |L| (measured).
MOMENTUM_RTOL = 1e-11
# The energy-sink estimate neglects terms of order J/I_t (2-3 % here);
# measured tau / estimate: 0.9991 (minor-axis spin, growth), 0.957 (major-axis
# spin, decay). Stated factor: 1.1.
TIME_CONSTANT_FACTOR = 1.1
# At 1500 s (17 time constants) the nutation angle is 90° to 1.6e-6 rad, the
# rate is along L to 2.3e-6 rad and the energy is L²/(2 I_t) to 3.7e-12 (measured).
FLAT_SPIN_TOL = 1e-4
FLOOR_RTOL = 1e-9


def omega_with_nutation(theta, i_s=I_S, i_t=I_T, spin=SPIN):
    """Body rate whose momentum I ω (sphere locked) makes the angle theta with the z axis."""
    return np.array([i_s * spin * math.tan(theta) / i_t, 0.0, spin])


@pytest.fixture(scope="module")
def explorer():
    return tumble.simulate(CRAFT, omega_with_nutation(THETA0), t=T, rtol=1e-12, atol=1e-12)


@pytest.mark.slow
def test_explorer1_ends_in_a_major_axis_spin(explorer):
    theta = d.nutation_angle(explorer, [0.0, 0.0, 1.0])
    assert abs(theta[-1] - math.pi / 2) < FLAT_SPIN_TOL  # L perpendicular to the long (minor) axis
    L_body = explorer.momentum_body[-1]
    w = explorer.omega[-1]
    assert np.linalg.norm(np.cross(w, L_body)) < FLAT_SPIN_TOL * np.linalg.norm(w) * np.linalg.norm(L_body)
    assert abs(w[2]) < FLAT_SPIN_TOL * np.linalg.norm(w)  # w in the plane of the largest moments ...
    assert passive.spin_stability(HUB, [w[0], w[1], 0.0]).role == "major"  # ... a major axis
    energy = explorer.energy
    size = np.linalg.norm(L_body)
    assert math.isclose(energy[-1], size**2 / (2 * I_T), rel_tol=FLOOR_RTOL)


@pytest.mark.slow
def test_explorer1_conserves_momentum_and_loses_energy_monotonically(explorer):
    L = explorer.momentum_inertial
    size = np.linalg.norm(L, axis=-1)
    assert np.max(np.abs(size / size[0] - 1)) < MOMENTUM_RTOL
    assert np.max(np.linalg.norm(L - L[0], axis=-1)) < MOMENTUM_RTOL * size[0]
    energy = explorer.energy
    assert np.all(np.diff(energy) < 0.0)  # strictly falling at every sample (largest step: -1.8e-14 T0)
    assert energy[-1] < 0.45 * energy[0]  # from L²/(2 I_s) to L²/(2 I_t): ratio I_s/I_t = 0.41


@pytest.mark.slow
def test_explorer1_time_constant_matches_energy_sink_estimate(explorer):
    theta = d.nutation_angle(explorer, [0.0, 0.0, 1.0])
    measured = d.measured_time_constant(explorer.t, theta, window=(2 * THETA0, 0.2))
    estimate = d.energy_sink_time_constant(I_S, I_T, DAMPER, SPIN)
    assert estimate > 0.0  # minor-axis spin: the nutation grows
    assert 1 / TIME_CONSTANT_FACTOR < measured / estimate < TIME_CONSTANT_FACTOR


@pytest.mark.slow
def test_major_axis_spin_nutation_decays_at_the_estimated_rate():
    """The same damper on an oblate hub spinning about its major axis: θ decays, τ < 0 as estimated."""
    hub = tumble.RigidBody(np.diag([0.6, 0.6, 1.0]))
    i_s, i_t = 1.0 + J, 0.6 + J
    damper = d.SphericalDamper.tuned(J, i_s, i_t, SPIN)
    t = np.linspace(0.0, 400.0, 801)
    traj = tumble.simulate(Spacecraft(hub=hub, damper=damper), omega_with_nutation(0.1, i_s, i_t), t=t, rtol=1e-12,
                           atol=1e-12)
    theta = d.nutation_angle(traj, [0.0, 0.0, 1.0])
    estimate = d.energy_sink_time_constant(i_s, i_t, damper, SPIN)
    measured = d.measured_time_constant(t, theta, window=(1e-4, 0.05))
    assert estimate < 0.0 and theta[-1] < 1e-3
    assert 1 / TIME_CONSTANT_FACTOR < measured / estimate < TIME_CONSTANT_FACTOR


def test_energy_sink_estimate_closed_forms():
    """At the tuned damping c = JΩI_s/I_t the rate is JΩ(I_t − I_s)/(2I_t²), the largest over c."""
    rate = 1 / d.energy_sink_time_constant(I_S, I_T, DAMPER, SPIN)
    assert math.isclose(rate, J * SPIN * (I_T - I_S) / (2 * I_T**2), rel_tol=1e-14)
    for factor in (0.9, 1.1):
        other = d.SphericalDamper(J, DAMPER.damping * factor)
        assert 1 / d.energy_sink_time_constant(I_S, I_T, other, SPIN) < rate
    assert d.energy_sink_time_constant(0.5, 0.5, DAMPER, SPIN) == math.inf


@pytest.mark.slow
def test_damper_energy_rate_and_steady_spin():
    """Ṫ = −c |ω_d − ω|² at the start of a run; a principal-axis spin with the sphere turning along is steady."""
    omega0, sphere0 = np.array([0.3, -0.2, 1.1]), np.array([0.1, 0.2, 0.9])
    h = 1e-4
    traj = tumble.simulate(CRAFT, omega0, damper_omega0=sphere0, t=[0.0, h, 2 * h], rtol=1e-13, atol=1e-15)
    energy = traj.energy
    rate = (-3 * energy[0] + 4 * energy[1] - energy[2]) / (2 * h)  # second-order one-sided difference
    expected = -DAMPER.damping * np.sum((sphere0 - omega0) ** 2)
    assert math.isclose(rate, expected, rel_tol=1e-6)  # truncation O(h²) ~ 1e-8; measured 7.6e-9
    steady = tumble.simulate(CRAFT, [0.0, 0.0, SPIN], t=np.linspace(0.0, 100.0, 11))
    assert np.array_equal(steady.omega, np.broadcast_to([0.0, 0.0, SPIN], (11, 3)))
    assert np.array_equal(steady.extras["damper_omega"].data, steady.omega)


@pytest.mark.slow
def test_external_torque_on_a_damped_hub_changes_the_momentum_by_its_impulse():
    """torque= acts on a hub with a damper as on any spacecraft, compiled or in Python: a torque fixed in
    inertial space adds τ_N t to the inertial momentum of hub and sphere."""
    tau = np.array([0.01, -0.02, 0.005])
    t = np.linspace(0.0, 5.0, 6)
    omega0 = omega_with_nutation(0.05)
    compiled = tumble.simulate(CRAFT, omega0, t=t, torque=tumble.torques.ConstantInertial(tau), rtol=1e-12,
                               atol=1e-12)
    python = tumble.simulate(CRAFT, omega0, t=t, torque=lambda t, q, w: tumble.attitude.rotate_inverse(q, tau),
                             rtol=1e-12, atol=1e-12)
    L = compiled.momentum_inertial
    # dop853 at rtol 1e-12 over 5 s of a 2 rad/s spin: the error of L is the integrator's (measured 3.8e-13 N m s,
    # |L| = 0.84 N m s)
    np.testing.assert_allclose(L - L[0], t[:, None] * tau, rtol=0, atol=1e-11)
    # the same torque evaluated in Python (q normalised, rotated by the one quaternion rotation): the same motion
    # to rounding (measured 1.8e-15 rad/s)
    np.testing.assert_allclose(python.omega, compiled.omega, rtol=0, atol=1e-13)
    assert python.info["torque"] == "Python function <lambda>"


def test_damper_refuses_bad_input():
    with pytest.raises(tumble.ValidationError, match="damper.inertia"):
        d.SphericalDamper(0.0, 1.0)
    with pytest.raises(tumble.ValidationError, match="damper.damping"):
        d.SphericalDamper(1.0, float("nan"))
    with pytest.raises(tumble.ValidationError, match="damper: must be a SphericalDamper"):
        Spacecraft(hub=HUB, damper=(J, 0.01))
    with pytest.raises(tumble.ValidationError, match="damper_omega0"):
        tumble.simulate(CRAFT, [0.0, 0.0, 1.0], damper_omega0=[1.0, 2.0], t=[0.0, 1.0])
    with pytest.raises(tumble.ValidationError, match="window"):
        d.measured_time_constant([0.0, 1.0, 2.0], [1.0, 2.0, 3.0], window=(0.2, 0.1))


# --- scenarios -----------------------------------------------------------------------------------------

EXAMPLES = tumble.examples.directory() / "spacecraft"


def test_explorer1_example_is_the_demo_spacecraft():
    """examples/spacecraft/explorer1.toml: 750 rpm, nutation 0.5°, damper tuned as in passive.EXPLORER1."""
    problem = load_scenario(EXAMPLES / "explorer1.toml").build()
    e = passive.EXPLORER1
    np.testing.assert_allclose(problem.body.inertia, e.hub().inertia, rtol=1e-15)
    np.testing.assert_allclose(problem.omega0, e.omega0(), rtol=1e-15)
    assert problem.damper == e.damper() and problem.damper_omega0 is None
    i_s, i_t = e.locked_moments()
    L = np.array([i_t * problem.omega0[0], 0.0, i_s * problem.omega0[2]])
    assert math.isclose(math.degrees(math.atan2(L[0], L[2])), 0.5, rel_tol=1e-12)


@pytest.mark.slow
def test_damper_scenario_runs_with_the_damper_states_in_extras():
    text = """
[body]
moments = [1.0, 1.0, 0.4]
[initial]
omega = [0.01, 0.0, 2.0]
[damper]
inertia = 0.02
damping = 0.0165
omega = [0.0, 0.0, 2.1]
[time]
stop = 20.0
samples = 41
[solver]
rtol = 1e-12
atol = 1e-12
"""
    traj = parse_scenario(text).build().simulate()
    assert traj.extras["damper_omega"].data.shape == (41, 3)
    np.testing.assert_array_equal(traj.extras["damper_omega"].data[0], [0.0, 0.0, 2.1])
    L = traj.momentum_inertial
    assert np.max(np.linalg.norm(L - L[0], axis=-1)) < MOMENTUM_RTOL * np.linalg.norm(L[0])
    with pytest.raises(ScenarioError, match=re.escape("damper.damping: must be > 0")):
        parse_scenario(text.replace("damping = 0.0165", "damping = -1.0"))
    with pytest.raises(ScenarioError, match="method"):
        parse_scenario(text.replace("[solver]", "[solver]\nmethod = 'splitting2'\ndt = 0.1").replace(
            "rtol = 1e-12\natol = 1e-12", "")).build().simulate()


@pytest.mark.slow
def test_demo_explorer1_writes_its_files_and_numbers(tmp_path):
    """The demo on the first 900 s of the Explorer 1 run (the nutation still growing: 0.5° → 4.5°)."""
    summary = demo_explorer1(tmp_path, passive.Explorer1(duration=900.0))
    assert (tmp_path / "explorer1.png").stat().st_size > 0
    traj = tumble.load(tmp_path / "explorer1.nc")
    assert traj.extras["damper_omega"].data.shape == (1801, 3)
    assert 1 / TIME_CONSTANT_FACTOR < summary["time_constant_s"] / summary["time_constant_estimate_s"] < (
        TIME_CONSTANT_FACTOR)
    assert summary["momentum_drift"] < 1e-10  # measured 1.7e-12 (1e5 steps at rtol 1e-12)
    assert summary["max_energy_increase"] < 0.0
    with pytest.raises(tumble.ValidationError, match="out_dir"):
        demo_explorer1(tmp_path / "missing")
