"""The model protocol: what an integrator needs from the compiled model it integrates.

A *compiled model* (a *kernel*) is an immutable :class:`typing.NamedTuple` of
NumPy arrays (its parameters: one row shared by the whole batch, or one row
per body), built by a user-level model (:class:`tumble.simulate.Model`). Its
state is a flat float64 vector. Integrators hold states as
structure-of-arrays *blocks* ``Y[i, j]`` = component ``i`` of batch member
``b0 + j``, so that the loop over the lanes ``j`` compiles to SIMD
instructions. A kernel type provides, through
:func:`numba.extending.overload` of the generic functions below, what the
methods need. Every kernel provides the core three::

    rhs(model, b0, t, Y, OUT)    # OUT[:, j] = dy/dt of batch member b0 + j at (t, Y[:, j])
    project(model, b0, t, Y)     # after a step that ends at t: e.g. normalise the quaternion
                                 # of every lane; also the place of discrete updates
    state_size(model)            # length of the state vector, a compile-time constant

where ``Y`` is a block (state × lanes) or the state vector of one body
(``Y[i]``, batch member ``b0``); the overloads specialise on ``Y.ndim``.

The others serve particular methods; a kernel provides those that apply to
it, and says so in Python with its ``provides`` property, a set of the
capability names of :data:`CAPABILITIES`. A method declares the capabilities
it needs (:class:`tumble.integrate.Method`), and one check
(:func:`tumble.integrate.check_method`) refuses a mismatch before anything
compiles::

    "rhs"          rhs, project, state_size (every kernel)
    "body_rate"    body_rate(model, Y, j) -> (ω₁, ω₂, ω₃) of lane j (rad/s, body axes of the
                   quaternion Y[0:4]): q̇ = ½ q ⊗ [0, ω]; the Lie-group method (cf4)
    "free_flow"    the state is [q_NP, ω_P] (7) of a rigid body in principal axes P, and
                   free_setup(model, b, x) -> motion,  free_evaluate(model, motion, τ) -> x
                   give its closed-form torque-free motion over τ seconds (any sign), while
                   torque_acceleration(model, b, t, x, ω₁, ω₂, ω₃) -> I⁻¹τ (rad/s²) and
                   torque_free(model) -> bool (a compile-time constant) give the kicks of
                   the torque; the exact method and the exact-flow splittings
    "torque_free"  no torque at all: the state is [q_NP, ω_P] and
                   inverse_moments(model, b) -> (1/I₁, 1/I₂, 1/I₃); the Lie–Poisson splittings
    "cuda"         every function above that the kernel provides also compiles for an NVIDIA GPU
                   (numba.cuda): nothing calls Python or allocates; the fixed-step methods of
                   tumble.integrate._cuda then run it there, one thread per batch member. A kernel
                   that cannot says why in its ``gpu_refusal`` (a ValidationError message naming the
                   part, or None)

Two more are optional: a kernel whose state is ``[q_NP, ω_P]`` (7) and whose
projection is ``q ← q/|q|`` may give its right-hand side on one body's state
held in registers (a 7-tuple), which the fixed-step RK4 and CF4 then run fused
(:mod:`tumble.integrate._fused`), a lane's whole step, stages, update and projection, in one pass::

    point_rates(model, r, t, y) -> dy/dt    (7-tuples) with the parameters of row r
    uniform(model) -> bool                  one row for all members (r = 0); otherwise member b has row b
    members(model, b0, b1) -> model         the kernel of members b0 … b1−1 alone (its rows 0 … b1−b0−1),
                                            contiguous copies, so that a block reads lane j's row j

(:func:`implemented` tells an overload whether a kernel type gives one.) Such a
kernel's class also declares, as a static method, whether compiled code of a
Numba type of it may call a Python function (known when a call is typed; the
fused passes over the lanes then keep reference counts)::

    may_call_python(numba_type) -> bool

A kernel also tells Python whether it calls back into the interpreter
(``calls_python``): the integrators then run its batch on one core.

A kernel whose right-hand side needs scratch memory (a robot's articulated-body
algorithm: its per-body spatial quantities) gives it as one float64 array that
the method allocates once per run with its own workspace, per block of lanes
on the CPU and per member on a GPU (where no code may allocate), and that the
evaluations then reuse::

    scratch(model, Y) -> S                  a new array, the scratch of evaluating Y (a block's lanes
                                            one after another, or one state vector)
    with_scratch(model, S) -> model         the kernel that evaluates its right-hand side in S

The methods that evaluate ``rhs`` (``rk4``, ``cf4``, ``dop853``) reach both
through :func:`model_workspace` (the model's share of a method's workspace:
``(S,)`` or ``()``) and :func:`evaluating` (the kernel that evaluates in it).

The integrators call these generic functions; Numba picks the implementation
from the model's type when it compiles the integrator, so a lone body of each
model gets its own fully inlined integrator, and the compiled code is cached
on disk. (A run-time switch on a model code costs 2–3× in the inner loop.) A
batch of a kind that registers its block functions runs through one driver
per method instead, calling them through function pointers
(:mod:`tumble._block`), where a block of lanes shares the cost of each call.
Adding a model is one kernel file under :mod:`tumble.kernels` and one model
file above the engine (``docs/architecture.md``).
"""

from __future__ import annotations

import functools
import math

from numba import njit, types
from numba.extending import overload


def is_type(numba_type, cls) -> bool:
    """True when ``numba_type`` (seen by an overload) is the Numba type of a ``cls`` NamedTuple.

    Models and schemes select their overloads with it.
    """
    return isinstance(numba_type, types.BaseNamedTuple) and numba_type.instance_class is cls


#: (generic, kernel class) pairs registered by :func:`implements`.
_IMPLEMENTED: set = set()


def implemented(generic, numba_type) -> bool:
    """True when the kernel type ``numba_type`` (seen by an overload) has an overload of ``generic``."""
    return (isinstance(numba_type, types.BaseNamedTuple)
            and (generic, numba_type.instance_class) in _IMPLEMENTED)


def implements(generic, cls, *, inline: bool = False, target: str = "generic", **jit_options):
    """Decorator: register a typing function as the overload of ``generic`` for the NamedTuple type ``cls``.

    The typing function receives the Numba types of a call whose first
    argument (a kernel, or a method's scheme) is a ``cls`` — calls with other
    types never reach it — and returns the implementation (or None where it
    does not apply). ``inline=True`` inlines the implementation into its
    caller at the IR level; ``jit_options`` add to ``cache=True`` (the
    implementations are cached on disk with the integrators) and NumPy's error
    model, the drivers' own (``tumble.integrate._fixed``): an implementation
    compiled on its own, not inlined, is then compiled as it would be inlined.
    With Python's error model a division checks its divisor and may raise, and
    LLVM keeps such a loop scalar: the fused RK4 lanes ran 5× slower in the
    process that compiled them than when loaded from the cache. ``target="cuda"``
    registers the implementation that code compiled for an NVIDIA GPU uses instead
    (Numba prefers an overload of the target it compiles for over a generic one).
    """
    def register(typer):
        @functools.wraps(typer)
        def for_this_kernel(*args):
            return typer(*args) if is_type(args[0], cls) else None

        overload(generic, inline="always" if inline else "never", target=target,
                 jit_options={"cache": True, "error_model": "numpy", **jit_options})(for_this_kernel)
        _IMPLEMENTED.add((generic, cls))
        return typer

    return register


def rhs(model, b0, t, Y, OUT):  # pragma: no cover - replaced by overloads in compiled code
    """``OUT[:, j] = dy/dt`` of batch member ``b0 + j`` of ``model`` at time ``t``, state ``Y[:, j]``."""
    raise NotImplementedError(f"no compiled right-hand side for {type(model).__name__}")


def project(model, b0, t, Y):  # pragma: no cover - replaced by overloads in compiled code
    """After an accepted step that ends at time ``t`` (s): put every lane ``Y[:, j]`` (batch member
    ``b0 + j``) back onto the state manifold, in place.

    It is also where a model applies its discrete-time updates, such as a
    controller sampled at a fixed rate whose command is held in the state
    (zero-order hold): the fixed-step methods land on every output time and
    call ``project`` after each step, so a model whose sample times are
    multiples of ``dt`` sees each of them. (The adaptive ``dop853`` calls it
    after each accepted step too, but its steps do not land on sample times.)
    """
    raise NotImplementedError(f"no compiled projection for {type(model).__name__}")


def state_size(model):  # pragma: no cover - replaced by overloads in compiled code
    """Length of the state vector of ``model`` (a constant, so loops over it unroll)."""
    raise NotImplementedError(f"no compiled state size for {type(model).__name__}")


def body_rate(model, Y, j):  # pragma: no cover - replaced by overloads in compiled code
    """Body angular velocity ``(ω₁, ω₂, ω₃)`` (rad/s) of lane ``j`` of the block ``Y`` (or of the state vector ``Y``).

    It is the rate in the attitude kinematics ``q̇ = ½ q ⊗ [0, ω]`` of the
    quaternion ``Y[0:4]``, in the body axes that quaternion maps to inertial.
    """
    raise NotImplementedError(f"no compiled body rate for {type(model).__name__}")


def point_rates(model, r, t, y):  # pragma: no cover - replaced by overloads in compiled code
    """``dy/dt`` (a 7-tuple) at time ``t`` (s) and state ``y = (q_NP, ω_P)`` (a 7-tuple) with the parameters
    of row ``r``: 0 for every member of a :func:`uniform` model, otherwise the member itself."""
    raise NotImplementedError(f"no compiled pointwise right-hand side for {type(model).__name__}")


def uniform(model):  # pragma: no cover - replaced by overloads in compiled code
    """True when every batch member of ``model`` has the same parameters (one row shared by all);
    otherwise every member has its own row."""
    raise NotImplementedError(f"{type(model).__name__} does not say whether its members share parameters")


def members(model, b0, b1):  # pragma: no cover - replaced by overloads in compiled code
    """The kernel of batch members ``b0 … b1−1`` alone: member ``b0 + j`` has row ``j`` (a non-:func:`uniform`
    model; its per-member arrays copied contiguous, so that the lanes of a block read them as vectors)."""
    raise NotImplementedError(f"no compiled member selection for {type(model).__name__}")


def inverse_moments(model, b):  # pragma: no cover - replaced by overloads in compiled code
    """``(1/I₁, 1/I₂, 1/I₃)`` (1/(kg·m²)) of batch member ``b`` of a torque-free rigid-body model.

    Only models whose state is ``[q, ω]`` with ``ω`` in principal axes and
    whose motion is torque-free provide it: the splitting methods rely on both.
    """
    raise NotImplementedError(f"{type(model).__name__} is not a torque-free rigid body")


def scratch(model, Y):  # pragma: no cover - replaced by overloads in compiled code
    """A new float64 array: the scratch memory the right-hand side of ``model`` evaluates ``Y`` in (a block,
    its lanes one after another, or one state vector)."""
    raise NotImplementedError(f"{type(model).__name__} needs no scratch")


def with_scratch(model, S):  # pragma: no cover - replaced by overloads in compiled code
    """The kernel ``model`` evaluating its right-hand side in the scratch ``S`` (a :func:`scratch` array, or
    a member's row of one on a GPU)."""
    raise NotImplementedError(f"{type(model).__name__} needs no scratch")


def model_workspace(model, Y):  # pragma: no cover - replaced by the overload in compiled code
    """The model's share of a method's workspace for ``Y``: ``(scratch(model, Y),)`` for a kernel that gives
    :func:`scratch`, else ``()``; a method appends it to its own arrays."""
    raise NotImplementedError("compiled code only")


def evaluating(model, work):  # pragma: no cover - replaced by the overload in compiled code
    """The kernel that evaluates in the scratch of a method's workspace ``work`` (its last array, from
    :func:`model_workspace`): ``with_scratch(model, work[-1])``, or ``model`` itself for a kernel without."""
    raise NotImplementedError("compiled code only")


@overload(model_workspace, inline="always", target="generic", jit_options={"cache": True})
def _model_workspace(model, Y):
    if implemented(scratch, model):
        return lambda model, Y: (scratch(model, Y),)
    return lambda model, Y: ()


@overload(evaluating, inline="always", target="generic", jit_options={"cache": True})
def _evaluating(model, work):
    if implemented(scratch, model):
        return lambda model, work: with_scratch(model, work[-1])
    return lambda model, work: model


#: What a compiled model can provide to the methods, in the words of the error message that
#: names what a method misses (see the module docstring for the functions behind each).
CAPABILITIES = {
    "rhs": "a right-hand side",
    "body_rate": "the body rate of its attitude quaternion",
    "free_flow": "the closed-form motion of a free rigid body, with torque kicks",
    "torque_free": "a rigid body without torque",
    "cuda": "compiled functions that run on an NVIDIA GPU (device='cuda')",
    "rigid_fields": "the fields of rigid bodies in principal axes that the GPU's fused RK4 kernel reads",
}


def python_on_gpu(field: str) -> str:
    """The ``gpu_refusal`` of a kernel whose ``field`` (a torque, a control law) is a Python function."""
    return (f"{field}: a Python function cannot run on the GPU (device='cuda'); use the compiled models "
            "or device='cpu'")


def free_setup(model, b, x):  # pragma: no cover - replaced by overloads in compiled code
    """The torque-free motion of batch member ``b`` from the state ``x = (q_NP, ω_P)`` (a 7-tuple),
    in a form that :func:`free_evaluate` reads (``"free_flow"``)."""
    raise NotImplementedError(f"{type(model).__name__} has no closed-form free motion")


def free_evaluate(model, motion, tau):  # pragma: no cover - replaced by overloads in compiled code
    """The state ``(q_NP, ω_P)`` (a 7-tuple) ``tau`` seconds (any sign) along a :func:`free_setup` motion."""
    raise NotImplementedError(f"{type(model).__name__} has no closed-form free motion")


def torque_acceleration(model, b, t, x, w1, w2, w3):  # pragma: no cover - replaced by overloads
    """``I⁻¹ τ(t, q, ω)`` (rad/s², principal axes) of batch member ``b`` at the attitude of the state
    ``x`` and the rate ``ω`` (``"free_flow"``: the kicks of the exact-flow splittings)."""
    raise NotImplementedError(f"{type(model).__name__} has no torque kicks")


def torque_free(model):  # pragma: no cover - replaced by overloads in compiled code
    """True when ``model`` has no torque (a compile-time constant of its type; ``"free_flow"``)."""
    raise NotImplementedError(f"{type(model).__name__} does not say whether it has a torque")


@njit(cache=True, error_model="numpy")
def quaternion_scale(qw, qx, qy, qz):
    """``1/|q|``: the factor that projects a quaternion back onto the unit sphere.

    This is the projection every attitude model uses: the exact flow keeps
    ``|q| = 1``; a Runge–Kutta step leaves it off by about the local error.
    Projecting after every accepted step keeps it at 1 to rounding without
    changing the order of the method. (NumPy's error model: a zero quaternion gives inf, then nan
    states, rather than a ZeroDivisionError check that would keep the lane loops scalar.)
    """
    return 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)


@njit(cache=True)
def normalize_quaternions(Y):
    """Normalise the quaternion ``Y[0:4, j]`` of every lane of a block (state × lanes)."""
    for j in range(Y.shape[1]):
        s = quaternion_scale(Y[0, j], Y[1, j], Y[2, j], Y[3, j])
        for i in range(4):
            Y[i, j] *= s


@njit(cache=True)
def normalize_quaternion(y):
    """Normalise the quaternion ``y[0:4]`` of one state vector."""
    s = quaternion_scale(y[0], y[1], y[2], y[3])
    for i in range(4):
        y[i] *= s


# Implementations shared by the models' overloads (each returns the ``impl`` an overload returns).


def quaternion_projection(Y):
    """``project`` for a model whose only constraint is the unit quaternion ``Y[0:4]``: normalise it
    (the state vector, or every lane of a block)."""
    if Y.ndim == 1:
        return lambda model, b0, t, Y: normalize_quaternion(Y)
    return lambda model, b0, t, Y: normalize_quaternions(Y)


def rate_at(offset, Y):
    """``body_rate`` for a model that stores ``(ω₁, ω₂, ω₃)`` at ``Y[offset:offset + 3]``."""
    if Y.ndim == 1:
        return lambda model, Y, j: (Y[offset], Y[offset + 1], Y[offset + 2])
    return lambda model, Y, j: (Y[offset, j], Y[offset + 1, j], Y[offset + 2, j])


def rhs_of_eight(derivative, Y):
    """``rhs`` for a model of eight state values whose jitted ``derivative(model, t, y0, ..., y7)`` returns
    their eight rates as a tuple (held in registers): on the state itself, or on each lane ``Y[:, j]``."""
    if Y.ndim == 1:

        def impl(model, b0, t, Y, OUT):
            (OUT[0], OUT[1], OUT[2], OUT[3], OUT[4], OUT[5], OUT[6], OUT[7]) = derivative(
                model, t, Y[0], Y[1], Y[2], Y[3], Y[4], Y[5], Y[6], Y[7])

        return impl

    def impl(model, b0, t, Y, OUT):
        for j in range(Y.shape[1]):
            (OUT[0, j], OUT[1, j], OUT[2, j], OUT[3, j], OUT[4, j], OUT[5, j], OUT[6, j], OUT[7, j]) = \
                derivative(model, t, Y[0, j], Y[1, j], Y[2, j], Y[3, j], Y[4, j], Y[5, j], Y[6, j], Y[7, j])

    return impl


def lanewise_rhs(derivative, Y):
    """``rhs`` for a model whose jitted ``derivative(model, t, y, out)`` works on one state vector:
    called on the state itself, or on each lane ``Y[:, j]`` of a block."""
    if Y.ndim == 1:
        return lambda model, b0, t, Y, OUT: derivative(model, t, Y, OUT)

    def impl(model, b0, t, Y, OUT):
        for j in range(Y.shape[1]):
            derivative(model, t, Y[:, j], OUT[:, j])

    return impl
