"""Tests of the heavy symmetric top: exact theory (tumble.analytic._heavy_top) against tumble.simulate + Gravity."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

import tumble
from tumble import analytic, attitude, dynamics
from tumble._validate import ValidationError
from tumble.analytic import _heavy_top as ht
from tumble.viz import top as viz_top

EPS = np.finfo(np.float64).eps
# f(u) = (α − βu)(1 − u²) − (b − au)² at a computed root: the root is right
# to about eps, and f is evaluated with a dozen roundings of terms as large as
# (|α| + β) + (|a| + |b|)² (measured ≤ 11 eps of that scale).
TOL_F_ROOT = 64 * EPS
# A quantity computed by two formulas from the same state (E, p_φ, p_ψ from
# the Euler angles vs from q, ω; θ, θ̇, φ̇, ω₃ read back from q, ω): a few
# roundings of trigonometric functions and a quaternion rotation; φ̇ divides
# by sin²θ (measured ≤ 1e-14 relative).
TOL_SAME_STATE = 1e-13
# dop853 at rtol = atol = 1e-12 over ≤ 10 nutation periods (≤ 2e4 steps)
# keeps the global error in u = cos θ ≲ 1e-11 (measured ≤ 3e-14 away from the
# unstable upright top); the theory is exact to rounding. 1e-10 is the bound.
TOL_SIMULATED_U = 1e-10
# φ accumulates over the run: the same global error times the number of
# radians swept (≤ 40 here) (measured ≤ 1.2e-13).
TOL_SIMULATED_PHI = 1e-9
# Turning points of u refined by a parabola through three samples: u is even
# about a turning point, so the vertex value is off by about (2λh)⁴/48 (u₂ − u₁),
# under 1e-13 with 2000 samples per period (2λh = 4K/2000 ≲ 3.3e-3), below
# the integration error; bound as for u(t) (measured ≤ 1e-13).
TOL_BOUNDS = 1e-10
# Vertex times are off by O(λ²h³) ≲ 1e-11 T with 2000 samples per period
# (measured ≤ 2e-14 T); the period is the mean spacing of ≥ 9 minima. The
# measured mean precession (φ between the first and last minimum) inherits
# that error times max |φ̇| (measured ≤ 1e-14 relative).
TOL_PERIOD = 1e-9
# Mean precession rate: closed form with Π vs adaptive quadrature of φ̇ over
# one period at epsrel = 1e-13 (measured 2e-15).
TOL_MEAN_QUAD = 1e-12
# φ advance over N exact periods vs N T ⟨φ̇⟩: the integration error in φ
# (TOL_SIMULATED_PHI) over an advance of ≥ 5 rad (measured ≤ 3e-12).
TOL_MEAN_SIMULATED = 1e-10
SAMPLES_PER_PERIOD = 2000
RTOL = ATOL = 1e-12

BASE = dict(I1=0.02, I3=0.01, mass=1.0, length=0.1, g=9.81)  # about the pivot; critical spin 28.0 rad/s
TOPS = {
    "general": ht.HeavyTop(**BASE, theta0=0.6, theta_dot0=0.5, phi_dot0=-1.0, spin=60.0),
    "looping": ht.HeavyTop(**BASE, theta0=1.0, theta_dot0=0.0, phi_dot0=-2.0, spin=40.0),
    "cusp": ht.HeavyTop(**BASE, theta0=0.7, theta_dot0=0.0, phi_dot0=0.0, spin=60.0),
    "negative spin": ht.HeavyTop(**BASE, theta0=0.7, theta_dot0=-0.4, phi_dot0=0.5, spin=-45.0),
    "below horizontal": ht.HeavyTop(**BASE, theta0=2.5, theta_dot0=-0.3, phi_dot0=2.0, spin=20.0),
    "from the pole": ht.HeavyTop(**BASE, theta0=0.0, theta_dot0=0.3, phi_dot0=0.0, spin=60.0),
}


def simulate_top(top, t, **inputs):
    return tumble.simulate(**top.simulation_inputs(**inputs), t=t, method="dop853", rtol=RTOL, atol=ATOL)


def standard_axes(top):
    """com (body axes) and g (inertial axes) of HeavyTop.simulation_inputs."""
    gravity = top.simulation_inputs()["torque"]
    return {"com": gravity.com, "g": gravity.g}


def periods(top, n):
    return np.linspace(0.0, n * top.nutation_period, n * SAMPLES_PER_PERIOD + 1)


# -- roots and conserved quantities -------------------------------------------------


@pytest.mark.parametrize("name", TOPS)
def test_roots_are_zeros_of_f_and_turning_points_of_the_effective_potential(name):
    top = TOPS[name]
    roots = np.array([top.u1, top.u2, top.u3])
    scale = abs(top.alpha) + top.beta + (abs(top.a) + abs(top.b)) ** 2
    assert np.abs(top.f(roots)).max() <= TOL_F_ROOT * scale
    assert -1.0 <= top.u1 <= math.cos(top.theta0) <= top.u2 <= 1.0 <= top.u3
    # E' = ½ I₁ θ̇² + V_eff(θ) off the poles (where V_eff is 0/0): at the start, and at the turning points.
    e_prime = top.energy - 0.5 * top.I3 * top.spin**2
    scale = abs(e_prime) + top.weight_torque
    checks = [(top.theta0, top.theta_dot0), (top.theta_min, 0.0), (top.theta_max, 0.0)]
    for theta, theta_dot in [(th, rate) for th, rate in checks if 0.0 < th < math.pi]:
        energy = 0.5 * top.I1 * theta_dot**2 + top.effective_potential(theta)
        assert abs(energy - e_prime) <= TOL_SAME_STATE * scale  # measured ≤ 1.5e-15


def test_conserved_quantities_from_the_euler_state_equal_those_of_the_simulation_state():
    top = TOPS["general"]
    inputs = top.simulation_inputs(phi0=0.4, psi0=-1.1)
    inertia, omega0, q0 = inputs["model"], inputs["omega0"], inputs["q0"]
    height = attitude.rotate(q0, [0.0, 0.0, top.length])[2]
    energy = dynamics.kinetic_energy(inertia, omega0) + top.mass * top.g * height
    p_phi = dynamics.angular_momentum_inertial(inertia, omega0, q0)[2]
    p_psi = dynamics.angular_momentum(inertia, omega0)[2]
    assert abs(top.energy - energy) <= TOL_SAME_STATE * abs(energy)
    assert abs(top.p_phi - p_phi) <= TOL_SAME_STATE * abs(p_psi)
    assert abs(top.p_psi - p_psi) <= TOL_SAME_STATE * abs(p_psi)
    back = ht.HeavyTop.from_simulation_state(inertia, top.mass, [0, 0, top.length], [0, 0, -top.g], omega0, q0)
    for name in ("I1", "I3", "mass", "length", "g", "theta0", "theta_dot0", "phi_dot0", "spin"):
        assert getattr(back, name) == pytest.approx(getattr(top, name), rel=TOL_SAME_STATE, abs=TOL_SAME_STATE)
    assert ht.HeavyTop.from_state(**BASE, theta0=0.6, theta_dot0=0.5, phi_dot0=-1.0, spin=60.0) == top


def rotated_setup(top, random_rotation):
    """The top described in random body axes B and random inertial axes N' (gravity along −R_N ẑ)."""
    r_body, r_inertial = random_rotation(1), random_rotation(2)        # v_S = R_b v_B; v_N' = R_n v_N
    inputs = top.simulation_inputs(phi0=0.3, psi0=0.7)
    q_sb, q_nn = attitude.from_matrix(r_body), attitude.from_matrix(r_inertial)
    return {
        "body": r_body.T @ inputs["model"] @ r_body,
        "com": r_body.T @ [0.0, 0.0, top.length],
        "g": r_inertial @ [0.0, 0.0, -top.g],
        "omega0": r_body.T @ inputs["omega0"],
        "q0": attitude.multiply(attitude.multiply(q_nn, inputs["q0"]), q_sb),
    }


def test_from_simulation_state_in_any_body_and_inertial_axes(random_rotation):
    top = TOPS["general"]
    s = rotated_setup(top, random_rotation)
    back = ht.HeavyTop.from_simulation_state(s["body"], top.mass, s["com"], s["g"], s["omega0"], s["q0"])
    for name in ("I1", "I3", "length", "g", "theta0", "theta_dot0", "phi_dot0", "spin"):
        assert getattr(back, name) == pytest.approx(getattr(top, name), rel=TOL_SAME_STATE, abs=TOL_SAME_STATE)
    # ... and the simulated motion in those axes follows the exact one.
    t = periods(top, 3)
    traj = tumble.simulate(s["body"], s["omega0"], q0=s["q0"], t=t, rtol=RTOL, atol=ATOL,
                           torque=tumble.torques.Gravity(top.mass, s["com"], s["g"]))
    motion = analytic.axis_motion(traj, com=s["com"], g=s["g"])
    assert np.abs(motion.u - top.u(t)).max() <= TOL_SIMULATED_U
    assert np.abs(motion.phi - motion.phi[0] - top.precession_angle(t)).max() <= TOL_SIMULATED_PHI


# -- the motion against tumble.simulate -----------------------------------------------


@pytest.mark.parametrize("name", TOPS)
def test_exact_motion_matches_simulation_over_several_periods(name):
    top = TOPS[name]
    t = periods(top, 5)
    motion = analytic.axis_motion(simulate_top(top, t, phi0=0.2, psi0=0.5), **standard_axes(top))
    assert np.abs(motion.u - top.u(t)).max() <= TOL_SIMULATED_U
    assert np.abs(motion.theta - top.theta(t)).max() <= TOL_SIMULATED_U / math.sin(max(top.theta_min, 1e-2))
    if top.theta_min > 0.0:  # φ is defined while the axis is off the vertical
        assert np.abs(motion.phi - motion.phi[0] - top.precession_angle(t)).max() <= TOL_SIMULATED_PHI
        rate = top.precession_rate(t)
        assert np.abs(motion.phi_dot - rate).max() <= TOL_SIMULATED_PHI * np.abs(rate).max()


@pytest.mark.parametrize("name", ["general", "looping", "cusp", "negative spin", "below horizontal"])
def test_nutation_bounds_and_period_match_refined_simulated_extremes(name):
    top = TOPS[name]
    measured = analytic.measure_nutation(simulate_top(top, periods(top, 10)), **standard_axes(top))
    assert measured.u_max.size >= 9 and measured.u_min.size >= 9
    assert np.abs(measured.u_max - top.u2).max() <= TOL_BOUNDS
    assert np.abs(measured.u_min - top.u1).max() <= TOL_BOUNDS
    assert abs(measured.period - top.nutation_period) <= TOL_PERIOD * top.nutation_period
    largest_rate = np.abs(top.precession_rate(np.linspace(0.0, top.nutation_period, 101))).max()
    assert abs(measured.mean_precession_rate - top.mean_precession_rate) <= TOL_PERIOD * largest_rate


@pytest.mark.parametrize("name", ["general", "looping", "cusp", "negative spin", "below horizontal"])
def test_mean_precession_rate_matches_quadrature_and_the_simulated_advance(name):
    top = TOPS[name]
    period = top.nutation_period
    by_quad = quad(top.precession_rate, 0.0, period, epsabs=0.0, epsrel=1e-13, limit=200)[0] / period
    assert abs(by_quad - top.mean_precession_rate) <= TOL_MEAN_QUAD * abs(top.mean_precession_rate)
    # φ(t + N T) − φ(t) = N T ⟨φ̇⟩ exactly: sample the simulation at multiples of T.
    n = 20
    t = np.concatenate([np.linspace(0.0, period, 50, endpoint=False) + k * period for k in range(n)] + [[n * period]])
    motion = analytic.axis_motion(simulate_top(top, t), **standard_axes(top))
    advance = motion.phi[-1] - motion.phi[0]
    assert abs(advance) >= 5.0
    assert abs(advance - n * period * top.mean_precession_rate) <= TOL_MEAN_SIMULATED * abs(advance)


def test_steady_precession_is_a_double_root_and_stays_at_its_angle():
    theta0, spin = 0.7, 60.0
    rates = ht.HeavyTop(**BASE, theta0=theta0, theta_dot0=0.0, phi_dot0=0.0, spin=spin).steady_precession_rates(theta0)
    for rate in rates:
        top = ht.HeavyTop(**BASE, theta0=theta0, theta_dot0=0.0, phi_dot0=rate, spin=spin)
        # The two rates solve I₁ cos θ φ̇² − I₃ ω₃ φ̇ + m g l = 0 (scaled residual to rounding).
        residual = top.I1 * math.cos(theta0) * rate**2 - top.p_psi * rate + top.weight_torque
        assert abs(residual) <= TOL_F_ROOT * top.p_psi * abs(rate)
        assert abs(top.u2 - top.u1) <= 4 * EPS  # the double root, without the √eps of a generic solver
        assert top.mean_precession_rate == pytest.approx(rate, rel=TOL_SAME_STATE)
        t = periods(top, 3)
        motion = analytic.axis_motion(simulate_top(top, t), **standard_axes(top))
        assert np.abs(motion.theta - theta0).max() <= TOL_SIMULATED_U
        assert np.abs(motion.phi - motion.phi[0] - rate * t).max() <= TOL_SIMULATED_PHI


# -- approximations for a fast top --------------------------------------------------------


def test_slow_precession_approximation_error_falls_like_inverse_spin_squared():
    # Released with θ̇ = φ̇ = 0: ⟨φ̇⟩ = Ω_slow (1 + I₁ m g l cos θ₀ / (I₃ω₃)² + O(ω₃⁻⁴)).
    spins = 100.0 * 2.0 ** np.arange(5)
    tops = [ht.HeavyTop(**BASE, theta0=0.7, theta_dot0=0.0, phi_dot0=0.0, spin=s) for s in spins]
    error = np.array([t.mean_precession_rate / t.slow_precession_rate - 1.0 for t in tops])
    ratio = error[:-1] / error[1:]
    assert np.all(np.abs(ratio[1:] - 4.0) <= 0.05)  # doubling ω₃ divides the error by 4 (measured 4.020 → 4.0004)
    leading = np.array([t.I1 * t.weight_torque * math.cos(t.theta0) / t.p_psi**2 for t in tops])
    assert abs(error[-1] / leading[-1] - 1.0) <= 1e-3  # the next term is O(ω₃⁻²) relative (measured 3e-5)
    # The nutation frequency tends to a = I₃ω₃/I₁, the fast steady precession to I₃ω₃/(I₁ cos θ₀).
    nutation = np.array([2.0 * np.pi / t.nutation_period / t.a - 1.0 for t in tops])
    assert np.all(np.abs(nutation[:-1] / nutation[1:] - 4.0) <= 0.1)
    fast = tops[-1].steady_precession_rates(0.7)[1] / tops[-1].fast_precession_rate - 1.0
    assert abs(fast) <= 2.0 * leading[-1]


# -- the sleeping top ----------------------------------------------------------------------


def test_critical_spin_and_the_upright_roots():
    top = ht.HeavyTop(**BASE, theta0=0.0, theta_dot0=0.0, phi_dot0=0.0, spin=1.0)
    critical = 2.0 * math.sqrt(BASE["I1"] * BASE["mass"] * BASE["g"] * BASE["length"]) / BASE["I3"]
    assert top.critical_spin == pytest.approx(critical, rel=4 * EPS)
    # Upright with no tilt rate: f(u) = (1 − u)² (β(1 + u) − a²), third root a²/β − 1.
    for factor, stable in ((1.25, True), (0.8, False)):
        top = ht.HeavyTop(**BASE, theta0=0.0, theta_dot0=0.0, phi_dot0=0.0, spin=factor * critical)
        assert top.is_sleeping_stable() is stable
        third = top.a**2 / top.beta - 1.0
        expected = [1.0, 1.0, third] if stable else [third, 1.0, 1.0]
        assert np.abs(np.array([top.u1, top.u2, top.u3]) - expected).max() <= 8 * EPS * max(1.0, third)


@pytest.mark.parametrize("factor", [1.25, 0.8])
def test_tilted_sleeping_top_stays_up_above_the_critical_spin_and_falls_below(factor):
    tilt = 1e-3  # rad
    top = ht.HeavyTop(**BASE, theta0=tilt, theta_dot0=0.0, phi_dot0=0.0, spin=factor * TOPS["cusp"].critical_spin)
    t = np.linspace(0.0, 2.5, 25001)  # 2.5 s: over ten nutation periods above, half a fall-and-return below
    motion = analytic.axis_motion(simulate_top(top, t), **standard_axes(top))
    if factor > 1.0:
        assert top.is_sleeping_stable() and top.theta_max <= 2.0 * tilt
        assert motion.theta.max() <= top.theta_max + TOL_SIMULATED_U  # stays near upright
    else:
        assert not top.is_sleeping_stable() and top.theta_max >= math.radians(60.0)
        assert motion.theta.max() >= math.radians(60.0)  # falls
        # Near the unstable upright position errors grow like e^{γt}; over one fall, measured 2.4e-12.
        assert np.abs(motion.u - top.u(t)).max() <= TOL_SIMULATED_U


# -- bad input ---------------------------------------------------------------------------------


@pytest.mark.parametrize("change, field", [
    (dict(mass=-1.0), "mass"),
    (dict(I1=0.0), "I1"),
    (dict(theta0=3.5), "theta0"),
    (dict(spin=float("nan")), "spin"),
    (dict(phi_dot0=[1.0, 2.0]), "phi_dot0"),
])
def test_heavy_top_refuses_bad_input(change, field):
    kwargs = dict(BASE, theta0=0.5, theta_dot0=0.0, phi_dot0=0.0, spin=10.0) | change
    with pytest.raises(ValidationError, match=field):
        ht.HeavyTop(**kwargs)


def test_from_simulation_state_refuses_a_body_not_symmetric_about_com():
    inertia = np.diag([0.02, 0.02, 0.01])
    with pytest.raises(ValidationError, match="axisymmetric about com"):
        ht.HeavyTop.from_simulation_state(inertia, 1.0, [0.1, 0.0, 0.0], [0, 0, -9.81], [0, 0, 1.0], [1, 0, 0, 0])
    with pytest.raises(ValidationError, match="com"):
        ht.HeavyTop.from_simulation_state(inertia, 1.0, [0.0, 0.0, 0.0], [0, 0, -9.81], [0, 0, 1.0], [1, 0, 0, 0])


# -- figure and demo ---------------------------------------------------------------------------


def test_top_figure_draws_three_panels_with_the_bounds():
    top = TOPS["looping"]
    fig = viz_top.top_figure(top)
    above, theta_panel, _ = fig.axes
    assert len(fig.axes) == 3
    levels = sorted(line.get_ydata()[0] for line in theta_panel.lines if line.get_linestyle() == "--")
    assert np.allclose(levels, np.degrees([top.theta_min, top.theta_max]), rtol=0.0, atol=1e-12)


def test_demo_top_writes_both_files_and_its_summary_agrees(tmp_path):
    summary = viz_top.demo_top(tmp_path, duration=0.6)
    traj = tumble.load(tmp_path / "top.nc")
    assert traj.t[-1] == pytest.approx(0.6, abs=0.0)
    assert (tmp_path / "top.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "top.html").read_text()[:15] == "<!DOCTYPE html>"  # the viewer's page
    assert sorted(p.name for p in tmp_path.iterdir()) == ["top.html", "top.nc", "top.png"]  # no temporary files
    # 500 samples per period: turning points to ~1e-10 deg, times to ~1e-9 T (see measure_nutation).
    assert abs(summary["theta_min_deg_measured"] - summary["theta_min_deg"]) <= 1e-7
    assert abs(summary["theta_max_deg_measured"] - summary["theta_max_deg"]) <= 1e-7
    assert summary["nutation_period_s_measured"] == pytest.approx(summary["nutation_period_s"], rel=1e-7)
    assert summary["mean_precession_rate_measured"] == pytest.approx(summary["mean_precession_rate"], rel=1e-7)
    assert summary["critical_spin"] < summary["spin"]


def test_demo_top_refuses_a_missing_directory(tmp_path):
    with pytest.raises(ValidationError, match="out_dir"):
        viz_top.demo_top(tmp_path / "missing")
