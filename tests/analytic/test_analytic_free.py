"""Exact torque-free motion (tumble.analytic._free) and its special functions (_elliptic).

References: scipy.special for the special functions; for the motion, tumble.simulate
(dop853 at rtol = atol = 1e-13), an extended-precision (80-bit) Taylor-series
integrator written here, the textbook closed forms of symmetric tops, the
invariants, and the motion restarted from an intermediate state.
"""

from fractions import Fraction

import numpy as np
import pytest
import scipy.special as sp

import tumble
from tumble import attitude
from tumble._validate import ValidationError
from tumble import _elliptic, _free_flow
from tumble.analytic import _free
from tumble.analytic._free import free_parameters, torque_free

EPS = np.finfo(np.float64).eps

# --- special functions -------------------------------------------------------
# K(m) from the AGM of (1, √m1) against scipy.special.ellipkm1: both are
# correctly rounded to an ulp or two (measured ≤ 2 eps).
RTOL_K = 4 * EPS
# Carlson R_F, R_J (duplication) against scipy.special.elliprf/elliprj
# (measured ≤ 2 eps over the grid).
RTOL_CARLSON = 8 * EPS
# sn, cn, dn, am against scipy.special.ellipj away from m = 1. Both lose the
# rounding of the argument, |u| eps |f'(u)|; beyond it scipy's dn (Cephes,
# cos φ₀ / cos(φ₁ − φ₀)) errs by up to ~300 eps near u = K for m1 = 1e-3, so
# the bound is absolute: 16 eps (1 + |u|) for the bounded sn, cn, dn; am relative.
TOL_JACOBI = 16 * EPS
# Near m = 1 scipy.special.ellipj switches to a first-order expansion in m1
# (not accurate past |u| ~ 1), so the reference there is the inverse function:
# r = sn r · R_F(cn² r, dn² r, 1) (DLMF 19.25.5) with scipy's elliprf, and the
# identities cn² + sn² = 1, dn² = cn² + m1 sn². Measured ≤ 8 eps (|u| + 1).
TOL_INVERSE = 16 * EPS

# --- the motion ---------------------------------------------------------------
# Exact against dop853 at rtol = atol = 1e-13 over 100 s: the brief's bound.
# Measured: ≤ 2e-12 away from the separatrix (the integrator's error), ≤ 4e-11
# near the intermediate axis with m1 = 2e-4 (dop853's rounding amplified).
TOL_VS_DOP853 = 1e-10
# Closer to the intermediate axis (ω = (1e-3, 1, 1e-3), m1 = 2e-6) 1e-10 over
# 100 s is NOT reachable by the integrator: its error does not shrink with the
# tolerance (8.7e-10, 5.6e-9, 2.3e-9 at rtol = 1e-12, 1e-13, 1e-14) because the
# passages near the unstable axis amplify its rounding. 1e-10 holds over the
# first 20 s (measured 2e-14) and 1e-8 over 100 s (measured 5.6e-9); the exact
# solution agrees with the 80-bit Taylor reference to 5e-13 there (test below).
TOL_NEAR_INTERMEDIATE_100S = 1e-8
# Exact against the 80-bit Taylor-series reference over 20 s: the reference
# errs by ~1e-18; the exact solution keeps the rates to a few ulp (measured
# ≤ 2e-15) and the attitude to eps × the angle turned (measured ≤ 1.5e-14).
TOL_VS_TAYLOR_RATE = 1e-14
TOL_VS_TAYLOR_ATTITUDE = 5e-14
# Invariants of the exact solution at every time: T, |L| and the direction of
# L_N, relative (measured ≤ 2.2e-15).
TOL_INVARIANT = 1e-14
# Restarting from the state at an intermediate time t_a gives the same motion;
# what separates them is the rounding of the state at t_a propagated by the
# motion. Bound: 1e-13, or twice the spread that 1-ulp perturbations of ω(t_a)
# produce where that is larger (near the separatrix, m = 0.97: the spread is
# 1.5e-13 over the 60 s after t_a, the restart differs by 1.1e-13).
TOL_RESTART = 1e-13
# Symmetric tops and the sphere against the textbook forms over 100 s: both
# lose eps × the angle turned (~100 rad) (measured ≤ 3e-14).
TOL_CLOSED_FORM = 1e-13
# On and near the separatrix, against dop853 over 5 s: the unstable passage
# near the intermediate axis amplifies the integrator's rounding (over 10 s
# dop853 strays by 2e-11 from the 80-bit reference, which the exact
# separatrix solution matches to 4e-16 in ω; measured here ≤ 1e-12).
TOL_SEPARATRIX = 1e-11
# m1 from the rates: relative to the exact rational value (measured ≤ 1 eps).
RTOL_M1 = 4 * EPS

Q0 = attitude.normalize([0.9, 0.1, -0.3, 0.2])
T100 = np.linspace(0.0, 100.0, 1001)


def rel_err(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)) / np.abs(np.asarray(b))


def assert_motion_close(a, b, tol):
    """Rates (rad/s, absolute) and attitudes (rad, relative angle) of two Trajectories agree to ``tol``."""
    assert np.abs(a.omega - b.omega).max() <= tol
    assert attitude.relative_angle(a.q, b.q).max() <= tol


def taylor_reference(moments, omega0, q0, t, order=24, h_max=0.05):
    """Rate and attitude (principal axes) at the times ``t`` by a Taylor-series integrator in long double.

    Euler's equations ``ω̇₁ = (I₂ − I₃)/I₁ ω₂ω₃`` (cyclic) and ``q̇ = ½ q ⊗ ω`` are
    quadratic, so their Taylor coefficients follow from Cauchy products:
    ``ω₁^(k+1) = c₁ Σᵢ ω₂^(i) ω₃^(k−i) / (k + 1)``. Order 24 with steps of
    0.05 s leaves a truncation error far below the 80-bit rounding (1e-19).
    """
    ld = np.longdouble
    i1, i2, i3 = (ld(float(x)) for x in moments)
    c = np.array([(i2 - i3) / i1, (i3 - i1) / i2, (i1 - i2) / i3], dtype=ld)
    w, q = np.array(omega0, dtype=ld), np.array(q0, dtype=ld)
    inv = ld(1) / np.arange(1, order + 1, dtype=ld)
    out_w, out_q = [w], [q]
    for t_a, t_b in zip(t[:-1], t[1:]):
        steps = int(np.ceil((t_b - t_a) / h_max))
        h = (ld(float(t_b)) - ld(float(t_a))) / steps
        for _ in range(steps):
            W, Q = np.zeros((order + 1, 3), dtype=ld), np.zeros((order + 1, 4), dtype=ld)
            W[0], Q[0] = w, q
            for k in range(order):
                a, b = W[: k + 1], W[k::-1]
                W[k + 1] = c * inv[k] * np.array([a[:, 1] @ b[:, 2], a[:, 2] @ b[:, 0], a[:, 0] @ b[:, 1]])
                p = Q[: k + 1]
                Q[k + 1] = 0.5 * inv[k] * np.array([
                    -(p[:, 1] @ b[:, 0] + p[:, 2] @ b[:, 1] + p[:, 3] @ b[:, 2]),
                    p[:, 0] @ b[:, 0] + p[:, 2] @ b[:, 2] - p[:, 3] @ b[:, 1],
                    p[:, 0] @ b[:, 1] - p[:, 1] @ b[:, 2] + p[:, 3] @ b[:, 0],
                    p[:, 0] @ b[:, 2] + p[:, 1] @ b[:, 1] - p[:, 2] @ b[:, 0],
                ])
            w, q = W[order], Q[order]
            for k in range(order - 1, -1, -1):
                w, q = w * h + W[k], q * h + Q[k]
        out_w.append(w)
        out_q.append(q)
    return np.array(out_w, dtype=float), np.array(out_q, dtype=float)


# =============================================================================
# Special functions
# =============================================================================

M1_GRID = [1.0, 0.9, 0.5, 0.1, 1e-3, 1e-6, 1e-8, 1e-10, 1e-12, 1e-100, 1e-300]


@pytest.mark.parametrize("m1", M1_GRID)
def test_ellipk_matches_scipy_ellipkm1(m1):
    assert rel_err(_elliptic.ellipk(1.0 - m1, m1), sp.ellipkm1(m1)) <= RTOL_K


def test_ellipk_at_the_ends():
    assert _elliptic.ellipk(0.0, 1.0) == pytest.approx(np.pi / 2, rel=EPS)
    assert _elliptic.ellipk(1.0, 0.0) == np.inf


def test_carlson_matches_scipy():
    rng = np.random.default_rng(0)
    scales = 10.0 ** rng.uniform(-8, 8, (400, 1))
    xyzp = rng.uniform(0.0, 1.0, (400, 4)) * scales
    xyzp[::4, 0] = 0.0  # one zero argument, as in the complete integrals
    for x, y, z, p in xyzp:
        assert rel_err(_elliptic.carlson_rf(x, y, z), sp.elliprf(x, y, z)) <= RTOL_CARLSON
        assert rel_err(_elliptic.carlson_rj(x, y, z, p), sp.elliprj(x, y, z, p)) <= RTOL_CARLSON


@pytest.mark.parametrize("m", [0.0, 1e-10, 0.1, 0.5, 0.9, 0.999])
def test_jacobi_matches_scipy_ellipj(m):
    quarter = sp.ellipk(m)
    rng = np.random.default_rng(1)
    u = np.concatenate([rng.uniform(-6 * quarter, 6 * quarter, 300), quarter * (1 - np.logspace(-12, 0, 30))])
    ref = np.array(sp.ellipj(u, m))
    got = np.array([_elliptic.ellipj(x, m, 1.0 - m) for x in u]).T
    assert np.all(np.abs(got[:3] - ref[:3]) <= TOL_JACOBI * (1.0 + np.abs(u)))
    assert np.all(np.abs(got[3] - ref[3]) <= TOL_JACOBI * (np.abs(ref[3]) + np.abs(u)))


@pytest.mark.parametrize("m1_target", [1e-8, 1e-10, 1e-12])
def test_jacobi_near_m_one_by_its_inverse(m1_target):
    m = 1.0 - m1_target
    m1 = 1.0 - m  # exact (Sterbenz): the pair (m, m1) is consistent
    quarter = sp.ellipkm1(m1)
    ks, kcs, n, agm = _elliptic.landen(m, m1)
    rng = np.random.default_rng(2)
    u = np.concatenate([rng.uniform(-3 * quarter, 3 * quarter, 300), quarter * (1 - np.logspace(-12, 0, 40))])
    for x in u:
        j, s, c, d = _elliptic.jacobi(x, _elliptic.ellipk(m, m1), ks, kcs, n, agm)
        r = x - 2.0 * quarter * j
        assert abs(s * sp.elliprf(c * c, d * d, 1.0) - r) <= TOL_INVERSE * (1.0 + abs(x))
        assert abs(s * s + c * c - 1.0) <= TOL_INVERSE
        assert abs(d * d - (c * c + m1 * s * s)) <= TOL_INVERSE * d * d
        assert c >= 0.0 and abs(r) <= quarter * (1 + 4 * EPS)
    # Where scipy's expansion in m1 is accurate (|u| ≤ 1/2), it agrees as well.
    for x in np.linspace(-0.5, 0.5, 21):
        ref = np.array(sp.ellipj(x, m))
        assert np.all(np.abs(np.array(_elliptic.ellipj(x, m, m1)) - ref) <= TOL_JACOBI)


def test_jacobi_limits_are_trigonometric_and_hyperbolic():
    for u in (-7.3, -0.2, 0.0, 1.1, 40.0):
        trig = (np.sin(u), np.cos(u), 1.0, u)
        assert _elliptic.ellipj(u, 0.0, 1.0) == pytest.approx(trig, rel=TOL_JACOBI, abs=TOL_JACOBI * (1 + abs(u)))
        sech, gd = 1.0 / np.cosh(u), 2 * np.arctan(np.tanh(u / 2))
        assert _elliptic.ellipj(u, 1.0, 0.0) == pytest.approx((np.tanh(u), sech, sech, gd), rel=TOL_JACOBI)


# =============================================================================
# free_parameters
# =============================================================================


def landau(moments, omega):
    """(regime, m, λ) straight from Landau & Lifshitz §37 with T and L² (cancellation and all)."""
    i1, i2, i3 = moments
    energy = 0.5 * np.sum(moments * omega**2)
    l2 = np.sum((moments * omega) ** 2)
    if l2 > 2 * energy * i2:
        m = (i2 - i1) * (2 * energy * i3 - l2) / ((i3 - i2) * (l2 - 2 * energy * i1))
        lam2 = (i3 - i2) * (l2 - 2 * energy * i1) / (i1 * i2 * i3)
        return "major", m, np.sqrt(lam2)
    m = (i2 - i3) * (2 * energy * i1 - l2) / ((i1 - i2) * (l2 - 2 * energy * i3))
    lam2 = (i1 - i2) * (l2 - 2 * energy * i3) / (i1 * i2 * i3)
    return "minor", m, np.sqrt(lam2)


@pytest.mark.parametrize("omega", [(0.3, 1.0, 0.2), (1.0, 0.3, 0.2), (0.1, 0.2, 1.0), (-1.0, 0.5, -0.1)])
def test_free_parameters_match_landau_lifshitz(omega):
    moments, omega = np.array([1.0, 2.0, 3.0]), np.array(omega)
    p = free_parameters(moments, omega)
    regime, m, lam = landau(moments, omega)
    assert p.regime == regime
    assert p.m == pytest.approx(m, rel=1e-13) and p.m1 == pytest.approx(1 - m, rel=1e-12)
    assert p.lam == pytest.approx(lam, rel=1e-14)
    assert p.energy == pytest.approx(0.5 * np.sum(moments * omega**2), rel=EPS)
    assert p.momentum == pytest.approx(np.linalg.norm(moments * omega), rel=2 * EPS)
    assert p.quarter_period == pytest.approx(sp.ellipk(m) / lam, rel=1e-12)


@pytest.mark.parametrize("delta", [2.0**-30, -(2.0**-40), 2.0**-50])
def test_m1_keeps_its_accuracy_near_the_separatrix(delta):
    # I = (3, 4, 6), ω = (2, 1/2, 1 + δ) lies δ away from the separatrix (δ = 0: L² = 2T I₂).
    moments, omega = (3, 4, 6), (2, 0.5, 1 + delta)
    f = [Fraction(x) for x in moments], [Fraction(x) for x in omega]
    energy = sum(i * w * w for i, w in zip(*f)) / 2
    l2 = sum((i * w) ** 2 for i, w in zip(*f))
    (i1, i2, i3) = f[0]
    if delta > 0:
        m1 = (i3 - i1) * (l2 - 2 * energy * i2) / ((i3 - i2) * (l2 - 2 * energy * i1))
    else:
        m1 = (i3 - i1) * (2 * energy * i2 - l2) / ((i2 - i1) * (2 * energy * i3 - l2))
    p = free_parameters(moments, omega)
    assert p.regime == ("major" if delta > 0 else "minor")
    assert rel_err(p.m1, float(m1)) <= RTOL_M1
    assert 0.0 < p.m1 < 1e-8


def test_free_parameters_regimes_and_batch():
    moments = [[1, 2, 3], [1, 1, 2], [1, 2, 2], [2, 2, 2], [3, 4, 6], [1, 2, 3]]
    omega = [[1, 0.1, 0.1], [0.3, 0.2, 1], [0.3, 0.2, 1], [0.3, 0.2, 1], [2, 0.5, 1], [0, 0, 0]]
    p = free_parameters(moments, omega)
    assert p.regime.tolist() == ["minor", "oblate", "prolate", "sphere", "separatrix", "rest"]
    assert p.m.tolist()[1:] == [0.0, 0.0, 0.0, 1.0, 0.0] and p.m1[4] == 0.0
    assert p.lam[1] == pytest.approx(1.0, rel=EPS)   # oblate: (I₃ − I₁) ω₃ / I₁
    assert p.lam[2] == pytest.approx(0.15, rel=EPS)  # prolate: (I₃ − I₁) ω₁ / I₃
    assert np.isinf(p.quarter_period[3:]).all()
    single = free_parameters(moments[0], omega[0])
    assert single.regime == "minor" and single.m == p.m[0] and single.period == 4 * single.quarter_period


def test_free_parameters_refuses_bad_moments():
    with pytest.raises(ValidationError, match="ascending"):
        free_parameters([3, 2, 1], [1, 0, 0])
    with pytest.raises(ValidationError, match="> 0"):
        free_parameters([0, 2, 3], [1, 0, 0])


@pytest.mark.parametrize("omega", [(0.3, 1.0, 0.2), (1.0, 0.3, -0.2)])
def test_rate_has_the_polhode_period(omega):
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    p = free_parameters(body.moments, omega)
    t = np.array([0.0, 2 * p.quarter_period, 4 * p.quarter_period])
    w = torque_free(body, omega, t=t).omega
    assert np.abs(w[2] - w[0]).max() <= 1e-14
    # half a period later ω₂ and the cn component have changed sign; the dn component has not
    k = 2 if p.regime == "major" else 0
    flip = np.ones(3)
    flip[[1, 2 - k]] = -1.0
    assert np.abs(w[1] - flip * w[0]).max() <= 1e-14


# =============================================================================
# The motion against the numerical solution and the extended-precision reference
# =============================================================================

CASES = {
    "major": (0.1, 0.2, 1.0),
    "minor": (1.0, 0.3, 0.2),
    "near-separatrix-major": (0.3, 1.0, 0.2),
    "near-intermediate": (0.01, 1.0, 0.01),
    "near-intermediate-minor": (0.02, 1.0, 0.005),
}


@pytest.mark.parametrize("rotated", [False, True])
@pytest.mark.parametrize("case", list(CASES))
def test_exact_matches_dop853(case, rotated, random_rotation):
    rot = random_rotation(7) if rotated else np.eye(3)
    body = tumble.RigidBody(rot @ np.diag([1.0, 2.0, 3.0]) @ rot.T)
    omega0 = rot @ np.array(CASES[case])
    exact = torque_free(body, omega0, Q0, t=T100)
    numeric = tumble.simulate(body, omega0, q0=Q0, t=T100, rtol=1e-13, atol=1e-13)
    assert exact.method == "exact" and exact.q.shape == (T100.size, 4)
    assert_motion_close(exact, numeric, TOL_VS_DOP853)


def test_a_lone_body_and_a_batch_share_one_compiled_exact_task():
    # a lone short run calls the task itself, a batch calls it from its parallel loop with an int64 task,
    # as the lone run does (docs/architecture.md, "One signature per path"): one compiled copy per model type
    from numba import typeof

    from tumble.integrate import _exact

    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    t = np.linspace(0.0, 1.0, 3)
    lone = tumble.simulate(body, [0.1, 1.0, 0.0], t=t, method="exact")
    batch = tumble.simulate(body, [[0.3, 1.0, 0.0], [0.1, 1.0, 0.0]], t=t, method="exact")
    assert np.array_equal(batch.q[:, 1], lone.q) and np.array_equal(batch.omega[:, 1], lone.omega)
    model = typeof(tumble.as_model(body).compile(None, 0.0))
    assert [signature[0] for signature in _exact.exact_task.signatures].count(model) == 1


def test_closest_to_the_intermediate_axis_against_dop853():
    body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
    omega0 = (1e-3, 1.0, 1e-3)
    exact = torque_free(body, omega0, Q0, t=T100)
    numeric = tumble.simulate(body, omega0, q0=Q0, t=T100, rtol=1e-13, atol=1e-13)
    assert_motion_close(exact, numeric, TOL_NEAR_INTERMEDIATE_100S)
    first = T100 <= 20.0
    assert np.abs(exact.omega[first] - numeric.omega[first]).max() <= TOL_VS_DOP853
    assert attitude.relative_angle(exact.q[first], numeric.q[first]).max() <= TOL_VS_DOP853


@pytest.mark.parametrize(
    "moments, omega",
    [((1, 2, 3), (0.3, 1.0, 0.2)), ((1, 2, 3), (1.0, 0.3, -0.2)), ((1, 2, 3), (-0.1, 0.2, 1.0)),
     ((1, 2, 3), (1e-3, 1.0, 1e-3)), ((1, 1 + 1e-7, 2), (0.2, 0.3, 1e-5)), ((1, 2, 2 + 1e-7), (1e-5, 0.3, 0.2))],
)
def test_exact_to_a_few_ulp_against_extended_precision(moments, omega):
    # the last two: nearly symmetric bodies whose polhode circles the far axis (|n| ≫ 1)
    t = np.linspace(0.0, 20.0, 5)
    body = tumble.RigidBody(np.diag(moments))
    exact = torque_free(body, omega, Q0, t=t)
    ref_w, ref_q = taylor_reference(body.moments, omega, Q0, t)
    assert np.abs(exact.omega - ref_w).max() <= TOL_VS_TAYLOR_RATE
    assert attitude.relative_angle(exact.q, ref_q).max() <= TOL_VS_TAYLOR_ATTITUDE


# The attitude's periodic part by the nome series against the same motion with
# it by Carlson's R_J and arctangents (the form used past the nome q = 0.6):
# the two share the rates and p(t) and differ in how ψ is summed; the series
# keeps Ω t as one product where the R_J form adds j half periods, so they
# part by eps × the angle turned (≤ 30 rad here; measured ≤ 1.1e-14).
TOL_SERIES_VS_RJ = 4e-14


def series_and_rj(moments, omega, times):
    """Attitudes at ``times`` from one set-up, by the nome series and by the R_J path (principal axes)."""
    motion = _free_flow._setup(*moments, *omega, *Q0)
    assert motion.series
    rj = motion._replace(series=False, bracket0=_free_flow._frame(motion, motion.tau0)[7])
    return np.array([[_free_flow._evaluate(m, dt)[3:] for dt in times] for m in (motion, rj)])


def test_nome_series_matches_carlson_r_j():
    # both polhode families, |n| ≤ 1 and n < −1, from m = 0.02 to the nome q = 0.59 (1 − m = 1.1e-7, 1.7e-7)
    rng = np.random.default_rng(11)
    times = np.linspace(-10.0, 20.0, 31)
    cases = [((1.0, 2.0, 3.0), (0.1, 0.2, 1.0)), ((1.0, 2.0, 3.0), (1.0, 0.3, -0.2)),
             ((1.0, 2.0, 3.0), (2.3e-4, 1.0, 2.3e-4)), ((1.0, 2.0, 3.0), (1.5e-3, -1.0, -1.5e-3 / 1.8)),
             ((1.0, 1.0 + 1e-7, 2.0), (0.2, 0.3, 1e-5)), ((1.0, 2.0, 2.0 + 1e-7), (1e-5, 0.3, 0.2))]
    for _ in range(12):
        moments = np.sort(rng.uniform(1.0, 3.0, 3))
        cases.append((tuple(moments), tuple(rng.standard_normal(3))))
    for moments, omega in cases:
        series, rj = series_and_rj(moments, omega, times)
        assert attitude.relative_angle(series, rj).max() <= TOL_SERIES_VS_RJ, (moments, omega)


@pytest.mark.parametrize("omega", [(3e-4, 1.0, 3e-4), (1e-4, 1.0, 1e-4)], ids=["q = 0.58", "q = 0.62"])
def test_either_side_of_the_nome_switch_against_extended_precision(omega):
    # 1 − m = 1.8e-7 (the nome series) and 2e-8 (R_J). Over 10 s: the passage
    # near the unstable intermediate axis amplifies the reference's own 80-bit
    # rounding (by ~e^{λt}, λ = 0.58 /s), which over 20 s would reach 1e-14.
    t = np.linspace(0.0, 10.0, 3)
    exact = torque_free(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), omega, Q0, t=t)
    ref_w, ref_q = taylor_reference([1.0, 2.0, 3.0], omega, Q0, t)
    assert np.abs(exact.omega - ref_w).max() <= TOL_VS_TAYLOR_RATE
    assert attitude.relative_angle(exact.q, ref_q).max() <= TOL_VS_TAYLOR_ATTITUDE


@pytest.mark.parametrize("case", ["major", "minor", "near-separatrix-major"])
@pytest.mark.parametrize("rotated", [False, True])
def test_invariants_at_all_times(case, rotated, random_rotation):
    rot = random_rotation(3) if rotated else np.eye(3)
    body = tumble.RigidBody(rot @ np.diag([1.0, 2.0, 3.0]) @ rot.T)
    traj = torque_free(body, rot @ np.array(CASES[case]), Q0, t=np.linspace(0.0, 1000.0, 5001))
    energy, momentum = traj.energy, traj.momentum_inertial
    magnitude = np.linalg.norm(momentum, axis=-1)
    assert rel_err(energy, energy[0]).max() <= TOL_INVARIANT
    assert rel_err(magnitude, magnitude[0]).max() <= TOL_INVARIANT
    direction = momentum / magnitude[:, None]
    assert np.abs(direction - direction[0]).max() <= TOL_INVARIANT


@pytest.mark.parametrize(
    "moments, omega",
    [((1, 2, 3), (0.3, 1.0, 0.2)), ((1, 2, 3), (1.0, 0.3, 0.2)), ((1, 2, 3), (0.1, 0.2, 1.0)),
     ((3, 4, 6), (2.0, 0.5, 1.0)), ((1, 1, 2), (0.3, 0.2, 1.0))],
)
def test_restart_from_an_intermediate_state(moments, omega):
    body = tumble.RigidBody(np.diag(moments))
    t = np.linspace(0.0, 100.0, 2001)
    whole = torque_free(body, omega, Q0, t=t)
    k = 777
    rest = torque_free(body, whole.omega[k], whole.q[k], t=t[k:])
    nudged = [whole.omega[k] * (1 + np.array(sign) * EPS) for sign in ([1, 1, 1], [-1, 1, -1], [1, -1, -1])]
    spread = max(np.abs(torque_free(body, w, whole.q[k], t=t[k:]).omega - rest.omega).max() for w in nudged)
    tol = max(TOL_RESTART, 2 * spread)
    assert np.abs(rest.omega - whole.omega[k:]).max() <= tol
    assert attitude.relative_angle(rest.q, whole.q[k:]).max() <= tol


def test_initial_state_is_reproduced():
    traj = torque_free(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), (0.3, -1.0, 0.2), Q0, t=[5.0, 6.0])
    assert np.abs(traj.omega[0] - [0.3, -1.0, 0.2]).max() <= 4 * EPS
    assert np.abs(traj.q[0] - Q0).max() <= 4 * EPS


# =============================================================================
# The separatrix
# =============================================================================

# I = (3, 4, 6): I₃(I₃ − I₂)ω₃² = I₁(I₂ − I₁)ω₁² exactly for ω₁ = 2ω₃, so L² = 2T I₂.
SEP_BODY = np.diag([3.0, 4.0, 6.0])


@pytest.mark.parametrize("omega", [(2.0, 0.5, 1.0), (-2.0, 0.5, 1.0), (2.0, -3.0, -1.0), (-2.0, 0.0, -1.0)])
def test_on_the_separatrix_hyperbolic_form_matches_references(omega):
    assert free_parameters([3, 4, 6], omega).regime == "separatrix"
    t = np.linspace(0.0, 10.0, 11)
    exact = torque_free(SEP_BODY, omega, Q0, t=t)
    ref_w, ref_q = taylor_reference([3, 4, 6], omega, Q0, t)
    assert np.abs(exact.omega - ref_w).max() <= TOL_VS_TAYLOR_RATE
    assert attitude.relative_angle(exact.q, ref_q).max() <= TOL_VS_TAYLOR_ATTITUDE
    t = np.linspace(0.0, 5.0, 101)
    numeric = tumble.simulate(SEP_BODY, omega, q0=Q0, t=t, rtol=1e-13, atol=1e-13)
    assert_motion_close(torque_free(SEP_BODY, omega, Q0, t=t), numeric, TOL_SEPARATRIX)
    # ω tends to the intermediate axis: ω₁, ω₃ ∝ sech λt vanish, ω₂ → ±|L|/I₂
    late = torque_free(SEP_BODY, omega, Q0, t=[0.0, 200.0, 2000.0]).omega
    assert np.abs(late[1:, [0, 2]]).max() <= 1e-40
    assert np.abs(np.abs(late[1:, 1]) - free_parameters([3, 4, 6], omega).momentum / 4.0).max() <= 4 * EPS


@pytest.mark.parametrize("delta", [1e-9, -1e-9, 1e-13, -1e-13])
def test_near_the_separatrix_is_finite_and_matches_dop853(delta):
    omega = (2.0, 0.5, 1.0 + delta)
    assert free_parameters([3, 4, 6], omega).m1 <= 1e-8
    t = np.linspace(0.0, 5.0, 101)
    exact = torque_free(SEP_BODY, omega, Q0, t=t)
    numeric = tumble.simulate(SEP_BODY, omega, q0=Q0, t=t, rtol=1e-13, atol=1e-13)
    assert np.isfinite(exact.q).all() and np.isfinite(exact.omega).all()
    assert_motion_close(exact, numeric, TOL_SEPARATRIX)
    # and it tends to the separatrix motion as δ → 0 (the orbits part as δ e^{λt})
    on = torque_free(SEP_BODY, (2.0, 0.5, 1.0), Q0, t=t)
    assert_motion_close(exact, on, 1e3 * abs(delta) * np.exp(0.72 * 5.0))


def test_rotation_about_the_intermediate_axis_is_steady():
    omega = (0.0, 1.3, 0.0)
    t = np.linspace(0.0, 50.0, 11)
    traj = torque_free(SEP_BODY, omega, Q0, t=t)
    assert np.array_equal(traj.omega, np.broadcast_to(omega, traj.omega.shape))
    ref = attitude.multiply(Q0, attitude.from_rotvec(t[:, None] * np.array(omega)))
    assert attitude.relative_angle(traj.q, ref).max() <= TOL_CLOSED_FORM


# =============================================================================
# Symmetric tops and the sphere: textbook closed forms
# =============================================================================


@pytest.mark.parametrize("moments, axis", [((1.0, 1.0, 2.0), 2), ((1.0, 2.0, 2.0), 0), ((2.0, 3.0, 3.0), 0)])
@pytest.mark.parametrize("rotated", [False, True])
@pytest.mark.parametrize("omega_p", [(0.3, -0.2, 1.0), (0.3, 0.2, 0.0)])
def test_symmetric_top_matches_textbook(moments, axis, rotated, omega_p, random_rotation):
    # R(t) = exp(t [L_N]× / I⊥) R₀ exp(μ t [e]×), μ = −(I_e − I⊥) ω_e / I⊥: the body
    # spins about its symmetry axis e at μ while e cones about L_N at |L|/I⊥.
    rot = random_rotation(5) if rotated else np.eye(3)
    body = tumble.RigidBody(rot @ np.diag(moments) @ rot.T)
    axis_b, omega0 = rot[:, axis], rot @ np.array(omega_p)
    i_axis, i_perp = moments[axis], moments[1]
    mu = -(i_axis - i_perp) * (omega0 @ axis_b) / i_perp
    traj = torque_free(body, omega0, Q0, t=T100)
    momentum_n = attitude.rotate(Q0, body.inertia @ omega0)
    ref_q = attitude.multiply(
        attitude.multiply(attitude.from_rotvec(T100[:, None] * momentum_n / i_perp), Q0),
        attitude.from_rotvec(T100[:, None] * mu * axis_b),
    )
    ref_w = attitude.rotate(attitude.from_rotvec(-T100[:, None] * mu * axis_b), omega0)
    assert np.abs(traj.omega - ref_w).max() <= TOL_CLOSED_FORM
    assert attitude.relative_angle(traj.q, ref_q).max() <= TOL_CLOSED_FORM


def test_sphere_and_rest_are_steady():
    t = np.linspace(0.0, 100.0, 101)
    omega = np.array([0.3, -1.1, 0.7])
    traj = torque_free(np.eye(3) * 2.5, omega, Q0, t=t)
    assert np.array_equal(traj.omega, np.broadcast_to(omega, traj.omega.shape))
    ref = attitude.multiply(Q0, attitude.from_rotvec(t[:, None] * omega))
    assert attitude.relative_angle(traj.q, ref).max() <= TOL_CLOSED_FORM
    rest = torque_free(np.diag([1.0, 2.0, 3.0]), np.zeros(3), Q0, t=t)
    assert np.array_equal(rest.q, np.broadcast_to(Q0, rest.q.shape)) and not rest.omega.any()


# =============================================================================
# Batches and input
# =============================================================================


def test_batch_equals_single_runs(random_rotation):
    rng = np.random.default_rng(4)
    rots = [random_rotation(s) for s in range(5)]
    moments = [(1.0, 2.0, 3.0), (1.0, 1.0, 2.0), (3.0, 4.0, 6.0), (2.0, 2.0, 2.0), (1.0, 2.5, 3.0)]
    bodies = [tumble.RigidBody(r @ np.diag(m) @ r.T) for r, m in zip(rots, moments)]
    omega0 = rng.standard_normal((5, 3))
    q0 = attitude.normalize(rng.standard_normal((5, 4)))
    t = np.linspace(0.0, 30.0, 1500)  # more than one chunk of the parallel loop
    batch = torque_free(bodies, omega0, q0, t=t)
    assert batch.q.shape == (t.size, 5, 4) and batch.batch_size == 5
    for i, body in enumerate(bodies):
        single = torque_free(body, omega0[i], q0[i], t=t)
        assert np.array_equal(batch.omega[:, i], single.omega) and np.array_equal(batch.q[:, i], single.q)
    shared = torque_free(bodies[0], omega0, q0, t=t)  # one body, many initial states
    assert np.array_equal(shared.omega[:, 0], batch.omega[:, 0])
    stacked = torque_free(np.stack([b.inertia for b in bodies]), omega0, q0, t=t)
    assert np.array_equal(stacked.q, batch.q)


def test_bad_input_is_refused():
    body = np.diag([1.0, 2.0, 3.0])
    with pytest.raises(ValidationError, match="increasing"):
        torque_free(body, (1.0, 0.0, 0.0), t=[0.0, 1.0, 1.0])
    with pytest.raises(ValidationError, match="q0"):
        torque_free(body, (1.0, 0.0, 0.0), [0.0, 0.0, 0.0, 0.0], t=[0.0, 1.0])
    with pytest.raises(ValidationError, match="batch sizes"):
        torque_free(body, np.ones((3, 3)), np.tile(Q0, (2, 1)), t=[0.0, 1.0])
    with pytest.raises(ValidationError, match="omega0"):
        torque_free(body, (np.nan, 0.0, 0.0), t=[0.0, 1.0])


def test_regime_codes_follow_regimes():
    assert _free.REGIMES[_free_flow._SEPARATRIX] == "separatrix" and _free.REGIMES[_free_flow._REST] == "rest"
