"""Pinocchio as the live oracle of tumble.robot: one URDF read by both, and the maps between their coordinates.

Used by tests/robot/test_robot_tree.py and tests/robot/test_robot_zoo.py. Tumble's coordinates: a floating base's
``[r, quat wxyz]`` and ``(ω, v)`` first, then one coordinate per independent 1-dof joint. Pinocchio's: the
free flyer's ``[r, quat xyzw]`` and ``(v, ω)``, and a continuous joint as ``(cos θ, sin θ)`` in ``q`` (one
coordinate in ``v``). Joints are matched by name, so the two orders of the joints may differ.
"""

from importlib import metadata
from pathlib import Path

import numpy as np

from tumble import robot

ERD = Path(metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share/example-robot-data/robots"))


def close(actual, expected, tol):
    """``|actual − expected| ≤ tol · max(1, max |expected|)``: absolute below 1, relative to the scale above."""
    scale = max(1.0, float(np.abs(expected).max()))
    np.testing.assert_allclose(actual, expected, rtol=0, atol=tol * scale)


class Pair:
    """One robot as a tumble RobotTree and a Pinocchio model, with the maps between their coordinates.

    ``options`` go to :meth:`tumble.robot.RobotTree.from_urdf` (``inertia``, ``min_inertia``, ...)."""

    def __init__(self, path, floating, mimic, **options):
        import pinocchio as pin

        self.tree = robot.RobotTree.from_urdf(path, floating_base=floating, mimic=mimic, check_triangle=False,
                                              **options)
        root = (pin.JointModelFreeFlyer(),) if floating else ()
        self.model = pin.buildModelFromUrdf(str(path), *root, mimic=mimic)
        self.data = self.model.createData()
        self.floating = floating
        self.mimic = mimic
        # Pinocchio's joint of each of tumble's joint coordinates, found by joint name
        joints = {self.model.names[j]: self.model.joints[j] for j in range(1, self.model.njoints)
                  if self.model.joints[j].nv == 1}
        matched = [joints[n] for n in self.tree.joint_names]
        self.v_of = np.array([j.idx_v for j in matched], dtype=int)
        self.q_of = np.array([j.idx_q for j in matched], dtype=int)
        self.unbounded = np.array([j.nq == 2 for j in matched], dtype=bool)  # continuous: q = (cos θ, sin θ)
        assert self.model.nv == self.tree.nv

    def states(self, seed, count):
        """``count`` random (q, v, a) in tumble's coordinates."""
        rng = np.random.default_rng(seed)
        out = []
        for _ in range(count):
            joints = rng.uniform(-np.pi, np.pi, self.tree.dof)
            base = rng.standard_normal(7) if self.floating else np.zeros(0)
            if self.floating:
                base[3:7] /= np.linalg.norm(base[3:7])
            q = np.concatenate([base, joints])
            v, a = rng.standard_normal((2, self.tree.nv))
            out.append((q, v, a))
        return out

    def to_pin_q(self, q):
        out = np.zeros(self.model.nq)
        if self.floating:
            out[0:3], out[3:6], out[6] = q[0:3], q[4:7], q[3]  # quaternion [x, y, z, w]
        theta = q[7 * self.floating:]
        out[self.q_of] = np.where(self.unbounded, np.cos(theta), theta)
        out[self.q_of[self.unbounded] + 1] = np.sin(theta[self.unbounded])
        return out

    def to_pin_v(self, v):
        """Tumble's (ω, v_B, joints) as Pinocchio's (v_B, ω, joints); forces likewise (n, f) → (f, n)."""
        out = np.zeros(self.model.nv)
        if self.floating:
            out[0:3], out[3:6] = v[3:6], v[0:3]
        out[self.v_of] = v[6 * self.floating:]
        return out

    def from_pin_v(self, x):
        out = np.zeros(self.tree.nv)
        if self.floating:
            out[0:3], out[3:6] = x[3:6], x[0:3]
        out[6 * self.floating:] = x[self.v_of]
        return out

    def from_pin_matrix(self, M):
        """Pinocchio's M (upper triangle filled) in tumble's coordinates."""
        M = np.triu(M) + np.triu(M, 1).T
        order = np.concatenate([[3, 4, 5, 0, 1, 2] if self.floating else [], self.v_of]).astype(int)
        return M[np.ix_(order, order)]
