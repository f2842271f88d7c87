"""The scene of a spacecraft: hub, reaction wheels spinning, CMG rotors on their gimbals, thruster firings, and
the nadir and orbit-normal directions when there is an orbit.

Drawn from the :class:`tumble.spacecraft.Spacecraft` (its parts) and its trajectory, all turned by the hub's
``R(q)``:

* the hub: the user's shape, else the equivalent box of ``hub`` (without wheels) or of the total inertia;
* wheel ``i``: a disk on its axis ``a_i`` at its ``position`` (less the centre of mass), or, without one,
  just outside the hub on its axis; its spin angle relative to the hub ``θ_i(t) = ∫ Ω_i dt`` is the
  trapezoidal integral of the sampled ``wheel_speed`` over every sample (exact for speeds linear between
  samples), shown by a spoke; a disk at ``θ`` has axes ``Rot(a_i, θ) Z(a_i)``, ``Z`` taking z onto ``a_i``;
* CMG ``i``: its rotor disk on the spin axis ``s_i(δ) = cos δ s0_i + sin δ (g_i × s0_i)``, axes
  ``Rot(g_i, δ) Z(s0_i)``, and its gimbal axis ``g_i`` as a line, just outside the hub along ``g_i``;
* thruster ``i``: a plume from its position against its direction while ``thruster_firing`` is 1;
* a residual dipole ``m``: a line from the centre of mass along ``m/|m|`` (body axes);
* flexible mode ``k``: a line from the centre of mass along its participation axis ``δ_k/|δ_k|`` (body axes;
  the appendages' geometry is not in the model) of length ``(1 + ½ η_k/max|η_k|)`` × its base length, so
  that it swings with the mode;
* slosh tank ``k``: its pendulum's rod from the hinge ``b_k`` to the slosh mass at ``b_k + l_k s_k(t)``
  (body axes, from the hub's centre of mass), the mass a marker;
* with an orbit (or an environment): the nadir ``−r/|r|`` and the orbit normal ``r × v/|r × v|`` (inertial
  axes);
* with an environment: the direction of the Sun ``ŝ`` (inertial axes), hidden while the craft is in the
  umbra (``ν = 0``) and drawn shorter in the penumbra (length ∝ ν);
* the facets of the solar pressure and drag parts: each a short line along its normal from its centre of
  pressure (body axes).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from tumble.kernels.spacecraft import environment_table as _table
from tumble.spacecraft import Orbit, Spacecraft
from tumble.viz.viewer._scene import Lines, Solid, check_model
from tumble.viz.viewer._shapes import Mesh, box_mesh, cylinder_mesh, turn_z_to
from tumble.viz.viewer.scenes._attitude import attitude_scene, rotations
from tumble.viz.viewer.scenes.rigid import hub_mesh

if TYPE_CHECKING:
    from tumble.trajectory import Trajectory
    from tumble.viz.viewer._scene import Scene
    from tumble.viz.viewer.scenes import Options

__all__ = ["scene", "spin_angles"]

_DISK = (0.22, 0.07)     # wheel and rotor disk radius and thickness, × the hub's half-diagonal
_OUTSIDE = 1.05          # a part without a position sits at this × the half-diagonal along its axis
_PLUME = 0.5             # plume length, × the half-diagonal
_DIPOLE = 1.3            # residual-dipole line length, × the half-diagonal
_MODE = 1.2              # flexible-mode line base length, × the half-diagonal
_SUN = 1.9               # Sun-direction line length in full sunlight, × the half-diagonal
_NORMAL = 0.35           # facet-normal line length, × the half-diagonal


def spin_angles(t: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """``θ(t) = ∫ Ω dt`` from ``t[0]`` (rad), trapezoidal over the samples: ``t`` (n,), ``speed`` (n, k) rad/s."""
    steps = 0.5 * (speed[1:] + speed[:-1]) * np.diff(t)[:, None]
    return np.concatenate([np.zeros((1, speed.shape[1])), np.cumsum(steps, axis=0)])


def _about(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (F, 3, 3) by ``angle`` (F,) about the unit ``axis`` (3,): Rodrigues' formula."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle)[:, None, None] * k + (1.0 - np.cos(angle))[:, None, None] * (k @ k)


def _rotor(radius: float, thickness: float) -> tuple[Mesh, Mesh]:
    """A disk along z and its spoke (a bar along x standing proud of the disk's faces)."""
    spoke = box_mesh([radius, 0.25 * radius, 1.6 * thickness]).moved(np.eye(3), [0.5 * radius, 0.0, 0.0])
    return cylinder_mesh(radius, thickness), spoke


def _modes(scene: Scene, participation: np.ndarray, eta: np.ndarray, R: np.ndarray, length: float) -> None:
    """One line per flexible mode along ``δ_k/|δ_k|`` (body axes, turned by ``R``: (F, 3, 3)), of length
    ``length (1 + ½ η_k/max|η_k|)`` at the frames (``eta``: (F, m))."""
    peak = np.abs(eta).max(axis=0)
    swing = 1.0 + 0.5 * np.divide(eta, peak, out=np.zeros_like(eta), where=peak > 0.0)
    for k, delta in enumerate(participation):
        norm = float(np.linalg.norm(delta))
        if norm == 0.0:
            continue
        tips = length * swing[:, k, None] * np.einsum("fij,j->fi", R, delta / norm)
        scene.lines.append(Lines(f"flexible mode {k + 1}", np.stack([np.zeros_like(tips), tips], axis=1),
                                 "#bcbd22", width=4.0, markers=True))
    scene.notes.append("flexible modes: a line along each participation axis δ_k/|δ_k| (the appendages' geometry "
                       "is not in the model), its length swinging with the modal coordinate η_k/max|η_k|")


def scene(traj: Trajectory, idx: np.ndarray, model: Spacecraft | None, options: Options) -> Scene:
    check_model(model, (Spacecraft,), traj)
    craft = model if isinstance(model, Spacecraft) else None
    body = None if craft is None else (craft.hub if craft.hub is not None else craft.body)
    mesh, note = hub_mesh(traj, body, options.shape)
    scene = attitude_scene(traj, idx, mesh=mesh, mesh_note=note, axis=options.axis, title=options.title, body="hub")
    if craft is None:
        scene.notes.append("wheels, gyros and thrusters not drawn: their geometry is in the model (pass model=)")
        return scene
    half = float(np.linalg.norm(mesh.vertices, axis=-1).max())
    com = np.zeros(3) if craft.body.com is None else craft.body.com
    R = rotations(cast(np.ndarray, traj.q)[idx])
    disk, spoke = _rotor(_DISK[0] * half, _DISK[1] * half)
    if craft.wheels:
        theta = spin_angles(traj.t, traj.wheel_speed)[idx]
        for i, wheel in enumerate(craft.wheels):
            where = (wheel.position - com) if wheel.position is not None else _OUTSIDE * half * wheel.axis
            axes = R @ _about(wheel.axis, theta[:, i]) @ turn_z_to(wheel.axis)
            position = np.einsum("fij,j->fi", R, where)
            scene.solids.append(Solid(f"wheel {i + 1}", disk, axes, position, "#7f7f7f"))
            scene.solids.append(Solid(f"wheel {i + 1} spoke", spoke, axes, position, "#ffffff", legend=False))
        scene.notes.append("wheels: disks on their axes (at their positions, or just outside the hub); the spoke "
                           "turns by the spin angle relative to the hub, the integral of the sampled wheel speed "
                           "(at the frames: a fast wheel aliases)")
    if craft.cmgs is not None:
        gimbal = traj.gimbal_angle[idx]
        for i, (g, s0) in enumerate(zip(craft.cmgs.gimbal_axes, craft.cmgs.spin_axes)):
            where = _OUTSIDE * half * g
            axes = R @ _about(g, gimbal[:, i]) @ turn_z_to(s0)
            position = np.einsum("fij,j->fi", R, where)
            scene.solids.append(Solid(f"CMG {i + 1} rotor", disk, axes, position, "#8c564b"))
            ends = np.array([where - 0.4 * half * g, where + 0.4 * half * g])
            scene.lines.append(Lines(f"CMG {i + 1} gimbal axis", np.einsum("fij,pj->fpi", R, ends), "#8c564b",
                                     width=3.0, legend=False))
        scene.notes.append("CMGs: each rotor disk spins about s(δ), turned about its gimbal axis (line) by the "
                           "gimbal angle δ")
    if craft.thrusters:
        firing = traj.thruster_firing[idx] > 0.5
        for i, thruster in enumerate(craft.thrusters):
            ends = np.array([thruster.position - com, thruster.position - com - _PLUME * half * thruster.direction])
            plume = np.einsum("fij,pj->fpi", R, ends)
            plume[~firing[:, i]] = np.nan
            scene.lines.append(Lines(f"thruster {i + 1} firing", plume, "#ff7f0e", width=9.0))
        scene.notes.append("thrusters: a plume (against the thrust) while the thruster fires")
    if craft.residual_dipole is not None and np.any(craft.residual_dipole.dipole):
        m = craft.residual_dipole.dipole / np.linalg.norm(craft.residual_dipole.dipole)
        ends = np.array([np.zeros(3), _DIPOLE * half * m])
        scene.lines.append(Lines("residual dipole", np.einsum("fij,pj->fpi", R, ends), "#9467bd", width=5.0,
                                 markers=True))
        scene.notes.append("residual dipole: its direction m/|m| from the centre of mass, fixed in the body")
    if craft.flexible_modes is not None:
        _modes(scene, craft.flexible_modes.participation, traj.modal_coordinate[idx], R, _MODE * half)
    if craft.slosh:
        direction = traj.pendulum_direction[idx]
        for k, tank in enumerate(craft.slosh):
            ends = np.stack([np.broadcast_to(tank.hinge, direction[:, k].shape),
                             tank.hinge + tank.length * direction[:, k]], axis=1)
            scene.lines.append(Lines(f"slosh pendulum {k + 1}", np.einsum("fij,fpj->fpi", R, ends), "#1f77b4",
                                     width=4.0, markers=True))
        scene.notes.append("slosh: each tank's pendulum rod from its hinge to the slosh mass (marker)")
    facets = {id(f): f for part in (craft.solar_pressure, craft.drag) if part is not None for f in part.facets}
    for i, facet in enumerate(facets.values()):
        centre, normal = np.asarray(facet.centre), np.asarray(facet.normal)
        ends = np.array([centre, centre + _NORMAL * half * normal])
        scene.lines.append(Lines("facet normals", np.einsum("fij,pj->fpi", R, ends), "#17becf", width=3.0,
                                 legend=i == 0))
    if facets:
        scene.notes.append("facets: a line along each facet's normal from its centre of pressure")
    env = craft.environment
    if craft.orbit is not None or env is not None:
        if env is not None:
            rows = env.at(np.clip(traj.t[idx], 0.0, env.t[-1]))
            r, v = rows[:, _table.POSITION:_table.POSITION + 3], rows[:, _table.VELOCITY:_table.VELOCITY + 3]
        else:
            r, v = cast(Orbit, craft.orbit).state(traj.t[idx])
        normal = np.cross(r, v)
        for name, direction, color in (("nadir", -r, "#2ca02c"), ("orbit normal", normal, "#e377c2")):
            unit = direction / np.linalg.norm(direction, axis=-1, keepdims=True)
            scene.lines.append(Lines(name, np.stack([np.zeros_like(unit), 1.6 * half * unit], axis=1), color,
                                     width=3.0, markers=True))
        scene.notes.append("nadir −r/|r| and orbit normal r × v/|r × v| of the orbit, inertial axes")
    if env is not None:
        sun, lit = rows[:, _table.SUN_DIRECTION:_table.SUN_DIRECTION + 3], rows[:, _table.SHADOW]
        line = np.stack([np.zeros_like(sun), _SUN * half * lit[:, None] * sun], axis=1)
        line[lit == 0.0] = np.nan
        scene.lines.append(Lines("Sun", line, "#ffbf00", width=5.0, markers=True))
        scene.notes.append("Sun: its direction, inertial axes, as long as the fraction of the solar disc seen "
                           "(hidden in the Earth's umbra)")
    for solid in scene.solids[1:]:
        reach = np.linalg.norm(solid.position, axis=-1).max() + np.linalg.norm(solid.mesh.vertices, axis=-1).max()
        scene.extent = max(scene.extent, 1.1 * float(reach))
    return scene
