"""Closed-form motion: exact torque-free rotation, stability of the principal axes, the heavy top.

====================================  ==============================================================
``torque_free(body, omega0, q0, t=)``  exact rates and attitude of a free body (any inertia, batches);
                                       the same ``Trajectory`` as ``simulate``; also
                                       ``simulate(..., method="exact")``
``free_parameters(moments, omega_p)``  energy, |L|, regime, elliptic parameter m = k², λ, K/λ
``stability(body, omega)``             axis classification, growth rate, flip interval, polhode period
``flip_interval``, ``polhode_period``  2K/λ and 4K/λ
``growth_rate(body, spin)``            σ = ω √((I₃ − I₂)(I₂ − I₁)/(I₁ I₃))
``flip_times(body, omega0, t_end)``    exact times of the intermediate-axis sign changes
``polhode``, ``polhode_family``,       curves on the energy ellipsoid; the herpolhode of a motion
``separatrix``, ``herpolhode``
``HeavyTop``                           the Lagrange top: nutation bounds, exact u(t), period, precession
``kovalevskaya_invariant``,            the extra invariants of the two other integrable heavy tops;
``goryachev_chaplygin_invariant``      ``heavy_top_energy``, ``vertical_momentum``, ``upward_vertical``,
                                       ``omega_at_energy``
====================================  ==============================================================

See ``docs/exact.md``, ``docs/stability.md``, ``docs/heavy_top.md`` and ``docs/chaos.md``.
"""

from tumble.analytic._free import REGIMES, FreeParameters, free_parameters, torque_free
from tumble.analytic._geometry import (
    Herpolhode,
    Polhode,
    herpolhode,
    polhode,
    polhode_family,
    polhode_through,
    separatrix,
)
from tumble.analytic._integrable import (
    goryachev_chaplygin_invariant,
    heavy_top_energy,
    kovalevskaya_invariant,
    omega_at_energy,
    upward_vertical,
    vertical_momentum,
)
from tumble.analytic._heavy_top import HeavyTop
from tumble.analytic._stability import (
    StabilityReport,
    classify_axes,
    flip_interval,
    flip_times,
    growth_rate,
    polhode_period,
    stability,
)
from tumble.analytic._top_axis import AxisMotion, NutationMeasurement, axis_motion, measure_nutation

__all__ = [
    "REGIMES",
    "AxisMotion",
    "FreeParameters",
    "HeavyTop",
    "Herpolhode",
    "NutationMeasurement",
    "Polhode",
    "StabilityReport",
    "axis_motion",
    "classify_axes",
    "flip_interval",
    "flip_times",
    "free_parameters",
    "goryachev_chaplygin_invariant",
    "growth_rate",
    "heavy_top_energy",
    "herpolhode",
    "kovalevskaya_invariant",
    "measure_nutation",
    "omega_at_energy",
    "polhode",
    "polhode_family",
    "polhode_period",
    "polhode_through",
    "separatrix",
    "stability",
    "torque_free",
    "upward_vertical",
    "vertical_momentum",
]
