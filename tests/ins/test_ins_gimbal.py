"""The gyro rotor in a two-axis gimbal with gimbal inertia (tumble.ins.gimbal)."""

import math

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.ins import GimbaledGyro, Gyroscope
from tumble._validate import ValidationError

# Every test here compiles this model kind's integrators on a cold Numba cache (several CPU s each).
pytestmark = pytest.mark.slow

# With massless gimbals the Lagrange equations are the heavy top's: the rotor must move as the
# free gyro simulated by tumble.simulate. Both run dop853 at rtol = atol = 1e-12; measured
# 1.3e-13 rad (attitude) and 3.9e-14 rad/s (rate) over 0.5 s.
HEAVY_TOP_TOL = 1e-10
# Released at rest, horizontal, under the inner-axis torquer: the mean precession over whole
# nutation periods is τ_θ/(I_s ω₃) to O(ε²) with ε = τ I/(I_s ω₃)² ≈ 3e-5 (measured −3.6e-9);
# the tolerance for the precession law.
PRECESSION_RTOL = 1e-6
# Nutation frequency with gimbal inertia vs its linearisation I_s ω₃/√((A + I_t)(J + B + I_t)):
# measured −1.9e-6 at ε = 7.4e-4 (an O(ε²) effect, as for the free rotor), from θ minima located
# by a parabola through three samples (400 per period).
NUTATION_RTOL = 1e-5

ROTOR = dict(spin_inertia=2e-3, transverse_inertia=1.5e-3)
GIMBALS = dict(inner_gimbal=(4e-4, 5e-4, 3e-4), outer_gimbal=1e-3)
TIGHT = dict(rtol=1e-12, atol=1e-12)


@pytest.mark.slow  # the first simulation compiles dop853 for the gimbal model (~20 s cold)
def test_massless_gimbals_reduce_to_the_free_gyro():
    free = Gyroscope(spin=100.0, mass=0.1, offset=0.02, **ROTOR)
    t = np.linspace(0.0, 0.5, 501)
    reference = tumble.simulate(free, t=t, **TIGHT)
    motion = tumble.simulate(GimbaledGyro(imbalance=free.imbalance_torque, **ROTOR), t=t, spin=100.0, **TIGHT)
    assert attitude.relative_angle(motion.q, reference.q).max() < HEAVY_TOP_TOL
    np.testing.assert_allclose(motion.omega, reference.omega, rtol=0, atol=HEAVY_TOP_TOL)
    # and so is its energy, the kinetic energy of the rotor plus m g l cos θ (measured 2e-16 relative)
    np.testing.assert_allclose(motion.energy, reference.energy, rtol=HEAVY_TOP_TOL, atol=0)


def test_precession_under_the_inner_torquer_with_gimbal_inertia():
    gyro = GimbaledGyro(inner_torque=0.0196, **ROTOR, **GIMBALS)
    spin = 500.0
    period = 2 * math.pi / gyro.nutation_frequency(spin)
    t = np.linspace(0.0, 200 * period, 200 * 40 + 1)
    released = tumble.simulate(gyro, t=t, spin=spin, **TIGHT)
    rate = (released.phi[-1] - released.phi[0]) / t[-1]
    assert rate == pytest.approx(0.0196 / (2e-3 * spin), rel=PRECESSION_RTOL)
    steady = tumble.simulate(gyro, t=t[:2001], spin=spin, phi_dot0=gyro.precession_rate(spin), **TIGHT)
    # exact steady precession: measured 8e-15 relative, tilt constant to 7e-16 rad
    assert np.polyfit(steady.t, steady.phi, 1)[0] == pytest.approx(gyro.precession_rate(spin), rel=1e-10)
    assert np.ptp(steady.theta) < 1e-12


def test_gimbal_inertia_slows_the_nutation():
    gyro = GimbaledGyro(inner_torque=0.0196, **ROTOR, **GIMBALS)
    spin = 100.0
    predicted = gyro.nutation_frequency(spin)
    assert predicted == pytest.approx(2e-3 * spin / math.sqrt((4e-4 + 1.5e-3) * (1e-3 + 5e-4 + 1.5e-3)), rel=1e-15)
    period = 2 * math.pi / predicted
    t = np.linspace(0.0, 20 * period, 20 * 400 + 1)
    theta = tumble.simulate(gyro, t=t, spin=spin, **TIGHT).theta
    k = np.flatnonzero((theta[1:-1] < theta[:-2]) & (theta[1:-1] <= theta[2:])) + 1
    offset = 0.5 * (theta[k - 1] - theta[k + 1]) / (theta[k - 1] - 2 * theta[k] + theta[k + 1])
    minima = t[k] + offset * (t[1] - t[0])
    assert np.diff(minima).mean() == pytest.approx(period, rel=NUTATION_RTOL)


def test_bearing_friction_drift_with_gimbal_inertia():
    # Viscous spin-bearing friction c_s, started in steady precession with the axis horizontal:
    # ψ̇ = ω₃ there, so I_s ω̇₃ = −c_s ω₃ and ω₃ = ω₀ exp(−c_s t/I_s); the axis follows the
    # slowing spin adiabatically, φ̇ = τ_θ/(I_s ω₃(t)), so φ(t) = τ_θ/(c_s ω₀) (exp(c_s t/I_s) − 1).
    # Measured over 100 s (500 → 452 rad/s): spin 1.5e-11 relative, azimuth 4.9e-10 rad of 2.06 rad.
    tau, spin, c_s = 0.0196, 500.0, 2e-6
    gyro = GimbaledGyro(inner_torque=tau, spin_friction=c_s, **ROTOR, **GIMBALS)
    t = np.linspace(0.0, 100.0, 4001)
    motion = tumble.simulate(gyro, t=t, spin=spin, phi_dot0=gyro.precession_rate(spin), **TIGHT)
    I_s = ROTOR["spin_inertia"]
    np.testing.assert_allclose(motion.spin, spin * np.exp(-c_s * t / I_s), rtol=1e-9)
    phi = tau / (c_s * spin) * np.expm1(c_s * t / I_s)
    np.testing.assert_allclose(motion.phi, phi, rtol=0, atol=1e-8 * phi[-1])
    # Viscous friction c_φ on the outer (vertical) axis opposes the precession with c_φ φ̇; the
    # gyroscopic law turns that torque into a tilt θ̇ = c_φ φ̇/(I_s ω₃) (the axis sinks below the
    # horizontal). Measured over 10 s: 2.3e-7 relative (the 0.2 mrad tilt changes sin θ).
    c_phi = 1e-3
    gyro = GimbaledGyro(inner_torque=tau, outer_friction=c_phi, **ROTOR, **GIMBALS)
    t = np.linspace(0.0, 10.0, 2001)
    motion = tumble.simulate(gyro, t=t, spin=spin, phi_dot0=gyro.precession_rate(spin), **TIGHT)
    tilt_rate = np.polyfit(t, motion.theta, 1)[0]
    assert tilt_rate == pytest.approx(c_phi * gyro.precession_rate(spin) / (I_s * spin), rel=1e-5)


def test_gimbaled_gyro_validation():
    with pytest.raises(ValidationError, match="inner_gimbal"):
        GimbaledGyro(inner_gimbal=(1.0, -1.0, 0.0), **ROTOR)
    with pytest.raises(ValidationError, match="spin"):
        tumble.simulate(GimbaledGyro(**ROTOR), t=[0.0, 1.0], spin=0.0)
    with pytest.raises(ValidationError, match="spin: a GimbaledGyro needs it"):
        tumble.simulate(GimbaledGyro(**ROTOR), t=[0.0, 1.0])
    with pytest.raises(ValidationError, match="torque: a GimbaledGyro takes no torque argument"):
        tumble.simulate(GimbaledGyro(**ROTOR), t=[0.0, 1.0], spin=1.0, torque=lambda t, q, omega: [0.0, 0.0, 0.0])


# E = ½ P θ̇² + ½ Q(θ) φ̇² + ½ I_s ω₃² + m g l cos θ and p_φ = Q φ̇ + I_s ω₃ cos θ (module docstring), with gimbal
# inertia and an imbalance, from a generic start (θ₀ = 1 rad, φ̇₀ = 0.3 rad/s, θ̇₀ = −0.2 rad/s): conserved
# without torquers and friction. dop853 at rtol = atol = 1e-12 over 0.5 s: measured 2.2e-16 (E) and 6.9e-15
# (p_φ) relative; a batch of two spins. E at the start by hand: measured equal.
GIMBAL_INVARIANT_TOL = 1e-12


def test_energy_and_vertical_momentum_of_rotor_and_gimbals_are_conserved():
    gyro = GimbaledGyro(imbalance=0.01, **ROTOR, **GIMBALS)
    t = np.linspace(0.0, 0.5, 501)
    traj = tumble.simulate(gyro, t=t, spin=[[100.0], [200.0]], theta0=1.0, phi_dot0=0.3, theta_dot0=-0.2, **TIGHT)
    # E at the start, by hand: P = A + I_t, Q(1 rad) = J + (B + I_t) sin²1 + C cos²1
    P, Q = 4e-4 + 1.5e-3, 1e-3 + (5e-4 + 1.5e-3) * math.sin(1.0) ** 2 + 3e-4 * math.cos(1.0) ** 2
    e0 = 0.5 * P * 0.2**2 + 0.5 * Q * 0.3**2 + 0.5 * 2e-3 * np.array([100.0, 200.0]) ** 2 + 0.01 * math.cos(1.0)
    np.testing.assert_allclose(traj.energy[0], e0, rtol=1e-14)   # the same terms in another order: rounding
    kept = gyro.invariants(traj)
    assert kept.keys() == {"energy", "momentum_vertical"}
    for value in kept.values():
        assert np.abs(value / value[0] - 1.0).max() < GIMBAL_INVARIANT_TOL
    # the batch members are the single runs, spin given as a plain number
    one = tumble.simulate(gyro, t=t, spin=200.0, theta0=1.0, phi_dot0=0.3, theta_dot0=-0.2, **TIGHT)
    np.testing.assert_array_equal(one.phi, traj.phi[:, 1])
    # the inner torquer works on θ: E changes, p_φ stays; outer friction: neither is kept
    torqued = GimbaledGyro(inner_torque=0.0196, **ROTOR, **GIMBALS)
    assert torqued.invariants(tumble.simulate(torqued, t=t[:3], spin=100.0)).keys() == {"momentum_vertical"}
    rubbed = GimbaledGyro(outer_friction=1e-3, **ROTOR, **GIMBALS)
    assert rubbed.invariants(tumble.simulate(rubbed, t=t[:3], spin=100.0)) == {}

