"""What a page shows, as plain arrays: the scene a model's builder makes and the page's script draws.

Every quantity is computed here, in Python, at the frames (the decimated
samples): the page's script only applies it. Frames ``f = 0 … F − 1`` are at
the times ``t[f]`` (s); all 3-D positions are in inertial axes, m, about the
centre of mass of the body (or the base of a robot arm):

* a :class:`Solid` is a mesh (vertices in its own axes) drawn at
  ``w = R[f] v + p[f]`` with ``R[f]`` its own axes → inertial (for the body,
  ``R(q(t))`` of :func:`tumble.attitude.to_matrix`) and ``p[f]`` where its
  origin is;
* a :class:`Lines` is a polyline per frame (arrows are lines from a point to a
  tip), or a trail that grows with the frames (the trace of a body axis);
* a :class:`Panel` is a set of curves against time beside the scene, with a
  cursor at the frame shown; a :class:`Polhode` is the body rate on the
  energy ellipsoid of a free rigid body, in principal axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tumble._validate import ValidationError
from tumble.viz.viewer._shapes import Mesh

__all__ = ["Lines", "Panel", "Polhode", "Scene", "Solid", "as_json", "check_model"]


def check_model(model, kinds: tuple, traj) -> None:
    """Refuse a ``model`` that is neither None nor one of ``kinds`` (classes) for the trajectory ``traj``."""
    if model is not None and not isinstance(model, kinds):
        names = " or ".join(kind.__name__ for kind in kinds)
        raise ValidationError(f"model: a {traj.model} trajectory is drawn with a {names} (or None), "
                              f"got a {type(model).__name__}")


@dataclass
class Solid:
    """A mesh at a pose per frame: ``rotation`` (F, 3, 3) or (1, 3, 3) own axes → inertial, ``position`` (F, 3)
    or (1, 3), m (one row: the same at every frame)."""

    name: str
    mesh: Mesh
    rotation: np.ndarray
    position: np.ndarray
    color: str
    opacity: float = 1.0
    legend: bool = True


@dataclass
class Lines:
    """``points`` (F, P, 3) or (1, P, 3), m: a polyline per frame (NaN breaks it); with ``trail``, ``points``
    (F, 3) drawn from the first frame to the one shown."""

    name: str
    points: np.ndarray
    color: str
    width: float = 4.0
    trail: bool = False
    markers: bool = False
    legend: bool = True


@dataclass
class Panel:
    """Curves against time beside the scene: ``series`` is a list of (name, values (F,), colour)."""

    title: str
    unit: str
    series: list


@dataclass
class Polhode:
    """The body rate (F, 3), rad/s, principal axes, on the energy ellipsoid ``ω·Iω = 2T`` (a mesh)."""

    ellipsoid: Mesh
    points: np.ndarray


@dataclass
class Scene:
    """Everything a page shows: frame times ``t`` (F,) s, their sample indices ``sample`` (F,) of ``samples``,
    the 3-D parts, the half-width ``extent`` (m) of the cube they are drawn in and the ``frame`` of its axes
    ("inertial", or "base" for a robot arm), the panel, the polhode, and
    ``notes``: sentences the page prints under the scene (what is drawn, at which scale)."""

    title: str
    t: np.ndarray
    sample: np.ndarray
    samples: int
    extent: float
    frame: str = "inertial"
    solids: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    panel: Panel | None = None
    polhode: Polhode | None = None
    notes: list = field(default_factory=list)


#: Playback speeds offered (multiples of real time).
SPEEDS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
#: The default speed plays the run in about this long (s of wall time).
PLAY_SECONDS = 20.0


def _plain(a) -> list:
    """An array as nested lists, NaN as None (JSON null)."""
    a = np.asarray(a, dtype=np.float64)
    if np.isnan(a).any():
        plain = a.astype(object)
        plain[np.isnan(a)] = None
        return plain.tolist()
    return a.tolist()


def default_speed(duration: float) -> float:
    """The smallest offered speed that plays ``duration`` (s of simulated time) in at most ``PLAY_SECONDS``."""
    return next((s for s in SPEEDS if duration / s <= PLAY_SECONDS), SPEEDS[-1])


def as_json(scene: Scene) -> dict:
    """The scene as the JSON document the page's script reads."""
    duration = float(abs(scene.t[-1] - scene.t[0]))
    doc = {
        "title": scene.title,
        "t": _plain(scene.t),
        "sample": [int(k) for k in scene.sample],
        "samples": int(scene.samples),
        "range": 1.05 * float(scene.extent),
        "frame": scene.frame,
        "speeds": list(SPEEDS),
        "speed": default_speed(duration),
        "solids": [{"name": s.name, "vertices": _plain(s.mesh.vertices), "faces": s.mesh.faces.tolist(),
                    "rotation": _plain(s.rotation), "position": _plain(s.position), "color": s.color,
                    "opacity": s.opacity, "legend": s.legend} for s in scene.solids],
        "lines": [{"name": line.name, "points": _plain(line.points), "color": line.color, "width": line.width,
                   "trail": line.trail, "markers": line.markers, "legend": line.legend} for line in scene.lines],
        "panel": None if scene.panel is None else {
            "title": scene.panel.title, "unit": scene.panel.unit,
            "series": [{"name": name, "values": _plain(values), "color": color}
                       for name, values, color in scene.panel.series]},
        "polhode": None if scene.polhode is None else {
            "ellipsoid": {"vertices": _plain(scene.polhode.ellipsoid.vertices),
                          "faces": scene.polhode.ellipsoid.faces.tolist()},
            "points": _plain(scene.polhode.points),
            "range": 1.15 * float(np.abs(scene.polhode.ellipsoid.vertices).max())},
        "notes": list(scene.notes),
    }
    return doc
