"""The flexible spacecraft's figure and demo: a rest-to-rest slew, flexible hub against the rigid body.

:func:`slew_figure` draws the slew angle and rate, the modal coordinates and the pointing jitter after the
manoeuvre; :func:`demo_flexible` runs the slew of :data:`tumble.flexible.DEMO_BODY` (``tumble demo flexible``,
``docs/flexible.md``).
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

import numpy as np

import tumble
from tumble._files import write_atomic
from tumble.flexible import DEMO_BODY, slew_angle, slew_torque
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_flexible", "slew_figure"]

_DEMO_SLEW = dict(angle=math.radians(30.0), duration=40.0, ramp=0.4)  # rad, s, s
_DEMO_SETTLE = 60.0  # s simulated after the manoeuvre
_DEMO_TOLERANCE = 1e-11  # rtol = atol of the demo runs
_ARCSEC = math.radians(1.0 / 3600.0)


def demo_flexible(out_dir: str | os.PathLike[str]) -> dict:
    """A 30° rest-to-rest slew of :data:`DEMO_BODY` (40 s, bang-bang with 0.4 s ramps), flexible vs rigid.

    Integrates with dop853 (rtol = atol = 1e-11) through the manoeuvre and 60 s after it,
    writes ``out_dir/flexible.nc`` (the flexible trajectory with its modal coordinates) and
    ``out_dir/flexible.png`` (:func:`slew_figure`) and ``out_dir/flexible.html`` (the offline viewer,
    :mod:`tumble.viz.viewer`) atomically and returns a summary: the peak
    torque (N·m), the residual modal amplitudes after the manoeuvre (kg^½·m), the pointing
    jitter (peak and RMS, arcsec) and rate jitter (peak, arcsec/s) of the flexible hub after
    the manoeuvre, the final pointing error of the rigid body (arcsec), the largest total
    angular momentum left after the manoeuvre (N·m·s) and the paths written.
    """
    out_directory(out_dir)
    fbody = DEMO_BODY
    T = _DEMO_SLEW["duration"]
    torque = slew_torque([0.0, 0.0, 1.0], inertia=fbody.body.inertia[2, 2], **_DEMO_SLEW)
    t = np.linspace(0.0, T + _DEMO_SETTLE, int(20 * (T + _DEMO_SETTLE)) + 1)
    flexible = tumble.simulate(fbody, np.zeros(3), t=t, torque=torque, method="dop853", rtol=_DEMO_TOLERANCE,
                               atol=_DEMO_TOLERANCE)
    rigid = tumble.simulate(fbody.body, np.zeros(3), t=t, torque=torque, method="dop853", rtol=_DEMO_TOLERANCE,
                            atol=_DEMO_TOLERANCE)
    assert flexible.q is not None and flexible.omega is not None and rigid.q is not None  # both have an attitude

    after = t >= T
    error = (slew_angle(flexible.q) - _DEMO_SLEW["angle"])[after] / _ARCSEC
    eta = flexible.modal_coordinate[after]
    summary = {
        "peak_torque": float(np.abs(torque.torque).max()),
        "residual_modal_amplitude": np.abs(eta).max(axis=0).tolist(),
        "jitter_peak_arcsec": float(np.abs(error).max()),
        "jitter_rms_arcsec": float(np.sqrt(np.mean((error - error.mean()) ** 2))),
        "rate_jitter_peak_arcsec_per_s": float(np.abs(flexible.omega[after, 2]).max() / _ARCSEC),
        "rigid_pointing_error_arcsec": float(abs(slew_angle(rigid.q[-1]) - _DEMO_SLEW["angle"]) / _ARCSEC),
        "residual_momentum": float(np.linalg.norm(flexible.momentum_body[after], axis=-1).max()),
    }
    figure = slew_figure(flexible, rigid, T, _DEMO_SLEW["angle"])
    nc_path, png_path = os.path.join(out_dir, "flexible.nc"), os.path.join(out_dir, "flexible.png")
    html_path = os.path.join(out_dir, "flexible.html")
    flexible.save(nc_path)
    write_atomic(png_path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))
    flexible.to_html(html_path, model=fbody)
    return {**summary, "nc": nc_path, "png": png_path, "html": html_path}


def slew_figure(flexible: Trajectory, rigid: Trajectory, end: float, target: float) -> Figure:
    """Four panels: slew angle and rate (flexible vs rigid), modal coordinates, and the pointing error
    from the ``target`` angle (rad) after the manoeuvre ends at ``end`` (s)."""
    from matplotlib.figure import Figure

    assert flexible.q is not None and flexible.omega is not None, "the flexible hub's trajectory has an attitude"
    assert rigid.q is not None and rigid.omega is not None, "the rigid body's trajectory has an attitude"
    fig = Figure(figsize=(10, 7), layout="constrained")
    (a, b), (c, d) = fig.subplots(2, 2)
    t = flexible.t
    a.plot(t, np.degrees(slew_angle(rigid.q)), "k--", label="rigid")
    a.plot(t, np.degrees(slew_angle(flexible.q)), label="flexible hub")
    a.set(xlabel="t (s)", ylabel="angle about z (deg)", title="(a) slew angle")
    b.plot(t, np.degrees(rigid.omega[:, 2]), "k--", label="rigid")
    b.plot(t, np.degrees(flexible.omega[:, 2]), label="flexible hub")
    b.set(xlabel="t (s)", ylabel="ω_z (deg/s)", title="(b) body rate")
    eta = flexible.modal_coordinate
    for k in range(eta.shape[1]):
        c.plot(t, eta[:, k], label=f"mode {k + 1}")
    c.set(xlabel="t (s)", ylabel="η (kg^½ m)", title="(c) modal coordinates")
    after = t >= end
    d.plot(t[after], (slew_angle(flexible.q[after]) - target) / _ARCSEC)
    d.set(xlabel="t (s)", ylabel="pointing error (arcsec)", title="(d) jitter after the manoeuvre")
    for ax in (a, b, c):
        ax.axvline(end, color="0.6", lw=0.8)
        ax.legend()
    return fig

