"""Moved: the estimation demo is :mod:`tumble.viz.estimation`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, dict.fromkeys(("TARGET", "FSW", "spacecraft", "monte_carlo", "dispersions",
                                             "loop_response", "demo_estimation"), "tumble.viz.estimation"))
