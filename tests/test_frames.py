"""The axisymmetric body integrated in a principal frame (tumble.axisymmetric, tumble.dynamics.euler_frame).

Compiled specialisations kept to four: the frame model with dop853, torque-free and with the heavy-top
gravity torque, and its references, the rigid model's closed form ("exact", torque-free) and dop853 with
gravity (both also compiled by the rigid-body tests).
"""

import numpy as np
import pytest

import tumble
from tumble import attitude, dynamics
from tumble.analytic import HeavyTop, axis_motion, measure_nutation
from tumble.axisymmetric import AxisymmetricBody

# A projectile-like prolate body (I_s/I_t = 0.2) described in tilted body axes, so that the symmetry axis is
# none of them: the frame model must find it (the prolate case cycles the principal axes).
_TILT = attitude.from_rotvec([0.3, -0.5, 0.2])
_PROLATE = tumble.RigidBody(np.diag([0.2, 1.0, 1.0]), mass=3.0).rotated(_TILT)
_SPIN = 50.0  # rad/s about the symmetry axis
_PERIOD = 2.0 * np.pi / _SPIN
# 2 degrees of nutation: the transverse rate is 0.035 I_s/I_t of the spin
_OMEGA0 = attitude.rotate_inverse(_TILT, [_SPIN, 0.35, -0.2])
_Q0 = attitude.normalize([0.9, 0.1, -0.3, 0.2])


def _difference(traj, reference):
    """Largest |Δq| (same hemisphere) and |Δω| / |ω|."""
    sign = np.sign(np.sum(traj.q * reference.q, axis=-1))[..., None]
    scale = np.linalg.norm(reference.omega, axis=-1).max()
    return np.abs(traj.q * sign - reference.q).max(), np.abs(traj.omega - reference.omega).max() / scale


def test_frame_equations_are_euler_equations_seen_from_a_turning_frame():
    # Independent check: for F turning at Ω₃, ω_F = R_z(ψ) ω_P with ψ̇ = ω₃ − Ω₃, so
    # dω_F/dt = R_z(ψ) ω̇_P + ψ̇ R_z'(ψ) ω_P with ω̇_P from the principal-axes equations (I₁ = I₂ = I_t).
    rng = np.random.default_rng(7)
    i_t, i_s = 1.3, 0.4
    for _ in range(20):
        omega_p, torque_p = rng.normal(size=3) * 5.0, rng.normal(size=3)
        psi, frame_rate = rng.uniform(-np.pi, np.pi), rng.normal() * 3.0
        c, s = np.cos(psi), np.sin(psi)
        rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        drz = np.array([[-s, -c, 0.0], [c, -s, 0.0], [0.0, 0.0, 0.0]])
        rates_p = dynamics.omega_dot_principal([i_t, i_t, i_s], omega_p, torque_p)
        expected = rz @ rates_p + (omega_p[2] - frame_rate) * drz @ omega_p
        got = dynamics.omega_dot_frame([i_t, i_s], rz @ omega_p, frame_rate, rz @ torque_p)
        # a few roundings of terms of size |ω|² ≈ 100
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    # the body's own axes (Ω₃ = ω₃): exactly the principal-axes form
    omega = np.array([0.3, -1.2, 7.0])
    np.testing.assert_allclose(dynamics.omega_dot_frame([i_t, i_s], omega, omega[2]),
                               dynamics.omega_dot_principal([i_t, i_t, i_s], omega), rtol=1e-15, atol=1e-15)


@pytest.mark.slow  # compiles dop853 for the axisymmetric frame model (~3 CPU s on a cold cache)
def test_torque_free_equals_the_closed_form_over_1000_spin_periods():
    # The reference is the body-frame closed form (method "exact", rounding-level at any time); dop853 in the
    # body frame itself drifts by ~1e-11 over 6283 rad of spin (the rounding of ~3e4 steps), so it would not
    # resolve the bound. The frame model at rtol = atol = 1e-14 (rtol at 1e-13 leaves ~4e-11 of truncation).
    t = np.linspace(0.0, 1000 * _PERIOD, 11)
    frame = tumble.simulate(AxisymmetricBody(_PROLATE), _OMEGA0, q0=_Q0, t=t, rtol=1e-14, atol=1e-14)
    exact = tumble.simulate(_PROLATE, _OMEGA0, q0=_Q0, t=t, method="exact")
    dq, dw = _difference(frame, exact)
    assert dq < 1e-11 and dw < 1e-11, (dq, dw)
    assert np.all(np.abs(frame.spin_angle) <= np.pi)
    np.testing.assert_allclose(np.linalg.norm(frame.frame_attitude, axis=-1), 1.0, rtol=0, atol=1e-15)


@pytest.mark.parametrize("frame_spin", [1.0, 0.37, -2.0])
@pytest.mark.slow  # compiles dop853 for the axisymmetric frame model (~3 CPU s on a cold cache)
def test_any_frame_rate_about_the_axis_gives_the_same_motion(frame_spin):
    # κ = 1: the body's own axes (ψ stays 0); any other κ only moves the split between q_NF and ψ.
    t = np.linspace(0.0, 20 * _PERIOD, 5)
    frame = tumble.simulate(AxisymmetricBody(_PROLATE, frame_spin=frame_spin), _OMEGA0, q0=_Q0, t=t,
                            rtol=1e-13, atol=1e-13)
    exact = tumble.simulate(_PROLATE, _OMEGA0, q0=_Q0, t=t, method="exact")
    dq, dw = _difference(frame, exact)
    assert dq < 1e-12 and dw < 1e-12, (dq, dw)  # 20 spin periods at rtol 1e-13: ~1e-13 measured
    if frame_spin == 1.0:
        assert np.all(frame.spin_angle == 0.0)


# A heavy top (inertia about the pivot), I_s/I_t = 0.1: released at rest in θ and φ at 40° with 1.8× its
# critical spin: it nutates between 40.1° and 47.1° while precessing.
_TOP = HeavyTop.from_state(I1=0.02, I3=0.002, mass=1.0, length=0.1, g=9.81, theta0=0.7, theta_dot0=0.0,
                           phi_dot0=0.0, spin=250.0)


def _top_runs(t, rtol):
    inputs = _TOP.simulation_inputs(phi0=0.3, psi0=1.1)
    body = tumble.RigidBody(inputs.pop("model"))
    frame = tumble.simulate(AxisymmetricBody(body), **inputs, t=t, rtol=rtol, atol=rtol)
    return frame, (body, inputs)


@pytest.mark.slow  # compiles dop853 for the axisymmetric frame model under a torque (~3 CPU s on a cold cache)
def test_heavy_top_equals_the_body_frame_simulation_over_1000_spin_periods():
    period = 2.0 * np.pi / _TOP.spin
    t = np.linspace(0.0, 1000 * period, 11)
    frame, (body, inputs) = _top_runs(t, 1e-14)
    # Both at rtol = atol = 1e-14. The body frame takes 5.2e4 steps (47 per spin period) and the frame model
    # 5.0e3: against the exact attitude (Euler angles, ψ by quadrature) each is off by up to ~6e-12 after
    # 6283 rad of spin, the floor of float64 stepping (rtol 1e-15 takes more steps and does no better; 1e-13
    # adds truncation). Measured difference 6.2e-12: the bound of 1e-11 has little margin, and cannot have more.
    reference = tumble.simulate(body, **inputs, t=t, rtol=1e-14, atol=1e-14)
    dq, dw = _difference(frame, reference)
    assert dq < 1e-11 and dw < 1e-11, (dq, dw)
    motion = axis_motion(frame, com=[0, 0, _TOP.length], g=[0, 0, -_TOP.g])
    assert np.abs(motion.u - _TOP.u(t)).max() < 1e-10


@pytest.mark.slow  # compiles dop853 for the axisymmetric frame model under a torque (~5 CPU s on a cold cache)
def test_heavy_top_nutation_bounds_are_the_exact_ones():
    # 2000 samples per nutation period: the parabola through three samples locates a turning point to
    # (2λh)⁴/48 (u₂ − u₁) ≈ 1e-16 (docs/heavy_top.md), far below the 1e-10 asked
    t = np.linspace(0.0, 4 * _TOP.nutation_period, 8001)
    frame, _ = _top_runs(t, 1e-13)
    motion = axis_motion(frame, com=[0, 0, _TOP.length], g=[0, 0, -_TOP.g])
    assert _TOP.u1 - 1e-10 <= motion.u.min() and motion.u.max() <= _TOP.u2 + 1e-10
    measured = measure_nutation(frame, com=[0, 0, _TOP.length], g=[0, 0, -_TOP.g])
    assert measured.u_min.size >= 3 and measured.u_max.size >= 3
    assert np.abs(measured.u_min - _TOP.u1).max() < 1e-10
    assert np.abs(measured.u_max - _TOP.u2).max() < 1e-10


def test_bad_input_is_refused_with_a_named_rule():
    with pytest.raises(tumble.ValidationError, match="body: must be axisymmetric") as err:
        AxisymmetricBody(tumble.RigidBody(np.diag([1.0, 2.0, 2.5])))
    assert err.value.field == "body"
    with pytest.raises(tumble.ValidationError, match="body: must be a tumble.RigidBody"):
        AxisymmetricBody(np.diag([1.0, 1.0, 2.0]))
    with pytest.raises(tumble.ValidationError, match="frame_spin: must be a number"):
        AxisymmetricBody(_PROLATE, frame_spin=[0.0, 1.0])
    with pytest.raises(tumble.ValidationError, match="method: 'cf4' needs"):
        tumble.simulate(AxisymmetricBody(_PROLATE), _OMEGA0, t=[0.0, 1.0], method="cf4", dt=0.1)
