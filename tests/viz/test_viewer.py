"""The viewer without a browser: decimation, the geometry it draws, what it refuses, the command line.

The trajectories here are written down, not integrated (a steady spin about a principal axis is an exact
free motion: ``q(t) = [cos(Ωt/2), sin(Ωt/2) e]``), so the module compiles nothing but the attitude
helpers. tests/viz/test_viewer_browser.py opens the pages in Chromium.
"""

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import tumble
from tumble import ValidationError
from tumble.viz import viewer
from tumble.cli import app
from tumble.trajectory import Extra, Trajectory
from tumble.viz.viewer._frames import frame_indices
from tumble.viz.viewer._shapes import body_mesh, box_mesh, cylinder_mesh, ellipsoid_mesh, equivalent_box
from tumble.viz.viewer.scenes.spacecraft import spin_angles

ROBOTS = tumble.examples.directory() / "robots"
INERTIA = np.diag([1.0, 2.0, 3.0])   # kg m²
SPIN = 2.0                           # rad/s about body z, the major axis


def steady_spin(n=501, duration=5.0) -> Trajectory:
    """A free rigid body spinning steadily about its principal axis z (exact), as simulate would return it."""
    t = np.linspace(0.0, duration, n)
    half = 0.5 * SPIN * t
    q = np.stack([np.cos(half), 0.0 * t, 0.0 * t, np.sin(half)], axis=-1)
    omega = np.broadcast_to([0.0, 0.0, SPIN], (n, 3))
    return Trajectory(t, q, omega, INERTIA, method="exact", info={"torque": "none"}, model="RigidBody")


def arm_trajectory() -> Trajectory:
    """A robot arm's trajectory as tumble.simulate gives it: no attitude, joint coordinates as an extra."""
    t = np.linspace(0.0, 1.0, 11)
    q = np.stack([0.3 + t, -0.5 + 0.2 * t], axis=-1)
    return Trajectory(t, None, None, None, method="rk4", extras={"joint_position": Extra(q, ("joint",), "rad")},
                      totals={"energy": np.zeros_like(t)}, model="SerialChain")


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    path = tmp_path_factory.mktemp("saved") / "spin.nc"
    steady_spin().save(path)
    return path


def test_frames_are_evenly_spaced_samples_with_the_first_and_the_last():
    np.testing.assert_array_equal(frame_indices(7, 600), np.arange(7))
    for n, budget in [(601, 600), (10_001, 600), (1000, 2), (5, 5)]:
        idx = frame_indices(n, budget)
        assert idx.size == min(n, budget) and idx[0] == 0 and idx[-1] == n - 1
        gaps = np.diff(idx)
        assert gaps.min() >= 1 and gaps.max() - gaps.min() <= 1   # distinct, spaced as evenly as whole indices can


def test_a_long_run_is_decimated_to_the_budget():
    scene = viewer.scene(steady_spin(n=5001), frames=600)
    assert len(scene.t) == 600 and scene.samples == 5001
    assert scene.t[0] == 0.0 and scene.t[-1] == 5.0


def test_the_equivalent_box_has_the_principal_moments_of_the_body():
    rng = np.random.default_rng(3)
    rotation, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    rotation *= np.linalg.det(rotation)
    inertia = rotation @ np.diag([2.0, 3.0, 4.0]) @ rotation.T
    mass = 1.5
    mesh, _ = body_mesh(inertia, mass=mass)
    sides = equivalent_box([2.0, 3.0, 4.0], mass)
    a1, a2, a3 = sides
    moments = mass / 12.0 * np.array([a2**2 + a3**2, a1**2 + a3**2, a1**2 + a2**2])
    np.testing.assert_allclose(moments, [2.0, 3.0, 4.0], rtol=1e-14)   # the formula inverted exactly, to rounding
    # the inertia of the drawn box (8 corners, uniform) about its centre equals the body's tensor
    # (the corners' second moment S_c is 3× the uniform box's: ∫x² dm / m = a²/12 against a²/4)
    corners = mesh.vertices
    second = corners.T @ corners / 8.0
    drawn = mass / 3.0 * (np.trace(second) * np.eye(3) - second)   # uniform box: I = m (tr S E − S), S = S_c/3
    np.testing.assert_allclose(drawn, inertia, atol=1e-13)


@pytest.mark.parametrize("mesh, volume", [
    (box_mesh([1.0, 2.0, 3.0]), 6.0),
    (cylinder_mesh(0.5, 2.0), 2.0 * 24 / 2 * 0.25 * np.sin(2 * np.pi / 24)),      # a 24-gon prism
    (ellipsoid_mesh([1.0, 2.0, 3.0]), None)], ids=["box", "cylinder", "ellipsoid"])
def test_meshes_are_closed_and_face_outward(mesh, volume):
    a, b, c = (mesh.vertices[mesh.faces[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)
    centres = (a + b + c) / 3.0
    assert np.all(np.einsum("ij,ij->i", normals, centres) > 0.0)   # every face seen counter-clockwise from outside
    edges = np.sort(np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]]), axis=1)
    _, count = np.unique(edges, axis=0, return_counts=True)
    assert np.all(count == 2)                                      # closed: every edge borders two faces
    if volume is not None:   # signed volume of the closed surface (divergence theorem)
        assert np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0 == pytest.approx(volume, rel=1e-14)


def test_wheel_spin_angle_is_exact_for_a_speed_linear_in_time():
    t = np.linspace(0.0, 3.0, 31)
    speed = np.stack([2.0 + 0.5 * t, -1.0 * t], axis=-1)
    exact = np.stack([2.0 * t + 0.25 * t**2, -0.5 * t**2], axis=-1)
    np.testing.assert_allclose(spin_angles(t, speed), exact, atol=1e-13)   # the trapezoid rule is exact here


def test_the_page_is_one_file_with_the_scene_and_no_external_script(tmp_path):
    traj = steady_spin()
    path = tmp_path / "spin.html"
    traj.to_html(path, frames=50)
    page = path.read_text(encoding="utf-8")
    head = page.split("<script>", 1)[0]
    assert "<script src" not in page[:200_000] and "<link" not in head
    assert 4_000_000 < path.stat().st_size < 10_000_000   # plotly.js (4.8 MB) and the scene
    assert [p.name for p in tmp_path.iterdir()] == ["spin.html"]   # no temporary file left


def test_notebook_html_is_an_iframe_and_a_robot_without_its_chain_falls_back_to_the_table():
    html = viewer.notebook_html(steady_spin(n=21))
    assert html.startswith("<iframe srcdoc=") and "&lt;!DOCTYPE html&gt;" in html
    assert viewer.notebook_html(arm_trajectory()) is None
    # a notebook shows the run's table, then the viewer where it can draw one; a robot arm's run, the table alone
    assert steady_spin(n=21)._repr_html_().endswith(html)
    assert arm_trajectory()._repr_html_().endswith("</table>")


@pytest.mark.parametrize("frames", [1, 0, -3, 2.5, "600"])
def test_a_frame_budget_below_two_is_refused_and_nothing_written(tmp_path, frames):
    with pytest.raises(ValidationError) as info:
        viewer.write_html(steady_spin(n=21), tmp_path / "x.html", frames=frames)
    assert info.value.field == "frames"
    assert list(tmp_path.iterdir()) == []


def test_what_is_not_a_trajectory_is_refused_and_nothing_written(tmp_path, saved):
    text = tmp_path / "notes.nc"
    text.write_text("not a trajectory\n")
    other = tmp_path / "other.nc"
    xr.Dataset({"temperature": ("x", np.arange(3.0))}).to_netcdf(other, engine="h5netcdf")
    for bad, rule in [(text, "is not a tumble trajectory"), (other, "is not a tumble trajectory"),
                      ({"t": [0.0]}, "must be a tumble.Trajectory"), (tmp_path / "missing.nc", "not a tumble")]:
        with pytest.raises(ValidationError, match=rule) as info:
            viewer.write_html(bad, tmp_path / "out.html")
        assert info.value.field == "traj"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.nc", "other.nc"]


def test_an_empty_trajectory_is_refused_and_nothing_written(tmp_path):
    empty = tmp_path / "empty.nc"
    steady_spin(n=3).to_xarray().isel(time=slice(0, 0)).to_netcdf(empty, engine="h5netcdf")
    with pytest.raises(ValidationError, match="empty trajectory") as info:
        viewer.write_html(empty, tmp_path / "out.html")
    assert info.value.field == "traj"
    assert [p.name for p in tmp_path.iterdir()] == ["empty.nc"]


def test_a_batch_a_wrong_model_and_a_robot_without_its_chain_are_refused():
    one = steady_spin(n=11)
    batch = Trajectory(one.t, np.stack([one.q, one.q], 1), np.stack([one.omega, one.omega], 1), INERTIA)
    with pytest.raises(ValidationError, match=r"traj: a batch of 2 runs; view one run with traj.member\(i\)"):
        viewer.scene(batch)
    with pytest.raises(ValidationError, match="model: a RigidBody trajectory is drawn with a RigidBody"):
        viewer.scene(one, model=tumble.robot.load(ROBOTS / "planar_2link.toml"))
    with pytest.raises(ValidationError, match="model: a SerialChain trajectory holds joint coordinates only"):
        viewer.scene(arm_trajectory())
    with pytest.raises(ValidationError, match="axis: must be 'x', 'y', 'z' or None"):
        viewer.scene(one, axis="w")


def test_the_scene_of_a_free_body_shows_its_motion():
    traj = steady_spin(n=101)
    scene = viewer.scene(traj, frames=101)
    body = scene.solids[0]
    np.testing.assert_allclose(body.rotation, tumble.attitude.to_matrix(traj.q), atol=1e-15)
    # L = I ω = (0, 0, 6) N m s stands still along inertial z; ω turns with it; the trace of z stays at the pole
    arrows = {line.name: line.points for line in scene.lines}
    tips = arrows["L (angular momentum)"][:, 1]
    np.testing.assert_allclose(tips / np.linalg.norm(tips, axis=-1, keepdims=True), [[0.0, 0.0, 1.0]] * 101,
                               atol=1e-15)
    assert scene.polhode is not None
    # the polhode of a steady spin about the major axis is one point on the energy ellipsoid ω·Iω = 2T
    np.testing.assert_allclose(np.einsum("fi,i,fi->f", scene.polhode.points, [1.0, 2.0, 3.0],
                                         scene.polhode.points), 3.0 * SPIN**2, rtol=1e-14)


def test_tumble_view_writes_the_page_and_refuses_bad_input(tmp_path, saved):
    runner = CliRunner()
    out = tmp_path / "spin.html"
    result = runner.invoke(app, ["view", str(saved), "-o", str(out), "--frames", "40", "--axis", "z"])
    assert result.exit_code == 0, result.output
    assert f"wrote     {out}" in result.stdout and out.stat().st_size > 4_000_000
    bad = tmp_path / "bad.nc"
    bad.write_text("no\n")
    for args, message in [([str(saved), "--frames", "1"], "error: frames: must be >= 2"),
                          ([str(bad)], "is not a tumble trajectory"),
                          ([str(saved), "--axis", "q"], "error: axis: must be")]:
        target = tmp_path / "refused.html"
        result = runner.invoke(app, ["view", *args, "-o", str(target)])
        assert result.exit_code == 2 and message in result.stderr, result.output
        assert not target.exists()
