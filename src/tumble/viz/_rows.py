"""A run as the ``tumble`` command prints it: rows ``(label, text)`` of its times, method and drifts, which the
``run`` and ``info`` commands and the demos that simulate one body print alike."""

from __future__ import annotations

import numpy as np

from tumble.trajectory import Trajectory

__all__ = ["summary"]


def _drift(drift: np.ndarray, initial: np.ndarray) -> str:
    """Largest |relative change|, or "n/a" where the initial value is 0 (the drift is then absolute) or there
    is no body (an empty batch)."""
    return "n/a" if drift.size == 0 or np.any(initial == 0.0) else f"{np.max(np.abs(drift)):.3g}"


def _setting(value: float | int | str) -> str:
    """A solver setting as printed: a number in ``%g``, a string as it is."""
    return value if isinstance(value, str) else f"{value:g}"


def summary(traj: Trajectory) -> list[tuple[str, str]]:
    """Rows: output times, method and its settings, the largest relative change of the energy, |L| and L_I
    (the energy alone for a model without an attitude, e.g. a robot arm)."""
    options = ", ".join(f"{key} {_setting(traj.info[key])}" for key in ("rtol", "atol", "dt") if key in traj.info)
    steps = f", {traj.info['n_steps']} steps" if "n_steps" in traj.info else ""
    torque = traj.info.get("torque", "none")
    drift = f"energy {_drift(traj.energy_drift, traj.energy[0])}"
    if traj.q is not None:
        drift += (f", |L| {_drift(traj.momentum_norm_drift, traj.momentum_norm[0])}, "
                  f"L_I {_drift(traj.momentum_inertial_drift, traj.momentum_norm[0])}")
    rows = [
        ("times", f"{traj.t[0]:g} to {traj.t[-1]:g} s, {len(traj)} samples"),
        ("method", f"{traj.method or 'unknown'}" + (f" ({options})" if options else "") + steps),
        ("drift", f"{drift} (max relative change)"),
    ]
    if torque != "none":
        kept = "T and |L|" if traj.q is not None else "the energy"
        rows.append(("", f"(torque {torque} acts: {kept} need not be conserved)"))
    if traj.extras and not traj.totals:
        rows.append(("", f"(drifts of the rigid hub alone: it exchanges momentum and energy with the model's "
                         f"{len(traj.extras)} other states, saved with it)"))
    return rows
