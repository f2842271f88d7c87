"""What a notebook shows of a trajectory: its summary as an HTML table, and its samples as a pandas DataFrame.

:func:`summary_html` is the table of ``Trajectory._repr_html_`` (shape, model,
method, time span, solver statistics and the drifts of the invariants);
:func:`to_dataframe` is ``Trajectory.to_dataframe()``. pandas comes with
xarray, a dependency of tumble; it is imported here only when a DataFrame is
asked for, so that ``import tumble`` does not pay for it.
"""

from __future__ import annotations

import html
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas

    from tumble.trajectory import Trajectory

__all__ = ["summary_html", "to_dataframe"]

_AXES = ("x", "y", "z")
_QUATERNION = ("w", "x", "y", "z")
# Solver statistics shown when the run recorded them (Trajectory.info).
_STATISTICS = ("n_steps", "n_rejected", "n_rhs", "dt", "rtol", "atol")


def _drifts(traj: Trajectory) -> list[tuple[str, float]]:
    """The largest drifts of the invariants over the run (and the batch): ``(label, value)``."""
    rows = [("max |E − E₀| / E₀", float(np.abs(traj.energy_drift).max()))]
    if traj.q is not None or "momentum_body" in traj.totals:
        rows.append(("max ||L| − |L₀|| / |L₀|", float(np.abs(traj.momentum_norm_drift).max())))
    if traj.q is not None:
        rows.append(("max |L_I − L_I₀| / |L_I₀|", float(np.abs(traj.momentum_inertial_drift).max())))
    return rows


def summary_html(traj: Trajectory) -> str:
    """An HTML table of the run: model, method, samples (and bodies), time span (s), solver statistics,
    the named extras and the largest relative drifts of the energy and angular momentum (constant without
    external torque; the absolute change where the initial value is zero)."""
    shape = f"{len(traj)} times" + ("" if traj.batch_size is None else f" × {traj.batch_size} bodies")
    rows = [("model", traj.model or "—"), ("method", traj.method or "—"), ("samples", shape),
            ("time span", f"{traj.t[0]:.6g} … {traj.t[-1]:.6g} s")]
    rows += [(key, f"{traj.info[key]:.6g}" if isinstance(traj.info[key], float) else str(traj.info[key]))
             for key in _STATISTICS if key in traj.info]
    if traj.extras:
        rows.append(("extras", ", ".join(f"{name} ({extra.units})" for name, extra in traj.extras.items())))
    rows += [(label, f"{value:.3e}") for label, value in _drifts(traj)]
    body = "".join(f"<tr><th style=\"text-align:left\">{html.escape(label)}</th>"
                   f"<td style=\"text-align:left\">{html.escape(value)}</td></tr>" for label, value in rows)
    return f'<table class="tumble-trajectory"><caption>tumble.Trajectory</caption>{body}</table>'


def _columns(name: str, data: np.ndarray, lead: int, labels: tuple[str, ...] | None = None) -> dict:
    """The columns of one sampled quantity: one per trailing component, named ``NAME_LABEL`` or ``NAME[i]``."""
    flat = np.reshape(data, (*np.shape(data)[:lead], -1))
    if data.ndim == lead:
        return {name: flat[..., 0]}
    suffixes = [f"[{i}]" for i in range(flat.shape[-1])] if labels is None else [f"_{label}" for label in labels]
    return {f"{name}{suffix}": flat[..., i] for i, suffix in enumerate(suffixes)}


def to_dataframe(traj: Trajectory) -> pandas.DataFrame:
    """The samples as a pandas DataFrame: one row per output time (and body, for a batch).

    The index is ``t`` (s), or the pair ``(t, body)`` for a batch. Columns:
    ``q_w, q_x, q_y, q_z`` (scalar-first quaternion, body → inertial),
    ``omega_x, omega_y, omega_z`` (rad/s, body axes), ``energy`` (J),
    ``momentum_body_x, ...`` (N m s, body axes), and each extra (its units in
    ``traj.extras``), one column per component (``wheel_speed[0]``, ...).
    """
    import pandas as pd   # comes with xarray; imported here to keep `import tumble` fast

    lead = len(traj._lead)
    columns: dict = {}
    if traj.q is not None and traj.omega is not None:
        columns |= _columns("q", traj.q, lead, _QUATERNION) | _columns("omega", traj.omega, lead, _AXES)
    columns |= _columns("energy", traj.energy, lead)
    if traj.q is not None or "momentum_body" in traj.totals:
        columns |= _columns("momentum_body", traj.momentum_body, lead, _AXES)
    for name, extra in traj.extras.items():
        columns |= _columns(name, extra.data, lead)
    if traj.batch_size is None:
        index = pd.Index(traj.t, name="t")
    else:
        index = pd.MultiIndex.from_product([traj.t, range(traj.batch_size)], names=["t", "body"])
    return pd.DataFrame({name: np.asarray(value).reshape(-1) for name, value in columns.items()}, index=index)
