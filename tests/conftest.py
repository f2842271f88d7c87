"""Shared fixtures of the dynamics, torque and simulation tests."""

import os

import numpy as np
import pytest

# The one-line notice of a compile that holds a run up (tumble._compiling) is tested in tests/test_compiling.py,
# which removes this; elsewhere the tests read the exact output of commands, which a cold cache must not change.
os.environ.setdefault("TUMBLE_QUIET", "1")


#: Test folders whose modules compile the same model kind: the spacecraft's assembled
#: right-hand side and sample are compiled into each spacecraft driver and not kept on disk apart from them
#: (docs/architecture.md, "The test suite and what it compiles"), so each process that compiles a spacecraft
#: driver compiles them again (~50 CPU s); the robot's kernels are shared by its modules.
KINDS = ("tests/spacecraft/", "tests/robot/")

#: Tests outside those folders that compile a kind's code, by the start of their node id -> the kind's folder:
#: the spacecraft's rows of the model × method matrix, and the GPU path's tests, whose CPU runs compile the
#: spacecraft's right-hand side on a state vector as the spacecraft's tests do (~40 CPU s each time, with its
#: sample and start sample); a whole module joins, so that its module fixtures run once.
JOINS = {"tests/test_models.py::test_every_model_under_every_method[Spacecraft-": "tests/spacecraft/",
         "tests/integrate/test_cuda_models.py": "tests/spacecraft/"}


def pytest_xdist_make_scheduler(config, log):
    """Under ``--dist loadfile`` (pyproject.toml): each module runs on one worker, and so do all the modules of
    a kind of :data:`KINDS` and the tests of :data:`JOINS`, so that the two workers do not compile the same code,
    each for itself."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class KindScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid):
            joined = next((kind for start, kind in JOINS.items() if nodeid.startswith(start)), None)
            if joined:
                return joined
            module = super()._split_scope(nodeid)
            return next((kind for kind in KINDS if module.startswith(kind)), module)

    return KindScheduling(config, log)


def pytest_configure(config):
    """``TUMBLE_COMPILE_PROFILE=DIR`` logs each test's CPU time and Numba compilations (tests/compile_profile.py)."""
    if os.environ.get("TUMBLE_COMPILE_PROFILE"):
        from compile_profile import CompileProfile

        config.pluginmanager.register(CompileProfile(os.environ["TUMBLE_COMPILE_PROFILE"]), "compile_profile")


@pytest.fixture
def random_rotation():
    """``random_rotation(seed)``: a proper rotation matrix drawn from the QR of a Gaussian matrix."""

    def make(seed):
        q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
        q = q * np.sign(np.diag(r))
        return q if np.linalg.det(q) > 0.0 else -q

    return make


@pytest.fixture
def random_batch():
    """``random_batch(n, seed=5)``: n bodies — inertia (n, 3, 3) with moments in [1, 1.9]
    (the triangle inequality holds), ω0 (n, 3), unit q0 (n, 4)."""

    def make(n, seed=5):
        rng = np.random.default_rng(seed)
        inertia = []
        for _ in range(n):
            r, _ = np.linalg.qr(rng.standard_normal((3, 3)))
            inertia.append(r @ np.diag(rng.uniform(1.0, 1.9, 3)) @ r.T)
        q0 = rng.standard_normal((n, 4))
        return np.array(inertia), rng.standard_normal((n, 3)), q0 / np.linalg.norm(q0, axis=-1, keepdims=True)

    return make
