"""Figures (matplotlib, object-oriented API: no display needed) that explain the motion.

``polhode_figure(body, omega)``: the energy ellipsoid with polhodes, separatrices and the herpolhode.
``top_figure(top, trajectory)``: the heavy top's axis trace with its nutation bounds.
``Trajectory.plot()`` (in :mod:`tumble.trajectory`): rates, invariant drifts, momentum direction.
"""

from tumble.viz.polhode import polhode_figure
from tumble.viz.top import demo_top, top_figure

__all__ = ["demo_top", "polhode_figure", "top_figure"]
