"""``tumble robot``: joint torques of a serial chain from the command line.

    tumble robot torques ROBOT_FILE --q "0.1, 0.2, ..." [--qd ...] [--qdd ...] [--gravity "0,0,-9.81"]
                         [--mass-matrix] [--inertia clip] [--min-inertia 1e-6]

``ROBOT_FILE`` is a DH table (``.toml``) or a URDF (``.urdf``); see
``docs/robot.md``. Exit codes as the ``tumble`` command: 0 success, 2 bad
input (one line on stderr naming the field and the rule). A repair of a
URDF's data (:class:`tumble.robot.UrdfRepairWarning`) is one ``warning:``
line on stderr.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from tumble.cli.errors import exit_codes
from tumble._validate import ValidationError
from tumble.robot.chain import load
from tumble.robot.dynamics import mass_matrix, rnea
from tumble.robot.urdf import UrdfRepairWarning

__all__ = ["app"]

app = typer.Typer(help="Serial robot arms: inverse dynamics of DH tables and URDF files.", no_args_is_help=True,
                  add_completion=False)


@app.callback()
def robot() -> None:
    """Serial robot arms: inverse dynamics of DH tables (.toml) and URDF files."""


def _vector(text: str | None, name: str, n: int) -> np.ndarray:
    """Numbers separated by commas or spaces (an empty entry, as in ``"1,,2"``, is refused); ``None`` is n zeros."""
    if text is None:
        return np.zeros(n)
    try:
        values = np.array([float(x) for x in re.split(r"\s*,\s*|\s+", text.strip())])
    except ValueError:
        raise ValidationError(f"--{name}: must be numbers separated by commas, got {text!r}") from None
    if values.shape != (n,) or not np.isfinite(values).all():
        raise ValidationError(f"--{name}: must be {n} finite numbers, got {text!r}")
    return values


@app.command()
def torques(
    robot_file: Annotated[Path, typer.Argument(help="DH table (.toml) or URDF (.urdf) of a serial chain.")],
    q: Annotated[str, typer.Option("--q", help="Joint coordinates, rad or m, e.g. '0, 0.5, -1'.")],
    qd: Annotated[str | None, typer.Option("--qd", help="Joint velocities, rad/s or m/s (default 0).")] = None,
    qdd: Annotated[str | None, typer.Option("--qdd", help="Joint accelerations (default 0).")] = None,
    gravity: Annotated[str | None, typer.Option("--gravity", help="m/s², base frame (default: the file's, "
                                                "else 0,0,-9.81).")] = None,
    show_mass_matrix: Annotated[bool, typer.Option("--mass-matrix", help="Also print M(q).")] = False,
    inertia: Annotated[str, typer.Option("--inertia", help="URDF link inertias that are not positive "
                                         "semi-definite: 'check' refuses them (round-off is repaired), 'clip' sets "
                                         "their negative principal moments to zero.")] = "check",
    min_inertia: Annotated[float, typer.Option("--min-inertia", help="Least principal moment of every moving URDF "
                                               "link, kg m^2 (default 0).")] = 0.0,
) -> None:
    """Print the joint torques ``τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`` (recursive Newton–Euler)."""
    with exit_codes(robot_file):
        try:
            with warnings.catch_warnings(record=True) as repairs:
                warnings.simplefilter("always", UrdfRepairWarning)
                chain = load(robot_file, inertia=inertia, min_inertia=min_inertia)
        except OSError as exc:
            raise ValidationError(f"{robot_file}: cannot be read ({exc})") from None
        for repair in repairs:
            typer.echo(f"warning: {repair.message}", err=True)
        n = chain.dof
        state = _vector(q, "q", n), _vector(qd, "qd", n), _vector(qdd, "qdd", n)
        g = None if gravity is None else _vector(gravity, "gravity", 3)
        tau = rnea(chain, *state, gravity=g)
    typer.echo(f"{chain.name or robot_file.name}: {n} joints")
    width = max(len(str(name)) for name in chain.joint_names)
    for name, kind, value in zip(chain.joint_names, chain.joint_types, tau):
        unit = "N m" if kind == "revolute" else "N"
        typer.echo(f"  {str(name):<{width}}  tau = {value: .12g} {unit}")
    if show_mass_matrix:
        typer.echo("mass matrix M(q):")
        for row in mass_matrix(chain, state[0]):
            typer.echo("  " + " ".join(f"{x: .9e}" for x in row))
