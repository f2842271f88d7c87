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
sloshing and shape-changing bodies, bodies in an ideal fluid, spacecraft, robot
arms, gyroscopes) implements :class:`tumble.Model` and runs through it.
"""

import sys as _sys
import types as _types
import typing as _typing

from tumble._cache import prepare_when_numba_loads
from tumble._moved import deprecated, moved_modules

# Numba is imported by the first compiled module, not here (it alone costs more than the rest of `import tumble`);
# its cache must then be writable and keyed on content before any function is decorated (docs/architecture.md).
prepare_when_numba_loads()

from tumble import limits  # noqa: E402
from tumble._validate import ValidationError  # noqa: E402
from tumble._version import __version__  # noqa: E402, F401 (tumble.__version__)
from tumble.limits import RigidityWarning  # noqa: E402
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


# Loaded on first use (PEP 562), so that `import tumble` stays light (no Numba, no compiled module): the submodules
# below, and the names of the front door with the module that defines each. `tumble.analytic.torque_free(...)` and
# `tumble.simulate(...)` work after a plain `import tumble`; so do the old names of the renamed modules
# (`tumble.analysis`), with their warning at the line that reads them.
_LAZY = ("attitude", "dynamics", "integrate", "torques", "model", "rigid_body", "rigid_model", "kernels", "analytic",
         "viz", "scenario", "measure", "ensemble", "variable", "flexible", "slosh", "fluid", "ins", "spacecraft", "robot",
         "sweep", "sweeps", "examples", "estimation")
if _typing.TYPE_CHECKING:  # what a type checker reads (mypy does not run __getattr__); imported on first use
    from tumble import attitude, dynamics, integrate, torques  # noqa: F401
    from tumble.integrate import SolverError  # noqa: F401
    from tumble.rigid_body import RigidBody  # noqa: F401
    from tumble.simulate import Model, as_model, simulate  # noqa: F401
_DEFINED_IN = {
    "Model": "tumble.simulate",
    "RigidBody": "tumble.rigid_body",
    "SolverError": "tumble.integrate",
    "as_model": "tumble.simulate",
    "simulate": "tumble.simulate",
}


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return importlib.import_module(f"tumble.{name}")
    if name in _DEFINED_IN:
        value = getattr(importlib.import_module(_DEFINED_IN[name]), name)
        globals()[name] = value  # found directly from now on
        return value
    if f"tumble.{name}" in _RENAMED:
        deprecated(f"tumble.{name}", _RENAMED[f"tumble.{name}"])
        return importlib.import_module(_RENAMED[f"tumble.{name}"])
    raise AttributeError(f"module 'tumble' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))


class _Package(_types.ModuleType):
    """The ``tumble`` module's type: the import system sets a package's attribute to each submodule it loads,
    which would make ``tumble.simulate`` the module :mod:`tumble.simulate` once anything imports it; the name
    stays the function, as ``from tumble import simulate`` gives it."""

    def __setattr__(self, name, value):
        if isinstance(value, _types.ModuleType) and _DEFINED_IN.get(name) == value.__name__:
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package

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
    "fluid",
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
