"""The sloshing spinner's figure and demo: fuel slosh turns a minor-axis spinner into a flat spin.

:func:`nutation_figure` draws the nutation angle, the energy and ``|H|``; :func:`demo_slosh` runs
:data:`tumble.slosh.DEMO_BODY` (``tumble demo slosh``, ``docs/slosh.md``).
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

import numpy as np

import tumble
from tumble._files import write_atomic
from tumble.slosh import DEMO_BODY, flat_spin_energy, growth_time_constant, nutation_angle, steady_spin_eigenvalues
from tumble.trajectory import Trajectory
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["demo_slosh", "nutation_figure"]

_DEMO_SPIN = 2.0  # rad/s about z
_DEMO_WOBBLE = 0.035  # rad/s about x at the start: an initial nutation of 1.8°
_DEMO_DURATION = 600.0  # s
_DEMO_TOLERANCE = 1e-11  # rtol = atol of the demo run


def demo_slosh(out_dir: str | os.PathLike[str]) -> dict:
    """Slosh-induced nutation growth of a minor-axis spinner (:data:`tumble.slosh.DEMO_BODY`).

    Spins the hub at 2 rad/s about its minor axis z with a small wobble, integrates 600 s
    with dop853 (rtol = atol = 1e-11), writes ``out_dir/slosh.nc``, ``out_dir/slosh.png``
    (:func:`nutation_figure`) and ``out_dir/slosh.html`` (the offline viewer, :mod:`tumble.viz.viewer`) atomically and returns: the initial and final nutation angles
    (deg), the growth time constant (s), measured (:func:`~tumble.slosh.growth_time_constant` over 2°–20°) and
    predicted by the linearisation about the steady spin (:func:`~tumble.slosh.steady_spin_eigenvalues`), the largest
    relative change of ``|H|``, the relative energy change, whether the energy decreased at every
    sample, the final energy and the flat-spin energy it tends to (:func:`~tumble.slosh.flat_spin_energy`, J),
    and the paths written.
    """
    out_directory(out_dir)
    sbody = DEMO_BODY
    t = np.linspace(0.0, _DEMO_DURATION, int(4 * _DEMO_DURATION) + 1)
    trajectory = tumble.simulate(sbody, [_DEMO_WOBBLE, 0.0, _DEMO_SPIN], t=t, direction0=[1.0, 0.0, 0.0],
                                 method="dop853", rtol=_DEMO_TOLERANCE, atol=_DEMO_TOLERANCE)
    angle = nutation_angle(sbody, trajectory)
    h = trajectory.momentum_norm
    e = trajectory.energy
    summary = {
        "nutation_initial_deg": math.degrees(angle[0]),
        "nutation_final_deg": math.degrees(angle[-1]),
        "growth_time_constant_s": growth_time_constant(t, angle),
        "growth_time_constant_linear_s": float(1.0 / steady_spin_eigenvalues(
            sbody, [0.0, 0.0, _DEMO_SPIN], [1.0, 0.0, 0.0])[0].real),
        "momentum_norm_drift": float(np.abs(h / h[0] - 1.0).max()),
        "energy_change": float(e[-1] / e[0] - 1.0),
        "energy_final": float(e[-1]),
        "energy_flat_spin": flat_spin_energy(sbody, h[0]),
        "energy_monotonic": bool(np.all(np.diff(e) <= 0.0)),
    }
    figure = nutation_figure(trajectory, angle, h, e, summary["growth_time_constant_linear_s"],
                             summary["energy_flat_spin"])
    nc_path, png_path = os.path.join(out_dir, "slosh.nc"), os.path.join(out_dir, "slosh.png")
    html_path = os.path.join(out_dir, "slosh.html")
    trajectory.save(nc_path)
    write_atomic(png_path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))
    trajectory.to_html(html_path, model=sbody)
    return {**summary, "nc": nc_path, "png": png_path, "html": html_path}


def nutation_figure(trajectory: Trajectory, angle: np.ndarray, momentum_norm: np.ndarray, total_energy: np.ndarray,
                    time_constant: float | None = None, flat_spin: float | None = None) -> Figure:
    """Three panels: nutation angle (log scale; with ``angle[0] exp(t/time_constant)`` (s) dashed, up to
    90°, when given), energy (with the ``flat_spin`` energy (J) dashed, when given), and the relative
    change of ``|H|``."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 7), layout="constrained")
    a, b, c = fig.subplots(3, 1, sharex=True)
    t = trajectory.t
    a.semilogy(t, np.degrees(angle), label="simulation")
    if time_constant is not None:
        line = np.degrees(angle[0]) * np.exp(t / time_constant)
        keep = line <= 90.0
        a.semilogy(t[keep], line[keep], "k--", label=f"linearised steady spin: exp(t / {time_constant:.1f} s)")
        a.legend()
    a.set(ylabel="nutation angle (deg)", title="(a) nutation of a minor-axis spinner with fuel slosh")
    b.plot(t, total_energy, label="simulation")
    if flat_spin is not None:
        b.axhline(flat_spin, color="k", ls="--", label="flat spin |H|²/(2 I_max)")
        b.legend()
    b.set(ylabel="T (J)", title="(b) kinetic energy (hub + slosh mass)")
    c.plot(t, momentum_norm / momentum_norm[0] - 1.0)
    c.set(xlabel="t (s)", ylabel="|H|/|H₀| − 1", title="(c) total angular momentum")
    return fig

