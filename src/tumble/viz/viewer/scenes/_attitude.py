"""The part of every scene of a body with an attitude: the body, its axes, ω and L, the trace of an axis.

For a trajectory with ``q`` (any model but a robot arm), at each frame:

* the body as a solid turned by ``R(q)`` (:func:`tumble.attitude.to_matrix`, body → inertial);
* its body axes, of length ``a`` = 1.5 × the body's half-diagonal ``s``;
* the angular velocity ``ω_I = R(q) ω`` and the angular momentum of the whole system ``L_I`` (the
  trajectory's ``momentum_inertial``) as arrows from the centre, each scaled so that its largest value
  over the run is ``1.3 s``: with no external torque ``L_I`` is constant and its arrow stands still;
* the trace of a chosen body axis (``axis``) on the sphere of radius ``a`` that its tip sweeps
  (the unit sphere, drawn at radius ``a``), with three great circles as a guide;
* beside it, the body rates ω (rad/s, body axes) against time and, for a free rigid body, the polhode:
  ω in principal axes on the energy ellipsoid ``ω·Iω = 2T`` (Landau & Lifshitz, *Mechanics*, §37).
"""

from __future__ import annotations

import numpy as np

from tumble import attitude
from tumble._inertia import principal_axes
from tumble.viz.viewer._scene import Lines, Panel, Polhode, Scene, Solid
from tumble.viz.viewer._shapes import Mesh, ellipsoid_mesh

__all__ = ["AXIS_COLORS", "attitude_scene", "rotations"]

AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")
_AXIS_LENGTH = 1.5   # body axes, × the half-diagonal
_ARROW_LENGTH = 1.3  # largest ω and L arrows, × the half-diagonal
_GUIDE_POINTS = 97


def rotations(q: np.ndarray) -> np.ndarray:
    """``R(q)`` (F, 3, 3) of the quaternions (F, 4): body → inertial."""
    return attitude.to_matrix(q)


def _arrow(name: str, vectors: np.ndarray, length: float, color: str, unit: str) -> tuple[Lines, str]:
    """An arrow per frame from the centre along ``vectors`` (F, 3), scaled so that the largest is ``length``."""
    largest = float(np.linalg.norm(vectors, axis=-1).max())
    scale = length / largest if largest > 0.0 else 0.0
    tips = np.stack([np.zeros_like(vectors), scale * vectors], axis=1)
    note = f"{name}: {scale:.4g} m per {unit}" if largest > 0.0 else f"{name}: zero throughout"
    return Lines(name, tips, color, width=6.0, markers=True), note


def _great_circles(radius: float) -> list[Lines]:
    angle = np.linspace(0.0, 2.0 * np.pi, _GUIDE_POINTS)
    c, s, z = radius * np.cos(angle), radius * np.sin(angle), np.zeros_like(angle)
    return [Lines("sphere", np.stack(points, -1)[None], "#c7c7c7", width=1.5, legend=False)
            for points in ((c, s, z), (c, z, s), (z, c, s))]


def _polhode(traj, idx) -> Polhode:
    """ω (F, 3) in principal axes and the energy ellipsoid of the first sample (semi-axes √(2T/Iₖ))."""
    _, moments, axes = principal_axes(traj.inertia, "inertia", check_triangle=False)
    omega = traj.omega[idx] @ axes  # components along the principal axes (columns of R_BP)
    two_t = float(traj.omega[0] @ traj.inertia @ traj.omega[0])
    return Polhode(ellipsoid_mesh(np.sqrt(two_t / moments)), omega)


def attitude_scene(traj, idx: np.ndarray, *, mesh: Mesh | None, mesh_note: str, axis: int, title: str,
                   body: str = "body", half: float | None = None) -> Scene:
    """The scene of the body of ``traj`` at the samples ``idx``, drawn as ``mesh`` (body axes, m); with ``mesh``
    None the caller draws the body and gives its half-diagonal ``half`` (m)."""
    R = rotations(traj.q[idx])
    if mesh is not None:
        half = float(np.linalg.norm(mesh.vertices, axis=-1).max())
    assert half is not None, "half: needed when the caller draws the body (mesh None)"
    a = _AXIS_LENGTH * half
    scene = Scene(title=title, t=traj.t[idx], sample=idx, samples=len(traj.t), extent=a,
                  notes=[f"{body}: {mesh_note}; body axes x, y, z (red, green, blue) drawn {a:.4g} m long"])
    if mesh is not None:
        scene.solids.append(Solid(body, mesh, R, np.zeros((1, 3)), "#f2a541"))
    for k, name in enumerate("xyz"):
        scene.lines.append(Lines(f"body {name}", np.stack([np.zeros((len(idx), 3)), a * R[:, :, k]], axis=1),
                                 AXIS_COLORS[k], width=5.0))
    omega_inertial = np.einsum("fij,fj->fi", R, traj.omega[idx])
    for name, vectors, color, unit in (("ω (angular velocity)", omega_inertial, "#9467bd", "rad/s"),
                                       ("L (angular momentum)", traj.momentum_inertial[idx], "#111111", "N m s")):
        line, note = _arrow(name, vectors, _ARROW_LENGTH * half, color, unit)
        scene.lines.append(line)
        scene.notes.append(note)
    scene.notes.append("L is that of the whole system: with no external torque it stands still in space")
    scene.lines.append(Lines(f"trace of body {'xyz'[axis]}", a * R[:, :, axis], AXIS_COLORS[axis], width=3.0,
                             trail=True))
    scene.lines.extend(_great_circles(a))
    scene.notes.append(f"the trace of body axis {'xyz'[axis]} on the unit sphere, drawn at radius {a:.4g} m")
    scene.panel = Panel("body rates", "ω, body axes (rad/s)",
                        [(f"ω{name}", traj.omega[idx, k], AXIS_COLORS[k]) for k, name in enumerate("xyz")])
    if traj.model in ("RigidBody", "RigidBodies") and traj.info.get("torque") == "none":
        scene.polhode = _polhode(traj, idx)
    return scene
