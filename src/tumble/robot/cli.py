"""Moved: ``tumble robot`` is :mod:`tumble.cli.robot`; ``tumble.robot.cli.app`` warns and works for one release."""

from tumble._moved import moved

__getattr__ = moved(__name__, {"app": "tumble.cli.robot"})
