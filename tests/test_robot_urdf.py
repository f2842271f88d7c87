"""tumble.robot URDF input: joint types, axes, origins, fixed-link merging, and what is refused."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tumble import RigidBody, ValidationError, robot

ROBOTS = Path(__file__).resolve().parents[1] / "examples" / "robots"
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
     r"link 'a' <inertial> <mass>: value must be >= 0"),
    (urdf(link("base") + link("a", 1.0, inertia=(1, 0, 0, 1, 0, -1)) + joint("j1", "base", "a")),
     r"link 'a' <inertial> <inertia>: must be positive semi-definite"),
    (urdf(link("base") + link("a", 1.0) + joint("j1", "base", "a", kind="fixed")),
     r"no revolute, continuous or prismatic joint"),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;">]><robot name="&b;"/>',
     r"URDF: refused unsafe XML"),
]


@pytest.mark.parametrize("text, message", BAD, ids=range(len(BAD)))
def test_bad_urdf_is_refused_naming_the_element(text, message):
    with pytest.raises(ValidationError, match=message):
        robot.SerialChain.from_urdf(text)


def test_triangle_inequality_opt_out():
    doc = urdf(link("base") + link("a", 1.0, inertia=(0.066, 0, 0, 0.086, 0, 0.0125)) + joint("j1", "base", "a"))
    with pytest.raises(ValidationError, match=r"link 'j1'\.inertia: principal moments break the triangle"):
        robot.SerialChain.from_urdf(doc)
    assert robot.SerialChain.from_urdf(doc, check_triangle=False).links[0].mass == 1.0
