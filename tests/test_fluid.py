"""A rigid body in an ideal fluid (tumble.fluid): Kirchhoff's equations against the free rigid body they reduce to,
their integrals, Munk's moment, Lamb's added mass of an ellipsoid and the refusals of bad input."""

import math

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble._validate import ValidationError
from tumble.fluid import KirchhoffBody, ellipsoid_added_mass, kirchhoff_matrix
from tumble.viz.viewer import html_page

from helpers import read_by

INERTIA = np.array([[2.0, 0.1, -0.05], [0.1, 3.0, 0.2], [-0.05, 0.2, 4.0]])  # kg·m², body axes
BODY = tumble.RigidBody(INERTIA, mass=10.0)
OMEGA0 = np.array([0.3, 1.0, -0.4])  # rad/s: a generic tumble
VELOCITY0 = np.array([1.0, 0.2, -0.3])  # m/s
Q0 = attitude.normalize([0.9, 0.1, -0.3, 0.2])
POSITION0 = np.array([1.0, -2.0, 0.5])  # m
TIGHT = dict(method="dop853", rtol=1e-12, atol=1e-12)


def coupled_added_mass():
    """A full, symmetric, positive definite M_A (Fossen's order) whose angular–linear block B is not zero."""
    rng = np.random.default_rng(7)
    root = rng.normal(size=(6, 6))
    return root @ root.T + np.diag([5.0, 8.0, 12.0, 1.0, 1.5, 2.0])


def run(kbody, t, **options):
    return tumble.simulate(kbody, OMEGA0, t=t, velocity0=VELOCITY0, q0=Q0, position0=POSITION0,
                           **read_by(**{**TIGHT, **options}))


# --------------------------------------------------------------------------
# The exact reduction: B = 0, C = c 1 is Euler's free rigid body of inertia A, moving on a straight line
# --------------------------------------------------------------------------


@pytest.mark.slow  # compiles the KirchhoffBody's dop853 and the rigid body's exact path (about 20 CPU s cold)
def test_without_coupling_and_with_isotropic_translation_the_rotation_is_the_free_rigid_body():
    angular = np.array([[0.5, 0.05, 0.0], [0.05, 0.8, -0.1], [0.0, -0.1, 0.3]])  # M_A[3:, 3:], kg·m²
    added_mass = np.zeros((6, 6))
    added_mass[:3, :3] = 5.0 * np.eye(3)  # C = (10 + 5) 1 kg
    added_mass[3:, 3:] = angular
    kbody = KirchhoffBody(BODY, added_mass)
    t = np.linspace(0.0, 10.0, 101)
    traj = run(kbody, t)
    exact = tumble.simulate(tumble.RigidBody(INERTIA + angular), OMEGA0, q0=Q0, t=t, method="exact")
    # dop853 at 1e-12 over 10 s (~11 rad turned): measured 8.3e-15 rad and 6.1e-15 rad/s
    assert attitude.relative_angle(traj.q, exact.q).max() < 1e-12
    assert np.abs(traj.omega - exact.omega).max() < 1e-12
    # P × v = c v × v = 0: the velocity is constant in inertial axes and the origin moves on a line
    inertial_velocity = attitude.rotate(traj.q, traj.velocity)
    start = attitude.rotate(Q0, VELOCITY0)
    assert np.abs(inertial_velocity - start).max() < 1e-12  # measured 2.8e-14 m/s
    assert np.abs(traj.position - (POSITION0 + t[:, None] * start)).max() < 1e-11  # measured 1.4e-13 m


# --------------------------------------------------------------------------
# The integrals on a general run (B ≠ 0, full A and C)
# --------------------------------------------------------------------------

# Relative change (|I − I₀| / |I₀|, the largest over 101 samples in 10 s) of each integral, allowed under each
# method. Measured: dop853 at rtol = atol = 1e-12 ≤ 7.3e-13, rk4 at dt = 1e-3 s ≤ 4.2e-13 (both the inertial
# angular impulse R K + x × R P, whose x × R P grows with the path). Each tolerance leaves a factor ≥ 10.
INTEGRAL_TOL = {"dop853": 1e-11, "rk4": 5e-12}


@pytest.mark.slow  # compiles the KirchhoffBody's dop853 and rk4 paths (about 15 CPU s cold)
@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_the_integrals_of_kirchhoffs_equations_are_kept(method):
    kbody = KirchhoffBody(BODY, coupled_added_mass())
    assert np.abs(kirchhoff_matrix(kbody.mass_matrix)[:3, 3:]).max() > 1.0  # B ≠ 0: strongly coupled
    traj = run(kbody, np.linspace(0.0, 10.0, 101), method=method, dt=1e-3)
    kept = kbody.invariants(traj)
    assert kept.keys() == {"energy", "momentum_inertial", "linear_impulse_inertial", "impulse_squared",
                           "impulse_product"}
    for name, value in kept.items():
        change = np.abs(value - value[0]).reshape(len(traj), -1).max() / np.abs(value[0]).max()
        assert change < INTEGRAL_TOL[method], (name, change)
    # the motion is not trivial: the body turns, and its velocity in body axes changes by its own size
    assert np.ptp(traj.velocity, axis=0).max() > 0.5 * np.linalg.norm(VELOCITY0)
    # the totals are T and the inertial angular impulse R K + x × R P
    K, P = traj.angular_impulse, traj.linear_impulse
    assert np.allclose(traj.energy, 0.5 * (np.sum(traj.omega * K, -1) + np.sum(traj.velocity * P, -1)), rtol=1e-14)
    np.testing.assert_allclose(traj.momentum_inertial,
                               attitude.rotate(traj.q, K) + np.cross(traj.position, attitude.rotate(traj.q, P)),
                               rtol=0.0, atol=1e-12 * np.abs(traj.momentum_inertial).max())


@pytest.mark.slow  # compiles the KirchhoffBody's rk4 path (about 7 CPU s cold)
def test_rk4_converges_at_fourth_order():
    kbody = KirchhoffBody(BODY, coupled_added_mass())
    t = np.array([0.0, 4.0])
    reference = run(kbody, t)
    errors = []
    for dt in (0.04, 0.02, 0.01):
        traj = run(kbody, t, method="rk4", dt=dt)
        errors.append(max(np.abs(traj.omega[-1] - reference.omega[-1]).max(),
                          np.abs(traj.velocity[-1] - reference.velocity[-1]).max()))
    # each halving of dt divides the error by 2⁴ = 16 (measured 16.6 and 16.3: 3.9e-7, 2.3e-8, 1.4e-9)
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    assert all(14.0 < r < 18.0 for r in ratios), (errors, ratios)


# --------------------------------------------------------------------------
# Munk's moment: steady translation along a principal axis, linearised
# --------------------------------------------------------------------------


def munk_lambda_squared(a2, c1, c3, u):
    """``λ²`` (1/s²) of a small pitch about translation at ``u`` (m/s) along axis 1 (module docstring of
    tumble.fluid): ``a₂ ω̇₂ = (c₃ − c₁) u v₃``, ``c₃ v̇₃ = c₁ u ω₂``."""
    return c1 * (c3 - c1) * u * u / (a2 * c3)


@pytest.mark.slow  # compiles the KirchhoffBody's dop853 path (about 8 CPU s cold)
@pytest.mark.parametrize("along", ["least mass: unstable", "most mass: stable"])
def test_a_small_pitch_about_steady_translation_grows_or_swings_at_munks_rate(along):
    body = tumble.RigidBody(np.diag([1.0, 2.0, 2.0]), mass=10.0)
    # sent along x with little added mass along x and much across it (c₁ = 12 kg, c₂ = c₃ = 40 kg), or the
    # other way round (c₁ = 40 kg, c₂ = c₃ = 12 kg); a₂ = 2 + 1 kg·m² in both
    moving = {"least mass: unstable": [2.0, 30.0, 30.0], "most mass: stable": [30.0, 2.0, 2.0]}[along]
    added_mass = np.diag([*moving, 0.0, 1.0, 1.0])
    kbody = KirchhoffBody(body, added_mass)
    a2, c1, c3 = 3.0, 10.0 + moving[0], 10.0 + moving[2]
    u, eps = 1.5, 1e-9
    lam2 = munk_lambda_squared(a2, c1, c3, u)
    assert (lam2 > 0.0) == along.endswith("unstable")
    rate = math.sqrt(abs(lam2))
    t = np.linspace(0.0, 6.0 / rate, 61)  # six e-foldings (or radians of the swing)
    # atol far below ε: the step control is relative in every component, the small ones (K₂, P₃) included
    traj = tumble.simulate(kbody, [0.0, eps, 0.0], velocity0=[u, 0.0, 0.0], t=t, method="dop853", rtol=1e-12,
                           atol=1e-24)
    # the linear solution from ω₂ = ε, v₃ = 0: ω₂ = ε cosh λt (cos for λ² < 0); the nonlinear terms are
    # O((ε e⁶)²) ~ 1e-13 relative; measured 2.4e-15 (unstable) and 3.4e-15 (stable) of the amplitude
    linear = np.cosh(rate * t) if lam2 > 0.0 else np.cos(rate * t)
    assert np.abs(traj.omega[:, 1] / eps - linear).max() < 1e-11 * np.abs(linear).max()
    assert np.abs(traj.omega[:, [0, 2]]).max() == 0.0 and np.abs(traj.velocity[:, 1]).max() == 0.0


# --------------------------------------------------------------------------
# Lamb's added mass of an ellipsoid
# --------------------------------------------------------------------------


def test_a_sphere_adds_half_its_displaced_mass_and_no_inertia():
    rho, r = 1025.0, 0.3
    added = ellipsoid_added_mass([r, r, r], rho)
    half = 0.5 * rho * 4.0 / 3.0 * math.pi * r**3
    np.testing.assert_allclose(np.diagonal(added), [half, half, half, 0.0, 0.0, 0.0], rtol=1e-15, atol=0.0)
    assert np.count_nonzero(added - np.diag(np.diagonal(added))) == 0


def test_a_prolate_spheroid_matches_the_closed_forms_in_its_eccentricity():
    # a > b = c: α₀ = 2(1 − e²)/e³ (½ ln((1 + e)/(1 − e)) − e), β₀ = γ₀ = 1/e² − (1 − e²)/(2e³) ln((1 + e)/(1 − e))
    # (Lamb §§ 114–115), independent of the Carlson integrals; translational k = α₀/(2 − α₀), rotational (about y)
    # k' = e⁴ (β₀ − α₀) / ((2 − e²)(2e² − (2 − e²)(β₀ − α₀))) of ρV(a² + b²)/5 (Lamb § 115; Newman, Marine
    # Hydrodynamics, 1977, ch. 4)
    rho, a, b = 1000.0, 2.0, 1.0
    e = math.sqrt(1.0 - (b / a) ** 2)
    log = math.log((1.0 + e) / (1.0 - e))
    alpha = 2.0 * (1.0 - e * e) / e**3 * (0.5 * log - e)
    beta = 1.0 / (e * e) - (1.0 - e * e) / (2.0 * e**3) * log
    mass = rho * 4.0 / 3.0 * math.pi * a * b * b
    k_rot = e**4 * (beta - alpha) / ((2.0 - e * e) * (2.0 * e * e - (2.0 - e * e) * (beta - alpha)))
    expected = [mass * alpha / (2.0 - alpha), mass * beta / (2.0 - beta), mass * beta / (2.0 - beta), 0.0,
                k_rot * mass * (a * a + b * b) / 5.0, k_rot * mass * (a * a + b * b) / 5.0]
    np.testing.assert_allclose(np.diagonal(ellipsoid_added_mass([a, b, b], rho)), expected, rtol=1e-13, atol=0.0)


def test_a_thin_disk_has_the_broadside_and_rocking_added_mass_of_a_disk():
    # a circular disk of radius a (the limit c → 0 of the ellipsoid a, a, c): broadside 8/3 ρa³, about a
    # diameter 16/45 ρa⁵ (the tabulated values: Newman, Marine Hydrodynamics, 1977, ch. 4), edgewise and about its
    # axis none; the error is O(c/a)
    rho, a, c = 1000.0, 0.5, 1e-7
    added = np.diagonal(ellipsoid_added_mass([a, a, c], rho))
    np.testing.assert_allclose(added[[2, 3, 4]], [8.0 / 3.0 * rho * a**3, 16.0 / 45.0 * rho * a**5,
                                                  16.0 / 45.0 * rho * a**5], rtol=1e-5)
    assert added[0] < 1e-5 * added[2] and added[1] < 1e-5 * added[2] and added[5] == 0.0


# --------------------------------------------------------------------------
# Refusals
# --------------------------------------------------------------------------


def _asymmetric():
    m = np.eye(6)
    m[0, 4] = 0.3
    return m


def _derivatives():
    return -np.eye(6)  # Fossen's X_u̇ … given instead of M_A


def _indefinite():
    m = np.diag([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    m[0, 4] = m[4, 0] = 20.0  # T < 0 for a surge and a pitch of opposite signs
    return m


@pytest.mark.parametrize(("added_mass", "message"), [
    (np.eye(3), r"^added_mass: must have shape \(6, 6\) \(Fossen's order: surge, sway, heave, roll, pitch, yaw\), "
                r"got \(3, 3\)$"),
    (np.full((6, 6), np.nan), r"^added_mass: must be finite \(found nan at index \(0, 0\)\)$"),
    (_asymmetric(), r"^added_mass: must be symmetric \(an ideal fluid's added mass is\), got max \|M − Mᵀ\| = 0.3$"),
    (_derivatives(), r"^added_mass: its diagonal must be ≥ 0 \(the added mass, M_A = −\[X_u̇ …\], not the "
                     r"hydrodynamic derivatives\), got added_mass\[0, 0\] = -1$"),
    (_indefinite(), r"^added_mass: the body's mass matrix plus the added mass must be positive definite \(the "
                    r"kinetic energy of body and fluid\), got the eigenvalue -\d"),
])
def test_bad_added_mass_is_refused_naming_the_field_and_the_rule(added_mass, message):
    with pytest.raises(ValidationError, match=message):
        KirchhoffBody(BODY, added_mass)


def test_a_body_without_its_mass_or_off_its_centre_is_refused():
    with pytest.raises(ValidationError, match=r"^body: must be a tumble.RigidBody with its mass \(kg\)"):
        KirchhoffBody(tumble.RigidBody(INERTIA), np.eye(6))
    with pytest.raises(ValidationError, match=r"^body: its centre of mass must be the body origin"):
        KirchhoffBody(tumble.RigidBody(INERTIA, mass=1.0, com=[0.1, 0.0, 0.0]), np.eye(6))


def test_a_torque_is_refused_the_body_is_free():
    with pytest.raises(ValidationError, match=r"^torque: a KirchhoffBody takes no torque argument$"):
        tumble.simulate(KirchhoffBody(BODY, np.eye(6)), OMEGA0, t=[0.0, 1.0], torque=[0.0, 0.0, 1.0])


def test_the_added_mass_is_read_only_and_reordered_for_kirchhoff():
    kbody = KirchhoffBody(BODY, coupled_added_mass())
    assert not kbody.added_mass.flags.writeable
    K = kirchhoff_matrix(kbody.mass_matrix)
    np.testing.assert_array_equal(K[:3, :3], INERTIA + kbody.added_mass[3:, 3:])  # A
    np.testing.assert_array_equal(K[:3, 3:], kbody.added_mass[3:, :3])  # B: angular rows, linear columns
    np.testing.assert_array_equal(K[3:, 3:], 10.0 * np.eye(3) + kbody.added_mass[:3, :3])  # C


# --------------------------------------------------------------------------
# The viewer
# --------------------------------------------------------------------------


@pytest.mark.slow  # compiles the KirchhoffBody's rk4 path (about 7 CPU s cold)
def test_the_viewer_draws_the_body_and_the_path_of_its_origin():
    kbody = KirchhoffBody(BODY, coupled_added_mass())
    traj = run(kbody, np.linspace(0.0, 2.0, 21), method="rk4", dt=1e-2)
    page = html_page(traj, model=kbody)
    assert page.startswith("<!DOCTYPE html>")
    assert "path of the body origin" in page and "drawn at" in page
    with pytest.raises(ValidationError, match=r"^model: a KirchhoffBody trajectory is drawn with a KirchhoffBody"):
        html_page(traj, model=BODY)
