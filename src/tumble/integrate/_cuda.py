"""Classical RK4 for a batch of rigid bodies on an NVIDIA GPU (``numba.cuda``): one thread per body.

This is :mod:`tumble.integrate._rk4` applied to the :class:`tumble.kernels.rigid.RigidModel`,
run as a CUDA kernel. Each thread keeps one body's state in registers,
``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃]`` (attitude of the principal axes P,
P → inertial; body rate in P, rad/s), and advances it with the same
arithmetic, step rule and landing as the CPU kernel:

* between output times ``t_{k-1}`` and ``t_k`` it takes ``m = ⌈(t_k − t_{k-1})/dt⌉``
  equal steps ``h = (t_k − t_{k-1})/m ≤ dt``, so it lands on every ``t_k``
  (:func:`tumble.integrate._fixed.landing_steps`, the CPU's own rule);
* the right-hand side is Euler's equations in principal axes with the
  precomputed coefficients of :func:`tumble.dynamics.euler_coefficients`
  (``ω̇₁ = c₁ ω₂ ω₃ + τ₁/I₁`` and cyclic, :func:`tumble.dynamics.euler_principal`)
  and ``q̇ = ½ q ⊗ [0, ω]`` (:func:`tumble._quat.qmul`);
* the quaternion is normalised after every step, ``q ← q/|q|``.

The scalar kernels are the project's own ``njit`` functions (``qmul``,
``qrotate_inv``, ``euler_principal``): ``numba.cuda`` compiles an ``@njit``
function called from a kernel again, as a device function. The functions
here that read arrays are :func:`~numba.extending.register_jitable` (plain
Python until compiled), so that Numba's CUDA simulator can run them on its
stand-in device arrays. The torques are the compiled torque programs of
:mod:`tumble.torques` (``ConstantBody``, ``ConstantInertial``, ``Tabulated``,
``Gravity``); a Python torque function cannot run on a GPU and is refused.

Arithmetic is float64 throughout. NVVM fuses ``a·b + c`` into fused
multiply–adds (its default), so on a GPU the results differ from the CPU's in
the last bits of each step; under Numba's CUDA simulator
(``NUMBA_ENABLE_CUDASIM=1``, how the tests run without a GPU) they are
bitwise equal.

Launch: :data:`THREADS_PER_BLOCK` threads per block, ``⌈N/128⌉`` blocks. Import
this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import cuda, types
from numba.extending import overload, register_jitable

from tumble import torques
from tumble.dynamics import rigid_rates
from tumble._validate import ValidationError
from tumble.integrate._fixed import landing_steps
from tumble.integrate._method import MAX_STEPS
from tumble.integrate._rk4 import axpy, update

#: Threads per block, a multiple of the warp (32). The kernel uses no shared
#: memory, so what limits the warps resident on a multiprocessor is registers:
#: on sm_90, 70 per thread torque-free and 156 with a torque program (ptxas),
#: room for 28 and 12 of its 64 warps; 128 does not lower that. Not tuned on a GPU.
THREADS_PER_BLOCK = 128

def cuda_available() -> bool:
    """True when ``numba.cuda`` finds a usable GPU (or runs its simulator)."""
    return cuda.is_available()


def _torque(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
    """The torque (N·m, principal axes) of the program ``codes``, or None (torque-free) for ``codes = ()``.

    Compiled code picks the implementation from the type of ``codes`` (the
    overload below), so that a torque-free kernel holds no torque code at all:
    on sm_90 it needs 70 registers per thread instead of 156, over twice the
    resident warps. The CUDA simulator runs this Python body.
    """
    if len(codes) == 0:
        return None
    return torques.evaluate_compiled(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes)


@overload(_torque)
def _torque_by_type(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
    if isinstance(codes, types.BaseTuple):  # torque-free

        def impl(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):
            return None

        return impl

    def program(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes):  # the typing signature's names, unannotated
        return torques.evaluate_compiled(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes)

    return program


@register_jitable
def _derivative(c, P, row, codes, t, y):
    """``dy/dt`` of one body: the rigid body's one right-hand side (:func:`tumble.dynamics.rigid_rates`)
    with coefficients ``c`` and the torque of ``codes``."""
    qw, qx, qy, qz, w1, w2, w3 = y
    return rigid_rates(c[0], c[1], c[2], c[3], c[4], c[5], qw, qx, qy, qz, w1, w2, w3,
                       _torque(t, qw, qx, qy, qz, w1, w2, w3, P, row, codes))


@register_jitable
def _rk4_step(c, P, row, codes, t, h, y):
    """One RK4 step of length ``h`` from ``(t, y)``, then ``q ← q/|q|``: the stages of the CPU's
    :func:`tumble.integrate._rk4.point_step`, with its :func:`~tumble.integrate._rk4.axpy` and
    :func:`~tumble.integrate._rk4.update`."""
    k1 = _derivative(c, P, row, codes, t, y)
    k2 = _derivative(c, P, row, codes, t + 0.5 * h, axpy(y, 0.5 * h, k1))
    k3 = _derivative(c, P, row, codes, t + 0.5 * h, axpy(y, 0.5 * h, k2))
    k4 = _derivative(c, P, row, codes, t + h, axpy(y, h, k3))
    return update(h, y, k1, k2, k3, k4)


@cuda.jit(cache=True)
def _rk4_kernel(coefficients, P, codes, y0, t_out, m, h, out):
    """Thread ``b`` integrates body ``b`` from ``y0[b]`` through ``t_out``, ``m[k]`` steps of ``h[k]``
    from ``t_out[k]`` to ``t_out[k+1]``; ``out[k, b]`` receives its state at ``t_out[k]``."""
    b = cuda.grid(1)
    if b >= y0.shape[0]:
        return
    r = b if coefficients.shape[1] > 1 else 0
    c = (coefficients[0, r], coefficients[1, r], coefficients[2, r],
         coefficients[3, r], coefficients[4, r], coefficients[5, r])
    row = b if P.shape[0] > 1 else 0
    y = (y0[b, 0], y0[b, 1], y0[b, 2], y0[b, 3], y0[b, 4], y0[b, 5], y0[b, 6])
    out[0, b, 0], out[0, b, 1], out[0, b, 2], out[0, b, 3], out[0, b, 4], out[0, b, 5], out[0, b, 6] = y
    for k in range(1, t_out.shape[0]):
        for s in range(m[k - 1]):
            y = _rk4_step(c, P, row, codes, t_out[k - 1] + s * h[k - 1], h[k - 1], y)
        out[k, b, 0], out[k, b, 1], out[k, b, 2], out[k, b, 3], out[k, b, 4], out[k, b, 5], out[k, b, 6] = y


def solve_cuda(model, y0, t_out, dt, max_steps=None) -> tuple[np.ndarray, int]:
    """Integrate a batch of rigid bodies with RK4 on the GPU.

    Returns the states (len(t_out), N, 7) at the output times and the number
    of steps summed over the batch.

    ``model`` is a :class:`tumble.kernels.rigid.RigidModel` (the ``"cuda"``
    capability), whose fields the kernel reads:

    coefficients : (6, N or 1) Euler coefficients ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)``,
                   one column per body or one shared
    params : (N or 1, n_p) torque-program parameters in each body's principal axes
    codes : int64 torque-program codes, or None for torque-free bodies

    and ``y0`` (N, 7) the initial states ``[q_NP (4), ω_P (3)]`` (ω in rad/s)
    t_out : (n,) output times (s), strictly increasing; ``t_out[0]`` is the start
    dt : the longest step (s)
    max_steps : the most steps per body (default :data:`tumble.integrate.MAX_STEPS`), checked before the run

    The states equal those of ``tumble.integrate.solve(model, y0, t_out, method="rk4", dt=dt)``
    to the rounding of fused multiply–adds (bitwise under the CUDA simulator).
    Raises :class:`~tumble._validate.ValidationError` for a Python torque
    function, and when no GPU is found.
    """
    coefficients, params, codes = model.coefficients, model.params, model.codes
    if torques.calls_python(codes):
        raise ValidationError(
            "torque: a Python function cannot run on the GPU (device='cuda'); use the compiled models "
            "(ConstantBody, ConstantInertial, Tabulated, Gravity) or device='cpu'"
        )
    if not cuda_available():
        raise ValidationError("device: 'cuda' needs an NVIDIA GPU with its driver, and numba.cuda finds none")
    y0 = np.ascontiguousarray(y0, dtype=np.float64)
    t_out = np.ascontiguousarray(t_out, dtype=np.float64)
    m, h = landing_steps(t_out, float(dt), MAX_STEPS if max_steps is None else max_steps)
    # torque-free: an empty tuple, and the kernel compiles without torque code (see _torque)
    program = () if codes is None else cuda.to_device(np.ascontiguousarray(codes, dtype=np.int64))
    out = cuda.device_array((t_out.shape[0], *y0.shape), dtype=np.float64)
    _rk4_kernel[math.ceil(y0.shape[0] / THREADS_PER_BLOCK), THREADS_PER_BLOCK](
        cuda.to_device(np.ascontiguousarray(coefficients, dtype=np.float64)),
        cuda.to_device(np.ascontiguousarray(params, dtype=np.float64)),
        program,
        cuda.to_device(y0),
        cuda.to_device(t_out),
        cuda.to_device(m),
        cuda.to_device(h),
        out,
    )
    return out.copy_to_host(), y0.shape[0] * int(m.sum())
