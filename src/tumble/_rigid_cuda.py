"""Rigid bodies set up, converted and read out on the GPU: the rigid model of ``simulate(..., device="cuda")``.

On the CPU a batch of rigid bodies given as inertia tensors (N, 3, 3) (kg·m²,
body axes) is validated and decomposed into principal moments and axes by
LAPACK (:func:`tumble._inertia.principal_axes`), its initial states turned into
principal axes and its results back into body axes
(:mod:`tumble.rigid_model`)::

    I = R_BP diag(I₁, I₂, I₃) R_BPᵀ,
    q_NP = q_NB ⊗ q_BP,   ω_P = R_BPᵀ ω_B        (in)
    q_NB = q_NP ⊗ q_BP*,  ω_B = R_BP ω_P         (out)

:class:`DeviceRigidBodies` does each step on the GPU, one thread per body, so
that only the tensors and the initial states travel to the device and, when
asked, the results back:

* **principal axes** (:func:`principal_axes_of_one`): the tensor symmetrised
  and checked by the CPU's rules (:func:`tumble._inertia.symmetrize`), then
  diagonalised by cyclic Jacobi rotations (:func:`jacobi`: each 2×2 symmetric
  Schur rotation, cyclic by rows; G. H. Golub & C. F. Van Loan, *Matrix
  Computations*, 4th ed., §8.5), sorted
  and signed as the CPU's (:func:`tumble._inertia.sort_ascending`,
  :func:`tumble._inertia.canonical`), its quaternion by Shepperd's method
  (:func:`tumble._quat.qfrom_matrix`). Eigenvectors are defined up to sign
  and, for equal moments, up to a rotation in their plane: the canonical signs
  make the axes those of LAPACK's to rounding where the moments differ, and the
  motion in body axes does not depend on the choice (tests/integrate/test_cuda_rigid.py
  compares both). A tensor that breaks a rule is decomposed again on the CPU,
  which raises the CPU's error naming the member.
* **conversions** in and out, by the CPU's own per-member functions
  (:func:`tumble.rigid_model.to_principal_axes`, :func:`tumble.rigid_model.to_body_axes`).

Import this module only when a GPU run is asked for: it imports ``numba.cuda``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import cuda, float64
from numba.extending import register_jitable

from tumble import limits, torques
from tumble._inertia import (_DEFINITE_RTOL, _LARGEST, _SYMMETRY_RTOL, _TRIANGLE_RTOL, canonical, sort_ascending,
                             symmetrize)
from tumble._quat import qfrom_matrix
from tumble._validate import ValidationError
from tumble.dynamics import euler_coefficients
from tumble.integrate._cuda import SCHEMES, THREADS_PER_BLOCK, on_device, require_gpu
from tumble.kernels import rigid as _kernel
from tumble.model import Model, Outputs
from tumble.rigid_model import _STACKLEVEL, RigidBodies, to_body_axes, to_principal_axes

__all__ = ["DeviceRigidBodies", "as_device_model"]

#: The most Jacobi sweeps (three rotations each); a 3×3 tensor converges quadratically, in 4 to 6.
_SWEEPS = 32
#: A set-up status bit: the tensor breaks a rule of :func:`tumble._inertia.principal_axes`.
BROKEN = 1
#: A set-up status bit: the smallest moment is below :data:`tumble.limits.THIN_RATIO` × the largest.
THIN = 2


@register_jitable
def _rotate(a, v, p, q):
    """One Jacobi rotation in the plane ``(p, q)``: ``a ← Jᵀ a J`` with ``a[p, q] = 0``, ``v ← v J``.

    ``θ = (a_qq − a_pp) / (2 a_pq)``, ``t = sgn θ / (|θ| + √(θ² + 1))`` (the smaller root of
    ``t² + 2θt − 1 = 0``), ``c = 1/√(1 + t²)``, ``s = t c``; ``a_pp ← a_pp − t a_pq``, ``a_qq ← a_qq + t a_pq``.
    An ``a_pq`` below the rounding of both diagonal entries is set to zero without a rotation."""
    apq = a[p, q]
    if abs(a[p, p]) + 100.0 * abs(apq) == abs(a[p, p]) and abs(a[q, q]) + 100.0 * abs(apq) == abs(a[q, q]):
        a[p, q] = a[q, p] = 0.0
        return
    theta = (a[q, q] - a[p, p]) / (2.0 * apq)
    t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0)) if abs(theta) < 1e150 else 0.5 / abs(theta)
    if theta < 0.0:
        t = -t
    c = 1.0 / math.sqrt(t * t + 1.0)
    s = t * c
    a[p, p] -= t * apq
    a[q, q] += t * apq
    a[p, q] = a[q, p] = 0.0
    r = 3 - p - q  # the third axis
    arp, arq = a[r, p], a[r, q]
    a[r, p] = a[p, r] = c * arp - s * arq
    a[r, q] = a[q, r] = s * arp + c * arq
    for k in range(3):
        vkp, vkq = v[k, p], v[k, q]
        v[k, p] = c * vkp - s * vkq
        v[k, q] = s * vkp + c * vkq


@register_jitable
def jacobi(a, v):
    """In place: the symmetric ``a`` (3, 3) diagonalised by cyclic Jacobi sweeps over the planes (0, 1),
    (0, 2), (1, 2), so that ``a₀ = v diag(a) vᵀ`` with ``v`` (3, 3) orthogonal (columns: the eigenvectors)."""
    for i in range(3):
        for j in range(3):
            v[i, j] = 1.0 if i == j else 0.0
    for _ in range(_SWEEPS):
        if a[0, 1] == 0.0 and a[0, 2] == 0.0 and a[1, 2] == 0.0:
            return
        for plane in range(3):
            p, q = (0, 1) if plane == 0 else (0, 2) if plane == 1 else (1, 2)
            if a[p, q] != 0.0:
                _rotate(a, v, p, q)


@register_jitable
def principal_axes_of_one(tensor, work, moments, axes):
    """The principal axes of one inertia tensor (3, 3) (kg·m², body axes), as
    :func:`tumble._inertia.principal_axes` gives them: ``moments`` (3,) ascending (equal ones merged) and
    ``axes`` (3, 3) R_BP (columns, canonical signs, det +1), with ``work`` (3, 3) as scratch. Returns the
    status bits :data:`BROKEN` (a rule broken: not finite, entries over 1e150, not symmetric, not positive
    definite, the triangle inequality) and :data:`THIN`."""
    for i in range(3):
        for j in range(3):
            if not math.isfinite(tensor[i, j]):
                return BROKEN
    scale, asym = symmetrize(tensor, work)
    if scale > _LARGEST or asym > _SYMMETRY_RTOL * scale:
        return BROKEN
    jacobi(work, axes)
    for i in range(3):
        moments[i] = work[i, i]
    sort_ascending(moments, axes)
    canonical(moments, axes)
    if not moments[0] > _DEFINITE_RTOL * moments[2] or \
            moments[0] + moments[1] < moments[2] * (1.0 - _TRIANGLE_RTOL):
        return BROKEN
    return THIN if moments[0] < limits.THIN_RATIO * moments[2] else 0


@cuda.jit(cache=True)
def _principal_axes_kernel(inertia, symmetric, moments, axes, q_bp, coefficients, status):
    """Thread ``b``: the principal axes of ``inertia[b]`` (:func:`principal_axes_of_one`), their quaternion
    ``q_bp[b]`` (P → body), the Euler coefficients ``coefficients[:, b]`` and the status bits ``status[b]``."""
    b = cuda.grid(1)
    if b >= inertia.shape[0]:
        return
    tensor = cuda.local.array((3, 3), float64)
    work = cuda.local.array((3, 3), float64)
    m = cuda.local.array(3, float64)
    r = cuda.local.array((3, 3), float64)
    for i in range(3):
        for j in range(3):
            tensor[i, j] = inertia[b, i, j]
    status[b] = principal_axes_of_one(tensor, work, m, r)
    symmetrize(tensor, work)  # the symmetrised tensor, the one the CPU keeps
    for i in range(3):
        moments[b, i] = m[i]
        for j in range(3):
            symmetric[b, i, j] = work[i, j]
            axes[b, i, j] = r[i, j]
    q_bp[b, 0], q_bp[b, 1], q_bp[b, 2], q_bp[b, 3] = qfrom_matrix(r)
    (coefficients[0, b], coefficients[1, b], coefficients[2, b],
     coefficients[3, b], coefficients[4, b], coefficients[5, b]) = euler_coefficients(m[0], m[1], m[2])


@cuda.jit(cache=True)
def _coefficients_kernel(moments, coefficients):
    """Thread ``b``: the Euler coefficients ``coefficients[:, b]`` of the principal moments ``moments[b]``."""
    b = cuda.grid(1)
    if b < moments.shape[0]:
        (coefficients[0, b], coefficients[1, b], coefficients[2, b],
         coefficients[3, b], coefficients[4, b], coefficients[5, b]) = euler_coefficients(
            moments[b, 0], moments[b, 1], moments[b, 2])


@cuda.jit(cache=True)
def _to_principal_kernel(q0, omega0, q_bp, axes, y0):
    """Thread ``b``: member ``b``'s initial state in principal axes (:func:`tumble.rigid_model.to_principal_axes`)."""
    b = cuda.grid(1)
    if b < y0.shape[0]:
        to_principal_axes(q0, omega0, q_bp, axes, y0, b, 0 if q_bp.shape[0] == 1 else b)


@cuda.jit(cache=True)
def _to_body_kernel(states, q_bp, axes, q, omega):
    """Thread ``b``: member ``b``'s states at every output time in body axes (:func:`tumble.rigid_model.to_body_axes`)."""
    b = cuda.grid(1)
    if b >= states.shape[1]:
        return
    j = 0 if q_bp.shape[0] == 1 else b
    for k in range(states.shape[0]):
        to_body_axes(states, q_bp, axes, q, omega, k, b, j)


def _blocks(n: int) -> int:
    return max(1, math.ceil(n / THREADS_PER_BLOCK))


class DeviceRigidBodies(RigidBodies):
    """:class:`tumble.rigid_model.RigidBodies` whose arrays live on the GPU: ``inertia`` (symmetrised), ``moments``,
    ``axes`` (R_BP), ``q_bp`` and the Euler ``coefficients`` are device arrays; the initial states and the
    outputs are converted there (:mod:`tumble._rigid_cuda`)."""

    __slots__ = ("coefficients", "thin")

    def __init__(self, inertia, moments, axes, q_bp, coefficients, masses, *, thin: bool, kind: str) -> None:
        self.inertia, self.moments, self.axes, self.q_bp = inertia, moments, axes, q_bp
        self.coefficients, self.masses, self.thin, self._kind = coefficients, masses, thin, kind

    @classmethod
    def of_tensors(cls, inertia) -> DeviceRigidBodies:
        """The bodies of the inertia tensors (N, 3, 3) (kg·m², body axes; a NumPy array or any array with
        ``__cuda_array_interface__``), set up on the GPU. A tensor that breaks a rule is decomposed on the
        CPU instead (:meth:`RigidBodies.of`), which raises its error naming the member (or, for a tensor at
        the border of a rule, gives the CPU's set-up, copied to the GPU)."""
        tensors = on_device(inertia)
        n = tensors.shape[0]
        symmetric, moments, axes = cuda.device_array((n, 3, 3)), cuda.device_array((n, 3)), cuda.device_array((n, 3, 3))
        q_bp, coefficients = cuda.device_array((n, 4)), cuda.device_array((6, n))
        status = cuda.device_array(n, dtype=np.int8)
        _principal_axes_kernel[_blocks(n), THREADS_PER_BLOCK](tensors, symmetric, moments, axes, q_bp, coefficients,
                                                              status)
        bits = np.bitwise_or.reduce(status.copy_to_host()) if n else 0
        if bits & BROKEN:
            return cls.of_host(RigidBodies.of(np.asarray(inertia)))
        return cls(symmetric, moments, axes, q_bp, coefficients, None, thin=bool(bits & THIN), kind="RigidBodies")

    @classmethod
    def of_host(cls, bodies: RigidBodies) -> DeviceRigidBodies:
        """The bodies of a :class:`RigidBodies` set up on the CPU, their arrays copied to the GPU."""
        moments = on_device(bodies.moments)
        coefficients = cuda.device_array((6, moments.shape[0]))
        _coefficients_kernel[_blocks(moments.shape[0]), THREADS_PER_BLOCK](moments, coefficients)
        thin = bool(np.any(bodies.moments[:, 0] < limits.THIN_RATIO * bodies.moments[:, 2]))
        return cls(on_device(bodies.inertia), moments, on_device(bodies.axes), on_device(bodies.q_bp), coefficients,
                   bodies.masses, thin=thin, kind=bodies.kind)

    @property
    def batch_size(self) -> int | None:
        return None if len(self.inertia.shape) == 2 else self.inertia.shape[0]

    def members(self, lo: int, hi: int) -> DeviceRigidBodies:
        """The bodies ``lo`` to ``hi − 1`` of the batch (a shared body: itself), views of the device arrays."""
        if self.batch_size is None:
            return self
        masses = None if self.masses is None else self.masses[lo:hi]
        return DeviceRigidBodies(self.inertia[lo:hi], self.moments[lo:hi], self.axes[lo:hi], self.q_bp[lo:hi],
                                 self.coefficients[:, lo:hi], masses, thin=self.thin, kind=self._kind)

    def compile(self, torque: torques.TorqueLike, t0: float) -> _kernel.RigidModel:
        """The rigid kernel on the device's arrays; a torque program is compiled on the CPU in each body's
        principal axes, for which the axes are copied back (9 numbers a body)."""
        program = torques.as_torque_model(torque)
        if program is None:
            return _kernel.RigidModel(self.coefficients, np.zeros((1, 0)), None, self.moments)
        return _kernel.from_principal(np.asarray(self.moments), np.asarray(self.axes), program)

    def _check_motion(self, states) -> None:
        """:func:`tumble.limits.check_rigid_motion` of the states (N, 7) on the device where it can warn (a thin
        body, or speeds with masses): then they are copied back (whole: a view of some columns is not
        contiguous)."""
        if self.thin or self.masses is not None:
            limits.check_rigid_motion(np.asarray(self.moments), states.copy_to_host()[:, 4:], self.masses,
                                      stacklevel=_STACKLEVEL + 1)

    def initial_states(self, kernel, values: dict[str, np.ndarray], t0: float):
        """The initial states (N, 7) on the GPU, ``[q_NP, ω_P]`` from ``q0`` and ``omega0`` in body axes."""
        n = values["omega0"].shape[0]
        y0 = cuda.device_array((n, _kernel.STATE_SIZE))
        _to_principal_kernel[_blocks(n), THREADS_PER_BLOCK](on_device(values["q0"]), on_device(values["omega0"]),
                                                            self.q_bp, self.axes, y0)
        self._check_motion(y0)
        return y0

    def outputs(self, kernel, t: np.ndarray, states):
        """``q`` (n, N, 4) and ``omega`` (n, N, 3) in body axes, on the GPU, from the states there."""
        if kernel.codes is not None:  # a torque may have spun the body up: check where it ended
            self._check_motion(states[states.shape[0] - 1])
        q, omega = cuda.device_array(states.shape[:-1] + (4,)), cuda.device_array(states.shape[:-1] + (3,))
        _to_body_kernel[_blocks(states.shape[1]), THREADS_PER_BLOCK](states, self.q_bp, self.axes, q, omega)
        return Outputs(q=q, omega=omega, inertia=self.inertia, extras={}, totals={}, info={})

    def __repr__(self) -> str:
        return f"DeviceRigidBodies(kind={self._kind!r}, batch_size={self.batch_size})"


def _is_tensor_batch(model) -> bool:
    """Whether ``model`` is a batch of inertia tensors (N, 3, 3), on the host or on the device."""
    if hasattr(model, "__cuda_array_interface__"):
        return len(model.__cuda_array_interface__["shape"]) == 3
    return isinstance(model, np.ndarray) and model.ndim == 3 and model.dtype.kind == "f"


def as_device_model(model, method: str) -> Model:
    """The model of ``simulate(model, ..., device="cuda")``: a batch of inertia tensors (N, 3, 3) set up on
    the GPU (:meth:`DeviceRigidBodies.of_tensors`), the rigid bodies of a :class:`tumble.RigidBody` or a
    sequence of them copied there (:meth:`DeviceRigidBodies.of_host`), any other model as it is (its states
    are converted on the CPU). A method without a GPU kernel, or no GPU, is refused first."""
    if method not in SCHEMES:
        raise ValidationError(f"device: 'cuda' runs the methods {', '.join(map(repr, SCHEMES))}; got "
                              f"method={method!r}")
    if _is_tensor_batch(model):
        require_gpu()
        shape = tuple(model.__cuda_array_interface__["shape"]) if hasattr(model, "__cuda_array_interface__") \
            else model.shape
        if shape[1:] != (3, 3):
            raise ValidationError(f"inertia: must have shape (3, 3) or (N, 3, 3), got {shape}")
        return DeviceRigidBodies.of_tensors(model)
    model = model if isinstance(model, Model) else RigidBodies.of(model)
    if type(model) is RigidBodies:
        require_gpu()
        return DeviceRigidBodies.of_host(model)
    return model


def to_host(out):
    """The :class:`~tumble.model.Outputs` ``out`` with its device arrays (``q``, ``omega``, ``inertia``) copied
    to the host."""
    def host(a):
        return a.copy_to_host() if hasattr(a, "copy_to_host") else a

    return out._replace(q=host(out.q), omega=host(out.omega), inertia=host(out.inertia))
