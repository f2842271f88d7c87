"""The figure of a sweep: a histogram of each outcome with its percentiles, and percentile bands over time of
each series (matplotlib's object-oriented API; nothing is shown or saved here)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import xarray
    from matplotlib.figure import Figure

__all__ = ["sweep_figure"]

_BINS = 40


def sweep_figure(ds: xarray.Dataset, *, title: str | None = None, units: dict[str, str] | None = None) -> Figure:
    """A :class:`matplotlib.figure.Figure` of the sweep ``ds`` (what :func:`tumble.sweep` returns).

    One panel per scalar outcome: a histogram of the samples, the stored
    percentiles as vertical lines. One panel per series: the median against
    time, the band between each pair of stored percentiles symmetric about 50
    shaded, the mean dashed. ``units`` maps a name to the units written on
    its axis (e.g. ``{"pointing": "rad"}``).
    """
    from matplotlib.figure import Figure

    units = units or {}
    settings = ds.attrs.get("tumble_sweep", {})
    outcomes = [name for name in settings.get("outcomes", {}) if ds[name].ndim == 1]
    series = list(settings.get("statistics", {}))
    panels = len(outcomes) + len(series)
    if panels == 0:
        raise ValueError("ds: the sweep has no scalar outcome or series to draw")
    fig = Figure(figsize=(6.0 * min(panels, 2), 3.6 * ((panels + 1) // 2)), layout="constrained")
    axes = np.atleast_1d(fig.subplots((panels + 1) // 2, min(panels, 2))).ravel()
    p = ds["percentile"].values
    for ax, name in zip(axes, outcomes, strict=False):
        values = ds[name].values
        finite = values[np.isfinite(values)]
        ax.hist(finite, bins=_BINS, color="0.75", edgecolor="0.4")
        for q, value in zip(p, ds[f"{name}_percentiles"].values, strict=True):
            if np.isfinite(value):
                ax.axvline(value, color="C3", lw=1.0)
                ax.annotate(f"{q:g}%", (value, 1.0), xycoords=("data", "axes fraction"), rotation=90,
                            va="top", ha="right", fontsize="small", color="C3")
        missing = values.size - finite.size
        note = f", {missing} without a value" if missing else ""
        ax.set(xlabel=f"{name} ({units[name]})" if name in units else name, ylabel="samples",
               title=f"{name}: {values.size} samples{note}")
    for ax, name in zip(axes[len(outcomes):], series, strict=False):
        t = ds["time"].values
        bands = ds[f"{name}_percentiles"].values
        for k, q in enumerate(p):
            upper = np.flatnonzero(np.isclose(p, 100.0 - q))
            if q < 50.0 and upper.size:
                ax.fill_between(t, bands[k], bands[upper[0]], color="C0", alpha=0.15 + 0.2 * q / 50.0, lw=0,
                                label=f"{q:g}-{100 - q:g}%")
        median = np.flatnonzero(np.isclose(p, 50.0))
        if median.size:
            ax.plot(t, bands[median[0]], "C0-", label="median")
        ax.plot(t, ds[f"{name}_mean"].values, "k--", lw=1.0, label="mean")
        ax.set(xlabel="time (s)", ylabel=f"{name} ({units[name]})" if name in units else name,
               title=f"{name} over time")
        ax.legend(fontsize="small")
    for ax in axes[panels:]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title)
    return fig
