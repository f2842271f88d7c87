"""The fixed-step methods on an NVIDIA GPU (``numba.cuda``): one thread per batch member.

Two kernels, both landing on every output time as the CPU does
(:func:`tumble.integrate._fixed.landing_steps`: between output times ``t_{k-1}``
and ``t_k``, ``m = ⌈(t_k − t_{k-1})/dt⌉`` equal steps ``h = (t_k − t_{k-1})/m ≤ dt``):

* :func:`_protocol_kernel` runs any compiled model (:mod:`tumble._protocol`)
  with ``rk4`` or ``cf4``: thread ``b`` advances member ``b`` with the method's
  own ``advance`` (:mod:`tumble.integrate._fixed`), the functions the CPU
  compiles, on the state vector ``Y[b]`` in global memory, with its own rows of
  the method's workspace (the workspace of one body, allocated once per member
  before the launch: no code on the device allocates). A kernel whose
  right-hand side reads a state held in registers (``point_rates``: the rigid
  body) runs its whole step in registers there.
* :func:`_rk4_kernel`, the rigid body's fused RK4, described below, which keeps
  the state in registers from the first output time to the last; it ran at
  8–10 × 10¹⁰ body-steps/s on an H100 (docs/gpu.md). It is the rigid body's
  ``rk4`` path; the protocol kernel has not been timed on a GPU.

The rigid kernel is :mod:`tumble.integrate._rk4` applied to the :class:`tumble.kernels.rigid.RigidModel`.
Each thread keeps one body's state in registers,
``y = [q_w, q_x, q_y, q_z, ω₁, ω₂, ω₃]`` (attitude of the principal axes P,
P → inertial; body rate in P, rad/s), and advances it with the same
arithmetic as the CPU kernel:

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
``Gravity``, ``GravityGradient``); what cannot run on a GPU (a Python torque
function or control law, a spacecraft's flight software) is refused before
the launch with the kernel's ``gpu_refusal``.

Arithmetic is float64 throughout. NVVM fuses ``a·b + c`` into fused
multiply–adds (its default), so on a GPU the results differ from the CPU's in
the last bits of each step. Under Numba's CUDA simulator
(``NUMBA_ENABLE_CUDASIM=1``, how the tests run without a GPU) they are
bitwise equal: the simulator runs the kernels' Python, and the protocol
kernel's per-member ``advance`` is the CPU's compiled function
(:func:`_advance`), so there it checks the launch, the landing, the
workspace rows and the transfers; that the same kernel compiles for a GPU is
checked on its PTX (``tests/integrate/test_cuda_models.py``).

Launch: :data:`THREADS_PER_BLOCK` threads per block, ``⌈N/128⌉`` blocks. Import
this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import cuda, njit, types
from numba.core import config
from numba.extending import overload, register_jitable

from tumble import torques
from tumble.dynamics import rigid_rates
from tumble._validate import ValidationError
from tumble.integrate import _fixed, _liegroup, _rk4
from tumble.integrate._fixed import landing_steps
from tumble.integrate._method import MAX_STEPS
from tumble.integrate._rk4 import axpy, update

#: The methods that run on a GPU, and their schemes (:mod:`tumble.integrate._fixed`).
SCHEMES = {"rk4": _rk4.SCHEME, "cf4": _liegroup.SCHEME}

#: Threads per block, a multiple of the warp (32). The kernel uses no shared
#: memory, so what limits the warps resident on a multiprocessor is registers:
#: on sm_90, 70 per thread torque-free and 156 with a torque program (ptxas),
#: room for 28 and 12 of its 64 warps; 128 does not lower that. Not tuned on a GPU.
THREADS_PER_BLOCK = 128

def cuda_available() -> bool:
    """True when ``numba.cuda`` finds a usable GPU (or runs its simulator)."""
    return cuda.is_available()


def require_gpu() -> None:
    """Raise :class:`~tumble._validate.ValidationError` naming ``device`` when no GPU is found."""
    if not cuda_available():
        raise ValidationError("device: 'cuda' needs an NVIDIA GPU with its driver, and numba.cuda finds none")


def on_device(a):
    """``a`` on the GPU: a NumPy array (or array_like) copied there as C-ordered float64, a device array
    (numba.cuda's, or any array with ``__cuda_array_interface__``: CuPy's) as it is, without a copy."""
    if hasattr(a, "copy_to_host"):  # numba.cuda's, and the simulator's stand-ins
        return a
    if hasattr(a, "__cuda_array_interface__"):
        return cuda.as_cuda_array(a)
    return cuda.to_device(np.ascontiguousarray(a, dtype=np.float64))


def is_on_device(a) -> bool:
    """Whether ``a`` is a device array (numba.cuda's or another with ``__cuda_array_interface__``)."""
    return hasattr(a, "copy_to_host") or hasattr(a, "__cuda_array_interface__")


@cuda.jit(cache=True)
def _first_not_finite_kernel(states, first):
    """``first[0] ← min(first[0], b)`` for each member ``b`` of ``states`` (n, N, size) with a value that is
    not finite."""
    b = cuda.grid(1)
    if b >= states.shape[1]:
        return
    for k in range(states.shape[0]):
        for i in range(states.shape[2]):
            if not math.isfinite(states[k, b, i]):
                cuda.atomic.min(first, 0, b)
                return


def all_finite(states) -> bool:
    """Whether every value of the device array ``states`` (n, N, size) is finite: one flag copied back."""
    first = cuda.to_device(np.array([states.shape[1]], dtype=np.int64))
    _first_not_finite_kernel[max(1, math.ceil(states.shape[1] / THREADS_PER_BLOCK)), THREADS_PER_BLOCK](
        states, first)
    return int(first.copy_to_host()[0]) == states.shape[1]


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


# ``max`` and ``min`` of two or three numbers, as Python's (the first of equals; ``b`` replaces ``a`` only when
# strictly greater, or smaller), for code compiled for a GPU: Numba's generic overload takes ``*args``, which
# the numba.cuda of Numba 0.68 does not compile ("Signature mismatch"); the kernels call them with numbers.
@register_jitable
def _larger(a, b):
    return b if b > a else a


@register_jitable
def _smaller(a, b):
    return b if b < a else a


_MAX = {2: _larger, 3: lambda a, b, c: _larger(_larger(a, b), c),
        4: lambda a, b, c, d: _larger(_larger(_larger(a, b), c), d)}  # a quaternion's largest (_quat.qnorm)
_MIN = {2: _smaller, 3: lambda a, b, c: _smaller(_smaller(a, b), c),
        4: lambda a, b, c, d: _smaller(_smaller(_smaller(a, b), c), d)}


@overload(max, target="cuda", strict=False)
def _max_gpu(*args):
    if all(isinstance(a, types.Number) for a in args):
        return _MAX.get(len(args))


@overload(min, target="cuda", strict=False)
def _min_gpu(*args):
    if all(isinstance(a, types.Number) for a in args):
        return _MIN.get(len(args))


class _NoneAsNull:
    """A ``numba.cuda`` kernel-argument extension: a field that is None in a kernel (a NamedTuple), such as a
    torque-free rigid body's ``codes``, passes as a null pointer, the argument Numba's None takes (an opaque
    pointer), which numba.cuda's launcher does not marshal itself."""

    def prepare_args(self, ty, val, stream=0, retr=None):
        if isinstance(ty, types.NoneType):
            return types.uintp, 0
        return ty, val


def _rows(work, b):
    """Member ``b``'s rows of each array of the workspace ``work`` (a tuple of per-member arrays)."""
    return tuple(w[b] for w in work)


# The workspaces of the device methods, by their number of arrays: none (a step in registers), cf4's 4, rk4's 5,
# and one more with the model's scratch (a robot's: tumble._protocol.scratch).
_ROWS = {
    0: lambda work, b: (),
    4: lambda work, b: (work[0][b], work[1][b], work[2][b], work[3][b]),
    5: lambda work, b: (work[0][b], work[1][b], work[2][b], work[3][b], work[4][b]),
    6: lambda work, b: (work[0][b], work[1][b], work[2][b], work[3][b], work[4][b], work[5][b]),
}


@overload(_rows, target="cuda")
def _rows_gpu(work, b):
    return _ROWS.get(len(work))


@njit(cache=True)
def _advance_host(scheme, model, b, t0, h, m, y, work):
    _fixed.advance(scheme, model, b, t0, h, m, y, work)


def _advance(scheme, model, b, t0, h, m, y, work):
    """Advance member ``b``'s state vector ``y`` (in place) by ``m`` steps of ``h`` (s) from ``t0`` (s): the
    method's ``advance`` (:mod:`tumble.integrate._fixed`) on one body, with its workspace rows ``work``.

    Compiled for the GPU, the overload below; the CUDA simulator runs this body, the same compiled
    function on the CPU, on its stand-in arrays.
    """
    _advance_host(scheme, simulated_on_host(model), b, t0, h, m, np.asarray(y), tuple(np.asarray(w) for w in work))


def simulated_on_host(model):
    """The compiled ``model`` with the CUDA simulator's stand-in device arrays as NumPy arrays, for the CPU's
    compiled functions that the simulated kernels call."""
    return type(model)(*(np.asarray(f) if hasattr(f, "__cuda_ndarray__") else f for f in model))


@overload(_advance, target="cuda")
def _advance_gpu(scheme, model, b, t0, h, m, y, work):
    return lambda scheme, model, b, t0, h, m, y, work: _fixed.advance(scheme, model, b, t0, h, m, y, work)


# The CUDA simulator passes Python values as they are, and its jit takes no extensions.
_LAUNCH_OPTIONS = {} if config.ENABLE_CUDASIM else {"extensions": [_NoneAsNull()]}


@cuda.jit(cache=True, **_LAUNCH_OPTIONS)
def _protocol_kernel(scheme, model, Y, t_out, m, h, out, work):
    """Thread ``b`` integrates member ``b`` of the compiled ``model`` from ``Y[b]`` (in place) through
    ``t_out`` with ``scheme``, ``m[k]`` steps of ``h[k]`` from ``t_out[k]`` to ``t_out[k+1]``; ``out[k, b]``
    receives its state at ``t_out[k]``. ``work`` holds the method's workspace, one row per member."""
    b = cuda.grid(1)
    if b >= Y.shape[0]:
        return
    y = Y[b]
    rows = _rows(work, b)
    for i in range(y.shape[0]):
        out[0, b, i] = y[i]
    for k in range(1, t_out.shape[0]):
        _advance(scheme, model, b, t_out[k - 1], h[k - 1], m[k - 1], y, rows)
        for i in range(y.shape[0]):
            out[k, b, i] = y[i]


@njit(cache=True)
def _workspace_of_one_host(scheme, model, y):
    return _fixed.workspace(scheme, model, 0, y)


def _workspace_of_one(scheme, model, y):
    """The method's workspace of one member (host arrays): what the launch allocates once per member. A
    model's fields on the device (a rigid batch set up there) stand in by host arrays of their shapes, not
    filled: the workspace depends on the model's types and sizes, not its values."""
    host = type(model)(*(np.empty(f.shape, f.dtype) if is_on_device(f) else f for f in model))
    return _workspace_of_one_host(scheme, host, y)


def check(kernel, method: str, who: str) -> None:
    """Refuse, before anything is compiled, a run that cannot go to the GPU: a method other than those of
    :data:`SCHEMES`, or a ``kernel`` without the ``"cuda"`` capability (its ``gpu_refusal`` names the part).
    ``who`` names the model in the message."""
    if method not in SCHEMES:
        raise ValidationError(f"device: 'cuda' runs the methods {', '.join(map(repr, SCHEMES))}; got "
                              f"method={method!r}")
    if "cuda" not in kernel.provides:
        raise ValidationError(getattr(kernel, "gpu_refusal", None)
                              or f"device: 'cuda' cannot run {who}: its compiled model does not run on a GPU")


def _to_device(model):
    """``model`` (a kernel: a NamedTuple) with its arrays copied to the GPU (those there already kept)."""
    return type(model)(*(cuda.to_device(np.ascontiguousarray(f)) if isinstance(f, np.ndarray) else f
                         for f in model))


def solve_cuda(model, y0, t_out, dt, max_steps=None, method="rk4", keep=False) -> tuple[np.ndarray, int]:
    """Integrate a batch of states of the compiled ``model`` with a fixed-step ``method`` on the GPU.

    Returns the states (len(t_out), N, n) at the output times and the number
    of steps summed over the batch.

    model : a compiled model with the ``"cuda"`` capability (:mod:`tumble._protocol`)
    y0 : (N, n) the initial states
    t_out : (n,) output times (s), strictly increasing; ``t_out[0]`` is the start
    dt : the longest step (s)
    max_steps : the most steps per body (default :data:`tumble.integrate.MAX_STEPS`), checked before the run
    method : ``"rk4"`` or ``"cf4"`` (:data:`SCHEMES`)
    keep : return the states as a device array, left on the GPU (``y0`` may be one too)

    The states equal those of ``tumble.integrate.solve(model, y0, t_out, method=method, dt=dt)``
    to the rounding of fused multiply–adds (bitwise under the CUDA simulator).
    Raises :class:`~tumble._validate.ValidationError` for what the model cannot run on a GPU
    (:func:`check`), and when no GPU is found.
    """
    check(model, method, f"a {type(model).__name__}")
    require_gpu()
    y0 = on_device(y0)
    t_out = np.ascontiguousarray(t_out, dtype=np.float64)
    m, h = landing_steps(t_out, float(dt), MAX_STEPS if max_steps is None else max_steps)
    steps = y0.shape[0] * int(m.sum())
    if method == "rk4" and "rigid_fields" in model.provides:  # rigid bodies: the fused kernel reads their fields
        out = _solve_rigid_rk4(model, y0, t_out, m, h)
    else:
        work = tuple(cuda.device_array((y0.shape[0], *w.shape)) for w in _workspace_of_one(
            SCHEMES[method], model, np.array(y0[0], dtype=np.float64)))
        out = cuda.device_array((t_out.shape[0], *y0.shape), dtype=np.float64)
        _protocol_kernel[math.ceil(y0.shape[0] / THREADS_PER_BLOCK), THREADS_PER_BLOCK](
            SCHEMES[method], _to_device(model), y0, cuda.to_device(t_out), cuda.to_device(m),
            cuda.to_device(h), out, work)
    return (out if keep else out.copy_to_host()), steps


def _solve_rigid_rk4(model, y0, t_out, m, h):
    """The states (len(t_out), N, 7) of the rigid bodies of ``model`` by :func:`_rk4_kernel`, on the GPU.

    It reads the fields of a kernel that provides ``"rigid_fields"`` (:class:`tumble.kernels.rigid.RigidModel`):

    coefficients : (6, N or 1) Euler coefficients ``(c₁, c₂, c₃, 1/I₁, 1/I₂, 1/I₃)``,
                   one column per body or one shared
    params : (N or 1, n_p) torque-program parameters in each body's principal axes
    codes : int64 torque-program codes, or None for torque-free bodies

    (host or device arrays) and ``y0`` (N, 7) the initial states ``[q_NP (4), ω_P (3)]`` (ω in rad/s), on
    the device.
    """
    # torque-free: an empty tuple, and the kernel compiles without torque code (see _torque)
    codes = model.codes
    program = () if codes is None else cuda.to_device(np.ascontiguousarray(codes, dtype=np.int64))
    out = cuda.device_array((t_out.shape[0], *y0.shape), dtype=np.float64)
    _rk4_kernel[math.ceil(y0.shape[0] / THREADS_PER_BLOCK), THREADS_PER_BLOCK](
        on_device(model.coefficients),
        on_device(model.params),
        program,
        y0,
        cuda.to_device(t_out),
        cuda.to_device(m),
        cuda.to_device(h),
        out,
    )
    return out
