"""Poincaré sections (tumble.measure.poincare_section): crossings of the exact Lagrange top, named rules."""

import numpy as np
import pytest
from scipy.optimize import brentq

import tumble
from tumble._validate import ValidationError
from tumble.measure import poincare_section
from tumble.analytic import HeavyTop

# Every test here compiles the variational (Lyapunov) integrators on a cold Numba cache (~10 CPU s).
pytestmark = pytest.mark.slow

# m g l = I₃ = 1: nutation period 4.64 s, spin 3 rad/s. With the body z axis along the symmetry axis, γ₃ = cos θ
# = u(t), known in closed form (HeavyTop.u): the section γ₃ = (u₁ + u₂)/2 is crossed once upwards per period.
TOP = HeavyTop(I1=2.0, I3=1.0, mass=1.0, length=1.0, g=1.0, theta0=0.6, theta_dot0=0.5, phi_dot0=-0.3, spin=3.0)
INPUTS = TOP.simulation_inputs()
LEVEL = 0.5 * (TOP.u1 + TOP.u2)
PERIODS = 10


def simulated(samples_per_period):
    t = np.linspace(0.0, PERIODS * TOP.nutation_period, PERIODS * samples_per_period + 1)
    return tumble.simulate(INPUTS["model"], omega0=INPUTS["omega0"], q0=INPUTS["q0"], torque=INPUTS["torque"], t=t,
                           method="dop853", rtol=1e-13, atol=1e-13)


def exact_crossings(t):
    """Times of the upward crossings of u(t) = LEVEL, by Brent's method on the closed form between samples."""
    s = TOP.u(t) - LEVEL
    k = np.flatnonzero((s[:-1] < 0.0) & (s[1:] >= 0.0))
    return np.array([brentq(lambda x: float(TOP.u(x)) - LEVEL, t[i], t[i + 1], xtol=1e-15, rtol=1e-15) for i in k])


# Quintic Hermite event location: the error in time is O(h⁶) for samples h apart (measured 5.3e-8 s at
# 20 samples per period, 1.3e-10 s at 50: the ratio 410 ≈ 2.5⁶ = 244 to within the integration error;
# 7e-14 s at 200, the dop853 error at rtol = 1e-13). Bounds: 1e-7 s, 5e-10 s, 1e-12 s; the crossing lies on
# the plane to rounding (1e-16 measured; bound 4 eps).
@pytest.mark.parametrize("samples, bound", [(20, 1e-7), (50, 5e-10), (200, 1e-12)])
def test_crossings_of_the_lagrange_top_match_the_closed_form(samples, bound):
    traj = simulated(samples)
    section = poincare_section(traj, INPUTS["torque"], section={"gamma3": LEVEL}, direction=1)
    exact = exact_crossings(traj.t)
    assert section.t.size == exact.size == PERIODS
    assert np.abs(section.t - exact).max() <= bound
    assert np.abs(section["gamma3"] - LEVEL).max() <= 4 * np.finfo(float).eps
    # every coordinate is within the stated interpolation bound (Ω h)⁶ / 46080, Ω = max |ω| (the spin, 3 rad/s,
    # turns γ₁, γ₂ fastest): |γ| = 1 off by 1.4e-6 at 20 samples per period (Ω h = 0.7, bound 2.5e-6)
    h, rate = traj.t[1] - traj.t[0], np.linalg.norm(traj.omega, axis=1).max()
    np.testing.assert_allclose(np.linalg.norm(section.gamma, axis=1), 1.0, rtol=0, atol=(rate * h) ** 6 / 46080 + 1e-12)


def test_a_model_is_simulated_and_both_directions_are_found():
    t = np.linspace(0.0, PERIODS * TOP.nutation_period, PERIODS * 200 + 1)
    both = poincare_section(INPUTS["model"], INPUTS["torque"], section={"gamma3": LEVEL}, direction=0,
                            omega0=INPUTS["omega0"], q0=INPUTS["q0"], t=t, method="dop853", rtol=1e-13, atol=1e-13)
    up = poincare_section(simulated(200), INPUTS["torque"], section={"gamma3": LEVEL})
    assert both.t.size == 2 * PERIODS
    assert np.intersect1d(both.t, up.t).size == PERIODS  # the same run and interpolant: bit for bit
    assert np.all(both["omega3"] == pytest.approx(TOP.spin, rel=1e-12))  # the spin is conserved


def test_a_plane_the_motion_never_crosses_is_refused():
    traj = simulated(20)
    with pytest.raises(ValidationError, match="never crosses gamma3 = 0.95") as error:
        poincare_section(traj, INPUTS["torque"], section={"gamma3": 0.95})  # above u₂ = cos θ_min = 0.896
    assert error.value.field == "section"
    with pytest.raises(ValidationError) as error:
        poincare_section(traj, INPUTS["torque"], section={"theta": 0.5})
    assert error.value.field == "section"
