"""The offline 3-D viewer: one self-contained HTML file that shows any trajectory moving.

    tumble.viz.viewer.write_html(traj, "run.html", model=craft)       # or traj.to_html("run.html", model=craft)
    tumble view run.nc -o run.html [--scenario run.toml]          # the command line

The page draws, frame by frame, the body as a solid (the user's shape, or
the uniform box with the body's principal moments), its body axes, the
angular velocity ω and the angular momentum L as arrows (L stands still in
space when no torque acts), the trace of a body axis on the unit sphere,
and each model's own parts: a spacecraft's wheels spinning, CMG gimbals,
thruster firings, nadir and orbit normal; a robot arm's links from the
chain's forward kinematics; a diver's segments; a flexible panel's
deflection and a slosh pendulum (``tumble.viz.viewer.scenes``). Beside it: the
body rates against time with a cursor and, for a free rigid body, the
polhode on the energy ellipsoid; controls: play/pause, speed, a time
slider, the time and the frame shown.

The page embeds plotly.js from the ``plotly`` package: it makes no network
request and opens by double-click, offline. Long runs are decimated to a
frame budget (default 600 frames, :mod:`._frames`); a default page is about
5 MB (sizes per demo in ``docs/viewer.md``). Everything drawn is computed here
in Python; the page's script only applies it (``w = R v + p``). Conventions:
SI units, positions in inertial axes about the centre of mass (a robot's
base axes), ``R(q)`` body → inertial.
"""

from __future__ import annotations

import html
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble._validate import ValidationError
from tumble._files import write_atomic
from tumble.trajectory import Trajectory, load
from tumble.viz.viewer._frames import DEFAULT_FRAMES, check_budget, frame_indices
from tumble.viz.viewer._page import document
from tumble.viz.viewer._scene import Scene, as_json
from tumble.viz.viewer._shapes import Box, Cylinder
from tumble.viz.viewer.scenes import BUILDERS, Options

if TYPE_CHECKING:
    from tumble.simulate import Model
    from tumble.variable.human import Human

__all__ = ["DEFAULT_FRAMES", "Box", "Cylinder", "html_page", "notebook_html", "scene", "write_html"]

_AXES = {"x": 0, "y": 1, "z": 2}


def _trajectory(traj) -> Trajectory:
    """``traj`` itself, or the trajectory saved at the path ``traj``; anything else refused naming the rule."""
    if isinstance(traj, Trajectory):
        return traj
    if not isinstance(traj, (str, os.PathLike)):
        raise ValidationError(f"traj: must be a tumble.Trajectory or the path of one saved by Trajectory.save, "
                              f"got {type(traj).__name__}")
    try:
        return load(traj)
    except ValidationError as exc:
        cause = exc.__cause__  # load names the file; the error of the field it read is the cause
        if isinstance(cause, ValidationError) and cause.field == "t" and "got shape (0,)" in cause.rule:
            raise ValidationError(f"traj: {os.fspath(traj)!r} is an empty trajectory (no samples): nothing to show") \
                from None
        raise ValidationError(f"traj: {os.fspath(traj)!r} is not a tumble trajectory ({exc})") from None
    except (OSError, ValueError) as exc:
        raise ValidationError(f"traj: {os.fspath(traj)!r} is not a tumble trajectory (not a NetCDF file written "
                              f"by Trajectory.save: {type(exc).__name__})") from None


def _axis(axis, traj: Trajectory) -> int:
    """The body axis whose trace is drawn: ``"x"``, ``"y"``, ``"z"``, or None: the one along which ω(0) is largest."""
    if axis is None:
        return 0 if traj.omega is None else int(np.argmax(np.abs(traj.omega[0])))
    if axis not in _AXES:
        raise ValidationError(f"axis: must be 'x', 'y', 'z' or None, got {axis!r}")
    return _AXES[axis]


def scene(traj: Trajectory | str | os.PathLike[str], *, model: Model | Human | None = None,
          frames: int = DEFAULT_FRAMES, axis: str | None = None,
          shape: Box | Cylinder | Sequence[Box | Cylinder] | None = None) -> Scene:
    """The :class:`~tumble.viz.viewer._scene.Scene` of a trajectory (what the page draws), refusing what it cannot show.

    traj   : a :class:`tumble.Trajectory` (one run, not a batch: ``traj.member(i)`` picks one) or the path of one
    model  : the model that made it, for what the trajectory cannot tell (a robot's links, a spacecraft's
             wheels, a diver's segments); its class must be ``traj.model``
    frames : the frame budget, a whole number ≥ 2: at most this many samples are shown
    axis   : the body axis whose trace on the unit sphere is drawn ("x", "y", "z"; None: the one along ω(0))
    shape  : a :class:`Box`, a :class:`Cylinder` or a list of them: the body's shape (body reference axes, m)
    """
    budget = check_budget(frames)
    traj = _trajectory(traj)
    if traj.batch_size is not None:
        raise ValidationError(f"traj: a batch of {traj.batch_size} runs; view one run with traj.member(i)")
    builder = BUILDERS.get(traj.model)
    if builder is None:  # a model with no scene of its own: drawn from its attitude; its model adds nothing
        if traj.q is None:
            raise ValidationError(f"traj: a {traj.model or 'model'} trajectory without an attitude has no scene")
        if model is not None and type(model).__name__ != traj.model:
            raise ValidationError(f"model: the trajectory was made by a {traj.model or 'model'}, "
                                  f"got a {type(model).__name__}")
        builder, model = BUILDERS["RigidBody"], None
    idx = frame_indices(len(traj), budget)
    title = (f"{traj.model or 'trajectory'}: {traj.method or 'unknown method'}, t = {traj.t[0]:g} … {traj.t[-1]:g} s, "
             f"{len(traj)} samples")
    return builder(traj, idx, model, Options(_axis(axis, traj), shape, title))


def html_page(traj: Trajectory | str | os.PathLike[str], **options: Any) -> str:
    """The page (one HTML document) of a trajectory; ``options`` are those of :func:`scene`."""
    return document(as_json(scene(traj, **options)))


def write_html(traj: Trajectory | str | os.PathLike[str], path: str | os.PathLike[str], **options: Any) -> None:
    """Write the page of a trajectory to ``path`` atomically (:func:`tumble.trajectory.write_atomic`).

    ``options`` are those of :func:`scene`. Bad input (not a trajectory, an empty one, a frame budget < 2, a
    batch, a model that did not make it) raises :class:`tumble.ValidationError` naming the field and the
    rule, before anything is written.
    """
    page = html_page(traj, **options)
    write_atomic(path, lambda tmp: _write_text(tmp, page))


def _write_text(path: str, text: str) -> None:
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)


def notebook_html(traj: Trajectory | str | os.PathLike[str], **options: Any) -> str | None:
    """The page in an ``<iframe srcdoc=…>`` for a notebook cell (Jupyter's ``_repr_html_``), or None (the text
    repr) for a trajectory that cannot be drawn without its model (a robot arm)."""
    try:
        page = html_page(traj, **options)
    except ValidationError:
        return None
    return (f'<iframe srcdoc="{html.escape(page, quote=True)}" style="width: 100%; height: 760px; border: 0" '
            f'sandbox="allow-scripts"></iframe>')
