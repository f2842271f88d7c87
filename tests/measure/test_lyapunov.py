"""Lyapunov exponents of heavy tops (tumble.measure.lyapunov_exponents): integrable tops, a chaotic top, spectrum.

The tangent kernel runs through the engine (tumble.integrate.Run), with the drivers tumble.simulate uses.
"""

import numpy as np
import pytest

from tumble import attitude
from tumble._validate import ValidationError
from tumble.measure import lyapunov_exponents
from tumble.analytic import heavy_top_energy, omega_at_energy
from tumble.torques import Gravity

# Every test here compiles the variational (Lyapunov) integrators on a cold Numba cache (~10 CPU s).
pytestmark = pytest.mark.slow

UP = [0.0, 0.0, -1.0]  # m g |r| of order 1 and moments of order 1: the time unit is about 1 s
GENERIC = np.diag([1.0, 1.6, 2.1]), Gravity(1.0, [1.0, 0.5, 0.3], UP)  # a generic (chaotic) heavy top
INTEGRABLE = {
    "Euler": (np.diag([1.0, 1.6, 2.1]), None),
    "Lagrange": (np.diag([2.0, 2.0, 1.0]), Gravity(1.0, [0.0, 0.0, 1.0], UP)),
    "Kovalevskaya": (np.diag([2.0, 2.0, 1.0]), Gravity(1.0, [1.0, 0.0, 0.0], UP)),
}
Q0 = attitude.from_rotvec([0.4, -0.3, 0.2])
OMEGA0 = [0.5, 0.3, 1.0]


def chaotic_states(n, energy=1.0, seed=3):
    """``n`` initial states of the generic top on the energy level ``energy`` (J), random directions and attitudes."""
    rng = np.random.default_rng(seed)
    q = attitude.normalize(rng.standard_normal((n, 4)))
    return omega_at_energy(GENERIC[0], GENERIC[1], energy, rng.standard_normal((n, 3)), q), q


# An integrable top's tangent vectors grow linearly (shear between neighbouring tori), so λ(t) t − ln t tends to
# a constant: measured in [−3.2, −1.6] for t in [1e2, 1e4] for the three tops (a chaotic top's grows like 0.13 t).
# Band [−4, 0]; and λ(1e4) ≤ ln(1e4)/1e4 = 9.2e-4 (measured 6.9e-4 to 7.2e-4).
@pytest.mark.parametrize("name", INTEGRABLE)
def test_integrable_tops_have_a_largest_exponent_decaying_like_log_t_over_t(name):
    result = lyapunov_exponents(*INTEGRABLE[name], omega0=OMEGA0, q0=Q0, t=np.linspace(0.0, 1e4, 10001),
                                method="dop853", rtol=1e-10, atol=1e-10)
    late = result.t >= 100.0
    offset = result.finite_time[late, 0] * result.t[late] - np.log(result.t[late])
    assert -4.0 <= offset.min() and offset.max() <= 0.0
    assert 0.0 < result.largest <= np.log(1e4) / 1e4


# Six states on the level H = 1 J of the generic top, 1e4 s, re-orthonormalised every 5 s. A single chaotic orbit's
# finite-time exponent fluctuates by ~10 % between integrators (the orbits separate after ~100 s and sample the
# sea differently); the mean over the six (the sea's exponent) converges: measured 0.1307 (dop853 rtol 1e-10),
# 0.1276 (dop853 1e-12), 0.1299 (rk4 dt 0.01) 1/s, within 2.5 %. Bound 5 %; each orbit's exponent > 0.05
# (smallest measured 0.070: the most regular of the six).
def test_a_generic_top_has_a_positive_converged_largest_exponent():
    omega0, q0 = chaotic_states(6)
    np.testing.assert_allclose(heavy_top_energy(*GENERIC, omega0, q0), 1.0, rtol=1e-14)
    t = np.linspace(0.0, 1e4, 2001)
    runs = [lyapunov_exponents(*GENERIC, omega0=omega0, q0=q0, t=t, **options).largest for options in
            (dict(method="dop853", rtol=1e-10, atol=1e-10), dict(method="dop853", rtol=1e-12, atol=1e-12),
             dict(method="rk4", dt=0.01))]
    means = np.array([run.mean() for run in runs])
    assert means.min() > 0.1
    assert means.max() - means.min() <= 0.05 * means.mean()
    assert min(run.min() for run in runs) > 0.05


# Full spectrum (six tangent vectors) of one chaotic orbit over 2000 s, dop853 rtol = 1e-12. The flow keeps
# volume: the sum is ln|det| / t of the integrated tangent map, measured 7e-14 1/s (bound 1e-8). Pairs
# λᵢ + λ₇₋ᵢ: measured ≤ 0.0066 λ₁ (λ₁ = 0.1289 1/s; bound 0.02 λ₁); the four middle exponents (the flow
# direction, the energy and the two Casimirs) tend to zero like ln t / t: measured ≤ 0.025 λ₁ (bound 0.1 λ₁).
def test_spectrum_sums_to_zero_and_comes_in_plus_minus_pairs():
    omega0, q0 = chaotic_states(1)
    result = lyapunov_exponents(*GENERIC, omega0=omega0[0], q0=q0[0], t=np.linspace(0.0, 2000.0, 2001), count=6,
                                method="dop853", rtol=1e-12, atol=1e-12)
    spectrum = result.exponents
    assert spectrum.shape == (6,)
    assert abs(spectrum.sum()) <= 1e-8
    assert spectrum[0] > 0.05
    assert np.abs(spectrum + spectrum[::-1]).max() <= 0.02 * spectrum[0]
    assert np.abs(spectrum[1:5]).max() <= 0.1 * spectrum[0]


def test_a_batch_is_the_single_runs_bit_for_bit():
    omega0, q0 = chaotic_states(3)
    t = np.linspace(0.0, 50.0, 51)
    batch = lyapunov_exponents(*GENERIC, omega0=omega0, q0=q0, t=t, count=2, method="rk4", dt=0.01)
    assert batch.finite_time.shape == (50, 3, 2)
    for b in range(3):
        single = lyapunov_exponents(*GENERIC, omega0=omega0[b], q0=q0[b], t=t, count=2, method="rk4", dt=0.01)
        np.testing.assert_array_equal(single.finite_time, batch.finite_time[:, b])


@pytest.mark.parametrize("options, field", [
    (dict(method="cf4", dt=0.01), "method"),
    (dict(method="dop853", dt=0.01), "dt"),
    (dict(method="rk4"), "dt"),
    (dict(count=7), "count"),
    (dict(t=[0.0]), "t"),
    (dict(omega0=np.zeros((2, 2, 3))), "omega0"),
])
def test_bad_input_is_refused_naming_the_field(options, field):
    arguments = dict(omega0=OMEGA0, q0=Q0, t=[0.0, 1.0]) | options
    with pytest.raises(ValidationError) as error:
        lyapunov_exponents(*GENERIC, **arguments)
    assert error.value.field == field
