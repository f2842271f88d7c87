"""Moved: the space-arm demo is :mod:`tumble.viz.space_arm`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, dict.fromkeys(("ARM", "DURATION", "GAINS", "HUB", "MANOEUVRE", "MOUNT", "TARGET",
                                             "demo_space_arm", "reference", "space_arm"), "tumble.viz.space_arm"))
