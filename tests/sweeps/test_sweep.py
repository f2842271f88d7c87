"""tumble.sweep in this process (workers=0): dispersions, per-sample reproducibility, outcomes, the store, bad input.

The Dask runs (LocalCluster, scheduler and worker processes, killed workers
and clients) are in tests/sweeps/test_sweep_dask.py. Every simulation here is a
batch of rigid bodies under rk4 without torque, the specialization the rest
of the suite compiles too, and one spacecraft with a damper under dop853 (as
tests/spacecraft/test_spacecraft_passive_damper.py).
"""

from __future__ import annotations

import importlib.util
import math
import os
import statistics

import numpy as np
import pytest

import tumble
from tumble.sweeps import (
    Final,
    Grid,
    Inertia,
    Max,
    Misalignment,
    NoiseSeed,
    Normal,
    NutationAngle,
    PointingError,
    SettlingTime,
    TruncatedNormal,
    Uniform,
    UniformAttitude,
    simulate_to_store,
)
from tumble.sweeps.plan import make_plan

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
T = np.linspace(0.0, 2.0, 11)
RK4 = dict(method="rk4", dt=0.01)
DISPERSIONS = {"omega0": Normal([0.0, 0.0, 1.0], [0.05, 0.05, 0.1]), "q0": UniformAttitude()}
OUTCOMES = {"nutation": Final(NutationAngle([0.0, 0.0, 1.0])), "pointing": Max(PointingError(), after=1.0)}
SERIES = {"omega_z": tumble.sweeps.Component("omega", 2)}
RUN = dict(t=T, **RK4, outcomes=OUTCOMES, statistics=SERIES, workers=0)
N = 23  # a prime: the chunks below leave remainders


def plan_of(dispersions, samples=4000, seed=3, chunk=None, model=BODY):
    return make_plan(model, dispersions, samples=samples, seed=seed, chunk=chunk, t=T, method="rk4",
                     options={"dt": 0.01}, torque=None, outcomes={}, series={}, fixed={})


def load_example(name):
    path = tumble.examples.directory() / "sweep" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"sweep_example_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# -- sample i is a function of (seed, i) ----------------------------------------------


def test_sample_inputs_depend_only_on_seed_and_index():
    plan = plan_of({**DISPERSIONS, "seed": NoiseSeed()}, samples=N, model=lambda seed: BODY)
    whole = plan.inputs(0, N)
    for lo, hi in [(0, 5), (5, 17), (17, 23), (11, 12)]:
        part = plan.inputs(lo, hi)
        for name in whole:
            np.testing.assert_array_equal(part[name], whole[name][lo:hi], err_msg=name)
    # sample i's variates, rebuilt independently: words 8i .. 8i+7 of Philox4x64 keyed by SeedSequence(3)
    # (3 for omega0, 4 for q0, 1 for the seed: 8 words, two counter steps), each word k -> (k >> 11 + 1/2) 2^-53,
    # a normal as its inverse distribution function; omega0 takes the first three, q0 the next four
    key = np.random.SeedSequence(3).generate_state(2, np.uint64)
    words = np.random.Philox(key=key).random_raw(8 * 8)[8 * 7:8 * 8]
    u = np.array([(int(k) >> 11) + 0.5 for k in words]) / 2.0**53
    z = np.array([statistics.NormalDist().inv_cdf(x) for x in u])  # the standard library's Φ⁻¹ (Wichura AS241)
    np.testing.assert_allclose(whole["omega0"][7], [0.0, 0.0, 1.0] + np.array([0.05, 0.05, 0.1]) * z[:3],
                               rtol=1e-15, atol=1e-15)  # scipy's ndtri and AS241 agree to a few ulps
    np.testing.assert_allclose(whole["q0"][7], z[3:7] / np.linalg.norm(z[3:7]), rtol=0, atol=1e-15)
    assert whole["seed"][7] == math.floor(u[7] * 2.0**53)
    assert len(set(whole["seed"].tolist())) == N
    other = plan_of(DISPERSIONS, samples=N, seed=4).inputs(0, N)
    assert not np.any(other["omega0"] == whole["omega0"])


def test_sweep_results_do_not_depend_on_the_chunk_size():
    a = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, **RUN)
    b = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=23, **RUN)
    for name in ("omega0", "q0", "nutation", "pointing", "omega_z", "nutation_percentiles", "omega_z_percentiles"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    # the per-time moments merge chunk by chunk (Chan et al.): equal up to the merge's rounding, measured
    # <= 2.9e-16 relative (the std; the mean 2.2e-16, min and max equal); bound 1e-14
    for stat in ("mean", "std", "min", "max"):
        np.testing.assert_allclose(a[f"omega_z_{stat}"].values, b[f"omega_z_{stat}"].values, rtol=1e-14, atol=0)
    assert a.attrs["chunks_computed"] == 5 and b.attrs["chunks_computed"] == 1


def test_sweep_equals_the_batch_run_through_simulate():
    ds = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=7, trajectories=True, **RUN)
    traj = tumble.simulate(BODY, t=T, **RK4, omega0=ds.omega0.values, q0=ds.q0.values)
    for name in ("q", "omega", "energy", "momentum_body"):  # every sample's run, sample-major
        np.testing.assert_array_equal(ds[name].values, np.swapaxes(getattr(traj, name), 0, 1), err_msg=name)
    np.testing.assert_array_equal(ds.nutation.values, OUTCOMES["nutation"](traj))
    np.testing.assert_array_equal(ds.pointing.values, OUTCOMES["pointing"](traj))
    w = traj.omega[..., 2]
    np.testing.assert_array_equal(ds.omega_z.values, w.T)
    # statistics against NumPy on the whole batch: merge rounding, bound 1e-14 relative to max |w|
    scale = np.abs(w).max()
    for stat, expected in (("mean", w.mean(1)), ("std", w.std(1)), ("min", w.min(1)), ("max", w.max(1))):
        assert np.abs(ds[f"omega_z_{stat}"].values - expected).max() <= 1e-14 * scale, stat
    np.testing.assert_array_equal(ds.omega_z_percentiles.values, np.percentile(w, ds.percentile.values, axis=1))
    np.testing.assert_array_equal(ds.nutation_percentiles.values,
                                  np.percentile(ds.nutation.values, ds.percentile.values))


# -- dispersions ----------------------------------------------------------------------

# Statistical checks on 4000 samples: a sample mean is within 5 standard errors of its expectation
# (a false alarm about once in 1.7 million runs); the samples are fixed by the seed, so the check is
# deterministic.
SAMPLES = 4000


def within(values, expected, sigma):
    return abs(np.mean(values) - expected) <= 5 * sigma / math.sqrt(SAMPLES)


def test_normal_uniform_and_truncated_draws():
    x = plan_of({"omega0": Normal([1.0, 2.0, 3.0], [0.1, 0.0, 2.0])}).inputs(0, SAMPLES)["omega0"]
    assert within(x[:, 0], 1.0, 0.1) and within(x[:, 2], 3.0, 2.0) and np.all(x[:, 1] == 2.0)
    assert abs(x[:, 2].std() / 2.0 - 1) < 5 / math.sqrt(2 * SAMPLES)  # std error of a normal sample std
    u = plan_of({"omega0": Uniform([-1.0, 0.0, 5.0], [1.0, 0.0, 7.0])}).inputs(0, SAMPLES)["omega0"]
    assert u[:, 0].min() >= -1 and u[:, 0].max() < 1 and within(u[:, 0], 0.0, 2 / math.sqrt(12))
    assert within(u[:, 2], 6.0, 2 / math.sqrt(12)) and np.all(u[:, 1] == 0.0)
    tn = plan_of({"x": TruncatedNormal(0.0, 1.0, 0.0, 2.0)}, model=lambda x: BODY).inputs(0, SAMPLES)["x"]
    assert tn.min() >= 0.0 and tn.max() <= 2.0
    # mean of N(0, 1) on [0, 2]: (φ(0) − φ(2)) / (Φ(2) − Φ(0)) = 0.7228 (exact), std 0.5714 (scipy.stats)
    phi = (1 - math.exp(-2)) / math.sqrt(2 * math.pi)
    assert within(tn.ravel(), phi / (0.5 * math.erf(2 / math.sqrt(2))), 0.58)


def test_uniform_attitudes_have_the_haar_angle_distribution():
    q = plan_of({"q0": UniformAttitude()}).inputs(0, SAMPLES)["q0"]
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, rtol=1e-15)
    # the rotation angle of a uniform rotation has density (1 − cos θ)/π on [0, π]:
    # mean π/2 + 2/π, standard deviation 0.6753 (the integral, computed)
    angle = tumble.attitude.angle(q)
    assert within(angle, math.pi / 2 + 2 / math.pi, 0.6753)


def test_inertia_dispersion_stays_physical_and_has_the_stated_moments():
    d = Inertia([1.0, 2.0, 2.4], [0.05, 0.05, 0.08], angle=0.02)
    j = plan_of({"inertia": d}).inputs(0, SAMPLES)["inertia"]
    np.testing.assert_array_equal(j, np.swapaxes(j, -1, -2))
    moments = np.linalg.eigvalsh(j)
    assert np.all(moments[:, 0] + moments[:, 1] >= moments[:, 2])
    # each moment is N(m, s²) truncated at ±3 s (symmetric: mean m); eigenvalues come sorted, and the
    # three boxes [0.85, 1.15], [1.85, 2.15], [2.16, 2.64] do not overlap, so sorted = drawn
    for k, (m, s) in enumerate([(1.0, 0.05), (2.0, 0.05), (2.4, 0.08)]):
        assert np.all(np.abs(moments[:, k] - m) <= 3 * s * (1 + 1e-12)) and within(moments[:, k], m, s)
    # the principal axes turn by the small rotation: |rotation vector| Rayleigh-like, mean 0.02 √(8/π)
    axes = np.linalg.eigh(j)[1]
    tilt = np.arccos(np.clip(np.abs(axes[:, 2, 2]), 0, 1))
    assert np.median(tilt) < 0.05
    with pytest.raises(tumble.ValidationError, match=r"^std: the moments could break the triangle inequality "
                                                     r"I1 \+ I2 >= I3"):
        Inertia([1.0, 2.0, 2.9], [0.05, 0.05, 0.1])
    with pytest.raises(tumble.ValidationError, match=r"^std: moments .* must stay > 0"):
        Inertia([0.1, 2.0, 2.0], [0.05, 0.0, 0.0])


def test_misalignment_tilts_each_axis_by_a_rayleigh_angle():
    axes = np.eye(3)
    a = plan_of({"axes": Misalignment(axes, 0.01)}, model=lambda axes: BODY).inputs(0, SAMPLES)["axes"]
    np.testing.assert_allclose(np.linalg.norm(a, axis=-1), 1.0, rtol=1e-14)
    tilt = np.arccos(np.clip(np.einsum("mki,ki->mk", a, axes), -1, 1))
    # Rayleigh(σ): mean σ √(π/2), standard deviation σ √((4 − π)/2)
    for k in range(3):
        assert within(tilt[:, k], 0.01 * math.sqrt(math.pi / 2), 0.01 * math.sqrt((4 - math.pi) / 2))


def test_grids_form_a_cartesian_product_in_c_order():
    plan = plan_of({"a": Grid([1.0, 2.0]), "b": Grid([[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]])}, samples=7,
                   model=lambda a, b: BODY)
    x = plan.inputs(0, 7)
    np.testing.assert_array_equal(x["a"], [1, 1, 1, 2, 2, 2, 1])
    np.testing.assert_array_equal(x["b"][:, 0], [0, 2, 4, 0, 2, 4, 0])


# -- outcomes -------------------------------------------------------------------------


def test_flip_interval_grid_matches_the_analytic_interval():
    example = load_example("flip_interval")
    ds, exact = example.run(epsilons=[1e-4, 1e-3, 1e-2], t=np.arange(0.0, 80.0 + 0.005, 0.01), workers=0)
    # measured relative difference <= 2.5e-10 (rk4 at dt = 0.01 s and the linear interpolation of the
    # crossings; 5.9e-9 at epsilon = 1e-4 over the 160 s of the example); bound 1e-7
    np.testing.assert_allclose(ds.flip_interval.values, exact, rtol=1e-7)


def test_settling_and_crossing_times():
    t = np.linspace(0.0, 4.0, 5)
    traj = tumble.Trajectory(t=t, q=np.tile([1.0, 0, 0, 0], (5, 3, 1)), omega=np.zeros((5, 3, 3)),
                             inertia=np.eye(3), extras={"x": tumble.trajectory.Extra(
                                 np.array([[3.0, 0.0, 0.0], [0.5, 0.0, 1.0], [2.0, 0.0, 2.0], [0.5, 0.0, 3.0],
                                           [0.1, 0.0, 4.0]]))})
    x = tumble.sweeps.Component("x")
    np.testing.assert_array_equal(SettlingTime(x, below=1.0)(traj), [3.0, 0.0, np.nan])
    np.testing.assert_array_equal(tumble.sweeps.CrossingTime(x, above=2.0)(traj), [0.0, np.nan, 2.0])
    np.testing.assert_array_equal(Max(x, after=1.0)(traj), [2.0, 0.0, 4.0])


def test_final_and_max_read_only_the_times_they_need():
    # a pointwise series is evaluated at the times the reduction reads only: the same numbers, bit for bit,
    # as the series over the whole run, then cut
    traj = tumble.simulate(BODY, np.random.default_rng(4).normal([0.0, 0.0, 1.0], 0.1, size=(N, 3)), t=T, **RK4)
    for series in (NutationAngle([0.0, 0.6, 0.8]), PointingError([0.5, 0.5, 0.5, 0.5])):
        whole = series(traj)
        np.testing.assert_array_equal(Final(series)(traj), whole[-1], err_msg=repr(series))
        np.testing.assert_array_equal(Max(series, after=1.0)(traj), whole[T >= 1.0].max(axis=0), err_msg=repr(series))
    drift = tumble.sweeps.Component("energy_drift")  # not pointwise (relative to t = 0): read over the whole run
    np.testing.assert_array_equal(Final(drift)(traj), traj.energy_drift[-1])


def test_outcome_percentiles_are_over_the_samples_where_the_event_happened():
    # omega_z crosses 1.0 rad/s only in the samples started above it (no torque: omega_z oscillates about its
    # start by the small transverse rates): the others have no crossing time (NaN); the percentiles are
    # those of the samples with a value, and the count says how many
    crossing = tumble.sweeps.CrossingTime(tumble.sweeps.Component("omega", 2), above=1.0)
    ds = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=5, t=T, **RK4, workers=0,
                      outcomes={"crossing": crossing})
    values = ds.crossing.values
    reached = ~np.isnan(values)
    assert 0 < reached.sum() < N and int(ds.crossing_count) == reached.sum()
    np.testing.assert_array_equal(ds.crossing_percentiles.values,
                                  np.percentile(values[reached], ds.percentile.values))


@pytest.mark.slow  # compiles the spacecraft (~35 CPU s on a cold cache)
def test_a_model_built_per_sample_runs_member_by_member(tmp_path):
    # a spacecraft with a dispersed damper: no batched form, so one simulate per sample inside the chunk
    from tumble.spacecraft import Spacecraft, SphericalDamper

    hub = tumble.RigidBody(np.diag([1.0, 1.0, 0.4]))

    def craft(damping):
        return Spacecraft(hub=hub, damper=SphericalDamper(0.02, damping))

    t = np.linspace(0.0, 2.0, 3)
    ds = tumble.sweep(craft, {"damping": Uniform(0.005, 0.02), "omega0": Normal([0.0, 0.0, 2.0], 0.01)},
                      samples=3, seed=2, t=t, rtol=1e-12, atol=1e-12, chunk=2, workers=0,
                      outcomes={"nutation": Final(NutationAngle())}, store=tmp_path / "craft.zarr")
    for i in range(3):
        one = tumble.simulate(craft(float(ds.damping[i])), ds.omega0.values[i], t=t, rtol=1e-12, atol=1e-12)
        assert ds.nutation.values[i] == tumble.spacecraft.damper.nutation_angle(one, [0, 0, 1])[-1]


# -- the store ------------------------------------------------------------------------


class Interrupt(Exception):
    pass


def stop_after(n):
    def progress(done, total):
        if done >= n:
            raise KeyboardInterrupt

    return progress


def test_an_interrupted_sweep_resumes_with_the_missing_chunks_only(tmp_path):
    store = tmp_path / "mc.zarr"
    whole = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, **RUN)
    with pytest.raises(KeyboardInterrupt):
        tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, store=store, progress=stop_after(2), **RUN)
    assert tumble.sweeps.open_sweep(store).done.values.tolist() == [True, True, False, False, False]
    resumed = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, store=store, **RUN)
    assert resumed.attrs["chunks_computed"] == 3
    for name in whole.data_vars:
        np.testing.assert_array_equal(resumed[name].values, whole[name].values, err_msg=name)
    again = tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, store=store, **RUN)
    assert again.attrs["chunks_computed"] == 0


def test_a_sweep_in_memory_is_its_store_on_disk_loaded(tmp_path):
    # without a store the results stay in NumPy arrays laid out as the Zarr store: the same variables,
    # dimensions, coordinates, attributes, dtypes and values, bit for bit
    import xarray as xr

    args = dict(dispersions=DISPERSIONS, samples=N, seed=1, chunk=5, trajectories=True, **RUN)
    memory = tumble.sweep(BODY, **args)
    disk = tumble.sweep(BODY, store=tmp_path / "mc.zarr", **args).load()
    xr.testing.assert_identical(memory, disk)
    assert {k: v.dtype for k, v in memory.variables.items()} == {k: v.dtype for k, v in disk.variables.items()}
    assert memory.attrs["tumble_sweep_complete"] is True and memory.attrs["chunks_computed"] == 5


def test_a_store_of_other_settings_is_refused_and_left_alone(tmp_path):
    store = tmp_path / "mc.zarr"
    tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, store=store, **RUN)
    before = {p: p.stat().st_mtime_ns for p in store.rglob("*")}
    changes = [(dict(seed=2), "seed = 1 there, 2 here"), (dict(chunk=6), "chunk = 5 there, 6 here"),
               (dict(samples=24), "samples = 23 there, 24 here"),
               (dict(dispersions={**DISPERSIONS, "omega0": Normal([0.0, 0.0, 1.0], 0.05)}), "dispersions = ")]
    for change, rule in changes:
        args = dict(dispersions=DISPERSIONS, samples=N, seed=1, chunk=5, **RUN) | change
        with pytest.raises(tumble.ValidationError, match=f"^store: .* was written with other settings: {rule}"):
            tumble.sweep(BODY, store=store, **args)
    with pytest.raises(tumble.ValidationError, match="^store: .* was written with other settings: t = "):
        tumble.sweep(BODY, DISPERSIONS, samples=N, seed=1, chunk=5, store=store, **(RUN | {"t": T * 2}))
    assert {p: p.stat().st_mtime_ns for p in store.rglob("*")} == before
    os.makedirs(tmp_path / "other")
    with pytest.raises(tumble.ValidationError, match="^store: .* is not a tumble sweep store"):
        tumble.sweep(BODY, DISPERSIONS, samples=N, store=tmp_path / "other", **RUN)


@pytest.mark.parametrize(("arguments", "message"), [
    (dict(dispersions={"omega": Normal([0, 0, 1.0], 0.1)}),
     r"^dispersions\['omega'\]: not an initial state or a parameter of the RigidBody; it takes omega0, q0, inertia"),
    (dict(dispersions={"k": Normal(1.0, 0.1), "gain": 1.0}, model=lambda gain: BODY),
     r"^dispersions\['k'\]: not an initial state or a parameter of the model built by .*; it takes omega0, q0, gain"),
    (dict(dispersions={"k": Normal(1.0, 0.1)}, model=lambda gain: BODY),
     r"^dispersions: the model's build function .* needs 'gain'"),
    (dict(dispersions={"omega0": Normal([0, 0], 0.1)}), r"^dispersions\['omega0'\]: a value of shape \(3,\)"),
    (dict(dispersions={"inertia": Normal(np.eye(3), 0.1)}),
     r"^dispersions\['inertia'\]: must be a tumble.sweeps.Inertia \(it stays physical\) or a Grid"),
    (dict(dispersions={"inertia": Grid([np.eye(3), np.diag([1.0, 1.0, 3.0])])}),
     r"^dispersions\['inertia'\]\[1\]: principal moments break the triangle inequality"),
    (dict(dispersions={"omega0": Normal([0, 0, 1.0], 0.1)}, samples=0), r"^samples: must be >= 1"),
    (dict(dispersions={"omega0": Normal([0, 0, 1.0], 0.1)}, seed=-1), r"^seed: must be an integer >= 0"),
    (dict(dispersions={"omega0": Normal([0, 0, 1.0], 0.1)}, dt=None, rtol=1e-9),
     r"^rtol: method 'rk4' does not use rtol"),
    (dict(dispersions={"omega0": Normal([0, 0, 1.0], 0.1)}, percentiles=[50, 101]), r"^percentiles: must lie in"),
    (dict(dispersions={"omega0": Normal([0, 0, 1.0], 0.1)}, outcomes={"omega0": Final(PointingError())}),
     r"^outcomes\['omega0'\]: names must be different from the dispersed inputs"),
])
def test_bad_input_is_refused_naming_the_field_and_nothing_is_written(tmp_path, arguments, message):
    args = dict(dict(model=BODY, samples=N, seed=1, t=T, workers=0, store=tmp_path / "bad.zarr", **RK4), **arguments)
    with pytest.raises(tumble.ValidationError, match=message):
        tumble.sweep(args.pop("model"), args.pop("dispersions"), **args)
    assert not os.listdir(tmp_path)


def test_bad_dispersions_are_refused_at_construction():
    with pytest.raises(tumble.ValidationError, match=r"^std: must be >= 0, got \[-0.1\]"):
        Normal([0.0], [-0.1])
    with pytest.raises(tumble.ValidationError, match=r"^high: must be >= low"):
        Uniform(1.0, 0.0)
    with pytest.raises(tumble.ValidationError, match=r"^std: must be > 0"):
        TruncatedNormal(0.0, 0.0)
    with pytest.raises(tumble.ValidationError, match=r"^angle: must be a finite number >= 0"):
        Misalignment(np.eye(3), -1.0)
    with pytest.raises(tumble.ValidationError, match=r"^points: a grid needs at least one point"):
        Grid([])


# -- simulate_to_store: a batch streamed to a store in chunks ------------------------------


def test_a_batch_streamed_to_a_store_in_chunks_equals_the_batch(tmp_path):
    rng = np.random.default_rng(4)
    inertia = np.diag([1.0, 2.0, 3.0]) + np.einsum("n,ij->nij", rng.uniform(0.0, 0.2, N), np.eye(3))
    omega0 = rng.normal(size=(N, 3))
    whole = tumble.simulate(inertia, omega0, t=T, **RK4)
    ds = simulate_to_store(inertia, omega0, store=tmp_path / "run.zarr", t=T, **RK4, chunk=5)
    assert ds.q.chunks[1] == (5, 5, 5, 5, 3)
    back = tumble.Trajectory.from_xarray(ds.load())
    for name in ("q", "omega", "energy", "momentum_body", "inertia"):
        np.testing.assert_array_equal(getattr(back, name), getattr(whole, name), err_msg=name)
    assert back.info == whole.info  # the solver statistics, summed over the chunks
    with pytest.raises(tumble.ValidationError, match="^store: .* exists"):
        simulate_to_store(BODY, omega0, store=tmp_path / "run.zarr", t=T, **RK4)
    assert sorted(os.listdir(tmp_path)) == ["run.zarr"]  # no temporary store left


def test_simulate_with_a_store_is_deprecated_and_still_streams(tmp_path):
    omega0 = np.random.default_rng(5).normal(size=(N, 3))
    with pytest.warns(DeprecationWarning, match=r"^simulate\(store=\.\.\.\) is deprecated .* use "
                                                r"tumble\.sweeps\.simulate_to_store\(model, \.\.\., store=\.\.\.\)"):
        front = tumble.simulate(BODY, omega0, t=T, **RK4, store=tmp_path / "front.zarr")
    np.testing.assert_array_equal(front.omega.values, tumble.simulate(BODY, omega0, t=T, **RK4).omega)


def test_a_store_refuses_an_empty_batch(tmp_path):
    # once zarr's GroupNotFoundError ("No group found in store None"): no chunk had made the store
    with pytest.raises(tumble.ValidationError, match="^store: the batch has no members"):
        simulate_to_store(BODY, np.zeros((0, 3)), store=tmp_path / "empty.zarr", t=T, **RK4)
    assert os.listdir(tmp_path) == []


def test_a_run_too_big_for_memory_is_refused_before_allocation():
    # 1e6 bodies x 1e5 output times: 1.4e13 bytes, more than any test machine has
    with pytest.raises(tumble.ValidationError, match=r"^store: 1000000 members x 100000 output times need at least "
                                                     r"14,400,000,000,000 bytes .* tumble\.sweeps\.simulate_to_store"
                                                     r"\(\.\.\., store='run\.zarr'\) streams it"):
        tumble.simulate(BODY, np.zeros((1_000_000, 3)), t=np.linspace(0.0, 1.0, 100_000), method="rk4", dt=1e-5)


# -- scenario files and the command line ----------------------------------------------

SPINNER = tumble.examples.directory() / "sweep" / "spinner.toml"


def test_tumble_sweep_of_a_scenario_file_writes_the_store_and_the_figure(tmp_path):
    from typer.testing import CliRunner

    from tumble.cli import app

    runner = CliRunner()
    store, figure = tmp_path / "spinner.zarr", tmp_path / "spinner.png"
    result = runner.invoke(app, ["sweep", str(SPINNER), "-o", str(store), "--samples", "12", "--workers", "0",
                                 "--plot", str(figure), "--quiet"])
    assert result.exit_code == 0, result.output
    assert "samples   12 (seed 2026), 1 of 1 chunks of 50 done" in result.output
    assert figure.stat().st_size > 10_000
    # the same sweep from Python: the scenario's model rebuilt per sample with its dispersed inertia
    ds = tumble.scenario.sweep_scenario(SPINNER, samples=12, workers=0)
    stored = tumble.sweeps.open_sweep(store)
    for name in ("body.inertia", "omega0", "q0", "nutation", "nutation_angle"):
        np.testing.assert_array_equal(stored[name].values, ds[name].values, err_msg=name)
    j = ds["body.inertia"].values
    t = np.array(ds.time.values)  # writable, as the sweep's: a read-only array would compile another kernel
    traj = tumble.simulate(j, t=t, method="rk4", dt=0.01, omega0=ds.omega0.values, q0=ds.q0.values)
    np.testing.assert_array_equal(ds.nutation.values, Max(NutationAngle([0.0, 0.0, 1.0]))(traj))
    info = runner.invoke(app, ["info", str(store)])
    assert info.exit_code == 0 and "a sweep, complete" in info.output and "nutation  1%:" in info.output


def test_a_bad_sweep_table_exits_2_and_writes_nothing(tmp_path):
    from typer.testing import CliRunner

    from tumble.cli import app

    text = SPINNER.read_text().replace('"initial.q" = { uniform_attitude = true }',
                                       '"time.stop" = { uniform = { low = 10.0, high = 20.0 } }\n'
                                       '"initial.q" = { normal = { mean = 1.0, std = -1.0 } }')
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    result = CliRunner().invoke(app, ["sweep", str(bad), "-o", str(tmp_path / "out.zarr"), "--workers", "0"])
    assert result.exit_code == 2
    assert "sweep.dispersions.time.stop: the samples of a sweep share time, solver, torque" in result.output
    assert "sweep.dispersions.initial.q: std: must be >= 0" in result.output
    assert sorted(os.listdir(tmp_path)) == ["bad.toml"]
