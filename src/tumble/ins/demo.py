"""Moved: the demos of :mod:`tumble.ins` are :mod:`tumble.viz.ins`; these names warn and work for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, {**dict.fromkeys(("DEMO_GYRO", "DEMO_GYRO_ERRORS", "demo_coning", "demo_gyroscope",
                                                "demo_ins"), "tumble.viz.ins"), "CONING_RANGES": "tumble.ins.coning"})
