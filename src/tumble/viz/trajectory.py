"""The views of a :class:`~tumble.Trajectory`: its figure, its viewer page, its notebook view and its table.

``traj.plot()``, ``traj.to_html(path)``, a notebook cell's ``traj`` and
``traj.to_dataframe()`` are these functions. The result type
(:mod:`tumble.trajectory`) sits below the figures and the viewer and imports
neither: this module fills its table of views, :data:`tumble.trajectory.VIEWS`,
when ``import tumble`` loads it. matplotlib, the viewer and pandas are
imported on the first call.

:func:`plot`          matplotlib figure: body rates, drift of the invariants, direction of ``L``
:func:`to_html`       the offline 3-D viewer page (:func:`tumble.viz.viewer.write_html`)
:func:`notebook_html` the table of the run, then the viewer in an ``<iframe>``
:func:`to_dataframe`  the samples as a pandas DataFrame
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble import trajectory
from tumble.trajectory import Extra, Trajectory

if TYPE_CHECKING:
    import pandas
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["notebook_html", "plot", "to_dataframe", "to_html"]

_AXES = ("x", "y", "z")
# Panel (b) of plot() shows |drift| on a symlog scale, linear below this value
# (under float64's rounding, 2.2e-16) and logarithmic above: exact zeros stay
# on the plot and every drift above rounding gets its own decade.
_DRIFT_LINTHRESH = 1e-16


def plot(traj: Trajectory, *, title: str | None = None) -> Figure:
    """Return a matplotlib figure of the trajectory (nothing is shown or saved): ``traj.plot()``.

    Panels, against time (s): (a) body rates ω_x, ω_y, ω_z (rad/s, body
    axes); (b) absolute values of the relative drifts of the energy and
    |L| (symlog scale, linear below 1e-16, so exact zeros show); (c)
    direction of the inertial angular momentum, ``L_I / |L_I|`` (inertial
    axes). A model without an attitude (a robot) shows its first two
    vector extras in (a) and (c) (joint coordinates and rates).
    For a batch, body 0 is plotted and the title says so.
    Save the figure with ``fig.savefig(path)``, or atomically with
    :func:`tumble.trajectory.write_atomic`.
    """
    from matplotlib.figure import Figure

    one = traj if traj.batch_size is None else traj.member(0)
    if title is None:
        title = f"tumble trajectory ({traj.method or 'unknown method'})"
    if traj.batch_size is not None:
        title += f" — body 0 of {traj.batch_size}"

    fig = Figure(figsize=(8.0, 9.0), layout="constrained")
    ax_rate, ax_drift, ax_direction = fig.subplots(3, 1, sharex=True)
    vectors = [(name, e) for name, e in one.extras.items() if len(e.dims) == 1]
    if one.omega is not None:
        for k, name in enumerate(_AXES):
            ax_rate.plot(one.t, one.omega[:, k], label=rf"$\omega_{name}$")
        ax_rate.set_title("(a) body rates", loc="left")
        ax_rate.set_ylabel("ω, body axes (rad/s)")
    else:  # no attitude (a robot): its first sampled vector, e.g. the joint coordinates
        _plot_extra(ax_rate, one.t, *vectors[0], "(a)")

    ax_drift.plot(one.t, np.abs(one.energy_drift), label=r"$|E - E_0|/E_0$")
    if one.q is not None or "momentum_body" in one.totals:
        ax_drift.plot(one.t, np.abs(one.momentum_norm_drift), label=r"$||L| - |L_0||/|L_0|$")
    ax_drift.set_yscale("symlog", linthresh=_DRIFT_LINTHRESH)
    ax_drift.set_ylim(bottom=0.0)
    ax_drift.set_title(
        f"(b) drift of energy and momentum (symlog scale, linear below {_DRIFT_LINTHRESH:g})", loc="left"
    )
    ax_drift.set_ylabel("|relative drift| (1)")

    if one.q is not None:
        momentum = one.momentum_inertial
        norm = np.linalg.norm(momentum, axis=-1, keepdims=True)
        direction = np.divide(momentum, norm, out=np.zeros_like(momentum), where=norm > 0)
        for k, name in enumerate(_AXES):
            ax_direction.plot(one.t, direction[:, k], label=rf"$L_{name}/|L|$")
        ax_direction.set_title("(c) direction of the angular momentum", loc="left")
        ax_direction.set_ylabel("$L_I/|L_I|$, inertial axes (1)")
    else:
        _plot_extra(ax_direction, one.t, *vectors[1], "(c)")
    ax_direction.set_xlabel("time t (s)")

    for ax in (ax_rate, ax_drift, ax_direction):
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    fig.suptitle(title)
    return fig


def _plot_extra(ax: Axes, t: np.ndarray, name: str, extra: Extra, panel: str) -> None:
    """One line per component of a vector extra (n, m) against time, labelled with its dimension."""
    dim = extra.dims[0]
    for k in range(extra.data.shape[-1]):
        ax.plot(t, extra.data[:, k], label=f"{dim} {k}")
    ax.set_title(f"{panel} {name.replace('_', ' ')}", loc="left")
    ax.set_ylabel(f"{name} ({extra.units})")


def to_html(traj: Trajectory, path: str | os.PathLike, **options: Any) -> None:
    """Write the offline 3-D viewer of ``traj`` to ``path``, atomically: ``traj.to_html(path, **options)``.

    ``options`` (``model=``, ``frames=``, ``axis=``, ``shape=``) and what the page shows:
    :func:`tumble.viz.viewer.write_html` (``docs/viewer.md``).
    """
    from tumble.viz.viewer import write_html

    write_html(traj, path, **options)


def notebook_html(traj: Trajectory) -> str:
    """A notebook cell's view of ``traj`` (its ``_repr_html_``): the table of the run (model, method, samples,
    time span, solver statistics, largest drifts of energy and angular momentum), then the viewer in an
    ``<iframe>`` (:func:`tumble.viz.viewer.notebook_html`) where the trajectory can be drawn without its model."""
    from tumble.viz._notebook import summary_html
    from tumble.viz.viewer import notebook_html as viewer_html

    return summary_html(traj) + (viewer_html(traj) or "")


def to_dataframe(traj: Trajectory) -> pandas.DataFrame:
    """The samples as a pandas DataFrame indexed by ``t`` (s), or by ``(t, body)`` for a batch:
    ``traj.to_dataframe()``.

    Columns ``q_w … q_z``, ``omega_x … omega_z`` (rad/s, body axes), ``energy`` (J),
    ``momentum_body_x …`` (N m s, body axes) and one per component of each extra
    (:func:`tumble.viz._notebook.to_dataframe`). pandas comes with xarray; it is imported on the first call.
    """
    from tumble.viz._notebook import to_dataframe as table

    return table(traj)


trajectory.VIEWS.update(plot=plot, to_html=to_html, notebook_html=notebook_html, to_dataframe=to_dataframe)
