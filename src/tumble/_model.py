"""The model protocol: what an integrator needs from the thing it integrates.

A *model* is an immutable :class:`typing.NamedTuple` of NumPy arrays (its
parameters, shared by the whole batch or one row per body). Its state is a
flat float64 vector whose first four entries are the attitude quaternion
(scalar first). A model type provides, through :func:`numba.extending.overload`
of the two generic functions below, its right-hand side and its projection
back onto the state manifold::

    rhs(model, b, t, y, out)     # out = dy/dt for batch member b at (t, y)
    project(model, y)            # e.g. normalise the quaternion y[0:4]

The integrators call these generic functions; Numba picks the implementation
from the model's type when it compiles the integrator, so each model gets its
own fully inlined integrator, and the compiled code is cached on disk. (Passing
functions as arguments instead would defeat the disk cache, and a run-time
switch on a model code costs 2–3× in the inner loop.) Adding a model is one
module: a NamedTuple, its two overloads, and a row in ``docs/architecture.md``.
"""

from __future__ import annotations

from numba import njit


def rhs(model, b, t, y, out):  # pragma: no cover - replaced by overloads in compiled code
    """``out = dy/dt`` of batch member ``b`` of ``model`` at time ``t``, state ``y``."""
    raise NotImplementedError(f"no compiled right-hand side for {type(model).__name__}")


def project(model, y):  # pragma: no cover - replaced by overloads in compiled code
    """Put the state ``y`` back onto its manifold after a step (in place)."""
    raise NotImplementedError(f"no compiled projection for {type(model).__name__}")


@njit(cache=True)
def normalize_quaternion(y):
    """Divide ``y[0:4]`` by its norm: the projection every attitude model uses.

    The exact flow keeps ``|q| = 1``; a Runge–Kutta step leaves it off by about
    the local error. Projecting after every accepted step keeps it at 1 to
    rounding without changing the order of the method.
    """
    n = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3]) ** 0.5
    for i in range(4):
        y[i] /= n
