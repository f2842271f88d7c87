"""The tumble.ins demonstrations: files written, numbers within their laws."""

import math

import pytest

from tumble.viz.ins import demo_coning, demo_gyroscope, demo_ins
from tumble._validate import ValidationError


def test_demo_gyroscope(tmp_path):
    s = demo_gyroscope(tmp_path)
    # ε = 7.4e-4: mean precession −2ε² = −1.1e-6 off the law (measured −2.7e-6 over 8 periods of
    # 100 samples, the period itself off by 3ε²); nutation period −3ε² = −1.6e-6 (measured)
    assert s["precession_rate_measured"] == pytest.approx(s["precession_rate"], rel=1e-5)
    assert s["nutation_period_s_measured"] == pytest.approx(s["nutation_period_s"], rel=5 * 7.4e-4**2)
    # against the exact heavy top (elliptic functions): measured 1.6e-14, as in test_ins_gyroscope
    assert s["nutation_period_s_measured"] == pytest.approx(s["nutation_period_s_exact"], rel=1e-9)
    assert s["imbalance_drift_error_rad"] < 1e-9       # measured 5.7e-12 rad
    assert s["spin_drag_drift_error_rad"] < 1e-6       # measured 3.8e-7 rad of 2.2 rad
    assert s["pivot_tilt_error_rad"] < 1e-6            # of a 1e-3 rad tilt; measured 3.8e-7 rad
    for key in ("precession_png", "drift_png"):
        assert (tmp_path / s[key].rsplit("/", 1)[-1]).stat().st_size > 10_000


def test_demo_coning(tmp_path):
    s = demo_coning(tmp_path, points=6)
    for algorithm in ("none", "one-sample", "two-sample", "three-sample"):
        assert s[algorithm]["max_relative_deviation"] < 0.05
    assert (tmp_path / "ins_coning.png").stat().st_size > 10_000


def test_demo_ins(tmp_path):
    s = demo_ins(tmp_path, duration=3.0)
    assert s["error-free"]["max_rad"] < 1e-9            # measured 4e-10 over 3 s at 200 Hz
    # one realisation of the angle random walk: within a factor 3 of its RMS N √(3t)
    ratio = s["angle random walk"]["final_rad"] / s["arw_prediction_rad"]
    assert 1 / 3 < ratio < 3
    assert s["white_noise_recovered"] == pytest.approx([s["white_noise"]] * 3, rel=0.1)
    assert (tmp_path / "ins_error.png").exists() and (tmp_path / "ins_allan.png").exists()
    with pytest.raises(ValidationError, match="out_dir"):
        demo_ins(tmp_path / "missing")
    assert math.isfinite(s["all error terms"]["final_rad"])
