"""The figure of a rigid body in an ideal fluid (:class:`tumble.fluid.KirchhoffBody`): velocities, path, integrals.

:func:`motion_figure` draws the velocity of the body origin (body axes), the angular velocity, the path of the
origin seen from the side (inertial x–z) and the relative change of the integrals of Kirchhoff's equations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tumble.fluid import KirchhoffBody

__all__ = ["motion_figure"]

_FLOOR = 1e-17  # where panel (d) draws a change below rounding (an exact 0 included)


def motion_figure(trajectory: Trajectory, model: KirchhoffBody) -> Figure:
    """Four panels: (a) ``v`` (m/s, body axes), (b) ``ω`` (rad/s, body axes), (c) the path of the origin in the
    inertial x–z plane (m), (d) the change of each invariant of ``model`` relative to its largest value over the
    run (log scale; ``K·P`` may start at zero)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 7), layout="constrained")
    (a, b), (c, d) = fig.subplots(2, 2)
    t, omega = trajectory.t, cast(np.ndarray, trajectory.omega)
    for k, name in enumerate("xyz"):
        a.plot(t, trajectory.velocity[:, k], label=f"v{name}")
        b.plot(t, omega[:, k], label=f"ω{name}")
    a.set(xlabel="t (s)", ylabel="m/s", title="(a) velocity of the body origin, body axes")
    b.set(xlabel="t (s)", ylabel="rad/s", title="(b) angular velocity, body axes")
    a.legend()
    b.legend()
    x = trajectory.position
    c.plot(x[:, 0], x[:, 2])
    c.plot(x[:1, 0], x[:1, 2], "ko", label="start")
    c.set(xlabel="x (m)", ylabel="z (m)", title="(c) path of the body origin, inertial")
    c.legend()
    for name, value in model.invariants(trajectory).items():
        change = np.abs(value - value[0]).reshape(len(t), -1).max(axis=-1)  # K·P may start at 0: scaled by its
        scale = max(float(np.abs(value).max()), np.finfo(float).tiny)         # largest value over the run
        d.semilogy(t, np.maximum(change / scale, _FLOOR), label=name)
    d.set(xlabel="t (s)", ylabel="|I − I₀| / max |I|", ylim=(0.5 * _FLOOR, None),
          title=f"(d) integrals of Kirchhoff's equations (0 drawn at {_FLOOR:g})")
    d.legend(fontsize="small")
    return fig
