"""Kinematics of kinematic trees: poses of named frames, frame Jacobians, centre of mass, centroidal momentum.

Frames and conventions: :mod:`tumble.robot.tree`. All results are in world
(base) axes. A spatial velocity is written angular part first, ``(ω, v)``,
``v`` the velocity of the point named (a frame's origin), as in
Featherstone (2008) and the rest of :mod:`tumble.robot`. Computed in NumPy
from the body poses of the compiled forward kinematics
(:func:`tumble.kernels.featherstone.body_poses_batch`): these functions are
for analysis, not hot loops; :func:`centroidal_momentum`, which a
floating-base simulation evaluates at every output sample, is compiled.

* :func:`frame_poses`: ``T_WF`` (4, 4) of every named frame.
* :func:`frame_jacobian`: ``J`` (6, nv) with ``(ω_F, v_F) = J q̇`` in world
  axes (Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobian, rows reordered).
* :func:`center_of_mass`: ``c = Σ mᵢ cᵢ / Σ mᵢ`` (m).
* :func:`centroidal_momentum_matrix`: ``A_G`` (6, nv) with ``h_G = (k_G, l) =
  A_G q̇``, the angular momentum about the centre of mass and the linear
  momentum, world axes (Orin & Goswami, "Centroidal momentum matrix of a
  humanoid robot", ICRA 2008; Orin, Goswami & Lee, Auton. Robots 35, 2013).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tumble._validate import ValidationError
from tumble.kernels import featherstone as _kernels
from tumble.kernels.featherstone import layout as _columns
from tumble.robot.dynamics import _joints, _like
from tumble.robot.tree import RobotTree

__all__ = ["frame_poses", "frame_pose", "frame_jacobian", "center_of_mass", "centroidal_momentum_matrix",
           "centroidal_momentum"]


def _bodies(model: RobotTree, q) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (…, nb, 3, 3) and origin (…, nb, 3) of the canonical body frames in the world."""
    q = _joints(model, q, "q")
    nb = len(model._links)
    out = np.empty((*q.shape[:-1], nb, 12))
    _kernels.body_poses_batch(model._params, q.reshape(-1, model._nq), out.reshape(-1, nb, 12))
    return out[..., :9].reshape(*out.shape[:-1], 3, 3), out[..., 9:]


def _frame_in_canonical(model: RobotTree, frame) -> tuple[np.ndarray, np.ndarray]:
    """Pose of a named frame in its body's canonical frame (the body's user frame is ``(R_f, p_f)`` there)."""
    if frame.body < 0:
        return frame.rotation, frame.position
    P, F = model._params[frame.body], _columns.USER_FRAME
    Rf, pf = P[F:F + 9].reshape(3, 3), P[F + _columns.ORIGIN:F + 12]
    return Rf @ frame.rotation, pf + Rf @ frame.position


def _frame(model: RobotTree, name: str):
    for frame in model._frames:
        if frame.name == name:
            return frame
    raise ValidationError(f"frame: no frame named {name!r}; this robot has {list(model.frame_names)}")


def frame_poses(model: RobotTree, q: ArrayLike) -> np.ndarray:
    """Poses ``T_WF`` of every named frame (``model.frame_names`` order): (nf, 4, 4) or (B, nf, 4, 4).

    ``T = [[R, p], [0, 1]]``: ``R`` maps frame axes to world axes, ``p`` the frame origin (m), world frame.
    """
    R, p = _bodies(model, q)
    T = np.zeros((*R.shape[:-3], len(model._frames), 4, 4))
    T[..., 3, 3] = 1.0
    for k, frame in enumerate(model._frames):
        Rc, pc = _frame_in_canonical(model, frame)
        if frame.body < 0:
            T[..., k, :3, :3], T[..., k, :3, 3] = Rc, pc
        else:
            Rb, pb = R[..., frame.body, :, :], p[..., frame.body, :]
            T[..., k, :3, :3] = Rb @ Rc
            T[..., k, :3, 3] = pb + Rb @ pc
    return T


def frame_pose(model: RobotTree, q: ArrayLike, name: str) -> np.ndarray:
    """Pose ``T_WF`` (4, 4) or (B, 4, 4) of the frame ``name`` (see :func:`frame_poses`)."""
    index = model.frame_names.index(_frame(model, name).name)
    return frame_poses(model, q)[..., index, :, :]


def _ancestors(model: RobotTree, body: int) -> list[int]:
    chain = []
    while body >= 0:
        chain.append(body)
        body = model._parents[body]
    return chain


def _point_jacobian(model: RobotTree, R, p, body: int, x: np.ndarray) -> np.ndarray:
    """``J`` (6, nv): ``(ω, v_x)`` of body ``body`` and its point ``x`` (world) from ``q̇``, world axes."""
    P, c = model._params, _columns
    J = np.zeros((6, model._nv))
    for j in _ancestors(model, body):
        if P[j, c.JOINT_TYPE] == c.FREE:
            r = x - p[0]
            J[0:3, 0:3] = R[0]
            J[3:6, 0:3] = -np.cross(r, R[0].T).T  # v = (R ω_B) × r = −[r]× R ω_B
            J[3:6, 3:6] = R[0]
            continue
        v, k = int(P[j, c.COORDINATE]), P[j, c.MULTIPLIER]
        axis = R[j] @ P[j, c.AXIS:c.AXIS + 3]
        if P[j, c.JOINT_TYPE] == c.REVOLUTE:
            J[0:3, v] += k * axis
            J[3:6, v] += k * np.cross(axis, x - p[j])
        else:
            J[3:6, v] += k * axis
    return J


def frame_jacobian(model: RobotTree, q: ArrayLike, name: str) -> np.ndarray:
    """Jacobian ``J`` (6, nv) of the frame ``name``: ``(ω_F, v_F) = J(q) q̇``, world axes, ``v_F`` the velocity of
    the frame origin (m/s); one configuration ``q`` (nq,)."""
    q = _joints(model, q, "q", model._nq)
    if q.ndim != 1:
        raise ValidationError(f"q: frame_jacobian takes one configuration ({model._nq},), got {q.shape}")
    frame = _frame(model, name)
    R, p = _bodies(model, q)
    x = frame_pose(model, q, name)[:3, 3]
    if frame.body < 0:
        return np.zeros((6, model._nv))
    return _point_jacobian(model, R, p, frame.body, x)


def _mass_properties(model: RobotTree, R, p):
    """Masses (nb,), world centres of mass (nb, 3), world inertias about them (nb, 3, 3)."""
    P, c = model._params, _columns
    m = P[:, c.MASS]
    h = P[:, c.FIRST_MOMENT:c.FIRST_MOMENT + 3]
    c_local = np.divide(h, m[:, None], out=np.zeros_like(h), where=m[:, None] > 0)
    I_O = P[:, c.INERTIA:c.INERTIA + 9].reshape(-1, 3, 3)
    eye = np.eye(3)
    I_c = I_O - m[:, None, None] * (np.einsum("ij,ij->i", c_local, c_local)[:, None, None] * eye
                                    - np.einsum("ij,ik->ijk", c_local, c_local))
    com = p + np.einsum("bij,bj->bi", R, c_local)
    return m, com, np.einsum("bij,bjk,blk->bil", R, I_c, R)


def center_of_mass(model: RobotTree, q: ArrayLike) -> np.ndarray:
    """Centre of mass of the whole robot (3,) or (B, 3), m, world frame: ``Σ mᵢ cᵢ / Σ mᵢ``."""
    R, p = _bodies(model, q)
    P, c = model._params, _columns
    first = P[:, c.MASS, None] * p + np.einsum("...bij,bj->...bi", R, P[:, c.FIRST_MOMENT:c.FIRST_MOMENT + 3])
    return first.sum(axis=-2) / P[:, c.MASS].sum()


def centroidal_momentum_matrix(model: RobotTree, q: ArrayLike) -> np.ndarray:
    """Orin's centroidal momentum matrix ``A_G`` (6, nv): ``(k_G, l) = A_G(q) q̇``; one configuration.

    ``k_G = Σ [I_cᵢ ωᵢ + (cᵢ − c) × mᵢ v_cᵢ]`` (N·m·s) is the angular momentum
    about the centre of mass ``c``, ``l = Σ mᵢ v_cᵢ`` (N·s) the linear momentum,
    world axes; ``I_cᵢ`` the inertia of body i about its centre of mass ``cᵢ``.
    """
    q = _joints(model, q, "q", model._nq)
    if q.ndim != 1:
        raise ValidationError(f"q: centroidal_momentum_matrix takes one configuration ({model._nq},), got {q.shape}")
    R, p = _bodies(model, q)
    m, com, inertia = _mass_properties(model, R, p)
    c = (m[:, None] * com).sum(axis=0) / m.sum()
    A = np.zeros((6, model._nv))
    for i in range(len(model._links)):
        if m[i] == 0.0 and not inertia[i].any():
            continue
        J = _point_jacobian(model, R, p, i, com[i])
        linear = m[i] * J[3:6]
        A[0:3] += inertia[i] @ J[0:3] + np.cross(com[i] - c, linear.T).T
        A[3:6] += linear
    return A


def centroidal_momentum(model: RobotTree, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
    """``h_G = (k_G, l) = A_G(q) q̇`` (6,) or (B, 6): angular momentum about the centre of mass and linear
    momentum, world axes (N·m·s, N·s); one state (nq,), (nv,) or a batch (B, ·). Compiled, summed body by
    body (:func:`tumble.kernels.featherstone.centroidal_momentum_one`) without forming ``A_G``."""
    q = _joints(model, q, "q", model._nq)
    qd = _like(model, q, qd, "qd")
    h = np.empty((*q.shape[:-1], 6))
    _kernels.centroidal_momentum_batch(model._params, q.reshape(-1, model._nq), qd.reshape(-1, model._nv),
                                       h.reshape(-1, 6))
    return h
