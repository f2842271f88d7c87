"""The segment model of a human body and the twisting somersault (tumble.variable.human, .diver)."""

from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.variable import diver
from tumble.variable.human import DE_LEVA_MALE, Human, Motion

HUMAN = Human.de_leva()
ARM_DROP = {"left_shoulder_abduction": Motion(np.pi, [(0.2, 0.6, 0.0)]), "right_shoulder_abduction": np.pi}


def test_de_leva_masses_sum_to_the_body_mass():
    # Table 4's mass fractions of the 14 segments sum to 1.0000 (head, trunk, 2 × (arm, forearm,
    # hand, thigh, shank, foot))
    fractions = [row[1] for row in DE_LEVA_MALE.values()]
    assert abs(fractions[0] + fractions[1] + 2 * sum(fractions[2:]) - 1.0) < 1e-12
    assert abs(Human.de_leva(mass=60.0).mass - 60.0) < 1e-12


def test_mirrored_motion_mirrors_inertia_and_shape_momentum():
    # the body is symmetric about its sagittal plane (x → −x): moving the right arm instead of the
    # left gives M I Mᵀ and det(M) M A with M = diag(−1, 1, 1) (A is an axial vector)
    t = np.linspace(0.0, 1.0, 11)
    left = HUMAN.kinematics(t, {"left_shoulder_abduction": Motion(0.0, [(0.1, 0.9, 2.5)]),
                                "left_hip_flexion": Motion(0.0, [(0.2, 0.7, 1.0)])})
    right = HUMAN.kinematics(t, {"right_shoulder_abduction": Motion(0.0, [(0.1, 0.9, 2.5)]),
                                 "right_hip_flexion": Motion(0.0, [(0.2, 0.7, 1.0)])})
    m = np.diag([-1.0, 1.0, 1.0])
    assert np.abs(right.inertia - m @ left.inertia @ m).max() < 1e-13
    assert np.abs(right.shape_momentum - (-1.0) * (left.shape_momentum @ m)).max() < 1e-13
    assert np.abs(left.shape_momentum).max() > 1.0   # the motion has real shape momentum (kg m²/s)


# Independent check of I(t) ω + A(t) and of the whole chain: from the simulated attitude and
# the segments' own motion, L_N = Σ [Rᵢ Jᵢ Rᵢᵀ Ωᵢ + mᵢ pᵢ × ṗᵢ] (inertial axes) with Ωᵢ and ṗᵢ from central
# differences (h = 1e-5 s) of the inertial segment attitudes and positions. It must equal the
# L_N held in the state. Measured relative errors 6.1e-10, 4.7e-10, 1.8e-9 (the O(h²) difference
# error; |A| reaches 9 kg m²/s = 11 % of |L| during the arm drop, so a wrong A would show).
FINITE_DIFFERENCE_TOL = 1e-7


def test_angular_momentum_from_segment_motion():
    h = 1e-5
    centres = np.array([0.35, 0.45, 0.55])
    t = np.concatenate([[0.0], np.sort(np.concatenate([centres - h, centres, centres + h]))])
    dive = diver.simulate_dive(HUMAN, ARM_DROP, momentum=80.0, t=t, rtol=1e-12, atol=1e-12, sample_dt=1e-3)
    kin = HUMAN.kinematics(t, ARM_DROP)
    R = attitude.to_matrix(dive.trajectory.q)                                   # (n, 3, 3) B → N
    seg_rot = R[:, None] @ kin.rotation                                          # (n, S, 3, 3)
    seg_pos = np.einsum("nij,nsj->nsi", R, kin.segment_com - kin.com[:, None])   # about the centre of mass
    masses = np.array([s.part.mass for s in HUMAN.segments])
    inertias = np.array([s.part.inertia for s in HUMAN.segments])
    for k in (1, 4, 7):   # the middle sample of each triplet is k + 1
        rot_dot = (seg_rot[k + 2] - seg_rot[k]) / (2 * h)
        spin = rot_dot @ np.swapaxes(seg_rot[k + 1], -1, -2)                      # [Ω]× in N axes
        omega = np.stack([spin[:, 2, 1], spin[:, 0, 2], spin[:, 1, 0]], axis=-1)
        vel = (seg_pos[k + 2] - seg_pos[k]) / (2 * h)
        inertia_n = seg_rot[k + 1] @ inertias @ np.swapaxes(seg_rot[k + 1], -1, -2)
        momentum = (np.einsum("sij,sj->i", inertia_n, omega)
                    + np.einsum("s,si->i", masses, np.cross(seg_pos[k + 1], vel)))
        assert np.linalg.norm(momentum - [80.0, 0.0, 0.0]) < FINITE_DIFFERENCE_TOL * 80.0


def test_orientation_angles_invert_the_somersault_tilt_twist_sequence():
    # build R = R_x(φ) R_y(θ) R_z(ψ) from known, growing angles and read them back (unwrapped)
    t = np.linspace(0.0, 1.0, 200)
    phi, theta, psi = 9.0 * t, 0.3 * np.sin(3.0 * t), 20.0 * t
    q = attitude.from_euler("XYZ", np.column_stack([phi, theta, psi]))
    got = diver.orientation_angles(q, [1.0, 0.0, 0.0])
    assert np.abs(got.somersault - phi).max() < 1e-12
    assert np.abs(got.tilt - theta).max() < 1e-12
    assert np.abs(got.twist - psi).max() < 1e-12
    assert abs(got.somersaults - 9.0 / (2 * np.pi)) < 1e-12 and abs(got.twists - 20.0 / (2 * np.pi)) < 1e-12


# After the arm has dropped (it stops at 0.6 s) the diver is rigid: the variable-body motion must
# continue exactly as tumble.simulate's rigid body with inertia I(0.6 s) from the same state.
# Both dop853 at rtol = atol = 1e-12 over 1.3 s; measured differences 4.3e-12 (q), 5.9e-11 rad/s (ω).
RIGID_CONTINUATION_TOL = 1e-9


def test_twisting_somersault():
    dive = diver.twisting_somersault(duration=2.0, n=201)
    traj, angles = dive.trajectory, dive.angles
    # a pure somersault before the arm moves (at 0.2 s): no tilt, no twist. (The cubic spline is
    # not local: the move leaks a ripple that decays by 2 − √3 per 2 ms sample before it,
    # measured 1.5e-8 rad at 0.2 s and 2e-14 at 0.18 s; 0.15 s is well clear of it.)
    before = traj.t <= 0.15
    assert np.abs(angles.tilt[before]).max() < 1e-12 and np.abs(angles.twist[before]).max() < 1e-12
    # then it twists, with L conserved to rounding
    assert abs(dive.twists) > 2.0
    assert dive.momentum_drift < 1e-12
    # and the flight after the arm drop is the rigid body's (from 0.7 s: clear of the spline's ripple)
    variable = diver.simulate_dive(HUMAN, ARM_DROP, momentum=diver.MOMENTUM, t=traj.t, rtol=1e-12, atol=1e-12)
    v = variable.trajectory
    k = int(np.flatnonzero(v.t >= 0.7)[0])
    rigid = tumble.simulate(v.extras["inertia_t"].data[k], v.omega[k], q0=v.q[k], t=v.t[k:], rtol=1e-12, atol=1e-12)
    assert np.abs(rigid.q - v.q[k:]).max() < RIGID_CONTINUATION_TOL
    assert np.abs(rigid.omega - v.omega[k:]).max() < RIGID_CONTINUATION_TOL


# The rule of thumb sin θ (I_s/I_l − 1) is exact for an axisymmetric body (measured agreement
# 4.4e-11 over 20 s, dop853 at rtol = 1e-11) ...
AXISYMMETRIC_TOL = 1e-9
# ... and for the de Leva layout (I_x = 12.09, I_y = 12.36, I_z = 0.90 kg m²) within 3 % for
# tilts of 10°–20°: measured +2.6 %, +1.8 %, +1.6 % at 10°, 15°, 20°. (Below ~5° it fails: the
# somersault axis is the intermediate axis, and at 2° the simulation twists 28 % more.)
RULE_TOL = 0.03


def test_twist_rule_of_thumb():
    sweep = diver.twist_rule_sweep(np.radians([10.0, 15.0, 20.0]), duration=20.0, n=401)
    assert np.abs(sweep["axisymmetric"] / sweep["rule"] - 1.0).max() < AXISYMMETRIC_TOL
    assert np.abs(sweep["simulated"] / sweep["rule"] - 1.0).max() < RULE_TOL


def test_bad_joint_angles_are_refused():
    with pytest.raises(tumble.ValidationError, match=r"angles: unknown joint angles \['left_wrist'\]"):
        HUMAN.kinematics([0.0], {"left_wrist": 1.0})
    with pytest.raises(tumble.ValidationError, match="moves\\[1\\]: must be"):
        Motion(0.0, [(0.0, 1.0, 1.0), (0.5, 2.0, 0.0)])


def test_documented_example_prints_what_it_claims(capsys):
    text = (Path(__file__).resolve().parents[1] / "docs" / "diver.md").read_text(encoding="utf-8")
    start = text.index("```python") + len("```python")
    exec(compile(text[start:text.index("```", start)], "diver.md", "exec"), {})  # the project's own text
    somersaults, twists, drift = (float(x) for x in capsys.readouterr().out.split())
    assert round(somersaults, 2) == 1.76 and round(twists, 2) == 2.99 and drift < 1e-12
