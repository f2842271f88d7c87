"""Figures (matplotlib, object-oriented API: no display needed) that explain the motion, and the demos.

``polhode_figure(body, omega)``: the energy ellipsoid with polhodes, separatrices and the herpolhode.
``top_figure(top, trajectory)``: the heavy top's axis trace with its nutation bounds.
``tumble.viz.trajectory``: a trajectory's figure (``Trajectory.plot()``), viewer page and tables.
``tumble.viz.viewer``: the offline 3-D viewer, one HTML page per trajectory (``docs/viewer.md``).

The names load on first use (PEP 562): ``import tumble`` loads :mod:`tumble.viz.trajectory` only, which
imports neither matplotlib nor the models the other figures draw.
"""

import importlib

__all__ = ["demo_top", "polhode_figure", "top_figure"]

# name -> the module of tumble.viz that defines it
_WHERE = {"polhode_figure": "polhode", "demo_top": "top", "top_figure": "top"}
# sub-packages loaded on first use: `import tumble; tumble.viz.viewer.write_html(...)`
_LAZY = ("viewer",)


def __getattr__(name: str):
    if name in _WHERE:
        return getattr(importlib.import_module(f"tumble.viz.{_WHERE[name]}"), name)
    if name in _LAZY:
        return importlib.import_module(f"tumble.viz.{name}")
    raise AttributeError(f"module 'tumble.viz' has no attribute {name!r}")
