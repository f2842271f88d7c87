"""``simulate_variable``: deprecated; a :class:`~tumble.variable.VariableBody` runs through :func:`tumble.simulate`."""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

import tumble
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from tumble.variable.body import VariableBody

__all__ = ["simulate_variable"]


def simulate_variable(body: VariableBody, omega0: ArrayLike | None = None, **options: Any) -> Trajectory:
    """Deprecated: ``tumble.simulate(body, omega0, **options)``, which it calls (see ``VariableBody``)."""
    warnings.warn("tumble.variable.simulate_variable is deprecated: call tumble.simulate(body, omega0, t=..., ...)",
                  DeprecationWarning, stacklevel=2)
    return tumble.simulate(body, omega0, **options)
