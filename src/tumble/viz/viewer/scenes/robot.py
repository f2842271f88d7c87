"""The scene of a robot arm: its links from the forward kinematics of the chain at each frame.

A :class:`tumble.robot.SerialChain` has no single attitude: the trajectory
carries the joint coordinates (``joint_position``). The link frames' origins
``p_i(q)`` in the base frame come from :func:`tumble.robot.link_poses` (the
chain's forward kinematics: ``T_i = T_{i−1} · (R_o, p_o) · joint(q_i) · (R_f,
p_f)``, ``docs/robot.md``), and the arm is drawn as the polyline base → p₁ →
… → p_n, a marker on each joint frame; beside it, the joint coordinates
against time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tumble._validate import ValidationError
from tumble.robot import SerialChain, link_poses
from tumble.viz.viewer._scene import Lines, Panel, Scene, Solid, check_model
from tumble.viz.viewer._shapes import box_mesh

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer.scenes import Options

__all__ = ["joint_points", "scene"]

_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")


def joint_points(chain: SerialChain, q: np.ndarray) -> np.ndarray:
    """(F, n + 1, 3): the base origin, then the origin of each link frame (m, base axes) at the joints ``q`` (F, n)."""
    poses = link_poses(chain, q)
    return np.concatenate([np.zeros((len(q), 1, 3)), poses[:, :, :3, 3]], axis=1)


def scene(traj: Trajectory, idx: np.ndarray, model: SerialChain | None, options: Options) -> Scene:
    check_model(model, (SerialChain,), traj)
    if model is None:
        raise ValidationError("model: a SerialChain trajectory holds joint coordinates only; pass its chain "
                              "(model=chain) to draw the links by forward kinematics")
    q = traj.joint_position[idx]
    points = joint_points(model, q)
    reach = float(np.linalg.norm(points, axis=-1).max())
    reach = reach if reach > 0.0 else 1.0
    scene = Scene(title=options.title, t=traj.t[idx], sample=idx, samples=len(traj.t), extent=1.1 * reach, frame="base",
                  notes=["links: straight segments between the link frames' origins (forward kinematics of the "
                         "chain, tumble.robot.link_poses), a marker on each; base axes, m"])
    scene.solids.append(Solid("base", box_mesh(np.full(3, 0.08 * reach)), np.eye(3)[None], np.zeros((1, 3)),
                              "#7f7f7f"))
    scene.lines.append(Lines("links", points, "#333333", width=12.0, markers=True))
    names = [f"q{k + 1}" for k in range(q.shape[1])]
    scene.panel = Panel("joint coordinates", "q (rad or m)",
                        [(name, q[:, k], _COLORS[k % len(_COLORS)]) for k, name in enumerate(names)])
    return scene
