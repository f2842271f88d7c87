"""Stability of the principal axes, the growth rate about the intermediate axis, flip times and polhode periods."""

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.measure import flip_times as measured_flip_times
from tumble.analytic import _stability as stability
from tumble.analytic._free import free_parameters, torque_free

INTEGRATION = dict(method="dop853", rtol=1e-12, atol=1e-12)
# Flip interval 2K/λ against the sign changes of ω₂ in a dop853 (rtol = atol
# = 1e-12) run sampled 1000 times a second: linear interpolation at a zero of
# sn (an inflection point) and the integration error; measured ≤ 5e-12 away
# from the separatrix and ≤ 6.4e-8 for the racket motions (see below).
FLIP_INTERVAL_RTOL = 1e-6
# Exact flip times against the same measurement. Away from the separatrix
# they agree to ≤ 2e-11 s (interpolation). Near it (the racket motions, m1 ~
# 1e-8) the period K ≈ ½ ln(16/m1) depends on Δ₂ = L² − 2T I₂ ~ 1e-8 L², and
# the simulation's rounding drift of T and |L| (~5e-14 over 40 000 steps)
# changes its own 2K/λ by up to 6e-8: flip times then differ by ≤ 4.5e-8 t.
FLIP_TIME_ATOL = 1e-9  # s
FLIP_TIME_RTOL = 2e-7
# Log-linear fit of ω₁ and ω₃ started in the growing eigenvector of the
# linearisation: the slope is σ up to the nonlinear terms (amplitude ≤ 3e-4 Ω,
# relative effect ~1e-8) and the integration error; measured ≤ 5.1e-10.
GROWTH_EIGENVECTOR_RTOL = 1e-8
# The same fit for an arbitrary small perturbation (1e-9 rad/s on both other
# axes of the T-handle) between 4 and 12 e-foldings: the decaying mode
# e^{−σt} biases the slope; measured ≤ 9.4e-5.
GROWTH_GENERIC_RTOL = 1e-3
# |ω₂| of the exact solution (tumble.analytic._free.torque_free) at the exact
# flip times, relative to |ω|: two independent closed forms; measured 7e-13.
EXACT_ZERO_RTOL = 1e-11
# After one polhode period 4K/λ the body rate is back at its start: integration error only (measured 1.5e-12).
PERIOD_RETURN_RTOL = 1e-10


@pytest.fixture
def body():
    """Moments (1, 2, 3) kg m² described in axes rotated away from the principal ones."""
    return tumble.RigidBody(np.diag([1.0, 2.0, 3.0])).rotated(attitude.from_rotvec([0.3, -0.2, 0.5]))


# -- classification -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("inertia", "expected"),
    [
        (np.diag([1.0, 2.0, 3.0]), ("stable", "unstable", "stable")),
        (np.diag([1.0, 1.0, 2.0]), ("neutral", "neutral", "stable")),   # oblate top
        (np.diag([1.0, 2.0, 2.0]), ("stable", "neutral", "neutral")),   # prolate top
        (np.eye(3), ("neutral", "neutral", "neutral")),                 # sphere
        (np.diag([1.0, 1.0 + 1e-12, 2.0]), ("neutral", "neutral", "stable")),  # equal within 1e-9 I₃
    ],
    ids=["asymmetric", "oblate", "prolate", "sphere", "nearly-oblate"],
)
def test_classification_of_the_principal_axes(inertia, expected):
    rotation = attitude.to_matrix(attitude.from_rotvec([0.4, 0.1, -0.3]))
    for described in (tumble.RigidBody(inertia), tumble.RigidBody(rotation @ inertia @ rotation.T)):
        assert stability.classify_axes(described) == expected


def test_t_handle_is_unstable_about_its_bar():
    handle = tumble.RigidBody.t_handle()
    report = stability.stability(handle, [0.0, 10.0, 0.0])  # spin about body y, along the cross bar
    assert report.axis_stability == ("stable", "unstable", "stable")
    np.testing.assert_allclose(np.abs(handle.axes[:, 1]), [0.0, 1.0, 0.0], atol=1e-15)  # y is the intermediate axis


# -- growth rate ----------------------------------------------------------------------


def test_growth_rate_formula_and_separatrix_identity(body):
    i1, i2, i3 = body.moments
    spin = -2.5
    sigma = stability.growth_rate(body, spin)
    assert sigma == pytest.approx(2.5 * np.sqrt((i3 - i2) * (i2 - i1) / (i1 * i3)), rel=1e-15)
    # On the separatrix the elliptic rate λ of the exact solution equals σ of the spin |L|/I₂.
    assert free_parameters(body.moments, [0.0, spin, 0.0]).lam == pytest.approx(sigma, rel=1e-15)
    assert stability.growth_rate(tumble.RigidBody(np.diag([1.0, 1.0, 2.0])), spin) == 0.0


def fitted_growth(body, omega_principal, t_end, t_fit):
    """Slopes of log|ω₁|, log|ω₃| (principal axes) against t over ``[t_fit, t_end]``, from a dop853 run from t = 0."""
    t = np.linspace(0.0, t_end, 801)
    traj = tumble.simulate(body, body.axes @ omega_principal, t=t, method="dop853", rtol=1e-13, atol=1e-20)
    rates = traj.omega @ body.axes
    fit = t >= t_fit
    return [np.polyfit(t[fit], np.log(np.abs(rates[fit, k])), 1)[0] for k in (0, 2)]


def test_growth_rate_matches_a_simulated_perturbation_in_its_eigenvector(body):
    i1, i2, i3 = body.moments
    spin, eps = 2.0, 1e-7
    sigma = stability.growth_rate(body, spin)
    # Linearisation ω̇₁ = (I₂ − I₃)/I₁ Ω ω₃: the growing mode has ω₃ = −σ I₁ ω₁ / ((I₃ − I₂) Ω).
    omega = np.array([eps, spin, -eps * sigma * i1 / ((i3 - i2) * spin)])
    slopes = fitted_growth(body, omega, 8.0 / sigma, 0.0)
    np.testing.assert_allclose(slopes, sigma, rtol=GROWTH_EIGENVECTOR_RTOL)


def test_growth_rate_matches_a_simulated_generic_perturbation():
    handle = tumble.RigidBody.t_handle()
    spin, eps = 10.0, 1e-9
    sigma = stability.growth_rate(handle, spin)
    slopes = fitted_growth(handle, np.array([eps, spin, eps]), 12.0 / sigma, 4.0 / sigma)
    np.testing.assert_allclose(slopes, sigma, rtol=GROWTH_GENERIC_RTOL)


# -- flips and periods ----------------------------------------------------------------


@pytest.mark.parametrize(
    "omega_principal",
    [[1e-3, 10.0, 1e-3], [1e-3, 10.0, -3e-3], [0.3, 1.0, 0.2], [1.0, 0.3, -0.2], [-1.0, 0.2, 0.3]],
    ids=["racket-major", "racket-minor", "major", "minor", "minor-negative"],
)
def test_flip_interval_and_flip_times_match_the_simulation(omega_principal):
    handle = tumble.RigidBody.t_handle()
    omega0 = handle.axes @ np.array(omega_principal)
    t_end = 40.0
    traj = tumble.simulate(handle, omega0, t=np.linspace(0.0, t_end, 40_001), **INTEGRATION)
    measured = measured_flip_times(traj, handle)
    assert measured.size >= 3
    np.testing.assert_allclose(np.diff(measured), stability.flip_interval(handle, omega0), rtol=FLIP_INTERVAL_RTOL)
    exact = stability.flip_times(handle, omega0, t_end)
    assert exact.shape == measured.shape
    np.testing.assert_allclose(exact, measured, rtol=FLIP_TIME_RTOL, atol=FLIP_TIME_ATOL)


@pytest.mark.parametrize("omega_principal", [[1e-3, 10.0, 1e-3], [1.0, 0.3, -0.2]], ids=["racket", "minor"])
def test_flip_times_are_the_zeros_of_the_exact_solution(omega_principal):
    handle = tumble.RigidBody.t_handle()
    omega0 = handle.axes @ np.array(omega_principal)
    flips = stability.flip_times(handle, omega0, 40.0)

    def rate(t):  # ω₂ of the exact solution at the times t
        return torque_free(handle, omega0, t=np.r_[0.0, t]).omega[1:] @ handle.axes[:, 1]

    assert np.abs(rate(flips)).max() <= EXACT_ZERO_RTOL * np.linalg.norm(omega0)
    assert np.all(rate(flips - 1e-6) * rate(flips + 1e-6) < 0.0)  # a sign change, not a touch


def test_rate_returns_after_one_polhode_period(body):
    omega0 = body.axes @ np.array([0.3, 1.0, 0.2])
    period = stability.polhode_period(body, omega0)
    assert period == pytest.approx(2.0 * stability.flip_interval(body, omega0), rel=1e-15)
    traj = tumble.simulate(body, omega0, t=[0.0, 0.5 * period, period], **INTEGRATION)
    np.testing.assert_allclose(traj.omega[-1], omega0, rtol=0, atol=PERIOD_RETURN_RTOL * np.linalg.norm(omega0))
    assert np.linalg.norm(traj.omega[1] - omega0) > 0.1 * np.linalg.norm(omega0)  # it went somewhere


@pytest.mark.parametrize(
    ("moments", "omega0", "precession"),
    [([1.0, 1.0, 1.6], [0.6, 0.3, 1.0], 0.6), ([0.5, 1.0, 1.0], [1.0, 0.4, 0.3], 0.5)],
    ids=["oblate", "prolate"],
)
def test_symmetric_top_flips_at_its_precession_rate(moments, omega0, precession):
    # The transverse rate turns about the symmetry axis (s) at Ω = |I_s − I_⊥| ω_s / I_⊥ (here 0.6 and
    # 0.5 rad/s), so the rate about any transverse axis changes sign every π/Ω.
    top = tumble.RigidBody(np.diag(moments))
    assert stability.flip_interval(top, omega0) == pytest.approx(np.pi / precession, rel=1e-15)
    traj = tumble.simulate(top, omega0, t=np.linspace(0.0, 20.0, 20_001), **INTEGRATION)
    np.testing.assert_allclose(stability.flip_times(top, omega0, 20.0), measured_flip_times(traj, top),
                               rtol=0, atol=FLIP_TIME_ATOL)


@pytest.mark.parametrize(
    ("inertia", "omega"),
    [
        (np.eye(3), [0.3, 1.0, 0.2]),                 # sphere: ω constant
        (np.diag([1.0, 2.0, 3.0]), [0.0, 1.0, 0.0]),  # steady spin about the intermediate axis
        (np.diag([1.0, 2.0, 3.0]), [0.0, 0.0, 1.0]),  # steady spin about the major axis
    ],
    ids=["sphere", "intermediate-axis", "major-axis"],
)
def test_no_flips_without_motion_of_the_rate(inertia, omega):
    body = tumble.RigidBody(inertia)
    assert stability.flip_times(body, omega, 100.0).size == 0


def test_separatrix_never_returns():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    assert stability.flip_interval(body, [0.0, 1.0, 0.0]) == np.inf
    assert stability.polhode_period(tumble.RigidBody(np.eye(3)), [0.0, 1.0, 0.0]) == np.inf


# -- report -------------------------------------------------------------------------------


def test_report_fields_and_text(body):
    omega0 = body.axes @ np.array([0.3, 1.0, 0.2])
    report = stability.stability(body, omega0)
    params = free_parameters(body.moments, body.axes.T @ omega0)
    assert report.regime == params.regime == "major"
    assert report.energy == params.energy and report.momentum == params.momentum
    assert report.flip_interval == 2.0 * params.quarter_period
    assert report.polhode_period == 4.0 * params.quarter_period
    assert report.growth_rate == stability.growth_rate(body, params.momentum / 2.0)
    np.testing.assert_allclose(report.omega_principal, [0.3, 1.0, 0.2], atol=1e-15)
    text = str(report)
    assert "axis 2: I = 2 kg m^2, unstable (intermediate axis)" in text
    assert "regime 'major'" in text and f"2K/lambda = {report.flip_interval:.6g} s" in text
    with pytest.raises(AttributeError):
        report.regime = "minor"


def test_report_of_a_symmetric_top_has_no_growth():
    report = stability.stability(tumble.RigidBody(np.diag([1.0, 1.0, 2.0])), [0.1, 0.0, 1.0])
    assert report.growth_rate == 0.0 and report.regime == "oblate"
    assert "growth rate" not in str(report)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda b: stability.stability(b, [0.0, 0.0, 0.0]), "omega: must be non-zero"),
        (lambda b: stability.stability(b, [[1.0, 0.0, 0.0]]), r"omega: must have shape \(3,\)"),
        (lambda b: stability.flip_interval(b, [np.nan, 1.0, 0.0]), "omega: must be finite"),
        (lambda b: stability.growth_rate(b, [1.0, 2.0]), "spin: must be a number"),
        (lambda b: stability.flip_times(b, [0.0, 1.0, 0.1], -1.0), "t_end: must be a finite number > 0"),
        (lambda b: stability.classify_axes(np.eye(3)), "body: must be a RigidBody"),
    ],
)
def test_bad_input_is_refused(body, call, message):
    with pytest.raises(tumble.ValidationError, match=message):
        call(body)
