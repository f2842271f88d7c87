"""``simulate_variable``: deprecated; a :class:`~tumble.variable.VariableBody` runs through :func:`tumble.simulate`."""

from __future__ import annotations

import warnings

import tumble
from tumble.trajectory import Trajectory

__all__ = ["simulate_variable"]


def simulate_variable(body, omega0=None, **options) -> Trajectory:
    """Deprecated: ``tumble.simulate(body, omega0, **options)``, which it calls (see ``VariableBody``)."""
    warnings.warn("tumble.variable.simulate_variable is deprecated: call tumble.simulate(body, omega0, t=..., ...)",
                  DeprecationWarning, stacklevel=2)
    return tumble.simulate(body, omega0, **options)
