"""Integrability and chaos of the heavy top: Poincaré sections and finite-time Lyapunov exponents side by side.

Three tops with the same axial moment ``C = 1 kg·m²`` about the pivot and the
same ``m g |r| = 1 N·m`` (time unit 1 s), on the same energy level ``H``:

* Lagrange: moments (2, 2, 1), centre of mass on the symmetry axis — integrable;
* Kovalevskaya: moments (2, 2, 1), centre of mass in the equatorial plane — integrable;
* generic: moments (1, 1.6, 2.1), centre of mass 1 m along (1, 0.5, 0.3) — chaotic.

For each, orbits from random attitudes and rate directions on the level
and on the level ``L_z = 0`` of the vertical momentum
(:func:`tumble.analytic.omega_at_energy`) are cut by the section ``γ₁ = 0``
crossed upwards (:func:`tumble.measure.poincare_section`) and drawn in the
plane (γ₂, ω₃); the largest finite-time exponent of one orbit
(:func:`tumble.measure.lyapunov_exponents`) is drawn against time with the
``ln t / t`` of an integrable top. ``docs/chaos.md`` shows and explains the figure.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

import numpy as np

from tumble import attitude
from tumble._validate import ValidationError, require_positive
from tumble.measure import lyapunov_exponents, poincare_section
from tumble.analytic import omega_at_energy, upward_vertical
from tumble.torques import Gravity
from tumble._files import write_atomic
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["TOPS", "demo_chaos", "figure_chaos"]

_DOWN = [0.0, 0.0, -1.0]

#: The three tops: name -> (inertia about the pivot (kg m², body axes), gravity torque).
TOPS = {
    "Lagrange": (np.diag([2.0, 2.0, 1.0]), Gravity(1.0, [0.0, 0.0, 1.0], _DOWN)),
    "Kovalevskaya": (np.diag([2.0, 2.0, 1.0]), Gravity(1.0, [1.0, 0.0, 0.0], _DOWN)),
    "generic": (np.diag([1.0, 1.6, 2.1]), Gravity(1.0, np.array([1.0, 0.5, 0.3]) / np.sqrt(1.34), _DOWN)),
}
ENERGY = 1.0  # J
SECTION = {"gamma1": 0.0}
PLANE = ("gamma2", "omega3")  # the coordinates drawn


def _orbits(name: str, n: int, seed: int):
    """``n`` initial states (ω₀, q₀) of top ``name`` on the level ``H = ENERGY``, ``L_z = 0``.

    Random attitudes and rate directions; the direction loses its component along ``I γ`` (so that
    ``L_z = ω·I γ = 0``), then is scaled to the energy. On one level of ``H`` and ``L_z`` the section is a
    surface that (γ₂, ω₃) parametrise.
    """
    inertia, gravity = TOPS[name]
    rng = np.random.default_rng(seed)
    q0 = attitude.normalize(rng.standard_normal((n, 4)))
    direction = rng.standard_normal((n, 3))
    normal = upward_vertical(q0, gravity) @ inertia.T
    direction -= (np.einsum("ni,ni->n", direction, normal) / np.einsum("ni,ni->n", normal, normal))[:, None] * normal
    return omega_at_energy(inertia, gravity, ENERGY, direction, q0), q0


def chaos_data(*, duration: float = 2000.0, orbits: int = 12, seed: int = 1) -> dict:
    """Section points and finite-time exponents of the three :data:`TOPS` (see the module docstring).

    Returns ``{name: {"sections": [(k, 2) arrays], "t": (n,), "lyapunov": (n,)}}``; ``duration`` in s.
    """
    import tumble

    duration = require_positive(duration, "duration")
    t = np.linspace(0.0, duration, int(round(duration * 10.0)) + 1)  # 10 samples per second: Ω h ≲ 0.2
    data = {}
    for name, (inertia, gravity) in TOPS.items():
        omega0, q0 = _orbits(name, orbits, seed)
        sections = []
        for i in range(orbits):  # one body per run: the same compiled path as any single heavy-top run
            try:
                cut = poincare_section(tumble.RigidBody(inertia), gravity, section=SECTION, direction=1,
                                       omega0=omega0[i], q0=q0[i], t=t, method="dop853", rtol=1e-10, atol=1e-10)
            except ValidationError as error:
                if error.field != "section":
                    raise
                continue  # an orbit that never crosses the plane (a fast sleeping top) adds no point
            sections.append(np.stack([cut[PLANE[0]], cut[PLANE[1]]], axis=1))
        exponents = lyapunov_exponents(inertia, gravity, omega0=omega0[0], q0=q0[0], t=t[::10],
                                       method="dop853", rtol=1e-10, atol=1e-10)
        data[name] = {"sections": sections, "t": exponents.t, "lyapunov": exponents.finite_time[:, 0]}
    return data


def figure_chaos(data: dict) -> Figure:
    """The matplotlib figure of :func:`chaos_data`: three sections above, the exponents against time below."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(13.0, 8.0), layout="constrained")
    figure.suptitle(f"Poincaré sections γ₁ = 0 (crossed upwards) on the level H = {ENERGY:g} J, L_z = 0: "
                    "invariant curves (integrable) against a chaotic sea")
    grid = figure.add_gridspec(2, 3, height_ratios=[1.3, 1.0])
    for column, (name, top) in enumerate(data.items()):
        ax = figure.add_subplot(grid[0, column])
        for points in top["sections"]:
            ax.plot(points[:, 0], points[:, 1], ".", markersize=1.2)
        ax.set(title=f"{name} top", xlabel="γ₂", ylabel="ω₃ (rad/s)")
    ax = figure.add_subplot(grid[1, :])
    for name, top in data.items():
        late = top["t"] >= 10.0  # the first seconds hold one or two renormalisations: noise
        ax.loglog(top["t"][late], top["lyapunov"][late], label=name)
    t = next(iter(data.values()))["t"]
    t = t[t >= 10.0]
    ax.loglog(t, np.log(np.maximum(t, math.e)) / t, "k--", linewidth=0.8, label="ln t / t")
    ax.set(xlabel="t (s)", ylabel="finite-time largest exponent λ₁(t) (1/s)",
           title="Largest Lyapunov exponent: → 0 like ln t / t when integrable, a plateau when chaotic")
    ax.legend()
    return figure


def demo_chaos(out_dir: str | os.PathLike[str], *, duration: float = 2000.0) -> dict:
    """``tumble demo chaos``: write ``chaos.png`` in ``out_dir``; returns the exponents and section sizes."""
    out_directory(out_dir)
    data = chaos_data(duration=duration)
    png_path = os.path.join(os.fspath(out_dir), "chaos.png")
    figure = figure_chaos(data)
    write_atomic(png_path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=110))
    return {
        "duration_s": float(duration),
        "largest_exponent": {name: float(top["lyapunov"][-1]) for name, top in data.items()},
        "section_points": {name: int(sum(len(p) for p in top["sections"])) for name, top in data.items()},
        "png": png_path,
    }
