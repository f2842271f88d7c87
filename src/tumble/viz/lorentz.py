"""The Lorentz-factor figure and demo: ``I(ω)/I₀`` of spinning incoherent matter, and a neutron star.

:func:`inertia_figure` draws :class:`tumble.lorentz.SpinningMatter`'s moment against the rim speed;
:func:`demo_lorentz` sizes the corrections for :data:`NEUTRON_STAR` (``tumble demo lorentz``, ``docs/limits.md``).
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from tumble._files import write_atomic
from tumble.limits import SPEED_OF_LIGHT
from tumble.lorentz import SpinningMatter
from tumble.viz._output import out_directory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["NEUTRON_STAR", "demo_lorentz", "inertia_figure"]

#: The demo's neutron star: radius 12 km, mass 1.4 solar masses (IAU nominal M☉ = 1.98847e30 kg), period 1.4 ms.
NEUTRON_STAR = {"radius": 12e3, "mass": 1.4 * 1.98847e30, "period": 1.4e-3}


def inertia_figure(betas: ArrayLike | None = None) -> Figure:
    """``I(ω)/I₀`` of the four shapes against the rim speed ωR/c (0 to γ = 10 at the rim; log scale);
    a matplotlib ``Figure`` (object-oriented API, nothing shown)."""
    from matplotlib.figure import Figure

    betas = np.linspace(0.0, math.sqrt(0.99), 400) if betas is None else np.asarray(betas)
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax = fig.add_subplot()
    for shape in ("ring", "shell", "disk", "sphere"):
        matter = SpinningMatter(shape, 1.0, 1.0)
        ax.plot(betas, matter.moment(betas * SPEED_OF_LIGHT) / matter.newtonian_moment, label=shape)
    ax.set_yscale("log")
    ax.set_xlabel("rim speed ωR / c")
    ax.set_ylabel("I(ω) / I₀")
    ax.set_title("Incoherent matter in rigid rotation (special relativity, no gravity)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def demo_lorentz(out_dir: str | os.PathLike[str]) -> dict:
    """The Lorentz-factor correction for a neutron star (:data:`NEUTRON_STAR`) taken as each shape of uniform
    incoherent matter, and the figure :func:`inertia_figure` written atomically to ``out_dir/lorentz.png``.

    Returns the angular velocity (rad/s), the rim speed β, and per shape the relative corrections of the
    moment of inertia (and angular momentum) and of the kinetic energy (:meth:`tumble.lorentz.SpinningMatter.corrections`),
    and the path written.
    """
    out_directory(out_dir)
    star = NEUTRON_STAR
    omega = 2.0 * math.pi / star["period"]
    summary: dict[str, Any] = {"omega": omega, "rim_speed": omega * star["radius"] / SPEED_OF_LIGHT}
    for shape in ("sphere", "shell", "ring"):
        fixes = SpinningMatter(shape, star["mass"], star["radius"]).corrections(omega)
        summary[shape] = {name: float(value) for name, value in fixes.items()}
    figure = inertia_figure()
    png_path = os.path.join(out_dir, "lorentz.png")
    write_atomic(png_path, lambda tmp_path: figure.savefig(tmp_path, format="png", dpi=120))
    return {**summary, "png": png_path}

