"""tumble: rotational dynamics of rigid bodies, built on Euler's equations.

Conventions (everywhere): SI units; attitude ``q`` is a unit Hamilton
quaternion, scalar first ``[w, x, y, z]``, mapping body to inertial axes
(``v_I = q ⊗ v_B ⊗ q*``); ``omega`` is the body's angular velocity relative to
inertial space in body axes; torques are in body axes; inertia is the 3×3
tensor about the centre of mass in body axes. See ``docs/conventions.md``.

    >>> import numpy as np, tumble
    >>> body = tumble.RigidBody(inertia=np.diag([1.0, 2.0, 3.0]))
    >>> traj = tumble.simulate(body, [1e-3, 1.0, 1e-3], t=np.linspace(0, 100, 1001))

``tumble.simulate`` is the one front door: every model (rigid bodies, flexible,
sloshing and shape-changing bodies, spacecraft, robot arms, gyroscopes)
implements :class:`tumble.Model` and runs through it.
"""

from tumble._cache import ensure_writable_cache, use_content_key
from tumble._moved import deprecated, moved_modules

ensure_writable_cache()  # before any compiled module: a read-only install must still import
use_content_key()  # and compiled code is stale when any source compiled into it changes (docs/architecture.md)

from tumble import attitude, dynamics, integrate, limits, torques  # noqa: E402
from tumble._validate import ValidationError  # noqa: E402
from tumble._version import __version__  # noqa: E402, F401 (tumble.__version__)
from tumble.rigid_body import RigidBody  # noqa: E402
from tumble.integrate import SolverError  # noqa: E402
from tumble.limits import RigidityWarning  # noqa: E402
from tumble.simulate import Model, as_model, simulate  # noqa: E402
from tumble.trajectory import Trajectory, load  # noqa: E402
from tumble.viz import trajectory as _views  # noqa: E402, F401 - fills Trajectory's figure, page and tables

# Modules renamed in 0.4: each old name imports the new module itself, with a DeprecationWarning naming it, until 0.5.
_RENAMED = {
    "tumble.analysis": "tumble.measure",
    "tumble.body": "tumble.rigid_body",
    "tumble.frames": "tumble.axisymmetric",
    "tumble.rigid": "tumble.rigid_model",
    "tumble.viewer": "tumble.viz.viewer",
}
moved_modules(_RENAMED)


# Submodules loaded on first use (PEP 562), so that `import tumble` stays fast:
# `tumble.analytic.torque_free(...)` works after a plain `import tumble`; so do the old names of the renamed
# modules (`tumble.analysis`), with their warning at the line that reads them.
_LAZY = ("analytic", "viz", "scenario", "measure", "ensemble", "variable", "flexible", "slosh", "ins", "spacecraft",
         "robot", "sweep", "sweeps", "examples", "estimation")


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return importlib.import_module(f"tumble.{name}")
    if f"tumble.{name}" in _RENAMED:
        deprecated(f"tumble.{name}", _RENAMED[f"tumble.{name}"])
        return importlib.import_module(_RENAMED[f"tumble.{name}"])
    raise AttributeError(f"module 'tumble' has no attribute {name!r}")

__all__ = [
    "Model",
    "RigidBody",
    "RigidityWarning",
    "analytic",
    "as_model",
    "SolverError",
    "Trajectory",
    "ValidationError",
    "attitude",
    "dynamics",
    "ensemble",
    "estimation",
    "examples",
    "flexible",
    "ins",
    "integrate",
    "limits",
    "load",
    "measure",
    "robot",
    "scenario",
    "simulate",
    "slosh",
    "spacecraft",
    "sweep",
    "sweeps",
    "torques",
    "variable",
    "viz",
]
