"""The attitude and body rate of states left on the GPU: ``simulate(..., output="device")`` for the protocol's models.

A model whose attitude is its state's quaternion ``Y[0:4]`` (body → inertial)
and whose body rate is its kernel's ``body_rate`` (:mod:`tumble._protocol`:
``ω`` in the body axes that quaternion maps to inertial, rad/s) has both made
here, from the states (n, N, size) at the output times, one thread per member:

    q[k, b] = Y_kb[0:4],    ω[k, b] = body_rate(model, Y_kb)

with the compiled function the CPU's integrators call (a slice of the state
for a flexible body, a slosh body and a spacecraft; ``ω = W [K; P]`` for a
body in a fluid, :mod:`tumble.kernels.fluid`; ``ω = I(s)⁻¹ (q* L_N q − A(s))``
for a body of changing shape, :func:`tumble.kernels.variable.angular_rate`).
The models' host ``outputs`` compute the same ``ω`` with NumPy (``@``,
``numpy.linalg.solve``), so for the last two the rates differ from the host's
in the last bits; the slices are the same numbers.

The kernel calls ``body_rate`` through :func:`_rate`: compiled for the GPU,
the protocol's overload; under Numba's CUDA simulator, which runs the
kernel's Python, the same function compiled for the CPU on the stand-in arrays
(as :func:`tumble.integrate._cuda._advance` does).

Import this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import cuda, njit
from numba.extending import overload

from tumble import _protocol
from tumble.integrate._cuda import _LAUNCH_OPTIONS, THREADS_PER_BLOCK, _to_device, simulated_on_host

__all__ = ["attitude_and_rate"]


@njit(cache=True)
def _rate_host(model, y):
    return _protocol.body_rate(model, y, 0)


def _rate(model, y):
    """The body rate ``(ω₁, ω₂, ω₃)`` (rad/s, body axes) of the state vector ``y`` of the compiled ``model``.

    Compiled for the GPU, the overload below; the CUDA simulator runs this body, the same compiled function
    on the CPU, on its stand-in arrays."""
    return _rate_host(simulated_on_host(model), np.asarray(y))


@overload(_rate, target="cuda")
def _rate_gpu(model, y):
    return lambda model, y: _protocol.body_rate(model, y, 0)


@cuda.jit(cache=True, **_LAUNCH_OPTIONS)
def _attitude_and_rate_kernel(model, states, q, omega):
    """Thread ``b``: ``q[k, b] = states[k, b, 0:4]`` and ``omega[k, b]``, the body rate of ``states[k, b]``, at
    every output time ``k``."""
    b = cuda.grid(1)
    if b >= states.shape[1]:
        return
    for k in range(states.shape[0]):
        y = states[k, b]
        q[k, b, 0], q[k, b, 1], q[k, b, 2], q[k, b, 3] = y[0], y[1], y[2], y[3]
        omega[k, b, 0], omega[k, b, 1], omega[k, b, 2] = _rate(model, y)


def attitude_and_rate(model, states) -> tuple[Any, Any]:
    """``q`` (n, N, 4) and ``omega`` (n, N, 3) (rad/s, body axes), device arrays, of the device array ``states``
    (n, N, size) of the compiled ``model`` (one with the ``"body_rate"`` capability whose attitude is
    ``Y[0:4]``), made on the GPU (see the module docstring)."""
    n, members = states.shape[0], states.shape[1]
    q, omega = cuda.device_array((n, members, 4)), cuda.device_array((n, members, 3))
    blocks = max(1, math.ceil(members / THREADS_PER_BLOCK))
    _attitude_and_rate_kernel[blocks, THREADS_PER_BLOCK](_to_device(model), states, q, omega)
    return q, omega
