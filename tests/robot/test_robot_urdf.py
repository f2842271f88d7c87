"""tumble.robot URDF input: joint types, axes, origins, fixed-link merging, and what is refused."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import tumble
from tumble import RigidBody, ValidationError, robot

# The tests here compile or share the robot's kernels (~30 CPU s on a cold Numba cache); the robot's modules run
# on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

ROBOTS = tumble.examples.directory() / "robots"
# Same arm through two descriptions: differences are rounding (measured ≤ 4e-15).
TOL = 1e-12


def urdf(body: str, name: str = "test") -> str:
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n{body}\n</robot>'


def joint(name, parent, child, kind="revolute", xyz="0 0 0", rpy="0 0 0", axis="0 0 1", extra=""):
    return (f'<joint name="{name}" type="{kind}"><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<parent link="{parent}"/><child link="{child}"/><axis xyz="{axis}"/>{extra}</joint>')


def link(name, mass=None, xyz="0 0 0", rpy="0 0 0", inertia=(0.1, 0.0, 0.0, 0.2, 0.0, 0.3)):
    if mass is None:
        return f'<link name="{name}"/>'
    ixx, ixy, ixz, iyy, iyz, izz = inertia
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial></link>')


def test_origin_rpy_is_fixed_axis_roll_pitch_yaw():
    """``<origin rpy="r p y">`` is R = Rz(y) Ry(p) Rx(r) (scipy: extrinsic "xyz")."""
    rpy = (0.3, -0.7, 1.1)
    doc = urdf(link("base") + link("a", 1.0) + joint("j", "base", "a", xyz="0.1 0.2 0.3",
                                                      rpy=" ".join(map(str, rpy))))
    chain = robot.SerialChain.from_urdf(doc)
    T = robot.link_poses(chain, [0.0])[0]
    np.testing.assert_allclose(T[:3, :3], Rotation.from_euler("xyz", rpy).as_matrix(), rtol=0, atol=TOL)
    np.testing.assert_allclose(T[:3, 3], [0.1, 0.2, 0.3], rtol=0, atol=TOL)


def test_negative_axes_mirror_the_joint_variables():
    """A joint about −z at q moves as one about +z at −q, so τ₋(q, q̇, q̈) = −τ₊(−q, −q̇, −q̈)."""
    text = (ROBOTS / "panda.urdf").read_text()
    plus = robot.SerialChain.from_urdf(text)
    minus = robot.SerialChain.from_urdf(text.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 -1"/>'))
    q, qd, qdd = np.random.default_rng(3).uniform(-1, 1, (3, 4, 7))
    np.testing.assert_allclose(robot.rnea(minus, q, qd, qdd), -robot.rnea(plus, -q, -qd, -qdd), rtol=0, atol=TOL)


def test_unnormalised_axis_and_prismatic_joint():
    """A vertical slider carrying 2 kg: τ = m (q̈ + 9.81) whatever the axis length; continuous = unlimited."""
    doc = urdf(link("base") + link("slider", 2.0) + link("arm", 0.5)
               + joint("lift", "base", "slider", kind="prismatic", axis="0 0 3",
                       extra='<limit lower="-0.5" upper="0.5" effort="100" velocity="1"/>')
               + joint("spin", "slider", "arm", kind="continuous", axis="0 0 1"))
    chain = robot.SerialChain.from_urdf(doc)
    assert chain.joint_types == ("prismatic", "revolute")
    np.testing.assert_array_equal(chain.lower, [-0.5, -np.inf])
    tau = robot.rnea(chain, [0.2, 0.3], [0.1, 0.0], [1.5, 0.0])
    np.testing.assert_allclose(tau, [2.5 * (1.5 + 9.81), 0.0], rtol=0, atol=TOL)


def test_fixed_links_are_merged_into_their_parent():
    """A tool on a fixed joint adds to the link before it as RigidBody.composite computes (parallel axes)."""
    inertia_a, inertia_tool = (0.1, 0.01, 0.0, 0.2, 0.0, 0.3), (0.02, 0.0, 0.0, 0.03, 0.0, 0.04)
    doc = urdf(link("base") + link("a", 1.5, xyz="0.1 0 0", inertia=inertia_a)
               + link("flange") + link("tool", 0.8, xyz="0 0.05 0", rpy="0 0 0.4", inertia=inertia_tool)
               + joint("j1", "base", "a", axis="0 1 0")
               + joint("mount", "a", "flange", kind="fixed", xyz="0.5 0 0", rpy="0.2 0 0")
               + joint("grip", "flange", "tool", kind="fixed", xyz="0 0 0.1"))
    chain = robot.SerialChain.from_urdf(doc)
    assert chain.dof == 1

    def tensor(i):
        ixx, ixy, ixz, iyy, iyz, izz = i
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])

    r_mount = Rotation.from_euler("xyz", [0.2, 0, 0]).as_matrix()
    r_tool = r_mount @ Rotation.from_euler("xyz", [0, 0, 0.4]).as_matrix()
    tool = RigidBody(tensor(inertia_tool), mass=0.8)
    a = RigidBody(tensor(inertia_a), mass=1.5)
    expected = RigidBody.composite([
        a.placed((0.1, 0.0, 0.0)),
        tool.placed(np.array([0.5, 0, 0]) + r_mount @ [0, 0, 0.1] + r_mount @ [0, 0.05, 0], rotation=r_tool),
    ])
    merged = chain.links[0]
    assert merged.mass == pytest.approx(2.3, abs=1e-15)
    np.testing.assert_allclose(merged.com, expected.com, rtol=0, atol=TOL)
    np.testing.assert_allclose(merged.inertia, expected.inertia, rtol=0, atol=TOL)


BAD = [
    ("<robot><link name='a'>", r"URDF: malformed XML"),
    (urdf(link("base") + link("a", 1.0) + link("b", 1.0) + joint("j1", "base", "a") + joint("j2", "base", "b")),
     r"link 'base': has 2 child joints \['j1', 'j2'\]: a tree"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", kind="ball")),
     r"joint 'j1': unknown joint type 'ball'"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", kind="floating")),
     r"joint 'j1': joint type 'floating' is not supported"),
    (urdf(link("base") + link("a", 1.0) + link("b", 1.0) + joint("j1", "base", "a")
          + joint("j2", "a", "b", extra='<mimic joint="j1" multiplier="2"/>')),
     r"joint 'j2': <mimic> is not supported"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "nowhere")),
     r"joint 'j1': <child link='nowhere'> names no <link>"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", xyz="0 0 x")),
     r"joint 'j1' <origin>: attribute xyz='0 0 x' must be 3 finite numbers"),
    (urdf(link("base") + link("a", "-1") + joint("j1", "base", "a")),
     r"link 'a' <inertial> <mass>: value must be a finite number >= 0"),
    (urdf(link("base") + link("a", 1.0, inertia=(1, 0, 0, 1, 0, -1)) + joint("j1", "base", "a")),
     r"link 'a' <inertial> <inertia>: must be positive semi-definite"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", kind="fixed")),
     r"no revolute, continuous or prismatic joint"),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;">]><robot name="&b;"/>',
     r"URDF: refused unsafe XML"),
    # an element read once, given twice: which one counts would be a guess (a second <mass> was taken silently)
    (urdf(link("base") + link("a", 1.0).replace('<mass value="1.0"/>', '<mass value="1.0"/><mass value="2"/>')
          + joint("j1", "base", "a")),
     r"^link 'a' <inertial>: has 2 <mass> elements; at most one is allowed$"),
    (urdf(link("base") + link("a", 1.0).replace("</inertial>", '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                                                              'izz="1"/></inertial>') + joint("j1", "base", "a")),
     r"^link 'a' <inertial>: has 2 <inertia> elements; at most one is allowed$"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", extra='<axis xyz="1 0 0"/>')),
     r"^joint 'j1': has 2 <axis> elements; at most one is allowed$"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", extra='<origin xyz="1 0 0"/>')),
     r"^joint 'j1': has 2 <origin> elements; at most one is allowed$"),
    (urdf(link("base") + link("a", 1.0, inertia=(1, 2, 0, 1, 0, 1)) + joint("j1", "base", "a")),
     r"^link 'a' <inertial> <inertia>: must be positive semi-definite \(principal moments \[-1\.0.*\] kg m\^2\); "
     r"inertia='clip' sets its negative principal moments to zero$"),
]


@pytest.mark.parametrize("text, message", BAD, ids=range(len(BAD)))
def test_bad_urdf_is_refused_naming_the_element(text, message):
    with pytest.raises(ValidationError, match=message):
        robot.SerialChain.from_urdf(text)


def test_triangle_inequality_opt_out():
    """Published inertias (here the PUMA's link 3) may break I1 + I2 >= I3: refused naming the URDF link,
    unless opted out."""
    doc = urdf(link("base") + link("a", 1.0, inertia=(0.066, 0, 0, 0.086, 0, 0.0125)) + joint("j1", "base", "a"))
    with pytest.raises(ValidationError, match=r"link 'a' <inertial> \(moved by joint 'j1'\): principal moments "
                                              r"break the triangle inequality .* pass check_triangle=False"):
        robot.SerialChain.from_urdf(doc)
    assert robot.SerialChain.from_urdf(doc, check_triangle=False).links[0].mass == 1.0
    # a fixed link merged into the moving one is named too
    tool = link("tool", 1e-6, inertia=(1e-9, 0, 0, 1e-9, 0, 1e-9)) + joint("grip", "a", "tool", kind="fixed")
    doc = urdf(link("base") + link("a", 1.0, inertia=(0.066, 0, 0, 0.086, 0, 0.0125)) + joint("j1", "base", "a") + tool)
    with pytest.raises(ValidationError, match=r"link 'a' <inertial> with the fixed link\(s\) \['tool'\] merged"):
        robot.SerialChain.from_urdf(doc)


# -- every construct of the parser at once, against Pinocchio's own URDF parser ------------------
#
# A 4-joint arm written for this test: a massive pedestal on a fixed joint before the first moving
# joint (it belongs to the base), a continuous joint about -z, a prismatic joint along an oblique
# axis, a fixed bracket between two moving links, an unnormalised axis (0 1 1), a revolute joint
# about -x, a tool on a fixed flange, origins with roll, pitch and yaw, products of inertia.
LIMIT = '<limit lower="-2" upper="2" effort="10" velocity="1"/>'
PEER_URDF = urdf(
    link("base") + link("pedestal", 3.0, xyz="0 0 0.05")
    + link("a", 1.2, xyz="0.02 -0.01 0.1", rpy="0.1 0.2 0.3", inertia=(0.02, 0.001, -0.002, 0.03, 0.003, 0.015))
    + link("b", 2.0, xyz="0.05 0.0 -0.03", inertia=(0.01, 0.0, 0.001, 0.012, -0.002, 0.008))
    + link("bracket", 0.4, xyz="0 0.02 0", rpy="0.5 0 0", inertia=(0.002, 0.0, 0.0, 0.003, 0.0, 0.004))
    + link("c", 0.5, xyz="0.1 0 0", inertia=(0.001, 0.0, 0.0, 0.01, 0.0, 0.01))
    + link("d", 0.7, xyz="0 0.03 0.04", inertia=(0.004, -0.0005, 0.0, 0.005, 0.0007, 0.003))
    + link("tool", 0.3, xyz="0 0 0.05", inertia=(0.0006, 0.0, 0.0, 0.0006, 0.0, 0.0002))
    + joint("mount", "base", "pedestal", kind="fixed", xyz="0 0 0.1", rpy="0 0 0.2")
    + joint("j1", "pedestal", "a", kind="continuous", axis="0 0 -1", xyz="0 0 0.1")
    + joint("j2", "a", "b", kind="prismatic", axis="0.6 0 -0.8", xyz="0.1 0 0.2", rpy="0.3 -0.2 0.1", extra=LIMIT)
    + joint("bolt", "b", "bracket", kind="fixed", xyz="0 0.15 0", rpy="0.4 0 0")
    + joint("j3", "bracket", "c", axis="0 1 1", xyz="0 0.2 0", rpy="0 0.5 -0.3", extra=LIMIT)
    + joint("j4", "c", "d", axis="-1 0 0", xyz="0.3 0 0", extra=LIMIT)
    + joint("flange", "d", "tool", kind="fixed", xyz="0 0 0.1", rpy="0 0.5 0"),
    name="peer arm")
# One state and a wrench (f, n) on the end link (URDF link "d", the child of the last moving joint).
PEER_STATE = dict(q=[0.3, 0.2, -0.5, 0.7], qd=[0.4, -0.3, 0.9, -1.1], qdd=[1.0, -2.0, 0.5, 0.8],
                  f_ext=[1.0, -2.0, 3.0, 0.1, -0.2, 0.3])
# Computed once with Pinocchio 4.1.0 (pinocchio.buildModelFromXML(PEER_URDF), gravity (0, 0, -9.81);
# rnea, crba, aba, the wrench as fext of the last joint) by benchmarks/robot_pinocchio_reference.py.
PEER = {
    "tau": [0.1464583093838328, -31.834398284450273, -0.9861596138538653, -0.35560984301502824],
    "tau_wrench": [-0.9373036028276117, -30.394001504153316, -0.5934290339857555, -0.2556098430150282],
    "M": [[0.6706461147181751, 0.08705432527447507, -0.14829446212887187, -0.03228979506079721],
          [0.08705432527447507, 3.9000000000000004, 0.1952717119667885, 0.04672066712377287],
          [-0.14829446212887187, 0.1952717119667885, 0.11345089810424294, 0.023049923030572045],
          [-0.03228979506079721, 0.04672066712377287, 0.023049923030572045, 0.012468421511545296]],
    "aba_wrench": [3.49574171412102, 4.99880740937451, -19.25017092356121, 102.21201905227483],
}
# Two parsers and two algorithms agree to rounding (measured <= 5e-14); the criterion is 1e-10.
PEER_TOL = 1e-10


def test_urdf_arm_matches_pinocchio():
    chain = robot.SerialChain.from_urdf(PEER_URDF)
    assert chain.joint_types == ("revolute", "prismatic", "revolute", "revolute")
    assert chain.joint_names == ("j1", "j2", "j3", "j4")
    q, qd, qdd, wrench = (np.array(PEER_STATE[k]) for k in ("q", "qd", "qdd", "f_ext"))
    np.testing.assert_allclose(robot.rnea(chain, q, qd, qdd), PEER["tau"], rtol=0, atol=PEER_TOL)
    np.testing.assert_allclose(robot.rnea(chain, q, qd, qdd, f_ext=wrench), PEER["tau_wrench"], rtol=0,
                               atol=PEER_TOL)
    np.testing.assert_allclose(robot.mass_matrix(chain, q), PEER["M"], rtol=0, atol=PEER_TOL)
    np.testing.assert_allclose(robot.forward_dynamics(chain, q, qd, qdd, f_ext=wrench), PEER["aba_wrench"], rtol=0,
                               atol=PEER_TOL)
    # batched, one wrench per sample: (no wrench, the wrench)
    Q, QD, QDD = (np.stack([x, x]) for x in (q, qd, qdd))
    W = np.stack([np.zeros(6), wrench])
    np.testing.assert_allclose(robot.rnea(chain, Q, QD, QDD, f_ext=W), [PEER["tau"], PEER["tau_wrench"]], rtol=0,
                               atol=PEER_TOL)
    np.testing.assert_allclose(robot.forward_dynamics(chain, Q, QD, QDD, f_ext=W)[1], PEER["aba_wrench"], rtol=0,
                               atol=PEER_TOL)


def test_a_huge_axis_is_the_direction_it_points_in():
    """``<axis xyz="1e200 1e200 0">`` is the axis (1, 1, 0)/√2 (its norm overflowed: a zero axis, τ = 0)."""
    def chain(axis):
        return robot.SerialChain.from_urdf(urdf(link("base") + link("a", 1.0, xyz="0.3 0 0.2")
                                                + joint("j1", "base", "a", axis=axis)))
    q, qd, qdd = [0.4], [0.7], [1.3]
    tau = robot.rnea(chain("1e200 1e200 0"), q, qd, qdd)
    assert abs(tau[0]) > 0.1
    np.testing.assert_array_equal(tau, robot.rnea(chain("1 1 0"), q, qd, qdd))


def test_a_chain_of_1500_links_loads_and_holds_its_weight():
    """The tree is walked without recursion (1500 links hit RecursionError). A horizontal chain of 1 kg points
    0.1 m apart, joints about y: joint i (0-based) carries the n − i points at 0, 0.1, …, 0.1 (n − i − 1) m from
    its axis; their weight turns it about +y, so it holds τᵢ = −0.1 g (n − i)(n − i − 1)/2."""
    n, g = 1500, 9.81
    inertia = '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
    links = "".join(f'<link name="l{i}"><inertial><mass value="1"/>{inertia}</inertial></link>' for i in range(n + 1))
    joints = "".join(joint(f"j{i}", f"l{i}", f"l{i + 1}", xyz="0.1 0 0", axis="0 1 0") for i in range(n))
    chain = robot.SerialChain.from_urdf(urdf(links + joints), check_triangle=False)
    assert chain.dof == n
    remaining = n - np.arange(n)
    np.testing.assert_allclose(robot.gravity_torques(chain, np.zeros(n)), -0.1 * g * remaining * (remaining - 1) / 2,
                               rtol=1e-12)


def test_round_off_inertia_is_clipped_and_named():
    """iCub's l_ankle_2: zero but for ixz = 1.35525e-20 (principal moments ±1.36e-20), within 1e-14 × the robot's
    largest entry: set to zero, with a warning naming the link and the rule; the same tensor in a robot whose
    largest entry is 1e-6 kg m^2 is not round-off, and refused."""
    ankle = link("ankle", 0.2675, inertia=(0, 0, 1.35525e-20, 0, 0, 0))
    doc = urdf(link("base") + link("a", 1.0) + ankle + joint("j1", "base", "a") + joint("j2", "a", "ankle"))
    with pytest.warns(robot.UrdfRepairWarning, match=r"link 'ankle' <inertial> <inertia>: principal moment "
                                                     r"-1\.35525e-20 kg m\^2 set to 0 by round-off, at most 1e-14 x "
                                                     r"the robot's largest entry 0\.3 kg m\^2$"):
        chain = robot.SerialChain.from_urdf(doc, check_triangle=False)
    half = 1.35525e-20 / 2  # the positive moment 1.35525e-20 kept on its axis (x + z)/√2
    np.testing.assert_allclose(chain.links[1].inertia, [[half, 0, half], [0, 0, 0], [half, 0, half]], rtol=1e-14)
    small = doc.replace('ixx="0.1" ixy="0.0" ixz="0.0" iyy="0.2" iyz="0.0" izz="0.3"',
                        'ixx="1e-7" ixy="0.0" ixz="0.0" iyy="2e-7" iyz="0.0" izz="1e-6"')
    with pytest.raises(ValidationError, match=r"^link 'ankle' <inertial> <inertia>: must be positive semi-definite"):
        robot.SerialChain.from_urdf(small, check_triangle=False)


def test_clip_makes_the_nearest_semidefinite_tensor_and_names_it():
    """``inertia="clip"``: the moments (−1, 1, 3) of a tensor become (0, 1, 3) about the same axes, the nearest
    positive semi-definite tensor (Frobenius norm), with a warning naming the link."""
    axes = Rotation.from_euler("xyz", [0.3, -0.2, 0.5]).as_matrix()
    tensor = axes @ np.diag([-1.0, 1.0, 3.0]) @ axes.T
    values = (tensor[0, 0], tensor[0, 1], tensor[0, 2], tensor[1, 1], tensor[1, 2], tensor[2, 2])
    doc = urdf(link("base") + link("a", 1.0, inertia=tuple(repr(float(v)) for v in values)) + joint("j1", "base", "a"))
    with pytest.warns(robot.UrdfRepairWarning, match=r"^URDF: non-physical inertia repaired: link 'a' <inertial> "
                                                     r"<inertia>: principal moment -1 kg m\^2 set to 0 by "
                                                     r"inertia='clip'$"):
        chain = robot.SerialChain.from_urdf(doc, inertia="clip", check_triangle=False)
    np.testing.assert_allclose(chain.links[0].inertia, axes @ np.diag([0.0, 1.0, 3.0]) @ axes.T, rtol=0, atol=4e-15)
    with pytest.raises(ValidationError, match=r"^inertia: must be one of \('check', 'clip'\), got 'fix'$"):
        robot.SerialChain.from_urdf(doc, inertia="fix")


def test_massless_last_link_loads_but_does_not_move():
    """A last link without <inertial>: M(q) = 0, named at load (a warning) and by simulate (was refused at load,
    and before that a NaN run); min_inertia gives it a least principal moment, and it then turns under a torque
    as I θ̈ = τ."""
    doc = urdf(link("base") + link("a") + joint("j1", "base", "a"))
    with pytest.warns(robot.UrdfRepairWarning, match=r"^test: joint\(s\) \['j1'\] move no mass or inertia"):
        chain = robot.SerialChain.from_urdf(doc)
    assert chain.massless_joints == ("j1",)
    np.testing.assert_array_equal(robot.mass_matrix(chain, [0.3]), [[0.0]])
    with pytest.raises(ValidationError, match=r"^model: joint\(s\) \['j1'\] move no mass or inertia, so M\(q\) is "
                                              r"singular and the motion undefined \(load the URDF with min_inertia"):
        tumble.simulate(chain, q0=[0.0], t=[0.0, 0.1], method="rk4", dt=0.1)
    regular = robot.SerialChain.from_urdf(doc, min_inertia=1e-3)
    assert regular.massless_joints == ()
    np.testing.assert_allclose(robot.forward_dynamics(regular, [0.3], [0.0], [2e-3]), [2.0], rtol=1e-14)
    with pytest.raises(ValidationError, match=r"^min_inertia: must be a finite number >= 0, got -1\.0$"):
        robot.SerialChain.from_urdf(doc, min_inertia=-1)


def test_the_cli_prints_the_torque_about_a_huge_axis(tmp_path):
    """``tumble robot torques`` on ``<axis xyz="1e200 1e200 0">``: the torque about (1, 1, 0)/√2, not 0."""
    from typer.testing import CliRunner

    from tumble.cli.robot import app

    body = link("base") + link("a", 1.0, xyz="0.3 0 0.2") + joint("j1", "base", "a", axis="{axis}")
    taus = []
    for axis in ("1e200 1e200 0", "1 1 0"):
        path = tmp_path / "arm.urdf"
        path.write_text(urdf(body.replace("{axis}", axis)))
        result = CliRunner().invoke(app, ["torques", str(path), "--q", "0.4", "--qdd", "1.3"])
        assert result.exit_code == 0, result.output
        taus.append(float(result.stdout.split("tau =")[1].split()[0]))
    assert taus[0] == taus[1] and abs(taus[0]) > 0.1
