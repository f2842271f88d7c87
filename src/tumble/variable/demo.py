"""Moved: the diver's demo and figures are :mod:`tumble.viz.diver`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, dict.fromkeys(("demo_diver", "figure_dive", "figure_twist_rule"), "tumble.viz.diver"))
