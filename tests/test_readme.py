"""The README's Python example runs as written, and its printed drifts are what it claims."""

from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"
DRIFT_CLAIM = 1e-13  # the README says "~1e-14": allow one order of magnitude


def _python_block(heading: str) -> str:
    text = README.read_text(encoding="utf-8")
    start = text.index("```python", text.index(heading)) + len("```python")
    return text[start : text.index("```", start)]


def test_ten_line_example_runs_and_conserves(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = _python_block("## Ten lines of Python")
    assert len([line for line in code.splitlines() if line.strip()]) <= 12
    namespace: dict = {}
    exec(compile(code, str(README), "exec"), namespace)  # the README is the project's own text
    traj = namespace["traj"]
    assert np.abs(traj.energy_drift).max() <= DRIFT_CLAIM
    assert np.abs(traj.momentum_norm_drift).max() <= DRIFT_CLAIM
    assert (tmp_path / "box.nc").stat().st_size > 0
    assert (tmp_path / "box.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_exact_motion_example_runs_and_prints_the_flip_interval(capsys):
    code = _python_block("## Exact motion, stability and the heavy top")
    namespace: dict = {}
    exec(compile(code, str(README), "exec"), namespace)
    printed = capsys.readouterr().out
    assert "2.98632" in f"{namespace['tumble'].analytic.flip_interval(namespace['body'], namespace['omega0']):.6g}"
    assert printed  # the example prints its results
    assert namespace["exact"].method == "exact"


def test_front_door_example_runs_and_keeps_what_it_says(capsys, monkeypatch):
    # run from the repository root: the example reads examples/robots/planar_2link.toml
    monkeypatch.chdir(README.parent)
    code = _python_block("## One front door for every model")
    namespace: dict = {}
    exec(compile(code, str(README), "exec"), namespace)
    assert capsys.readouterr().out
    # the undamped panel keeps hub + panel energy: rk4 at dt = 0.01 s over 60 s, measured 3.4e-11
    flex = namespace["flex"]
    assert flex.model == "FlexibleBody" and np.ptp(flex.energy) / flex.energy[0] <= 1e-9
    # the falling arm keeps E - W: dop853 at its default tolerances, measured 4.0e-11 J
    assert np.ptp(namespace["arm"].invariants(namespace["fall"])["energy_minus_work"]) <= 1e-9
    run = namespace["run"]
    assert run.model == "Spacecraft" and run.wheel_speed.shape == (61, 3)
