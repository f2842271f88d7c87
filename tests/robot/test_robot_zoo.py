"""Every URDF of example-robot-data loads (issue 34), with each repair of non-physical data named; a sample of
them, iCub, TIAGo and Romeo included, against Pinocchio's RNEA, CRBA and gravity torques.

Pinocchio (PyPI ``pin``) and ``example-robot-data`` are in the ``test`` extra. Loading is parsing only; the
compiled dynamics are compiled once for all robots (a robot is arrays), so the sample adds little time.
"""

import warnings

import numpy as np
import pytest

import tumble
from robot_oracle import ERD, Pair, close
from tumble import ValidationError, robot
from tumble.robot.urdf import UrdfRepairWarning

# The tests here compile or share the robot's kernels (~30 CPU s on a cold Numba cache); the robot's modules run
# on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

pin = pytest.importorskip("pinocchio")

URDFS = sorted(str(p.relative_to(ERD)) for p in ERD.rglob("*.urdf"))

# What a URDF needs beyond the defaults, and why.
OPTIONS = {
    # 1 mg antennas whose tensors have a negative principal moment (-3.5e-8 kg m^2): not round-off
    "tiago_description/robots/tiago.urdf": dict(inertia="clip"),
    "tiago_description/robots/tiago_dual.urdf": dict(inertia="clip"),
    "tiago_description/robots/tiago_no_hand.urdf": dict(inertia="clip"),
    # the torso 'body' and both hip-pitch links have a negative principal moment (-0.021 kg m^2 for 'body')
    "romeo_description/urdf/romeo_laas_small.urdf": dict(inertia="clip"),
    # single bodies without joints: free bodies
    "hector_description/robots/quadrotor_base.urdf": dict(floating_base=True),
    "iris_description/robots/iris_simple.urdf": dict(floating_base=True),
    # its hands' <mimic joint="index_q1"> name joints called 'Left_index_q1' and 'Right_index_q1'
    "alex_description/urdf/alex_psyonic_hands.urdf": dict(mimic=False),
}
# The repaired links of each URDF (its warning names each of them).
REPAIRED = {
    "icub_description/robots/icub.urdf": ["l_ankle_2", "r_hip_2", "r_upper_leg", "r_lower_leg", "r_ankle_2", "head"],
    "icub_description/robots/icub_reduced.urdf": ["l_ankle_2", "r_hip_2", "r_upper_leg", "r_lower_leg", "r_ankle_2",
                                                  "head"],
    **{name: ["base_antenna_left_link", "base_antenna_right_link"] for name in OPTIONS if "tiago_desc" in name},
    "romeo_description/urdf/romeo_laas_small.urdf": ["body", "LHipPitch_link", "RHipPitch_link"],
}
# Joints that move only massless links (no <inertial>): Romeo's hands, each finger joint (read as joints, the
# fingers' mimic joints too), and the grippers of romeo_laas_small.
MASSLESS = {"romeo_description/urdf/romeo.urdf":
            tuple(f"{side}{joint}" for side in "LR" for joint in ("Hand", "Finger12", "Finger13", "Finger21",
                  "Finger22", "Finger23", "Finger31", "Finger32", "Finger33", "Thumb1", "Thumb2", "Thumb3")),
            "romeo_description/urdf/romeo_laas_small.urdf": ("l_gripper_joint", "r_gripper_joint")}
# The installed ur3.urdf is an empty <robot> (what xacro left): Pinocchio refuses it too.
EMPTY = {"ur_description/urdf/ur3.urdf"}


def test_the_zoo_is_the_installed_example_robot_data():
    assert len(URDFS) == 69


def _load(name, **extra):
    return robot.RobotTree.from_urdf(ERD / name, check_triangle=False, **{**OPTIONS.get(name, {}), **extra})


@pytest.mark.parametrize("name", sorted(set(URDFS) - EMPTY))
def test_every_urdf_loads_and_names_its_repairs(name):
    """Loaded with its options; the warning names every repaired link and nothing else warns; the joints and
    the mass of the moving bodies are Pinocchio's (its parser reads mimic joints as joints, so tumble too, here)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UrdfRepairWarning)
        tree = _load(name, mimic=False)
    messages = [str(w.message) for w in caught if issubclass(w.category, UrdfRepairWarning)]
    repaired = [m for m in messages if "inertia repaired" in m]
    if name in REPAIRED:
        assert len(repaired) == 1
        for link in REPAIRED[name]:
            assert f"link {link!r} <inertial> <inertia>: principal moment" in repaired[0]
        assert repaired[0].count("set to 0 by") == len(REPAIRED[name])
    else:
        assert not repaired
    assert tree.massless_joints == MASSLESS.get(name, ())
    assert len(messages) == len(repaired) + bool(tree.massless_joints)
    floating = OPTIONS.get(name, {}).get("floating_base", False)
    model = pin.buildModelFromUrdf(str(ERD / name), *((pin.JointModelFreeFlyer(),) if floating else ()))
    assert tree.nv == model.nv
    assert sorted(tree.joint_names) == sorted(model.names[j] for j in range(1, model.njoints)
                                              if model.joints[j].nv == 1)
    # the fixed base's own links carry no motion in tumble; Pinocchio counts them in the universe's mass
    moving_mass = sum(model.inertias[j].mass for j in range(1, model.njoints))
    assert tree.mass == pytest.approx(moving_mass, rel=1e-12)


def test_an_empty_robot_is_refused_as_empty():
    with pytest.raises(ValidationError, match=r"^ur3\.urdf: <robot> has no <link> element; a robot needs at least "
                                              r"one link$"):
        robot.RobotTree.from_urdf(ERD / "ur_description/urdf/ur3.urdf")


@pytest.mark.parametrize("name, message", [
    ("tiago_description/robots/tiago.urdf",
     r"^link 'base_antenna_left_link' <inertial> <inertia>: must be positive semi-definite \(principal moments "
     r"\[-3\.53485.*e-08, .*\] kg m\^2\); inertia='clip' sets its negative principal moments to zero$"),
    ("hector_description/robots/quadrotor_base.urdf",
     r"^quadrotor_base\.urdf: no revolute, continuous or prismatic joint: nothing moves on a fixed base \(for a "
     r"single free body, a quadrotor, pass floating_base=True\)$"),
    ("alex_description/urdf/alex_psyonic_hands.urdf",
     r"^joint 'Left_index_q2' <mimic>: joint='index_q1' names no joint of the robot \(mimic=False reads"),
])
def test_without_its_option_a_urdf_is_refused_naming_the_option(name, message):
    with pytest.raises(ValidationError, match=message):
        robot.RobotTree.from_urdf(ERD / name, check_triangle=False)


# (URDF, floating base): iCub (round-off clipped), TIAGo (antennas clipped: fixed to the fixed base, so without
# effect on the joints), Romeo (massless fingers: M singular), a quadrotor (one free body), PR2 (continuous
# joints), Unitree G1 with hands (floating humanoid), Kinova (continuous joints).
SAMPLE = [
    ("icub_description/robots/icub.urdf", False),
    ("tiago_description/robots/tiago.urdf", False),
    ("romeo_description/urdf/romeo.urdf", False),
    ("hector_description/robots/quadrotor_base.urdf", True),
    ("pr2_description/urdf/pr2.urdf", False),
    ("g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf", True),
    ("kinova_description/robots/kinova.urdf", False),
]
# Two implementations of the same algorithms in float64 agree to rounding: measured worst 2.5e-15 relative to
# the largest entry (iCub), at most 4e-16 on the others; the criterion is 1e-10 relative to the largest
# entry (absolute below 1).
ORACLE_TOL = 1e-10


@pytest.mark.parametrize("name, floating", SAMPLE, ids=[name.split("/")[-1] for name, _ in SAMPLE])
def test_sample_matches_pinocchio(name, floating):
    """RNEA torques, the mass matrix (CRBA) and the gravity torques at 5 random states, one batch each."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UrdfRepairWarning)
        pair = Pair(ERD / name, floating, False, **{k: v for k, v in OPTIONS.get(name, {}).items()
                                                    if k != "floating_base"})
    states = pair.states(34, 5)
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    tau = robot.rnea(pair.tree, Q, V, A)
    M = robot.mass_matrix(pair.tree, Q)
    g = robot.gravity_torques(pair.tree, Q)
    for k, (q, v, a) in enumerate(states):
        pq = pair.to_pin_q(q)
        close(tau[k], pair.from_pin_v(pin.rnea(pair.model, pair.data, pq, pair.to_pin_v(v), pair.to_pin_v(a))),
              ORACLE_TOL)
        close(M[k], pair.from_pin_matrix(pin.crba(pair.model, pair.data, pq)), ORACLE_TOL)
        close(g[k], pair.from_pin_v(pin.computeGeneralizedGravity(pair.model, pair.data, pq)), ORACLE_TOL)


def test_romeo_with_massless_fingers_loads_and_only_what_needs_m_inverse_refuses():
    """Romeo's LHand and RHand (their fingers mimic them) move only massless links: loaded with a warning naming
    them; M(q) has zero rows there; forward dynamics and simulate refuse naming them; min_inertia (MuJoCo's
    boundinertia) gives each moving body a least principal moment, and the robot then moves."""
    path = ERD / "romeo_description/urdf/romeo.urdf"
    with pytest.warns(UrdfRepairWarning, match=r"^romeo: joint\(s\) \['LHand', 'RHand'\] move no mass or inertia"):
        tree = robot.RobotTree.from_urdf(path, check_triangle=False)
    hands = [tree.joint_names.index(n) for n in ("LHand", "RHand")]
    q = tree.neutral()
    M = robot.mass_matrix(tree, q)
    np.testing.assert_array_equal(M[hands], 0.0)
    assert np.linalg.matrix_rank(M) == tree.nv - 2
    with pytest.raises(ValidationError, match=r"^forward_dynamics: the result is not finite although the inputs "
                                              r"are: joint\(s\) \['LHand', 'RHand'\] move no mass or inertia"):
        robot.forward_dynamics(tree, q, np.zeros(tree.nv), np.zeros(tree.nv))
    with pytest.raises(ValidationError, match=r"^model: joint\(s\) \['LHand', 'RHand'\] move no mass or inertia, "
                                              r"so M\(q\) is singular"):
        tumble.simulate(tree, q0=q, t=[0.0, 0.01], method="rk4", dt=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UrdfRepairWarning)
        regular = robot.RobotTree.from_urdf(path, check_triangle=False, min_inertia=1e-6)
    assert regular.massless_joints == ()
    # the hand link's principal moments are now at least 1e-6 kg m^2, so is its moment about the joint axis
    assert robot.mass_matrix(regular, q)[hands[0], hands[0]] >= 1e-6
    qdd = robot.forward_dynamics(regular, q, np.zeros(regular.nv), np.zeros(regular.nv))
    assert np.isfinite(qdd).all()


def test_the_cli_repairs_tiago_on_request_and_says_so():
    """``tumble robot torques``: TIAGo refused (exit 2, one line naming the link and the option), then loaded with
    ``--inertia clip``: one ``warning:`` line per repair message on stderr, the torques on stdout."""
    from typer.testing import CliRunner

    from tumble.cli.robot import app

    path = str(ERD / "tiago_description/robots/tiago_no_hand.urdf")
    with pytest.warns(UrdfRepairWarning):
        dof = _load("tiago_description/robots/tiago_no_hand.urdf").dof
    q = ", ".join(["0.1"] * dof)
    refused = CliRunner().invoke(app, ["torques", path, "--q", q])
    assert refused.exit_code == 2
    assert refused.stderr.startswith("error: link 'base_antenna_left_link' <inertial> <inertia>: must be positive "
                                     "semi-definite")
    repaired = CliRunner().invoke(app, ["torques", path, "--q", q, "--inertia", "clip"])
    assert repaired.exit_code == 0, repaired.output
    assert repaired.stderr.startswith("warning: tiago_no_hand.urdf: non-physical inertia repaired: link "
                                      "'base_antenna_left_link'")
    assert repaired.stderr.count("\n") == 1 and repaired.stdout.count("tau =") == dof


def test_a_quadrotor_is_a_free_body_that_falls_and_keeps_its_spin():
    """The hector quadrotor (one link, no joint) as a floating base: nq = 7, nv = 6, no joint coordinate to give;
    its centre of mass falls as g t²/2 and its angular momentum about it stays (dop853 at rtol = atol = 1e-12;
    measured 4.3e-13 m and 1.1e-13 relative)."""
    quad = robot.RobotTree.from_urdf(ERD / "hector_description/robots/quadrotor_base.urdf", floating_base=True)
    assert (quad.nq, quad.nv, quad.dof) == (7, 6, 0)
    run = tumble.simulate(quad, t=[0.0, 0.5], method="dop853", rtol=1e-12, atol=1e-12, base_omega0=[0.1, 2.0, 0.3])
    centre = robot.center_of_mass(quad, np.concatenate([run.base_position, run.base_attitude], axis=1))
    np.testing.assert_allclose(centre[-1] - centre[0], [0.0, 0.0, -9.81 * 0.5 ** 2 / 2], rtol=0, atol=1e-10)
    np.testing.assert_allclose(run.angular_momentum[-1], run.angular_momentum[0], rtol=1e-10)
