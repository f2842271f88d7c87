"""Kinematic trees, real URDFs, mimic joints and floating bases against Pinocchio, live (issue 15).

Pinocchio (PyPI ``pin``) builds each robot from the same URDF with its own parser; tumble's RNEA, CRBA, ABA,
frame placements, centre of mass and centroidal momentum matrix must agree on 20 random states per robot.
The URDFs come from ``example-robot-data`` (both in the ``test`` extra) and tumble.examples.path("industrial6.urdf").
"""

import numpy as np
import pytest

import tumble
from robot_oracle import ERD, Pair, close
from tumble import ValidationError, robot

# The tests here compile or share the robot's kernels (tumble.kernels.featherstone and the chain model's
# integrators, ~50 CPU s on a cold Numba cache); the robot's modules run on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

pin = pytest.importorskip("pinocchio")

ROBOTS = tumble.examples.directory() / "robots"
STATES = 20
# Two implementations of the same algorithms in float64 agree to rounding: measured worst 3e-13 relative to
# the largest entry (Talos' mass matrix, ~1e1); the issue's criterion is 1e-10.
ORACLE_TOL = 1e-10
# Identities between tumble's own algorithms: measured worst 4e-14 relative to the scale of the torques.
IDENTITY_TOL = 1e-12

CASES = {  # name: (URDF, floating base, Pinocchio's mimic option)
    "industrial6": (ROBOTS / "industrial6.urdf", False, False),
    "ur5": (ERD / "ur_description/urdf/ur5_robot.urdf", False, False),
    "panda": (ERD / "panda_description/urdf/panda.urdf", False, True),  # finger_joint2 mimics finger_joint1
    # humanoid tree, 44 joints; Pinocchio 4.1.0 refuses its gripper mimics ("The parent joint of the mimic joint is
    # not in the kinematic tree": a mimic joint comes before the joint it copies), so both read them as joints
    "talos": (ERD / "talos_data/robots/talos_full_v2.urdf", True, False),
    "solo12": (ERD / "solo_description/robots/solo12.urdf", True, False),  # quadruped, floating base
}


@pytest.fixture(scope="module", params=list(CASES))
def pair(request):
    return Pair(*CASES[request.param])


def test_dynamics_match_pinocchio(pair):
    """RNEA, CRBA and ABA (ABA: Pinocchio has none with mimic joints; tumble's CRBA solve is then compared with
    Pinocchio's M⁻¹(τ − h)) on 20 random states, in one batch per algorithm."""
    states = pair.states(15, STATES)
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    tau = robot.rnea(pair.tree, Q, V, A)
    M = robot.mass_matrix(pair.tree, Q)
    qdd = robot.forward_dynamics(pair.tree, Q, V, tau)
    for k, (q, v, a) in enumerate(states):
        pq, pv, pa = pair.to_pin_q(q), pair.to_pin_v(v), pair.to_pin_v(a)
        close(tau[k], pair.from_pin_v(pin.rnea(pair.model, pair.data, pq, pv, pa)), ORACLE_TOL)
        M_pin = pair.from_pin_matrix(pin.crba(pair.model, pair.data, pq))
        close(M[k], M_pin, ORACLE_TOL)
        if pair.mimic:
            h = pair.from_pin_v(pin.rnea(pair.model, pair.data, pq, pv, np.zeros(pair.model.nv)))
            expected = np.linalg.solve(M_pin, tau[k] - h)
        else:
            expected = pair.from_pin_v(pin.aba(pair.model, pair.data, pq, pv, pair.to_pin_v(tau[k])))
        close(qdd[k], expected, ORACLE_TOL)
        close(qdd[k], a, IDENTITY_TOL)  # ABA(RNEA(q̈)) = q̈


def test_frames_and_centroidal_quantities_match_pinocchio(pair):
    """Every URDF link's frame (merged and massless ones included: base, flange, tool0, ...), the centre of mass
    and Orin's centroidal momentum matrix, on 20 random states."""
    frames = {f.name: k for k, f in enumerate(pair.model.frames) if f.type == pin.FrameType.BODY}
    assert set(pair.tree.frame_names) == set(frames)
    states = pair.states(16, STATES)
    poses = robot.frame_poses(pair.tree, np.array([s[0] for s in states]))
    for k, (q, v, _) in enumerate(states[:5] if len(pair.tree.links) > 20 else states):
        pq = pair.to_pin_q(q)
        pin.framesForwardKinematics(pair.model, pair.data, pq)
        for j, name in enumerate(pair.tree.frame_names):
            close(poses[k, j], pair.data.oMf[frames[name]].homogeneous, ORACLE_TOL)
        close(robot.center_of_mass(pair.tree, q), pin.centerOfMass(pair.model, pair.data, pq), ORACLE_TOL)
        if not pair.mimic:
            Ag = pin.computeCentroidalMap(pair.model, pair.data, pq)  # rows (l, k_G)
            close(robot.centroidal_momentum_matrix(pair.tree, q), _cmm(pair, Ag), ORACLE_TOL)


def _cmm(pair, Ag):
    """Pinocchio's (l; k_G) rows and coordinates, as tumble's (k_G; l)."""
    rows = np.array([pair.from_pin_v(row) for row in Ag])
    return np.vstack([rows[3:], rows[:3]])


def test_identities(pair):
    """M from RNEA columns = CRBA; RNEA = M q̈ + RNEA(q, q̇, 0); gravity = RNEA(q, 0, 0)."""
    q, v, a = pair.states(17, 1)[0]
    tree = pair.tree
    h = robot.rnea(tree, q, v, np.zeros(tree.nv))
    g = robot.rnea(tree, q, np.zeros(tree.nv), np.zeros(tree.nv))
    M = robot.mass_matrix(tree, q)
    columns = np.array([robot.rnea(tree, q, np.zeros(tree.nv), e) - g for e in np.eye(tree.nv)]).T
    close(columns, M, IDENTITY_TOL)
    close(robot.rnea(tree, q, v, a), M @ a + h, IDENTITY_TOL)
    np.testing.assert_array_equal(robot.gravity_torques(tree, q), g)


def test_industrial_arm_keeps_its_ros_i_frames_and_limits():
    """A ROS-I arm (massless base, flange and tool0 beside and after the joints) is a serial chain with named
    frames, and its limits are read: was refused as 'a tree, not a serial chain'."""
    chain = robot.load(ROBOTS / "industrial6.urdf")
    assert type(chain) is robot.SerialChain and chain.dof == 6
    assert {"base", "flange", "tool0"} <= set(chain.frame_names)
    np.testing.assert_array_equal(chain.lower[:2], [-3.2289, -2.7053])
    # tool0 is the flange turned by 90° about y: its z axis is the flange's x axis
    T = robot.frame_poses(chain, np.zeros(6))
    names = chain.frame_names
    np.testing.assert_allclose(T[names.index("tool0"), :3, 2], T[names.index("flange"), :3, 0], atol=1e-15)
    np.testing.assert_allclose(T[names.index("flange"), :3, 3], [0.26 + 0.68 + 0.67 + 0.158, 0, 0.675 - 0.035],
                               atol=1e-15)


def test_frame_jacobian_is_the_derivative_of_the_frame_pose():
    """``J q̇`` against central differences of the frame pose along q̇ (step 1e-6: error ~1e-12·|q̈| + rounding
    1e-10), for a floating quadruped's foot."""
    tree = robot.RobotTree.from_urdf(CASES["solo12"][0], floating_base=True)
    q = tree.neutral()
    q[7:] = np.linspace(-1.0, 1.0, 12)
    v = np.linspace(0.3, -0.4, tree.nv)
    J = robot.frame_jacobian(tree, q, "FL_FOOT")
    step = 1e-6

    def pose(s):  # q ⊕ s v: base by its body-frame velocity, joints linearly
        from scipy.spatial.transform import Rotation
        x = q.copy()
        R0 = Rotation.from_quat(q[3:7], scalar_first=True)
        x[0:3] = q[0:3] + s * R0.apply(v[3:6])
        x[3:7] = (R0 * Rotation.from_rotvec(s * v[0:3])).as_quat(scalar_first=True)
        x[7:] = q[7:] + s * v[6:]
        return robot.frame_pose(tree, x, "FL_FOOT")

    d = (pose(step) - pose(-step)) / (2 * step)
    np.testing.assert_allclose((J @ v)[3:], d[:3, 3], atol=1e-8)


_TWO_LINKS = ('<robot name="r"><link name="a"/><link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
              'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><link name="c"><inertial><mass value="1"/>'
              '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><link name="d"/>'
              '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>'
              '<joint name="f" type="fixed"><parent link="a"/><child link="d"/></joint>'
              '<joint name="k" type="revolute"><parent link="b"/><child link="c"/>{mimic}</joint></robot>')

BAD = [
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="a"/>'
     '<child link="b"/></joint><joint name="k" type="revolute"><parent link="b"/><child link="a"/></joint></robot>',
     r"a robot needs exactly one root link, found \[\] \(the joints close a loop\)"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="screw"><parent link="a"/>'
     '<child link="b"/></joint></robot>', r"joint 'j': unknown joint type 'screw'"),
    ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute"><parent link="z"/>'
     '<child link="b"/></joint></robot>', r"joint 'j': <parent link='z'> names no <link>"),
    ('<robot name="r"><link name="a"/><link name="b"><inertial><mass value="-1"/><inertia ixx="1" ixy="0" '
     'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="revolute"><parent link="a"/>'
     '<child link="b"/></joint></robot>', r"link 'b' <inertial> <mass>: value must be a finite number >= 0"),
    ('<robot name="r"><link name="a"/><link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
     'ixz="0" iyy="1" iyz="0" izz="-1"/></inertial></link><joint name="j" type="revolute"><parent link="a"/>'
     '<child link="b"/></joint></robot>', r"link 'b' <inertial> <inertia>: must be positive semi-definite"),
    ('<robot name="r"><link name="a"/><link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" '
     'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><link name="c"><inertial><mass value="1"/><inertia '
     'ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="revolute">'
     '<parent link="a"/><child link="b"/></joint><joint name="k" type="revolute"><parent link="b"/>'
     '<child link="c"/><mimic joint="nope"/></joint></robot>',
     r"^joint 'k' <mimic>: joint='nope' names no joint of the robot \(mimic=False reads the <mimic> joints as "
     r"independent joints"),
    (_TWO_LINKS.format(mimic='<mimic joint="f"/>'), r"^joint 'k' <mimic>: joint='f' names a 'fixed' joint; a mimic "
                                                    r"joint copies a moving joint$"),
    (_TWO_LINKS.format(mimic='<mimic joint="k"/>'), r"^joint 'k' <mimic>: joint='k' names a mimic joint; a mimic "
                                                    r"joint copies an independent joint$"),
    ('<robot name="r"/>', r"^URDF: <robot> has no <link> element; a robot needs at least one link$"),
    ('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><joint name="j" type="revolute">'
     '<parent link="b"/><child link="c"/></joint><joint name="k" type="revolute"><parent link="c"/>'
     '<child link="b"/></joint></robot>',
     r"^link 'b': not reached from the root link 'a' \(the joints close a loop\)$"),
]


@pytest.mark.parametrize("text, message", BAD, ids=range(len(BAD)))
def test_bad_trees_are_refused_naming_the_element_and_the_rule(text, message):
    with pytest.raises(ValidationError, match=message):
        robot.RobotTree.from_urdf(text)


def test_centroidal_momentum_matches_pinocchio(pair):
    """The compiled ``h_G = (k_G, l)``, batched (what a floating-base simulate outputs at every sample), against
    Pinocchio's computeCentroidalMomentum on 20 random states."""
    states = pair.states(18, STATES)
    h = robot.centroidal_momentum(pair.tree, np.array([s[0] for s in states]), np.array([s[1] for s in states]))
    assert h.shape == (STATES, 6)
    for k, (q, v, _) in enumerate(states):
        expected = pin.computeCentroidalMomentum(pair.model, pair.data, pair.to_pin_q(q), pair.to_pin_v(v))
        close(h[k], np.concatenate([expected.angular, expected.linear]), ORACLE_TOL)
        np.testing.assert_array_equal(robot.centroidal_momentum(pair.tree, q, v), h[k])
