"""The scene of a spacecraft with flexible appendages: the hub and one panel per mode, bending with ηₖ.

The model's modes carry no mode shape, only the participation vector
``δₖ`` (the angular momentum per unit modal rate, body axes): a panel whose
deflection turns it about ``δ̂ₖ``. Panel ``k`` is drawn as a line from the
hub's surface along the body direction ``±uₖ ⊥ δ̂ₖ`` closest to a body axis (the modes alternate sides),
of length ``s`` (the hub's half-diagonal), bent along ``δ̂ₖ × uₖ`` by
``d(x) = g ηₖ (x/s)²`` — a picture of the deflection, not the mode shape —
with one gain ``g`` (m per kg^½·m) for all modes, chosen so that the largest
tip deflection is a quarter of ``s``, and stated on the page.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from tumble.flexible import FlexibleBody
from tumble.viz.viewer._scene import Lines, check_model
from tumble.viz.viewer.scenes._attitude import attitude_scene, rotations
from tumble.viz.viewer.scenes.rigid import hub_mesh

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer.scenes import Options

__all__ = ["scene"]

_POINTS = 9           # along each panel
_TIP = 0.25           # largest drawn tip deflection, × the panel length
_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def _panel_axes(delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``u`` ⊥ δ̂ (the body axis least along δ̂, made orthogonal) and the bending direction ``δ̂ × u``."""
    d = delta / np.linalg.norm(delta)
    e = np.eye(3)[int(np.argmin(np.abs(d)))]
    u = e - (e @ d) * d
    u /= np.linalg.norm(u)
    return u, np.cross(d, u)


def scene(traj: Trajectory, idx: np.ndarray, model: FlexibleBody | None, options: Options) -> Scene:
    check_model(model, (FlexibleBody,), traj)
    body = model.body if isinstance(model, FlexibleBody) else None
    mesh, note = hub_mesh(traj, body, options.shape)
    scene = attitude_scene(traj, idx, mesh=mesh, mesh_note=note, axis=options.axis, title=options.title, body="hub")
    if not isinstance(model, FlexibleBody):
        scene.notes.append("appendages not drawn: their participation vectors are in the model (pass model=)")
        return scene
    eta = traj.modal_coordinate[idx]
    length = float(np.linalg.norm(mesh.vertices, axis=-1).max())
    largest = float(np.abs(eta).max())
    gain = _TIP * length / largest if largest > 0.0 else 0.0
    x = np.linspace(0.0, 1.0, _POINTS)
    R = rotations(cast(np.ndarray, traj.q)[idx])
    for k, delta in enumerate(model.participation.T):
        u, bend = _panel_axes(delta)
        u, bend = (-1) ** k * u, (-1) ** k * bend   # modes alternate sides of the hub
        root = u * np.abs(mesh.vertices @ u).max()
        shape = root + length * x[:, None] * u                                      # (P, 3) undeformed
        points = shape + gain * eta[:, k, None, None] * (x**2)[:, None] * bend       # (F, P, 3)
        scene.lines.append(Lines(f"mode {k + 1} panel", np.einsum("fij,fpj->fpi", R, points),
                                 _COLORS[k % len(_COLORS)], width=8.0))
        scene.extent = max(scene.extent, 1.1 * float(np.linalg.norm(points, axis=-1).max()))
    scene.notes.append(f"panels: deflection exaggerated, {gain:.4g} m per kg^½·m of modal coordinate "
                       f"(largest tip deflection {_TIP:g} × the panel length); a picture, not the mode shape")
    return scene
