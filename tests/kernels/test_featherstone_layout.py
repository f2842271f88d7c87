"""The named columns of a kinematic tree's table ``P`` and of the algorithms' scratch ``W``
(tumble.kernels.featherstone.layout): each column has one name, the blocks an algorithm holds at once do not
overlap, and a RobotTree's table holds under each name what the name says."""

import numpy as np
import pytest

import tumble
from tumble import robot
from tumble.kernels.featherstone import layout as L

EPS = np.finfo(np.float64).eps

# (first column, width) of every named block of P, in column order
P_BLOCKS = {"JOINT_FRAME": 12, "AXIS": 3, "JOINT_TYPE": 1, "OFFSET": 1, "MASS": 1, "FIRST_MOMENT": 3, "INERTIA": 9,
            "USER_FRAME": 12, "PARENT": 1, "COORDINATE": 1, "MULTIPLIER": 1}
# The blocks of W that one algorithm holds at the same time (name: width)
W_BLOCKS = {
    "RNEA": {"PARENT_POSE": 12, "VELOCITY": 6, "ACCELERATION": 6, "FORCE": 6},
    "ABA": {"PARENT_POSE": 12, "VELOCITY": 6, "BIAS_ACCELERATION": 6, "ARTICULATED_INERTIA": 36, "BIAS_FORCE": 6,
            "AXIS_INERTIA": 6, "JOINT_INERTIA": 1, "JOINT_FORCE": 1, "TRANSMITTED_BIAS": 6, "ABA_ACCELERATION": 6},
    "CRBA": {"PARENT_POSE": 12, "COMPOSITE_MASS": 1, "COMPOSITE_MOMENT": 3, "COMPOSITE_INERTIA": 9,
             "COMPOSITE_PRODUCT": 9},
    "momentum": {"PARENT_POSE": 12, "WORLD_POSE": 12, "MOMENTUM": 6},
}


def _columns(blocks):
    """Each column of the blocks {name: width}, with the names that claim it."""
    owners = {}
    for name, width in blocks.items():
        for column in range(getattr(L, name), getattr(L, name) + width):
            owners.setdefault(column, []).append(name)
    return owners


def test_every_column_of_the_tree_has_one_name():
    owners = _columns(P_BLOCKS)
    assert sorted(owners) == list(range(L.PARAMS))
    assert {column: names for column, names in owners.items() if len(names) > 1} == {}
    # the rigid inertia (m, h, I_O) is RIGID_INERTIA consecutive columns, in the composite's order in W
    assert (L.FIRST_MOMENT - L.MASS, L.INERTIA - L.MASS, L.RIGID_INERTIA) == (1, 4, 13)
    assert (L.COMPOSITE_MOMENT - L.COMPOSITE_MASS, L.COMPOSITE_INERTIA - L.COMPOSITE_MASS) == (1, 4)


@pytest.mark.parametrize("algorithm", sorted(W_BLOCKS))
def test_the_scratch_blocks_an_algorithm_holds_at_once_are_apart_and_inside_the_width(algorithm):
    owners = _columns(W_BLOCKS[algorithm])
    assert {column: names for column, names in owners.items() if len(names) > 1} == {}
    assert min(owners) == 0 and max(owners) < L.WIDTH


@pytest.mark.slow  # compiles the robot's kinematics (~2 CPU s on a cold cache)
def test_a_tree_holds_under_each_name_what_the_name_says():
    tree = robot.RobotTree.from_urdf(tumble.examples.path("panda.urdf"))
    P = tree.params
    masses = np.array([link.mass for link in tree.links])
    np.testing.assert_array_equal(P[:, L.MASS], masses)
    np.testing.assert_array_equal(P[:, L.PARENT], tree.parents)
    np.testing.assert_array_equal(P[:, L.COORDINATE], np.arange(tree.nv))
    np.testing.assert_array_equal(P[:, L.MULTIPLIER], np.ones(tree.nv))
    np.testing.assert_array_equal(P[:, L.JOINT_TYPE], L.REVOLUTE)
    np.testing.assert_array_equal(P[:, L.AXIS:L.AXIS + 3], np.tile([0.0, 0.0, 1.0], (tree.nv, 1)))
    for block in (L.JOINT_FRAME, L.USER_FRAME):  # rotations: orthonormal to a few roundings (≤ 5 eps)
        R = P[:, block:block + 9].reshape(-1, 3, 3)
        np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), rtol=0, atol=1e-15)
    I_O = P[:, L.INERTIA:L.INERTIA + 9].reshape(-1, 3, 3)
    # symmetric to the rounding of R_f I_c R_fᵀ (a few eps of its largest entry)
    np.testing.assert_allclose(I_O, I_O.transpose(0, 2, 1), rtol=0, atol=4 * EPS * np.abs(I_O).max())
    # h = m c about the canonical origin: the arm's centre of mass at q = 0 from the named columns, and from each
    # link's centre of mass (its own frame) placed by link_poses; the two differ by a few roundings of terms
    # under 1 m (≤ 5 eps)
    T = robot.link_poses(tree, tree.neutral())
    R_canonical = T[:, :3, :3] @ P[:, L.USER_FRAME:L.USER_FRAME + 9].reshape(-1, 3, 3).transpose(0, 2, 1)
    p_canonical = T[:, :3, 3] - np.einsum("bij,bj->bi", R_canonical, P[:, L.USER_FRAME + L.ORIGIN:L.USER_FRAME + 12])
    first = masses[:, None] * p_canonical + np.einsum("bij,bj->bi", R_canonical,
                                                      P[:, L.FIRST_MOMENT:L.FIRST_MOMENT + 3])
    links = masses[:, None] * (T[:, :3, 3] + np.einsum("bij,bj->bi", T[:, :3, :3], [link.com for link in tree.links]))
    np.testing.assert_allclose(first.sum(axis=0) / masses.sum(), links.sum(axis=0) / masses.sum(), rtol=0,
                               atol=1e-15)
