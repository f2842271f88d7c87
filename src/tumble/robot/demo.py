"""Moved: the Panda demo is :mod:`tumble.viz.robot`; ``demo_robot`` warns and works for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, {"demo_robot": "tumble.viz.robot"})
