"""Tests of tumble.trajectory: derived invariants, drifts, xarray/NetCDF layout, atomic writes, plot."""

from __future__ import annotations

import dataclasses
import datetime
import os

import numpy as np
import pytest
import xarray as xr

from tumble._validate import ValidationError
from tumble.trajectory import CONVENTIONS, Extra, Trajectory, load, write_atomic

EPS = np.finfo(np.float64).eps
# Hand values below are exact binary fractions, and the quaternions used are
# exact (identity, 180° turns) except cos/sin 45°: allow a few roundings.
ROUNDING = 8 * EPS

IDENTITY = [1.0, 0.0, 0.0, 0.0]
HALF_TURN_X = [0.0, 1.0, 0.0, 0.0]  # R = diag(1, -1, -1), exact
QUARTER_TURN_Z = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]  # body x -> inertial y

FULL_TENSOR = np.array([[2.0, -0.5, 0.0], [-0.5, 3.0, 0.25], [0.0, 0.25, 4.0]])


def _trajectory(omega, q, inertia=np.diag([1.0, 2.0, 3.0]), **kwargs):
    omega = np.asarray(omega, dtype=float)
    return Trajectory(np.arange(omega.shape[0], dtype=float), q, omega, inertia, **kwargs)


def _batch(n=5, n_bodies=3, shared_inertia=False, seed=0):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, n_bodies, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    a = rng.normal(size=(n_bodies, 3, 3))
    inertia = a @ np.swapaxes(a, -1, -2) + 3.0 * np.eye(3)  # symmetric positive definite
    return Trajectory(
        t=np.linspace(0.0, 2.0, n),
        q=q,
        omega=rng.normal(size=(n, n_bodies, 3)),
        inertia=inertia[0] if shared_inertia else inertia,
        method="dop853",
        info={"rtol": 1e-12, "atol": 1e-12, "n_steps": 417, "n_rejected": 3, "torque": "none"},
    )


def _bits(a):
    return np.ascontiguousarray(a).view(np.uint64)


# -- derived quantities -----------------------------------------------------------------


def test_diagonal_body_invariants_match_hand_values():
    # I = diag(1, 2, 3), ω = (1, 2, 3): L = (1, 4, 9), T = ½ (1 + 8 + 27) = 18, |L| = √98.
    traj = _trajectory([[1.0, 2.0, 3.0]] * 2, [IDENTITY, QUARTER_TURN_Z])
    np.testing.assert_array_equal(traj.energy, [18.0, 18.0])
    np.testing.assert_array_equal(traj.momentum_body, [[1.0, 4.0, 9.0]] * 2)
    np.testing.assert_allclose(traj.momentum_norm, np.sqrt(98.0), rtol=ROUNDING, atol=0)
    # A quarter turn about z maps body (Lx, Ly, Lz) to inertial (-Ly, Lx, Lz).
    np.testing.assert_allclose(
        traj.momentum_inertial, [[1.0, 4.0, 9.0], [-4.0, 1.0, 9.0]], rtol=0, atol=ROUNDING * 9.0
    )


def test_full_tensor_invariants_match_hand_values():
    # I ω for ω = (1, -1, 2): (2 + 0.5, -0.5 - 3 + 0.5, -0.25 + 8) = (2.5, -3, 7.75);
    # T = ½ (2.5 + 3 + 15.5) = 10.5; a half turn about x flips y and z.
    traj = _trajectory([[1.0, -1.0, 2.0]], [HALF_TURN_X], FULL_TENSOR)
    np.testing.assert_array_equal(traj.energy, [10.5])
    np.testing.assert_array_equal(traj.momentum_body, [[2.5, -3.0, 7.75]])
    np.testing.assert_array_equal(traj.momentum_inertial, [[2.5, 3.0, -7.75]])
    np.testing.assert_allclose(traj.momentum_norm, [np.sqrt(2.5**2 + 9.0 + 7.75**2)], rtol=ROUNDING)


def test_drifts_are_relative_to_the_first_sample():
    # Sample 1 scales ω by 1.5 (T by 2.25, |L| by 1.5); sample 2 keeps ω and
    # turns the body a quarter about z, so only the inertial direction moves:
    # |L_I - L_I0| = |(-4, 1, 9) - (1, 4, 9)| = √34, over |L_I0| = √98.
    omega = [[1.0, 2.0, 3.0], [1.5, 3.0, 4.5], [1.0, 2.0, 3.0]]
    traj = _trajectory(omega, [IDENTITY, IDENTITY, QUARTER_TURN_Z])
    np.testing.assert_allclose(traj.energy_drift, [0.0, 1.25, 0.0], rtol=0, atol=ROUNDING)
    np.testing.assert_allclose(traj.momentum_norm_drift, [0.0, 0.5, 0.0], rtol=0, atol=ROUNDING)
    np.testing.assert_allclose(
        traj.momentum_inertial_drift, [0.0, 0.5, np.sqrt(34.0 / 98.0)], rtol=0, atol=ROUNDING
    )


def test_drifts_from_a_zero_initial_value_are_absolute():
    # A body starting at rest: T0 = |L0| = 0, so the drifts are T, |L| and |L_I|.
    traj = _trajectory([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]], [IDENTITY] * 2)
    np.testing.assert_array_equal(traj.energy_drift, [0.0, 18.0])
    np.testing.assert_allclose(traj.momentum_norm_drift, [0.0, np.sqrt(98.0)], rtol=ROUNDING)
    np.testing.assert_allclose(traj.momentum_inertial_drift, [0.0, np.sqrt(98.0)], rtol=ROUNDING)


@pytest.mark.parametrize("shared_inertia", [False, True])
def test_batch_shapes_and_members(shared_inertia):
    n, n_bodies = 5, 3
    traj = _batch(n, n_bodies, shared_inertia)
    assert traj.batch_size == n_bodies and len(traj) == n
    for name in ("energy", "momentum_norm", "energy_drift", "momentum_norm_drift",
                 "momentum_inertial_drift"):
        assert getattr(traj, name).shape == (n, n_bodies), name
    for name in ("momentum_body", "momentum_inertial"):
        assert getattr(traj, name).shape == (n, n_bodies, 3), name
    for i in range(n_bodies):
        one = traj.member(i)
        assert one.batch_size is None and one.method == traj.method and one.info == traj.info
        np.testing.assert_array_equal(one.omega, traj.omega[:, i])
        np.testing.assert_array_equal(one.q, traj.q[:, i])
        np.testing.assert_array_equal(one.inertia, traj.inertia if shared_inertia else traj.inertia[i])
        # Each body's invariants, computed alone, are the batch's column (same arithmetic).
        for name in ("energy", "momentum_body", "momentum_inertial", "momentum_inertial_drift"):
            np.testing.assert_allclose(getattr(one, name), getattr(traj, name)[:, i], rtol=ROUNDING,
                                       atol=0, err_msg=name)
    np.testing.assert_array_equal(traj.member(-1).omega, traj.omega[:, -1])


def test_member_index_errors():
    traj = _batch(n_bodies=2)
    with pytest.raises(IndexError, match=r"^i: member 2 is out of range for a batch of 2$"):
        traj.member(2)
    with pytest.raises(ValidationError, match=r"^i: member\(i\) needs a batch; this Trajectory holds a single run$"):
        traj.member(0).member(0)


def test_body_is_a_deprecated_alias_of_member():
    traj = _batch(n_bodies=3)
    with pytest.warns(DeprecationWarning, match=r"^Trajectory\.body\(i\) is deprecated: use Trajectory\.member\(i\)$"):
        one = traj.body(1)
    np.testing.assert_array_equal(one.omega, traj.omega[:, 1])
    np.testing.assert_array_equal(one.q, traj.q[:, 1])


def test_at_cuts_every_sampled_array_along_time():
    traj = _batch(n=5, n_bodies=3)
    traj = Trajectory(traj.t, traj.q, traj.omega, traj.inertia, traj.method, traj.info,
                      extras={"x": Extra(np.arange(30.0).reshape(5, 3, 2), ("k",), "m", "a test extra")},
                      totals={"energy": np.arange(15.0).reshape(5, 3)})
    for index, rows in ((-1, [4]), (slice(1, None, 2), [1, 3]), ([0, 4], [0, 4]), (np.array([2]), [2])):
        part = traj.at(index)
        for name in ("t", "q", "omega"):
            np.testing.assert_array_equal(getattr(part, name), getattr(traj, name)[rows], err_msg=name)
        np.testing.assert_array_equal(part.x, traj.x[rows])
        np.testing.assert_array_equal(part.energy, traj.energy[rows])
        assert part.extras["x"][1:] == traj.extras["x"][1:]
        np.testing.assert_array_equal(part.inertia, traj.inertia)
        assert part.info == traj.info and part.method == traj.method and part.batch_size == 3
        # an invariant derived per sample is the same number either way
        np.testing.assert_array_equal(part.momentum_body, traj.momentum_body[rows])


def test_at_index_errors():
    traj = _batch(n=5)
    with pytest.raises(IndexError, match="out of range"):
        traj.at([5])
    with pytest.raises(ValidationError, match="^index: "):
        traj.at(0.5)
    with pytest.raises(ValidationError, match="^t: .*at least one time"):
        traj.at(slice(5, None))


def test_arrays_are_read_only_copies():
    omega = np.array([[1.0, 2.0, 3.0]])
    traj = _trajectory(omega, [IDENTITY])
    assert omega.flags.writeable  # the caller's array is not frozen
    omega[0, 0] = 7.0
    assert traj.omega[0, 0] == 1.0
    for name in ("t", "q", "omega", "inertia", "energy", "momentum_body", "momentum_inertial",
                 "momentum_norm", "energy_drift"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(traj, name)[...] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        traj.t = np.zeros(1)


def test_repr_is_short():
    assert repr(_batch(n=5, n_bodies=3)) == "Trajectory(method='dop853', n=5, t=[0, 2] s, batch_size=3)"


# -- validation -----------------------------------------------------------------------

_Q2 = np.tile(IDENTITY, (2, 1))
_W2 = np.ones((2, 3))
_I = np.eye(3)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"t": [[0.0, 1.0]]}, "t"),
        ({"t": []}, "t"),
        ({"t": [0.0, 0.0]}, "t"),
        ({"t": [0.0, np.nan]}, "t"),
        ({"q": np.ones((2, 3))}, "q"),
        ({"q": np.tile(IDENTITY, (3, 1))}, "q"),
        ({"q": np.ones((2, 2, 2, 4))}, "q"),
        ({"omega": np.ones((2, 2, 3))}, "omega"),
        ({"omega": [[1.0, 2.0, np.inf], [0.0, 0.0, 0.0]]}, "omega"),
        ({"inertia": np.eye(2)}, "inertia"),
        ({"inertia": np.ones((2, 3, 3))}, "inertia"),
        ({"method": 4}, "method"),
        ({"info": [("rtol", 1e-9)]}, "info"),
        ({"info": {"dense": True}}, r"info\['dense'\]"),
        ({"info": {"tols": [1e-9, 1e-9]}}, r"info\['tols'\]"),
        ({"info": {3: 1.0}}, "info"),
    ],
)
def test_validation_errors_name_the_field(kwargs, field):
    args = {"t": [0.0, 1.0], "q": _Q2, "omega": _W2, "inertia": _I} | kwargs
    with pytest.raises(ValidationError, match=f"^{field}: "):
        Trajectory(**args)


def test_batch_inertia_must_match_batch_size():
    q = np.tile(IDENTITY, (2, 3, 1))
    with pytest.raises(ValidationError, match=r"^inertia: must have shape \(3, 3\) or \(3, 3, 3\)"):
        Trajectory([0.0, 1.0], q, np.ones((2, 3, 3)), np.ones((2, 3, 3)))


def test_decreasing_times_and_numpy_info_values_are_accepted():
    traj = Trajectory([1.0, 0.0], _Q2, _W2, _I, info={"n_steps": np.int64(4), "dt": np.float64(0.5)})
    assert traj.info == {"n_steps": 4, "dt": 0.5}
    assert type(traj.info["n_steps"]) is int and type(traj.info["dt"]) is float


# -- xarray -----------------------------------------------------------------------------


@pytest.mark.parametrize("batch", [False, True])
def test_to_xarray_layout(batch):
    traj = _batch() if batch else _batch().member(1)
    ds = traj.to_xarray()
    lead = ("time", "body") if batch else ("time",)
    expected = {
        "omega": (lead + ("axis",), "rad/s", "body"),
        "q": (lead + ("component",), "1", "body->inertial"),
        "inertia": ((("body",) if batch else ()) + ("axis", "axis2"), "kg m2", "body"),
        "energy": (lead, "J", None),
        "momentum_body": (lead + ("axis",), "N m s", "body"),
        "momentum_inertial": (lead + ("axis",), "N m s", "inertial"),
    }
    assert set(ds.data_vars) == set(expected)
    for name, (dims, units, frame) in expected.items():
        var = ds[name]
        assert var.dims == dims, name
        assert var.attrs["units"] == units and var.attrs.get("frame") == frame, name
        assert var.attrs["description"], name
        np.testing.assert_array_equal(var.values, getattr(traj, name), err_msg=name)
    assert list(ds["axis"].values) == ["x", "y", "z"] == list(ds["axis2"].values)
    assert list(ds["component"].values) == ["w", "x", "y", "z"]
    assert ds["time"].attrs["units"] == "s"
    np.testing.assert_array_equal(ds["time"].values, traj.t)
    if batch:
        np.testing.assert_array_equal(ds["body"].values, np.arange(traj.batch_size))
    assert ds.attrs["conventions"] == CONVENTIONS
    assert ds.attrs["method"] == "dop853"
    assert ds.attrs["solver_rtol"] == 1e-12 and ds.attrs["solver_n_steps"] == 417
    assert ds.attrs["solver_torque"] == "none"
    assert isinstance(ds.attrs["tumble_version"], str) and ds.attrs["tumble_version"]
    created = datetime.datetime.fromisoformat(ds.attrs["created"])
    assert abs(datetime.datetime.now(datetime.timezone.utc) - created) < datetime.timedelta(minutes=5)


def test_from_xarray_follows_labels_not_positions():
    traj = _batch()
    ds = traj.to_xarray().isel(axis=[2, 0, 1], component=[3, 1, 0, 2]).transpose("axis", ...)
    back = Trajectory.from_xarray(ds)
    for name in ("t", "q", "omega", "inertia"):
        np.testing.assert_array_equal(_bits(getattr(back, name)), _bits(getattr(traj, name)), name)


def test_from_xarray_refuses_other_datasets():
    with pytest.raises(ValidationError, match=r"^ds: not a tumble trajectory \(missing q, inertia\)"):
        Trajectory.from_xarray(xr.Dataset({"omega": (("time", "axis"), np.ones((1, 3)))},
                                          coords={"time": [0.0]}))


# -- NetCDF -----------------------------------------------------------------------------


@pytest.mark.parametrize("make", [lambda: _batch().member(0), _batch, lambda: _batch(shared_inertia=True)],
                         ids=["single", "batch", "batch-shared-inertia"])
def test_save_load_round_trip_is_bitwise(tmp_path, make):
    traj = make()
    path = tmp_path / "run.nc"
    traj.save(path)
    back = load(path)
    for name in ("t", "q", "omega", "inertia"):
        assert getattr(back, name).shape == getattr(traj, name).shape, name
        np.testing.assert_array_equal(_bits(getattr(back, name)), _bits(getattr(traj, name)), name)
    assert back.method == traj.method and back.batch_size == traj.batch_size
    assert back.info == traj.info
    assert {k: type(v) for k, v in back.info.items()} == {k: type(v) for k, v in traj.info.items()}
    assert os.listdir(tmp_path) == ["run.nc"]


def _with_extras(traj):
    """``traj`` with a wheel-speed extra (n, [N,] 4) and a scalar extra (n, [N])."""
    lead = traj.q.shape[:-1]
    wheels = np.arange(np.prod(lead) * 4, dtype=float).reshape(lead + (4,)) / 7.0  # not binary fractions
    power = np.arange(np.prod(lead), dtype=float).reshape(lead) / 3.0
    return dataclasses.replace(traj, extras={
        "wheel_speed": Extra(wheels, ("wheel",), "rad/s", "wheel spin rate relative to the hub"),
        "motor_work": Extra(power, (), "J", "work done by the wheel motors"),
    })


@pytest.mark.parametrize("make", [lambda: _batch().member(1), _batch], ids=["single", "batch"])
def test_extras_round_trip_bitwise_with_their_labels(tmp_path, make):
    traj = _with_extras(make())
    traj.save(tmp_path / "run.nc")
    back = load(tmp_path / "run.nc")
    assert set(back.extras) == {"wheel_speed", "motor_work"}
    for name, extra in traj.extras.items():
        got = back.extras[name]
        assert (got.dims, got.units, got.description) == (extra.dims, extra.units, extra.description)
        np.testing.assert_array_equal(_bits(got.data), _bits(extra.data), name)


def test_extras_follow_body_selection_and_are_read_only():
    traj = _with_extras(_batch())
    one = traj.member(2)
    np.testing.assert_array_equal(one.extras["wheel_speed"].data, traj.extras["wheel_speed"].data[:, 2])
    assert one.extras["motor_work"].data.shape == (len(traj),)
    with pytest.raises(ValueError):
        traj.extras["wheel_speed"].data[0, 0, 0] = 1.0


@pytest.mark.parametrize("extras, message", [
    ({"w": np.zeros((5, 4))}, r"extras\['w'\]: must be a tumble.trajectory.Extra"),
    ({"w": Extra(np.zeros((4, 4)), ("wheel",))}, r"extras\['w'\].data: must have shape \(5,\)"),
    ({"w": Extra(np.zeros((5, 4)), ())}, r"extras\['w'\].data: must have shape"),
    ({"w": Extra(np.zeros((5, 3)), ("axis",))}, r"extras\['w'\].dims: must be names other than"),
    ({"not a name": Extra(np.zeros(5))}, r"extras: names must be identifiers"),
])
def test_extras_validation_names_the_entry(extras, message):
    with pytest.raises(ValidationError, match=message):
        _trajectory(np.zeros((5, 3)), np.tile(IDENTITY, (5, 1)), extras=extras)


def test_save_round_trips_empty_method_and_info(tmp_path):
    traj = _trajectory([[1.0, 2.0, 3.0]], [IDENTITY])
    traj.save(tmp_path / "bare.nc")
    back = load(str(tmp_path / "bare.nc"))
    assert back.method == "" and back.info == {}


def test_save_overwrites_an_existing_file(tmp_path):
    path = tmp_path / "run.nc"
    path.write_bytes(b"old contents")
    _batch().save(path)
    np.testing.assert_array_equal(load(path).omega, _batch().omega)


def test_save_refuses_a_missing_directory(tmp_path):
    missing = tmp_path / "no" / "such"
    with pytest.raises(FileNotFoundError, match="does not exist"):
        _batch().save(missing / "run.nc")
    assert not (tmp_path / "no").exists()


def _failing_to_netcdf(self, path=None, *args, **kwargs):
    """Stand-in writer that leaves a partial file where it is given one, then fails."""
    if path is not None:
        with open(path, "wb") as f:
            f.write(b"\x89HDF\r\n partial")
    raise OSError("disk full (simulated)")


@pytest.mark.parametrize("pre_existing", [None, b"previous run"])
def test_failed_save_leaves_target_untouched_and_no_temp_file(tmp_path, monkeypatch, pre_existing):
    path = tmp_path / "run.nc"
    if pre_existing is not None:
        path.write_bytes(pre_existing)
    monkeypatch.setattr(xr.Dataset, "to_netcdf", _failing_to_netcdf)
    with pytest.raises(OSError, match="simulated"):
        _batch().save(path)
    if pre_existing is None:
        assert not path.exists()
    else:
        assert path.read_bytes() == pre_existing
    assert sorted(os.listdir(tmp_path)) == ([] if pre_existing is None else ["run.nc"])


def test_write_atomic_cleans_up_after_keyboard_interrupt(tmp_path):
    def write(tmp):
        with open(tmp, "w") as f:
            f.write("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomic(tmp_path / "out.txt", write)
    assert os.listdir(tmp_path) == []


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_write_atomic_file_permissions(tmp_path):
    umask = os.umask(0o022)
    try:
        new = tmp_path / "new.txt"
        write_atomic(new, lambda tmp: open(tmp, "w").close())
        assert new.stat().st_mode & 0o777 == 0o644  # 0o666 & ~umask, not tempfile's 0o600
        old = tmp_path / "old.txt"
        old.write_text("x")
        old.chmod(0o640)
        write_atomic(old, lambda tmp: open(tmp, "w").close())
        assert old.stat().st_mode & 0o777 == 0o640  # the replaced file's permissions are kept
    finally:
        os.umask(umask)


# -- plot -------------------------------------------------------------------------------


@pytest.mark.parametrize("batch", [False, True])
def test_plot_returns_a_figure_that_saves_to_png(tmp_path, batch):
    from matplotlib.figure import Figure

    traj = _batch(n=50) if batch else _batch(n=50).member(0)
    fig = traj.plot(title="test run")
    assert isinstance(fig, Figure)
    ax_rate, ax_drift, ax_direction = fig.axes
    assert len(ax_rate.lines) == 3 and len(ax_drift.lines) == 2 and len(ax_direction.lines) == 3
    assert "rad/s" in ax_rate.get_ylabel() and ax_direction.get_xlabel() == "time t (s)"
    assert ax_drift.get_yscale() == "symlog"
    one = traj.member(0) if batch else traj
    np.testing.assert_array_equal(ax_rate.lines[1].get_ydata(), one.omega[:, 1])
    heading = fig.get_suptitle()
    assert heading.startswith("test run") and (("body 0 of 3" in heading) == batch)

    path = tmp_path / "run.png"
    write_atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=50))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert os.listdir(tmp_path) == ["run.png"]
