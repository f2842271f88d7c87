"""Polhodes, separatrices and the herpolhode: the invariants they keep and the simulated motion they predict."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import tumble
from tumble import attitude
from tumble.analytic import _geometry as geometry
from tumble.analytic._free import torque_free

# Points built from T and |L| keep them to a few rounding errors of the sums.
INVARIANT_RTOL = 1e-12
# The simulated rates (dop853, rtol = atol = 1e-12) lie on the predicted polhode
# within the chord error of its 200001-point polyline (measured 4.4e-10 |ω|)
# plus the integration error.
ON_CURVE_RTOL = 2e-9
CURVE_POINTS = 200_001
# ω_I·L̂ = 2T/|L| along a dop853 (rtol = atol = 1e-12) or exact trajectory:
# integration error (measured 1.4e-14) or rounding (1.3e-15) only.
PLANE_RTOL = 1e-10
# The polhode through ω starts at ω: a few rounding errors of the sums Δᵢ.
START_RTOL = 1e-14
INTEGRATION = dict(method="dop853", rtol=1e-12, atol=1e-12)


@pytest.fixture
def body():
    """Moments (1, 2, 3) kg m² described in axes rotated away from the principal ones."""
    return tumble.RigidBody(np.diag([1.0, 2.0, 3.0])).rotated(attitude.from_rotvec([0.3, -0.2, 0.5]))


def invariants(moments, points):
    """(T, |L|) of body rates ``points`` (…, 3) in principal axes."""
    return 0.5 * (points**2) @ moments, np.sqrt((points**2) @ moments**2)


# L²/(2T) from just above I₁ to I₃: minor regime, near the separatrix on both sides, major, the axes.
LEVELS = [1.0, 1.05, 1.5, 1.999999, 2.0, 2.000001, 2.5, 2.99, 3.0]


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("sign", [1, -1])
def test_polhode_points_keep_energy_and_momentum(body, level, sign):
    energy = 0.7
    momentum = np.sqrt(2.0 * energy * level)
    points = geometry.polhode(body, energy, momentum, n=257, sign=sign)
    assert points.shape == (257, 3)
    t, l = invariants(body.moments, points)
    np.testing.assert_allclose(t, energy, rtol=INVARIANT_RTOL)
    np.testing.assert_allclose(l, momentum, rtol=INVARIANT_RTOL)
    np.testing.assert_array_equal(points[0], points[-1])  # closed
    circled = 2 if level >= 2.0 else 0
    assert np.all(sign * points[:, circled] >= 0.0)  # on the side ``sign`` of the circled axis


def test_polhode_of_a_symmetric_top_is_a_circle_about_its_axis():
    oblate = tumble.RigidBody(np.diag([1.0, 1.0, 1.6]))
    energy, level = 2.0, 1.3
    points = geometry.polhode(oblate, energy, np.sqrt(2.0 * energy * level), n=91)
    radius = np.hypot(points[:, 0], points[:, 1])
    # ω₁² + ω₂² = A² with A² = (2T I₃ − L²)/(I₁ (I₃ − I₁)) (the module docstring with c = 3, I₁ = I₂).
    np.testing.assert_allclose(radius, np.sqrt(2.0 * energy * (1.6 - level) / 0.6), rtol=INVARIANT_RTOL)
    np.testing.assert_allclose(points[:, 2], np.sqrt(2.0 * energy * (level - 1.0) / (1.6 * 0.6)),
                               rtol=INVARIANT_RTOL)


def test_polhode_family_covers_both_stable_axes(body):
    energy = 1.5
    family = geometry.polhode_family(body, energy, 4, n=101)
    assert len(family) == 16  # 4 levels x 2 axes x 2 sides
    assert [c.regime for c in family].count("minor") == 8
    assert [c.momentum for c in family] == sorted(c.momentum for c in family)
    for curve in family:
        t, l = invariants(body.moments, curve.points)
        np.testing.assert_allclose(t, energy, rtol=INVARIANT_RTOL)
        np.testing.assert_allclose(l, curve.momentum, rtol=INVARIANT_RTOL)
        assert (curve.momentum**2 > 2.0 * energy * 2.0) == (curve.regime == "major")
        assert np.all(curve.sign * curve.points[:, curve.axis] >= 0.0)


def test_symmetric_tops_have_polhodes_about_the_symmetry_axis_only():
    oblate = geometry.polhode_family(tumble.RigidBody(np.diag([1.0, 1.0, 2.0])), 1.0, 3)
    prolate = geometry.polhode_family(tumble.RigidBody(np.diag([1.0, 2.0, 2.0])), 1.0, 3)
    assert {c.regime for c in oblate} == {"major"} and len(oblate) == 6
    assert {c.regime for c in prolate} == {"minor"} and len(prolate) == 6


def test_separatrix_lies_on_L2_equal_2T_I2(body):
    energy = 0.9
    ellipses = geometry.separatrix(body, energy, n=181)
    assert ellipses.shape == (2, 181, 3)
    t, l = invariants(body.moments, ellipses)
    np.testing.assert_allclose(t, energy, rtol=INVARIANT_RTOL)
    np.testing.assert_allclose(l**2, 2.0 * energy * body.moments[1], rtol=INVARIANT_RTOL)
    # Planes √(I₁(I₂ − I₁)) ω₁ = ±√(I₃(I₃ − I₂)) ω₃ through the intermediate axis, crossing at ±√(2T/I₂) e₂.
    i1, i2, i3 = body.moments
    scale = np.sqrt(2.0 * energy / i1)
    for side, ellipse in zip((1.0, -1.0), ellipses):
        residual = np.sqrt(i1 * (i2 - i1)) * ellipse[:, 0] - side * np.sqrt(i3 * (i3 - i2)) * ellipse[:, 2]
        assert np.abs(residual).max() <= INVARIANT_RTOL * scale
        np.testing.assert_allclose(ellipse[0], [0.0, np.sqrt(2.0 * energy / i2), 0.0], atol=INVARIANT_RTOL * scale)


@pytest.mark.parametrize("inertia, zero_axis", [(np.diag([1.0, 1.0, 2.0]), 2), (np.diag([1.0, 2.0, 2.0]), 0)])
def test_separatrix_of_a_symmetric_top_is_the_circle_of_steady_rotations(inertia, zero_axis):
    top = tumble.RigidBody(inertia)
    circle = geometry.separatrix(top, 1.0, n=73)
    assert circle.shape == (1, 73, 3)
    np.testing.assert_array_equal(circle[0, :, zero_axis], 0.0)  # Δ₂ = 0 exactly, so ω about the axis is 0
    np.testing.assert_allclose(invariants(top.moments, circle[0])[0], 1.0, rtol=INVARIANT_RTOL)


def on_polyline(points, polyline):
    """Distance from each of ``points`` (m, 3) to the polyline (n, 3): nearest vertex, then its two segments."""
    _, nearest = cKDTree(polyline).query(points)
    distance = np.full(len(points), np.inf)
    for offset in (-1, 0):
        start = np.clip(nearest + offset, 0, len(polyline) - 2)
        a, segment = polyline[start], polyline[start + 1] - polyline[start]
        s = np.clip(np.einsum("ij,ij->i", points - a, segment) / np.einsum("ij,ij->i", segment, segment), 0.0, 1.0)
        distance = np.minimum(distance, np.linalg.norm(points - a - s[:, None] * segment, axis=1))
    return distance


@pytest.mark.parametrize("omega_principal", [[0.3, 1.0, 0.2], [1.0, 0.3, -0.2], [0.1, -0.4, -1.0]],
                         ids=["major", "minor", "major-negative"])
def test_simulated_rates_stay_on_the_predicted_polhode(body, omega_principal):
    omega0 = body.axes @ np.array(omega_principal)
    traj = tumble.simulate(body, omega0, t=np.linspace(0.0, 60.0, 3001), **INTEGRATION)
    rates = traj.omega @ body.axes  # principal axes
    curve = geometry.polhode_through(body, omega0, n=CURVE_POINTS)
    np.testing.assert_allclose(curve.points[0], omega_principal, rtol=0, atol=START_RTOL * np.linalg.norm(omega0))
    assert on_polyline(rates, curve.points).max() <= ON_CURVE_RTOL * np.linalg.norm(omega0)
    # The curve runs in the direction of the motion.
    assert (rates[1] - rates[0]) @ (curve.points[50] - curve.points[0]) > 0.0


def test_steady_rotation_has_a_one_point_polhode():
    principal = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    curve = geometry.polhode_through(principal, [0.0, 2.0, 0.0], n=5)  # exactly about the intermediate axis
    np.testing.assert_array_equal(curve.points, np.tile([0.0, 2.0, 0.0], (5, 1)))


@pytest.mark.parametrize("source", ["simulate", "exact"])
def test_herpolhode_lies_on_the_invariable_plane(body, source):
    omega0 = body.axes @ np.array([0.4, 1.0, 0.3])
    q0, t = attitude.from_rotvec([0.1, 0.7, -0.4]), np.linspace(0.0, 40.0, 2001)
    if source == "exact":
        traj = torque_free(body, omega0, q0, t=t)
    else:
        traj = tumble.simulate(body, omega0, q0=q0, t=t, **INTEGRATION)
    path = geometry.herpolhode(traj)
    energy, momentum = traj.energy[0], traj.momentum_norm[0]
    # Independent: ω_I from the attitude matrices, L_I from the first sample.
    omega_inertial = np.einsum("tij,tj->ti", attitude.to_matrix(traj.q), traj.omega)
    normal = traj.momentum_inertial[0] / momentum
    np.testing.assert_allclose(path.omega_inertial, omega_inertial, rtol=0, atol=1e-14)
    np.testing.assert_allclose(path.normal, normal, rtol=0, atol=1e-15)
    assert path.height == pytest.approx(2.0 * energy / momentum, rel=1e-15)
    heights = omega_inertial @ normal
    assert np.abs(heights / path.height - 1.0).max() <= PLANE_RTOL
    # points are the in-plane components: ω_I = h n + points @ basis.
    np.testing.assert_allclose(path.basis @ path.basis.T, np.eye(2), atol=1e-15)
    np.testing.assert_allclose(np.cross(path.basis[0], path.basis[1]), normal, atol=1e-15)
    rebuilt = path.height * normal + path.points @ path.basis
    np.testing.assert_allclose(rebuilt, omega_inertial, rtol=0, atol=PLANE_RTOL * path.height)
    # Between the circles set by the extremes of |ω| on the polhode: r² = |ω|² − h².
    polhode = geometry.polhode_through(body, omega0, n=20001).points
    radii = np.sqrt(np.sum(polhode**2, axis=1) - path.height**2)
    r = np.linalg.norm(path.points, axis=1)
    assert radii.min() * (1 - 1e-6) <= r.min() and r.max() <= radii.max() * (1 + 1e-6)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda b: geometry.polhode(b, 1.0, 3.0), r"momentum: \|L\|\^2 = 9 must lie between 2 T I1 = 2 and 2 T I3 = 6"),
        (lambda b: geometry.polhode(b, -1.0, 1.0), "energy: must be a finite number > 0"),
        (lambda b: geometry.polhode(b, 1.0, 2.0, sign=0), r"sign: must be \+1 or -1"),
        (lambda b: geometry.polhode(b, 1.0, 2.0, n=2), "n: must be an integer >= 3"),
        (lambda b: geometry.polhode_family(b, 1.0, 0), "n_curves: must be an integer >= 1"),
        (lambda b: geometry.polhode(tumble.RigidBody(np.eye(3)), 1.0, 1.0), "body: a spherical body"),
        (lambda b: geometry.separatrix(np.eye(3), 1.0), "body: must be a RigidBody"),
        (lambda b: geometry.polhode_through(b, [0.0, 0.0, 0.0]), "omega: must be non-zero"),
    ],
)
def test_bad_input_is_refused(body, call, message):
    with pytest.raises(tumble.ValidationError, match=message):
        call(body)


def test_herpolhode_refuses_torques_and_batches(body):
    t = np.linspace(0.0, 1.0, 3)
    pushed = tumble.simulate(body, [0.0, 1.0, 0.0], t=t, torque=tumble.torques.ConstantBody([0.0, 0.0, 0.1]))
    with pytest.raises(tumble.ValidationError, match="trajectory: the herpolhode needs torque-free motion"):
        geometry.herpolhode(pushed)
    batch = tumble.simulate(body, [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], t=t)
    with pytest.raises(tumble.ValidationError, match="trajectory: must hold a single body"):
        geometry.herpolhode(batch)


@pytest.mark.parametrize("inertia", [np.diag([1.0, 2.0, 3.0]), np.diag([1.0, 1.0, 1.6])], ids=["asymmetric", "oblate"])
def test_polhode_figure_draws_the_given_herpolhode(inertia):
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from tumble.viz.polhode import polhode_figure

    body = tumble.RigidBody(inertia)
    omega0 = np.array([0.6, 0.3, 1.0])
    traj = tumble.simulate(body, omega0, t=np.linspace(0.0, 10.0, 501), **INTEGRATION)
    fig = polhode_figure(body, omega0, traj, n_curves=2)
    assert isinstance(fig, Figure)
    panel = fig.axes[1]
    (path,) = [c for c in panel.collections if isinstance(c, LineCollection)]
    segments = np.array(path.get_segments())
    np.testing.assert_array_equal(segments[:, 0], geometry.herpolhode(traj).points[:-1])
    with pytest.raises(tumble.ValidationError, match="body: a spherical body"):
        polhode_figure(tumble.RigidBody(np.eye(3)), omega0)
