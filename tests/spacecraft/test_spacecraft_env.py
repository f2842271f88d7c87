"""Orbit, LVLH frame, gravity-gradient torque and dipole field (tumble.spacecraft.orbit / .environment)."""

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tumble
from tumble.scenario import ScenarioError, load_scenario, parse_scenario
from tumble.spacecraft import environment, orbit
from tumble.spacecraft.environment import DipoleField, dipole_field, gravity_gradient_torque
from tumble.spacecraft.orbit import Orbit, lvlh_matrix, lvlh_quat, lvlh_quaternion, orbit_state
from tumble.spacecraft.passive import gravity_gradient_stability

EXAMPLES = tumble.examples.directory() / "spacecraft"

# Kepler's equation is solved to the Newton stopping rule (1e-15 rad); the
# residual |E - e sin E - M| measured over the grid below is <= 4.5e-16 rad.
KEPLER_RESIDUAL_TOL = 2e-15
# Two-body integration by solve_ivp (DOP853, rtol = atol-scaled 1e-13) over one
# period of the elliptic orbit below reproduces the closed form to 3e-9 relative.
TWO_BODY_TOL = 1e-7
# Rounding of the vis-viva energy v^2/2 - mu/r (terms ~3e7 m^2/s^2).
VIS_VIVA_RTOL = 1e-13

ELLIPTIC = Orbit(semi_major_axis=9.0e6, eccentricity=0.3, inclination=0.9, raan=0.4, arg_periapsis=1.3,
                 mean_anomaly=0.2)


@pytest.mark.parametrize("e", [0.0, 0.1, 0.5, 0.9, 0.99, 0.999])
def test_kepler_equation_is_solved(e):
    M = np.linspace(-12.0, 12.0, 241)
    E = np.array([orbit.eccentric_anomaly(m, e) for m in M])
    residual = np.remainder(E - e * np.sin(E) - M + np.pi, 2 * np.pi) - np.pi
    assert np.max(np.abs(residual)) < KEPLER_RESIDUAL_TOL


def test_orbit_state_matches_two_body_integration():
    """The closed form against an independent numerical integration of r'' = -mu r / |r|^3."""
    r0, v0 = ELLIPTIC.state(0.0)
    t = np.linspace(0.0, ELLIPTIC.period, 7)

    def f(_, y):
        r = y[:3]
        return np.concatenate([y[3:], -ELLIPTIC.mu * r / np.linalg.norm(r) ** 3])

    sol = solve_ivp(f, (0.0, t[-1]), np.concatenate([r0, v0]), method="DOP853", t_eval=t, rtol=1e-13,
                    atol=1e-13 * np.array([1e7] * 3 + [1e4] * 3))
    r, v = ELLIPTIC.state(t)
    assert np.max(np.abs(r - sol.y[:3].T)) / ELLIPTIC.semi_major_axis < TWO_BODY_TOL
    assert np.max(np.abs(v - sol.y[3:].T)) / np.linalg.norm(v0) < TWO_BODY_TOL


def test_orbit_invariants_and_geometry():
    t = np.linspace(0.0, 2.0 * ELLIPTIC.period, 101)
    r, v = ELLIPTIC.state(t)
    a, e, i, raan = ELLIPTIC.semi_major_axis, ELLIPTIC.eccentricity, ELLIPTIC.inclination, ELLIPTIC.raan
    energy = 0.5 * np.sum(v * v, axis=-1) - ELLIPTIC.mu / np.linalg.norm(r, axis=-1)
    np.testing.assert_allclose(energy, -ELLIPTIC.mu / (2 * a), rtol=VIS_VIVA_RTOL)
    h = np.cross(r, v)
    p = a * (1 - e * e)  # semi-latus rectum: |h| = sqrt(mu p)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), math.sqrt(ELLIPTIC.mu * p), rtol=VIS_VIVA_RTOL)
    normal = np.array([math.sin(i) * math.sin(raan), -math.sin(i) * math.cos(raan), math.cos(i)])
    np.testing.assert_allclose(h / np.linalg.norm(h, axis=-1, keepdims=True), np.broadcast_to(normal, h.shape),
                               atol=1e-14)
    n = ELLIPTIC.mean_motion
    t_peri = (2 * math.pi - ELLIPTIC.mean_anomaly) / n
    r_apsides = np.linalg.norm(ELLIPTIC.state([t_peri, t_peri + math.pi / n])[0], axis=-1)
    np.testing.assert_allclose(r_apsides, [a * (1 - e), a * (1 + e)], rtol=1e-14)
    np.testing.assert_allclose(r[-1], r[0], rtol=1e-12, atol=1e-12 * a)  # two whole periods


def test_orbit_state_kernel_equals_vectorised_and_circular_constructor():
    orb = Orbit.circular(700e3, inclination=math.radians(98.0), raan=0.3, arg_latitude=0.5)
    assert orb.semi_major_axis == orbit.EARTH_RADIUS + 700e3
    r, v = orb.state(123.0)
    assert orbit_state(orb.elements(), 123.0) == tuple(np.concatenate([r, v]))
    assert math.isclose(np.linalg.norm(r), orb.semi_major_axis, rel_tol=1e-15)
    assert math.isclose(np.linalg.norm(v), math.sqrt(orb.mu / orb.semi_major_axis), rel_tol=1e-15)
    assert math.isclose(orb.period, 2 * math.pi * math.sqrt(orb.semi_major_axis**3 / orb.mu), rel_tol=1e-15)
    assert r.shape == v.shape == (3,) and orb.state(np.zeros((2, 5)))[0].shape == (2, 5, 3)


@pytest.mark.parametrize("kwargs, field", [
    ({"semi_major_axis": -1.0}, "semi_major_axis"),
    ({"semi_major_axis": 7e6, "eccentricity": 1.0}, "eccentricity"),
    ({"semi_major_axis": 7e6, "inclination": 4.0}, "inclination"),
    ({"semi_major_axis": 7e6, "raan": float("nan")}, "raan"),
])
def test_orbit_refuses_bad_elements(kwargs, field):
    with pytest.raises(tumble.ValidationError, match=field):
        Orbit(**kwargs)


def test_lvlh_frame_axes():
    t = np.linspace(0.0, ELLIPTIC.period, 13)
    r, v = ELLIPTIC.state(t)
    m = lvlh_matrix(r, v)
    np.testing.assert_allclose(m @ np.swapaxes(m, -1, -2), np.broadcast_to(np.eye(3), m.shape), atol=1e-15)
    np.testing.assert_allclose(np.linalg.det(m), 1.0, atol=1e-15)
    np.testing.assert_allclose(m[..., 2], -r / np.linalg.norm(r, axis=-1, keepdims=True), atol=1e-15)
    h = np.cross(r, v)
    np.testing.assert_allclose(m[..., 1], -h / np.linalg.norm(h, axis=-1, keepdims=True), atol=1e-15)
    q = lvlh_quaternion(r, v)
    np.testing.assert_allclose(tumble.attitude.to_matrix(q), m, atol=1e-15)
    np.testing.assert_allclose(lvlh_quat(*r[5], *v[5]), q[5], atol=1e-16)
    # circular orbit: o1 is the velocity direction
    rc, vc = Orbit.circular(500e3, 0.7).state(321.0)
    np.testing.assert_allclose(lvlh_matrix(rc, vc)[:, 0], vc / np.linalg.norm(vc), atol=1e-15)
    with pytest.raises(tumble.ValidationError, match="r, v"):
        lvlh_matrix([7e6, 0, 0], [1.0, 0, 0])


def test_attitude_in_lvlh_of_an_lvlh_held_body():
    """A body whose attitude is q_I_LVLH(t) ⊗ q_LVLH_B with constant q_LVLH_B reads back that q_LVLH_B."""
    orb = Orbit.circular(600e3, 0.5)
    t = np.linspace(0.0, orb.period, 9)
    q_lvlh_b = tumble.attitude.from_euler("ZYX", [0.3, -0.2, 0.1])  # yaw, pitch, roll
    q = tumble.attitude.multiply(lvlh_quaternion(*orb.state(t)), q_lvlh_b)
    traj = tumble.Trajectory(t=t, q=q, omega=np.zeros((t.size, 3)), inertia=np.eye(3))
    rel = orbit.attitude_in_lvlh(traj, orb)
    np.testing.assert_allclose(tumble.attitude.relative_angle(rel.q, q_lvlh_b), 0.0, atol=2e-8)
    np.testing.assert_allclose(rel.yaw, 0.3, atol=1e-14)
    np.testing.assert_allclose(rel.pitch, -0.2, atol=1e-14)
    np.testing.assert_allclose(rel.roll, 0.1, atol=1e-14)


# --- gravity gradient ------------------------------------------------------------------------------------

# Point-mass sum of the exact torque against the leading-order formula: with
# the masses in +/- pairs the odd terms cancel, so the next term is
# O((rho/R)^2) = 2e-12 relative, below the cancellation error of the sum (~1e-10).
POINT_MASS_TOL = 1e-8


def test_gravity_gradient_equals_exact_torque_on_point_masses():
    rng = np.random.default_rng(5)
    rho = rng.normal(size=(4, 3)) * 5.0  # m, pairs at +rho and -rho
    masses = np.array([3.0, 1.0, 2.0, 5.0])
    inertia = sum(m * (p @ p * np.eye(3) - np.outer(p, p)) for m, p in zip(2 * masses, rho))
    mu = orbit.EARTH_MU
    R = np.array([4.1e6, -3.3e6, 4.4e6])
    exact = np.zeros(3)
    for m, p in zip(masses, rho):
        for s in (1.0, -1.0):
            x = R + s * p
            exact += np.cross(s * p, -mu * m * x / np.linalg.norm(x) ** 3)
    tau = gravity_gradient_torque(mu, *R, inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                  inertia[0, 1], inertia[0, 2], inertia[1, 2])
    np.testing.assert_allclose(tau, exact, rtol=POINT_MASS_TOL, atol=POINT_MASS_TOL * np.abs(exact).max())


def test_gravity_gradient_torque_model_in_body_axes():
    """GravityGradient(orbit, I)(t, q, ω) = 3μ/|r|⁵ r_B × (I r_B) with r_B = R(q)ᵀ r_N(t), any body axes."""
    orb = Orbit.circular(700e3, 1.0)
    inertia = np.array([[300.0, 12.0, -5.0], [12.0, 400.0, 8.0], [-5.0, 8.0, 200.0]])
    model = tumble.torques.GravityGradient(orb, inertia)
    q = tumble.attitude.normalize([0.9, 0.2, -0.3, 0.1])
    r_b = tumble.attitude.rotate_inverse(q, orb.state(40.0)[0])
    expected = 3 * orb.mu / np.linalg.norm(r_b) ** 5 * np.cross(r_b, inertia @ r_b)
    np.testing.assert_allclose(model(40.0, q, np.zeros(3)), expected, rtol=1e-13, atol=1e-20)
    with pytest.raises(tumble.ValidationError, match="orbit"):
        tumble.torques.GravityGradient([7e6, 0, 0], inertia)
    with pytest.raises(tumble.ValidationError, match="inertia"):
        tumble.torques.GravityGradient(orb, np.eye(2))


# --- dipole field --------------------------------------------------------------------------------------

# Central differences with a 10 m step on fields that vary on the scale of
# r ~ 7e6 m: truncation ~ (h/r)^2 ~ 1e-12, rounding ~ 1e-16 |B| r / h ~ 1e-11 relative.
FIELD_DIFF_TOL = 1e-8


def test_dipole_defaults_are_the_igrf_2020_dipole():
    f = DipoleField()
    assert math.isclose(f.strength, 29805.92e-9, rel_tol=1e-6)
    assert math.isclose(90.0 - math.degrees(f.tilt), 80.5895, abs_tol=1e-4)  # north geomagnetic pole latitude
    assert math.isclose(math.degrees(f.longitude), -72.6797, abs_tol=1e-4)


def test_dipole_magnitude_at_magnetic_equator_and_poles():
    f = DipoleField(greenwich_angle=0.4)
    t = 5000.0
    angle = f.greenwich_angle + f.earth_rate * t
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # Earth-fixed -> inertial
    m_hat = rot @ f.moment_direction()
    r = 7.2e6
    scale = f.strength * (f.radius / r) ** 3
    pole = f.field(t, -r * m_hat)  # north geomagnetic pole: field points down, along m_hat
    np.testing.assert_allclose(pole, 2 * scale * m_hat, rtol=1e-14, atol=1e-14 * scale)
    equator_dir = np.cross(m_hat, [0.3, 0.5, 0.8])
    equator_dir /= np.linalg.norm(equator_dir)
    equator = f.field(t, r * equator_dir)
    np.testing.assert_allclose(equator, -scale * m_hat, rtol=1e-14, atol=1e-14 * scale)


def test_dipole_is_minus_gradient_of_its_potential_and_divergence_free():
    """B = -∇Ψ with Ψ = B₀a³ (m̂·r)/|r|³ (independent of the kernel's form), hence ∇·B = 0."""
    f = DipoleField()
    t = 1234.0
    r0 = np.array([3.1e6, -5.2e6, 3.9e6])
    rot_angle = f.earth_rate * t
    c, s = math.cos(rot_angle), math.sin(rot_angle)
    m_hat = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ f.moment_direction()
    k = f.strength * f.radius**3

    def potential(r):
        return k * (m_hat @ r) / np.linalg.norm(r) ** 3

    h = 10.0
    steps = h * np.eye(3)
    grad = np.array([(potential(r0 + d) - potential(r0 - d)) / (2 * h) for d in steps])
    b = f.field(t, r0)
    np.testing.assert_allclose(b, -grad, rtol=0, atol=FIELD_DIFF_TOL * np.linalg.norm(b))
    div = sum((f.field(t, r0 + d)[i] - f.field(t, r0 - d)[i]) / (2 * h) for i, d in enumerate(steps))
    assert abs(div) < FIELD_DIFF_TOL * 3 * np.linalg.norm(b) / np.linalg.norm(r0)


def test_dipole_turns_with_the_earth():
    f = DipoleField()
    r = np.array([7e6, 1e6, -2e6])
    day = 2 * math.pi / f.earth_rate  # sidereal day
    np.testing.assert_allclose(f.field(day, r), f.field(0.0, r), rtol=1e-12, atol=1e-20)
    assert dipole_field(0.0, *r, f.params()) == tuple(f.field(0.0, r))
    quarter = f.field(day / 4, [-r[1], r[0], r[2]])  # the point turned by 90° with the Earth
    b0 = f.field(0.0, r)
    np.testing.assert_allclose(quarter, [-b0[1], b0[0], b0[2]], rtol=1e-12, atol=1e-12 * np.linalg.norm(b0))
    with pytest.raises(tumble.ValidationError, match="tilt"):
        DipoleField(tilt=4.0)
    with pytest.raises(tumble.ValidationError, match="r"):
        f.field(0.0, np.zeros(3))
    assert environment.EARTH_RATE == 7.2921159e-5


# --- scenarios -----------------------------------------------------------------------------------------

GG_SCENARIO = """
[body]
moments = [300.0, 400.0, 200.0]
[initial]
omega = [0.0, -0.001, 0.0]
[time]
stop = 10.0
samples = 2
[[torque]]
kind = "gravity_gradient"
[torque.orbit]
{orbit}
"""


def test_scenario_gravity_gradient_torque():
    problem = parse_scenario(GG_SCENARIO.format(orbit="altitude = 700e3\ninclination = 98.0\nraan = 30.0")).build()
    orb = problem.torque.orbit
    assert orb == Orbit.circular(700e3, math.radians(98.0), raan=math.radians(30.0))
    q = tumble.attitude.normalize([0.9, 0.1, 0.2, 0.3])
    direct = tumble.torques.GravityGradient(orb, np.diag([300.0, 400.0, 200.0]))
    assert np.array_equal(problem.torque(5.0, q, np.zeros(3)), direct(5.0, q, np.zeros(3)))
    radians = parse_scenario(GG_SCENARIO.format(
        orbit="semi_major_axis = 7.2e6\neccentricity = 0.1\narg_periapsis = 1.0\ndegrees = false")).build()
    assert radians.torque.orbit == Orbit(7.2e6, eccentricity=0.1, arg_periapsis=1.0)


@pytest.mark.parametrize("orbit, where", [
    ("altitude = 7e5\nsemi_major_axis = 7e6", "torque[0].orbit.semi_major_axis: give exactly one"),
    ("inclination = 10.0", "torque[0].orbit.semi_major_axis: give exactly one"),
    ("altitude = 7e5\neccentricity = 1.5", "torque[0].orbit.eccentricity: must be in [0, 1)"),
    ("altitude = 7e5\nperiod = 5.0", "torque[0].orbit.period: unknown key"),
])
def test_scenario_gravity_gradient_refuses_bad_orbits(orbit, where):
    with pytest.raises(ScenarioError, match=re.escape(where)):
        parse_scenario(GG_SCENARIO.format(orbit=orbit)).build()


def test_gravity_gradient_example_starts_at_its_stated_angles_from_lvlh():
    """examples/spacecraft/gravity_gradient.toml: 3° roll, 5° pitch, 2° yaw off LVLH, at rest in LVLH."""
    problem = load_scenario(EXAMPLES / "gravity_gradient.toml").build()
    orb = problem.torque.orbit
    q_lvlh_b = tumble.attitude.multiply(tumble.attitude.conjugate(lvlh_quaternion(*orb.state(0.0))), problem.q0)
    np.testing.assert_allclose(tumble.attitude.to_euler(q_lvlh_b, "ZYX", degrees=True), [2.0, 5.0, 3.0], atol=1e-12)
    lvlh_rate = tumble.attitude.rotate_inverse(q_lvlh_b, [0.0, -orb.mean_motion, 0.0])
    np.testing.assert_allclose(problem.omega0, lvlh_rate, rtol=1e-13, atol=1e-18)
    assert gravity_gradient_stability(problem.body).region == "Lagrange"
