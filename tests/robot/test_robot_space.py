"""A two-link arm on a free hub (free-floating space manipulator) against an independent planar solution.

The independent solution: Lagrange's equations of the planar system (hub x, y, θ; joints q1, q2), written
from the positions of the three centres of mass, ``M(q) q̈ = Q − Σ mᵢ Jᵢᵀ J̇ᵢ q̇``, integrated by scipy's
DOP853. Tumble integrates the 3-D floating-base tree (Featherstone's floating-base ABA, quaternion attitude).
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import tumble
from tumble import robot

# The tests here compile or share the robot's kernels (tumble.kernels.featherstone and the chain model's
# integrators, ~50 CPU s on a cold Numba cache); the robot's modules run on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

HUB = dict(mass=50.0, inertia=np.diag([20.0, 25.0, 8.0]))
B, L1 = 0.5, 1.0  # mount offset on the hub (m), length of link 1 (m)
ARM = [dict(mass=4.0, c=0.5, I=0.4), dict(mass=2.0, c=0.4, I=0.15)]  # kg, m (com along the link), kg m² (z)
TAU = np.array([0.3, -0.2])  # constant joint torques, N m
STATE0 = dict(x=0.1, y=-0.2, theta=0.3, q1=0.4, q2=-0.6, xd=0.02, yd=-0.01, thetad=0.05, q1d=0.1, q2d=-0.2)
T = np.linspace(0.0, 3.0, 7)
# Both integrations at rtol = atol = 1e-13 over 3 s: their difference (measured ≤ 3e-12) is far below 1e-9,
# the criterion.
TOL = 1e-9
# Momentum: internal torques only, so exactly conserved; drift is the integrator's, measured ≤ 2e-14 relative.
MOMENTUM_TOL = 1e-12


def tumble_model():
    links = [robot.Link(joint="revolute", axis=(0, 0, 1), origin_position=(0.0, 0, 0), mass=ARM[0]["mass"],
                        com=(ARM[0]["c"], 0, 0), inertia=np.diag([0.01, ARM[0]["I"], ARM[0]["I"]]), name="shoulder"),
             robot.Link(joint="revolute", axis=(0, 0, 1), origin_position=(L1, 0, 0), mass=ARM[1]["mass"],
                        com=(ARM[1]["c"], 0, 0), inertia=np.diag([0.01, ARM[1]["I"], ARM[1]["I"]]), name="elbow")]
    hub = tumble.RigidBody(HUB["inertia"], mass=HUB["mass"])
    return robot.space_manipulator(hub, robot.SerialChain(links), mount_position=(B, 0, 0))


def planar_dynamics(mount, link1, masses, moments, coms):
    """Lagrange's equations of a planar hub + two links, q = (x, y, θ, q1, q2), by hand: the function
    ``(q, qd) -> (M(q), bias)`` with ``M q̈ = Q − bias``. ``mount`` the joint's offset on the hub along its x
    axis, ``link1`` the length of link 1 (m); ``masses``, ``moments`` (about z, at the centre of mass) and
    ``coms`` (along each link) of hub, link 1, link 2."""
    A = np.array([[0, 0, 1, 0, 0], [0, 0, 1, 1, 0], [0, 0, 1, 1, 1]], float)  # body angles ψ = A q
    a = np.array([[0, 0, 0], [mount, coms[1], 0], [mount, link1, coms[2]]])  # pᵢ = (x, y) + Σₖ aᵢₖ e(ψₖ)

    def dynamics(q, qd):
        psi, psid = A @ q, A @ qd
        e = np.array([np.cos(psi), np.sin(psi)])  # (2, 3)
        ep = np.array([-np.sin(psi), np.cos(psi)])
        M, bias = np.zeros((5, 5)), np.zeros(5)
        for i in range(3):
            J = np.zeros((2, 5))
            J[:, 0:2] = np.eye(2)
            J += (ep * a[i]) @ A  # ∂pᵢ/∂q
            Jdot_qd = -(e * a[i]) @ psid ** 2  # J̇ᵢ q̇ = −Σₖ aᵢₖ e(ψₖ) ψ̇ₖ²
            M += masses[i] * J.T @ J + moments[i] * np.outer(A[i], A[i])
            bias += masses[i] * J.T @ Jdot_qd
        return M, bias

    return dynamics


def planar_solution():
    """The planar equations of this file's hub and arm under the constant torques TAU, by scipy's DOP853."""
    dynamics = planar_dynamics(B, L1, [HUB["mass"], ARM[0]["mass"], ARM[1]["mass"]],
                               [HUB["inertia"][2, 2], ARM[0]["I"], ARM[1]["I"]], [0.0, ARM[0]["c"], ARM[1]["c"]])
    Q = np.array([0, 0, 0, *TAU])

    def rhs(_, y):
        M, bias = dynamics(y[:5], y[5:])
        return np.concatenate([y[5:], np.linalg.solve(M, Q - bias)])

    s = STATE0
    y0 = [s["x"], s["y"], s["theta"], s["q1"], s["q2"], s["xd"], s["yd"], s["thetad"], s["q1d"], s["q2d"]]
    return solve_ivp(rhs, (T[0], T[-1]), y0, method="DOP853", t_eval=T, rtol=1e-13, atol=1e-13).y.T


def test_space_manipulator_matches_the_planar_lagrangian_and_keeps_its_momentum():
    s = STATE0
    c, si = np.cos(s["theta"]), np.sin(s["theta"])
    v_world = np.array([s["xd"], s["yd"], 0.0])
    v_body = np.array([c * v_world[0] + si * v_world[1], -si * v_world[0] + c * v_world[1], 0.0])
    run = tumble.simulate(tumble_model(), q0=[s["q1"], s["q2"]], qd0=[s["q1d"], s["q2d"]],
                          base_position0=[s["x"], s["y"], 0.0],
                          base_q0=[np.cos(s["theta"] / 2), 0, 0, np.sin(s["theta"] / 2)],
                          base_omega0=[0, 0, s["thetad"]], base_velocity0=v_body, torque=TAU, t=T,
                          method="dop853", rtol=1e-13, atol=1e-13)
    expected = planar_solution()
    q = run.base_attitude
    theta = np.unwrap(2 * np.arctan2(q[:, 3], q[:, 0]))
    np.testing.assert_allclose(theta, expected[:, 2], rtol=0, atol=TOL)
    np.testing.assert_allclose(run.joint_position, expected[:, 3:5], rtol=0, atol=TOL)
    np.testing.assert_allclose(run.base_position[:, :2], expected[:, 0:2], rtol=0, atol=TOL)
    # the joint torques turn the hub: 3 s of its initial spin alone would give 0.15 rad, it turns 0.016 rad
    assert abs(theta[-1] - theta[0] - 3.0 * s["thetad"]) > 0.1
    for h in (run.angular_momentum, run.linear_momentum):
        np.testing.assert_allclose(h, np.broadcast_to(h[0], h.shape), rtol=0,
                                   atol=MOMENTUM_TOL * np.abs(h[0]).max())


def test_space_arm_demo_turns_the_hub_as_zero_momentum_requires(tmp_path):
    from scipy.interpolate import CubicHermiteSpline

    from tumble.viz import space_arm as demo

    summary = demo.demo_space_arm(tmp_path)
    run = tumble.load(tmp_path / "space_arm.nc")
    # started at rest with internal torques only: the total momentum stays zero; dop853 at rtol = atol =
    # 1e-11 on the arm's momenta of order 10 N m s, measured 8.7e-14 N m s and 4.6e-14 N s; bound 1e-11
    assert summary["max_angular_momentum"] <= 1e-11 and summary["max_linear_momentum"] <= 1e-11
    # the PD law brings the joints to the target, 2 s after the path ends: measured 2.3e-7 rad off; bound 1e-5
    np.testing.assert_allclose(run.joint_position[-1], demo.TARGET, rtol=0, atol=1e-5)
    # independently: zero momentum of the planar system (hub x, y, θ and the joints) gives the hub's rates from
    # the joints' (the generalised Jacobian): v_b = −M_bb⁻¹ M_bj q̇, integrated along the run's joint motion
    # (a cubic Hermite interpolant of its 501 samples of q and q̇: error O(h⁴), h = 0.02 s)
    dynamics = planar_dynamics(demo.MOUNT[0], demo.ARM[0]["length"],
                               [demo.HUB["mass"], demo.ARM[0]["mass"], demo.ARM[1]["mass"]],
                               [demo.HUB["inertia"][2, 2], demo.ARM[0]["inertia"], demo.ARM[1]["inertia"]],
                               [0.0, demo.ARM[0]["com"], demo.ARM[1]["com"]])
    joints = CubicHermiteSpline(run.t, run.joint_position, run.joint_velocity)

    def hub_rates(t, base):
        q, qd = np.concatenate([base, joints(t)]), np.concatenate([np.zeros(3), joints(t, 1)])
        M, _ = dynamics(q, qd)
        return -np.linalg.solve(M[:3, :3], M[:3, 3:] @ qd[3:])

    planar = solve_ivp(hub_rates, (run.t[0], run.t[-1]), np.zeros(3), method="DOP853", rtol=1e-12, atol=1e-12)
    # the hub turns -0.727 rad; measured difference 4.6e-11 rad (the interpolation of the joint motion, and the
    # two integrators' tolerances); bound 1e-8 rad
    assert summary["hub_rotation_rad"] < -0.5
    assert abs(planar.y[2, -1] - summary["hub_rotation_rad"]) <= 1e-8
