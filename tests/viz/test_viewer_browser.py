"""The viewer's pages in a real headless Chromium (Debian's chromium and chromium-driver, driven by selenium).

For a free rigid body, a spacecraft with reaction wheels and a robot arm: the page loads with no console
error and no network request, its 3-D canvas is not blank, Play advances the time shown, and at three frames
what the page drew equals the trajectory: the body's rotation read back from the drawn vertices is R(q(t)) to
1e-6, and the robot's drawn joint positions are the chain's forward kinematics to 1e-6 m.

Without Chromium (or selenium) the tests are skipped with the reason; with TUMBLE_REQUIRE_BROWSER=1 (set by
.ci/run) they fail instead. One browser serves the module. TUMBLE_SCREENSHOT_DIR=docs/img writes the
screenshots of the pages there (docs/img/viewer*.png are made so).
"""

import base64
import io
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import attitude, robot
from tumble.spacecraft import MRPFeedback, ReactionWheel, Spacecraft
from tumble.viz.viewer import Cylinder

# Every test here opens pages in Chromium and simulates a spacecraft or a robot arm on a cold Numba cache.
pytestmark = pytest.mark.slow

ROBOTS = tumble.examples.directory() / "robots"
CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
# Chromium offline: no sandbox (root in CI), no GPU (software GL through SwiftShader for WebGL), and every
# background service that would reach the network switched off, with a fresh profile.
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1400,900"]
FRAMES = 120          # frame budget of the test pages: fewer than their samples, so decimation is exercised
# The drawn vertices are float64 products R v + p computed by the page from the float64 numbers of the
# scene: the read-back rotation differs from R(q) by rounding only (~1e-15); 1e-6 is the bound.
ROTATION_TOLERANCE = 1e-6
POSITION_TOLERANCE = 1e-6   # m, the robot's joints


def _browser():
    """A headless Chromium under selenium, or the reason there is none."""
    missing = [path for path in (CHROMIUM, DRIVER) if shutil.which(path) is None]
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        missing.append("the selenium package")
    if missing:
        return None, f"Chromium not found ({', '.join(missing)}): apt-get install chromium chromium-driver"
    os.environ.setdefault("SE_OFFLINE", "true")  # selenium never looks for a driver on the network
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    profile = tempfile.mkdtemp(prefix="tumble-chromium-")
    for flag in [*FLAGS, f"--user-data-dir={profile}"]:
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    driver.set_script_timeout(30)
    return (driver, profile), None


@pytest.fixture(scope="module")
def browser():
    made, reason = _browser()
    if made is None:
        if os.environ.get("TUMBLE_REQUIRE_BROWSER") == "1":
            pytest.fail(reason + " (TUMBLE_REQUIRE_BROWSER=1)")
        pytest.skip(reason)
    driver, profile = made
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


class Page:
    """A page opened in the browser, with the network requests and console messages it caused."""

    def __init__(self, driver, path: Path):
        driver.get("about:blank")
        driver.get_log("performance"), driver.get_log("browser")  # drain: only what the page does counts
        self.driver, self.url = driver, path.resolve().as_uri()
        driver.get(self.url)
        deadline = time.monotonic() + 60.0
        while not driver.execute_script("return !!(window.tumbleViewer && window.tumbleViewer.state.ready)"):
            assert time.monotonic() < deadline, "the page did not get ready in 60 s"
            time.sleep(0.05)
        self.scene = json.loads(driver.execute_script("return document.getElementById('tumble-scene').textContent"))

    def requests(self) -> list[str]:
        events = [json.loads(entry["message"])["message"] for entry in self.driver.get_log("performance")]
        return [e["params"]["request"]["url"] for e in events if e["method"] == "Network.requestWillBeSent"]

    def show(self, frame: int) -> None:
        self.driver.execute_async_script(
            "const done = arguments[arguments.length - 1]; window.tumbleViewer.show(arguments[0]).then(() => done());",
            frame)

    def trace(self, name: str) -> np.ndarray:
        """The drawn points (P, 3) of the main plot's trace called ``name`` (None as NaN)."""
        data = self.driver.execute_script(
            "const d = window.tumbleViewer.main.data.find(t => t.name === arguments[0]);"
            "return [Array.from(d.x), Array.from(d.y), Array.from(d.z)];", name)
        return np.array(data, dtype=np.float64).T

    def solid(self, name: str) -> np.ndarray:
        """The vertices (V, 3) of solid ``name`` in its own axes, as the scene gives them to the page."""
        return np.array(next(s for s in self.scene["solids"] if s["name"] == name)["vertices"])

    def clock(self) -> str:
        return self.driver.execute_script("return document.getElementById('tumble-clock').textContent")


def _fit_rotation(own: np.ndarray, drawn: np.ndarray) -> np.ndarray:
    """The matrix R with drawn = own Rᵀ (least squares; exact when the page drew R v + 0)."""
    solution, *_ = np.linalg.lstsq(own, drawn, rcond=None)
    return solution.T


def _pixels(png: bytes) -> np.ndarray:
    from matplotlib.image import imread

    return imread(io.BytesIO(png), format="png")[..., :3]


def _scene_pixels(page: Page, name: str) -> np.ndarray:
    """Where the 3-D canvas shows the scene: the pixels that change when its traces are hidden (axes, grid and
    labels stay); the whole page is saved as ``name`` in TUMBLE_SCREENSHOT_DIR when that is set."""
    element = page.driver.find_element("id", "tumble-3d")
    folder = os.environ.get("TUMBLE_SCREENSHOT_DIR")
    if folder:
        Path(folder, name).write_bytes(base64.b64decode(page.driver.get_screenshot_as_base64()))
    shown = _pixels(element.screenshot_as_png)
    page.driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "Plotly.restyle(window.tumbleViewer.main, {visible: false}).then(() => done());")
    hidden = _pixels(element.screenshot_as_png)
    page.driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "Plotly.restyle(window.tumbleViewer.main, {visible: true}).then(() => done());")
    return shown, np.any(np.abs(shown - hidden) > 0.1, axis=-1)


def _check_page(page: Page, screenshot: str) -> None:
    """No console error, no request but the page itself, a canvas that is not blank, Play advances time."""
    errors = [e for e in page.driver.get_log("browser") if e["level"] == "SEVERE"]
    assert errors == []
    outside = [url for url in page.requests() if url != page.url and not url.startswith("data:")]
    assert outside == []
    resources = page.driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    assert [url for url in resources if not url.startswith("data:")] == []
    page.show(FRAMES // 3)
    rgb, drawn = _scene_pixels(page, screenshot)
    # not blank: the scene's traces cover part of the canvas (measured 0.90 % for the thin robot arm, 2.7 % for
    # the T-handle, 6.4 % for the spacecraft) in shades of their colours (measured 136 to 596: lit faces,
    # antialiased lines); a blank canvas changes nowhere
    assert drawn.mean() > 0.004, f"only {drawn.mean():.2%} of the canvas shows the scene"
    assert len(np.unique((rgb[drawn] * 255).astype(np.uint8), axis=0)) > 20
    before = page.driver.execute_script("return window.tumbleViewer.state.frame")
    page.driver.find_element("id", "tumble-play").click()
    deadline = time.monotonic() + 10.0
    while page.driver.execute_script("return window.tumbleViewer.state.frame") <= before:
        assert time.monotonic() < deadline, "Play did not advance the frame in 10 s"
        time.sleep(0.05)
    frame, clock = page.driver.execute_script(
        "return [window.tumbleViewer.state.frame, document.getElementById('tumble-clock').textContent];")
    assert float(clock.split()[2]) == pytest.approx(page.scene["t"][frame], rel=1e-5)   # the time shown, 6 digits
    assert page.scene["t"][frame] > page.scene["t"][before]
    page.driver.execute_script("window.tumbleViewer.pause()")   # (a click could come after the run ended by itself)


def _sample(traj, page: Page, frame: int) -> int:
    """The index of the trajectory sample shown at ``frame``, found by its time (the page gives its time)."""
    k = int(np.searchsorted(traj.t, page.scene["t"][frame]))
    assert traj.t[k] == page.scene["t"][frame]
    return k


def _check_rotations(page: Page, traj, name: str) -> float:
    """At three frames, the rotation the page applied to solid ``name`` (read back from its drawn vertices)
    equals R(q(t)) (scipy's matrix of the quaternion); returns the largest difference."""
    own = page.solid(name)
    worst = 0.0
    for frame in (1, FRAMES // 2 + 3, FRAMES - 1):
        page.show(frame)
        k = _sample(traj, page, frame)
        expected = attitude.to_scipy(traj.q[k]).as_matrix()
        read_back = _fit_rotation(own, page.trace(name))
        applied = np.array(page.driver.execute_script(
            "return window.tumbleViewer.state.applied[arguments[0]].rotation", name))
        worst = max(worst, np.abs(read_back - expected).max(), np.abs(applied - expected).max())
    assert worst < ROTATION_TOLERANCE
    return worst


# The three trajectories and their pages, each built by the test that opens it (under pytest-xdist a worker
# builds only those it runs): short runs on the compiled kernels of the rest of the suite (a RigidBody under rk4,
# a Spacecraft with wheels under rk4, the planar two-link arm under dop853, none with a torque).


def free_page(folder: Path):
    body = tumble.RigidBody.t_handle()
    free = tumble.simulate(body, body.axes @ [0.05, 6.0, 0.05], q0=[0.9, 0.1, -0.3, 0.2],
                           t=np.linspace(0.0, 3.0, 601), method="rk4", dt=1e-3)
    shape = [Cylinder(radius=0.004, length=0.08, axis="x", position=(0.04, 0.0, 0.0)),
             Cylinder(radius=0.004, length=0.08, axis="y", position=(0.08, 0.0, 0.0))]
    free.to_html(folder / "free.html", model=body, shape=shape, frames=FRAMES)
    return free, folder / "free.html"


def spacecraft_page(folder: Path):
    craft = Spacecraft(inertia=np.diag([900.0, 800.0, 600.0]),
                       wheels=[ReactionWheel(axis=a, inertia=0.1) for a in np.eye(3)],
                       controller=MRPFeedback(K=10.0, P=150.0))
    slew = tumble.simulate(craft, [0.01, -0.01, 0.005], q0=[0.9, 0.2, 0.3, -0.2], t=np.linspace(0.0, 60.0, 601),
                           method="rk4", dt=0.05)
    slew.to_html(folder / "spacecraft.html", model=craft, frames=FRAMES)
    return slew, craft, folder / "spacecraft.html"


def robot_page(folder: Path):
    arm = robot.load(ROBOTS / "planar_2link.toml")
    fall = tumble.simulate(arm, t=np.linspace(0.0, 2.0, 401), q0=[0.3, -0.5], qd0=[0.1, 0.2],
                           rtol=1e-12, atol=1e-12)
    fall.to_html(folder / "robot.html", model=arm, frames=FRAMES)
    return fall, arm, folder / "robot.html"


def test_free_rigid_body_page(browser, tmp_path):
    traj, path = free_page(tmp_path)
    page = Page(browser, path)
    assert len(page.scene["t"]) == FRAMES and page.scene["polhode"] is not None
    _check_page(page, "viewer.png")
    worst = _check_rotations(page, traj, "body")
    print(f"free rigid body: largest rotation read-back error {worst:.2e}")
    # the angular momentum arrow stands still in space (no torque): its drawn tip at the three frames
    tips = []
    for frame in (1, FRAMES // 2, FRAMES - 1):
        page.show(frame)
        tips.append(page.trace("L (angular momentum)")[1])
    # L_I is kept by rk4 to ~1e-12 relative (tests/test_models.py); the arrow is drawn ~0.1 m long
    np.testing.assert_allclose(tips, [tips[0]] * 3, atol=1e-9)


def test_spacecraft_with_wheels_page(browser, tmp_path):
    traj, craft, path = spacecraft_page(tmp_path)
    page = Page(browser, path)
    _check_page(page, "viewer_spacecraft.png")
    worst = _check_rotations(page, traj, "hub")
    print(f"spacecraft: largest rotation read-back error {worst:.2e}")
    # each wheel is drawn on its axis: the disk's own z axis is R(q) a at every frame checked
    for frame in (1, FRAMES - 1):
        page.show(frame)
        k = _sample(traj, page, frame)
        R = attitude.to_scipy(traj.q[k]).as_matrix()
        for i, wheel in enumerate(craft.wheels):
            applied = np.array(page.driver.execute_script(
                "return window.tumbleViewer.state.applied[arguments[0]].rotation", f"wheel {i + 1}"))
            np.testing.assert_allclose(applied[:, 2], R @ wheel.axis, atol=ROTATION_TOLERANCE)


def test_robot_arm_page(browser, tmp_path):
    traj, arm, path = robot_page(tmp_path)
    page = Page(browser, path)
    _check_page(page, "viewer_robot.png")
    worst = 0.0
    for frame in (1, FRAMES // 2 + 3, FRAMES - 1):
        page.show(frame)
        q1, q2 = traj.joint_position[_sample(traj, page, frame)]
        drawn = page.trace("links")
        # the planar two-link arm (standard DH, a = 1 m, α = d = 0): base, elbow, hand in closed form
        closed_form = np.array([[0.0, 0.0, 0.0], [np.cos(q1), np.sin(q1), 0.0],
                                [np.cos(q1) + np.cos(q1 + q2), np.sin(q1) + np.sin(q1 + q2), 0.0]])
        chain = robot.link_poses(arm, [q1, q2])[:, :3, 3]
        np.testing.assert_allclose(drawn[1:], chain, atol=POSITION_TOLERANCE)
        worst = max(worst, np.abs(drawn - closed_form).max())
    assert worst < POSITION_TOLERANCE
    print(f"robot arm: largest joint position error {worst:.2e} m")
