"""Moved: the figure of a sweep is :mod:`tumble.viz.sweep`; ``sweep_figure`` warns and works for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, {"sweep_figure": "tumble.viz.sweep"})
