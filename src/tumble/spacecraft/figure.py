"""Moved: the spacecraft's figure is :mod:`tumble.viz.spacecraft`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, dict.fromkeys(("save_spacecraft_figure", "spacecraft_figure"), "tumble.viz.spacecraft"))
