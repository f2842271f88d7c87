"""`tumble demo chaos` (tumble.viz.chaos): the figure, the numbers, the command."""

import numpy as np
import pytest
from typer.testing import CliRunner

from tumble._validate import ValidationError
from tumble.cli import app
from tumble.viz.chaos import TOPS, demo_chaos

# The chaos demo compiles the Lyapunov spectra and the figure's integrators on a cold Numba cache (~17 CPU s).
pytestmark = pytest.mark.slow


def test_demo_chaos_writes_the_figure_and_separates_chaos_from_integrability(tmp_path):
    # 100 s: the integrable tops' exponents are already below 2 ln(t)/t = 0.092 1/s (measured 0.039), the
    # generic top's above 0.05 (measured 0.125); 177-247 section points per top
    summary = demo_chaos(tmp_path, duration=100.0)
    assert (tmp_path / "chaos.png").stat().st_size > 50_000
    exponents = summary["largest_exponent"]
    assert set(exponents) == set(TOPS)
    for name in ("Lagrange", "Kovalevskaya"):
        assert 0.0 < exponents[name] <= 2.0 * np.log(100.0) / 100.0
    assert exponents["generic"] > 0.05
    assert all(count > 100 for count in summary["section_points"].values())


def test_demo_chaos_is_a_command_and_refuses_a_missing_directory(tmp_path):
    result = CliRunner().invoke(app, ["demo", "chaos", "--help"])
    assert result.exit_code == 0 and "Kovalevskaya" in result.stdout
    with pytest.raises(ValidationError) as error:
        demo_chaos(tmp_path / "missing", duration=10.0)
    assert error.value.field == "out_dir"
