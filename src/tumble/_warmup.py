"""What ``tumble warmup`` compiles: every built-in model kind under every method it provides, and the paths
a first session takes.

tumble's kernels are compiled by Numba on their first call and cached on
disk (``__pycache__`` beside the source, or ``NUMBA_CACHE_DIR``), one
compiled version per model kind and integration method (docs/architecture.md,
"The compiled-code cache"). A first call therefore spends seconds compiling;
every later process loads the cached code in milliseconds. ``tumble warmup``
(or ``python -m tumble warmup``) makes those first calls at install time
instead: each path below runs a tiny simulation (a few steps) — each model
kind of the registry :data:`tumble._kinds.MODEL_KINDS` under each method its kernel provides for, then the
quick-start demo, a batch of rigid bodies and a heavy top.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from tumble._kinds import MODEL_KINDS, resolve

if TYPE_CHECKING:
    from tumble.simulate import Model, SolverOptions

__all__ = ["example", "flexible", "fluid", "gimbaled_gyro", "gyroscope", "human", "kind_path", "methods", "paths",
           "rigid", "robot_tree", "serial_chain", "slosh", "spacecraft", "variable"]

_OMEGA0 = np.array([0.1, 1.0, 0.1])  # rad/s
_T = np.array([0.0, 0.02, 0.04])  # s: a few steps
_INERTIA = np.diag([1.0, 2.0, 3.0])  # kg·m²


def rigid() -> tuple[Model, dict[str, Any]]:
    import tumble

    return tumble.as_model(tumble.RigidBody(_INERTIA)), {"omega0": _OMEGA0}


def spacecraft() -> tuple[Model, dict[str, Any]]:
    """Three reaction wheels under Schaub's MRP feedback (the craft of tests/test_models.py)."""
    from tumble.spacecraft import MRPFeedback, ReactionWheel, Spacecraft

    craft = Spacecraft(inertia=np.diag([900.0, 800.0, 600.0]),
                       wheels=[ReactionWheel(axis=axis, inertia=0.1) for axis in np.eye(3)],
                       controller=MRPFeedback(K=10.0, P=150.0))
    return craft, {"omega0": [0.01, -0.01, 0.005], "wheel_speeds0": [20.0, -10.0, 5.0]}


def flexible() -> tuple[Model, dict[str, Any]]:
    import tumble
    from tumble.flexible import FlexibleBody, Mode

    body = FlexibleBody(tumble.RigidBody(_INERTIA), (Mode(3.0, 0.0, np.array([0.3, 0.5, 0.2])),))
    return body, {"omega0": _OMEGA0, "eta0": [0.05]}


def slosh() -> tuple[Model, dict[str, Any]]:
    import tumble
    from tumble.slosh import Pendulum, SloshBody

    pendulum = Pendulum(mass=2.0, length=0.5, hinge=np.array([0.3, -0.2, 0.4]))
    body = SloshBody(tumble.RigidBody(_INERTIA, mass=10.0), pendulum)
    return body, {"omega0": _OMEGA0, "direction0": [1.0, 1.0, 0.0]}


def fluid() -> tuple[Model, dict[str, Any]]:
    """A body in an ideal fluid with a full added mass (coupled: B ≠ 0), moving and turning."""
    import tumble
    from tumble.fluid import KirchhoffBody

    added_mass = np.diag([5.0, 8.0, 12.0, 1.0, 1.5, 2.0])
    added_mass[0, 4] = added_mass[4, 0] = 0.3
    return KirchhoffBody(tumble.RigidBody(_INERTIA, mass=10.0), added_mass), {"omega0": _OMEGA0,
                                                                             "velocity0": [1.0, 0.2, -0.3]}


def variable() -> tuple[Model, dict[str, Any]]:
    """A body whose inertia grows by 10 % a second."""
    from tumble.variable import VariableBody

    def inertia(t):
        return _INERTIA * (1.0 + 0.1 * np.asarray(t))[:, None, None]

    return VariableBody.from_functions(inertia, t_span=(0.0, 1.0), dt=0.01), {"omega0": _OMEGA0}


def human() -> tuple[Model, dict[str, Any]]:
    """de Leva's diver raising the left arm."""
    from tumble.variable import Human, Motion

    diver = Human.de_leva().moving({"left_shoulder_abduction": Motion(np.pi, [(0.0, 1.0, 0.0)])}, t_span=(0.0, 1.0))
    return diver, {"omega0": [5.0, 0.0, 0.3]}


def gyroscope() -> tuple[Model, dict[str, Any]]:
    from tumble.ins import Gyroscope

    return (Gyroscope(spin_inertia=2e-3, transverse_inertia=1.5e-3, spin=100.0, mass=0.1, offset=0.02, tilt=1.0),
            {"precession_rate0": 0.5})


def gimbaled_gyro() -> tuple[Model, dict[str, Any]]:
    from tumble.ins import GimbaledGyro

    gyro = GimbaledGyro(spin_inertia=2e-3, transverse_inertia=1.5e-3, inner_gimbal=(4e-4, 5e-4, 3e-4),
                        outer_gimbal=1e-3, imbalance=0.01)
    return gyro, {"spin": 100.0, "theta0": 1.0}


def serial_chain() -> tuple[Model, dict[str, Any]]:
    """The planar two-link arm of the examples, falling."""
    import tumble
    from tumble import robot

    return robot.load(tumble.examples.directory() / "robots" / "planar_2link.toml"), {"q0": [0.3, -0.5]}


def robot_tree() -> tuple[Model, dict[str, Any]]:
    """A tree: a shoulder link carrying two one-link arms, turning about z, falling along −z."""
    from tumble.robot import Link, RobotTree

    def rod(origin: tuple[float, float, float]) -> Link:
        """A 1 kg, 1 m rod along x from the joint, turning about y."""
        return Link(axis=np.array([0.0, 1.0, 0.0]), origin_position=np.array(origin), mass=1.0,
                    com=np.array([0.5, 0.0, 0.0]), inertia=np.diag([1e-3, 0.085, 0.085]))

    links = [rod((0.0, 0.0, 0.0)), rod((1.0, 0.2, 0.0)), rod((1.0, -0.2, 0.0))]
    return RobotTree(links, [-1, 0, 0]), {"q0": [0.3, -0.5, 0.2]}


def example(kind: str) -> tuple[Model, dict[str, Any]]:
    """A tiny model of ``kind`` and its initial state (keyword arguments of ``simulate``): the example that the
    registry of model kinds names (:data:`tumble._kinds.MODEL_KINDS`), one of the functions above."""
    return resolve(MODEL_KINDS[kind].example)()


def _options(method: str) -> SolverOptions:
    """The solver options of the paths: a 10 ms step for a method that reads ``dt``, the declared defaults of
    the others (:data:`tumble.integrate.METHODS`)."""
    from tumble import integrate

    return {"dt": 0.01} if "dt" in integrate.METHODS[method].options else {}


def kind_path(kind: str, method: str) -> Callable[[], None]:
    """A path: ``simulate`` of the model of ``kind`` under ``method``."""

    def run() -> None:
        import tumble

        model, state = example(kind)
        tumble.simulate(model, t=_T, method=method, **state, **_options(method))

    return run


def methods(kind: str) -> list[str]:
    """The methods whose needs the kernel of ``kind`` provides (:func:`tumble.integrate.check_method`'s rule)."""
    from tumble import integrate

    provides = example(kind)[0].compile(None, 0.0).provides
    return [name for name, method in integrate.METHODS.items() if method.needs <= provides]


def _rigid_paths(*, members: int = 1, torque: bool = False, method: str) -> Callable[[], None]:
    """A path: ``members`` rigid bodies (a batch when > 1) under ``method``, with the heavy-top torque when
    ``torque``: 1 kg, centre of mass 0.1 m along body z from the pivot, standard gravity along −z inertial
    (:class:`tumble.torques.Gravity`)."""

    def run() -> None:
        import tumble
        from tumble import torques

        omega0 = _OMEGA0 if members == 1 else np.tile(_OMEGA0, (members, 1))
        tumble.simulate(tumble.RigidBody(_INERTIA), omega0, t=_T, method=method,
                        torque=torques.Gravity(1.0, [0.0, 0.0, 0.1]) if torque else None, **_options(method))

    return run


def _racket() -> None:
    """The quick start's ``tumble demo racket``: the T-handle under dop853, with a progress callback."""
    import tumble

    body = tumble.RigidBody.t_handle()
    tumble.simulate(body, body.axes @ _OMEGA0, t=_T, method="dop853", rtol=1e-12, atol=1e-12,
                    progress=lambda done, total: None)


def paths() -> dict[str, Callable[[], None]]:
    """Path name -> the call that compiles it, in the order ``tumble warmup`` runs them: ``"KIND, METHOD"`` for
    each model kind and each method it provides, then the first session's paths."""
    return {
        **{f"{kind}, {method}": kind_path(kind, method) for kind in MODEL_KINDS for method in methods(kind)},
        "demo racket": _racket,
        "a batch, rk4": _rigid_paths(members=2, method="rk4"),
        "a batch, dop853": _rigid_paths(members=2, method="dop853"),
        "heavy top, rk4": _rigid_paths(torque=True, method="rk4"),
        "heavy top, dop853": _rigid_paths(torque=True, method="dop853"),
    }
