"""The residual magnetic dipole, a part added as one kernel function and one class: τ = m × B.

A body dipole ``m`` along body x in a uniform field ``B`` along inertial x is a compass needle: turning
about the principal axis z by ``θ``, ``I θ̈ = −m B sin θ``, a pendulum whose motion from rest at ``θ₀`` is
``sin(θ/2) = k sn(K(k) − ω₀ t, k)``, ``k = sin(θ₀/2)``, ``ω₀² = m B / I`` (Lawden, *Elliptic Functions and
Applications*, 1989, §5.2), here through SciPy's ``ellipj``/``ellipk``.
"""

import numpy as np
import pytest
from scipy.special import ellipj, ellipk

import tumble
from tumble import ValidationError, attitude
from tumble.scenario import parse_scenario
from tumble.spacecraft import ResidualDipole, Spacecraft

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

MOMENTS = np.array([2.0, 3.0, 4.0])     # kg·m²
DIPOLE, FIELD = 2.0, 3e-5               # A·m², T
THETA0 = 2.0                            # rad: a large swing, far from the harmonic limit
OMEGA0 = np.sqrt(DIPOLE * FIELD / MOMENTS[2])
T = np.linspace(0.0, 2.0 * 4.0 * ellipk(np.sin(THETA0 / 2) ** 2) / OMEGA0, 201)   # two periods
# DOP853 at rtol = atol = 1e-12 over two periods: the angle matches the elliptic closed form to 2e-10 rad
# (measured 4e-11); the torque is m × R(q)ᵀB evaluated again here, equal to rounding.
ANGLE_TOL = 2e-10
TORQUE_RTOL = 1e-12
ENERGY_RTOL = 1e-10


def needle():
    return Spacecraft(inertia=np.diag(MOMENTS), magnetic_field=[FIELD, 0.0, 0.0],
                      residual_dipole=ResidualDipole([DIPOLE, 0.0, 0.0]))


@pytest.fixture(scope="module")
def swing():
    q0 = [np.cos(THETA0 / 2), 0.0, 0.0, np.sin(THETA0 / 2)]
    return tumble.simulate(needle(), [0.0, 0.0, 0.0], q0=q0, t=T, method="dop853", rtol=1e-12, atol=1e-12)


def test_compass_needle_swings_as_the_elliptic_pendulum(swing):
    k = np.sin(THETA0 / 2)
    sn, _, _, _ = ellipj(ellipk(k * k) - OMEGA0 * T, k * k)
    theta = 2.0 * np.arcsin(k * sn)
    measured = 2.0 * np.arctan2(swing.q[:, 3], swing.q[:, 0])
    np.testing.assert_allclose(measured, theta, rtol=0, atol=ANGLE_TOL)
    np.testing.assert_array_equal(swing.omega[:, :2], 0.0)


def test_torque_is_m_cross_b_in_body_axes(swing):
    b_body = attitude.rotate_inverse(swing.q, [FIELD, 0.0, 0.0])
    expected = np.cross([DIPOLE, 0.0, 0.0], b_body)
    np.testing.assert_allclose(swing.residual_dipole_torque, expected, rtol=TORQUE_RTOL, atol=1e-24)
    np.testing.assert_allclose(swing.actuator_torque, expected, rtol=TORQUE_RTOL, atol=1e-24)


def test_kinetic_energy_less_m_dot_b_is_conserved(swing):
    b_body = attitude.rotate_inverse(swing.q, [FIELD, 0.0, 0.0])
    total = swing.energy - b_body @ np.array([DIPOLE, 0.0, 0.0])     # T + U, U = −m·B
    np.testing.assert_allclose(total, total[0], rtol=ENERGY_RTOL)
    assert needle().invariants(swing) == {}                          # an external torque: nothing to check


def test_a_dipole_needs_a_field_and_three_numbers():
    with pytest.raises(ValidationError, match=r"^residual_dipole: needs a magnetic_field"):
        Spacecraft(inertia=np.diag(MOMENTS), residual_dipole=ResidualDipole([1.0, 0.0, 0.0]))
    with pytest.raises(ValidationError, match=r"^dipole: must be 3 numbers"):
        ResidualDipole([1.0, 0.0])
    with pytest.raises(ValidationError, match=r"^dipole: "):
        ResidualDipole([np.nan, 0.0, 0.0])


def test_scenario_table_builds_the_part():
    scenario = parse_scenario("""
[spacecraft]
moments = [2.0, 3.0, 4.0]
magnetic_field = {uniform = [3e-5, 0.0, 0.0]}
residual_dipole = {dipole = [2.0, 0.0, 0.0]}
[initial]
omega = [0.0, 0.0, 0.0]
[time]
stop = 1.0
step = 1.0
""")
    np.testing.assert_array_equal(scenario.model.residual_dipole.dipole, [DIPOLE, 0.0, 0.0])
    np.testing.assert_array_equal(scenario.model.magnetic_field, [FIELD, 0.0, 0.0])


def test_viewer_draws_the_dipole_along_body_x(swing):
    from tumble.viz import viewer

    scene = viewer.scene(swing, model=needle(), frames=50)
    line = {line.name: line.points for line in scene.lines}["residual dipole"]
    hub = scene.solids[0].rotation                                    # R(q) of the frames
    tips = line[:, 1] / np.linalg.norm(line[:, 1], axis=-1, keepdims=True)
    np.testing.assert_allclose(tips, hub[:, :, 0], atol=1e-15)        # R(q) x̂: the needle's direction
    np.testing.assert_array_equal(line[:, 0], 0.0)
