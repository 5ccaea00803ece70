"""Shared fixtures of the posefuse Python tests.

Run by ctest (python/CMakeLists.txt) as
    PYTHONPATH=<build> /usr/bin/python3 -m pytest -q python/tests
or by hand the same way. The C++ program the results are compared with is
$POSEFUSE_EVALUATE_TRAJECTORY, else <build>/examples/evaluate_trajectory;
the real recordings are under $POSEFUSE_DATA_DIR, else the folder CMake was
configured with ($POSEFUSE_DEFAULT_DATA_DIR), else ../shared/data beside the
checkout. Tests that need what is absent are skipped with the reason.
"""
import json
import os
import pathlib
import subprocess

import pytest

import posefuse

REPO = pathlib.Path(__file__).resolve().parents[2]


def _data_dir():
    for key in ("POSEFUSE_DATA_DIR", "POSEFUSE_DEFAULT_DATA_DIR"):
        value = os.environ.get(key)
        if value:
            return pathlib.Path(value)
    return REPO.parent / "shared" / "data"


def _program():
    value = os.environ.get("POSEFUSE_EVALUATE_TRAJECTORY")
    if value:
        return pathlib.Path(value)
    return pathlib.Path(posefuse.__file__).resolve().parents[1] / "examples" / "evaluate_trajectory"


@pytest.fixture(scope="session")
def data_dir():
    return _data_dir()


@pytest.fixture(scope="session")
def kitti06(data_dir):
    d = data_dir / "kitti" / "06"
    if not (d / "groundtruth.txt").is_file():
        pytest.skip("KITTI 06 not found under %s (set POSEFUSE_DATA_DIR)" % d)
    return d


@pytest.fixture(scope="session")
def euroc_v101(data_dir):
    d = data_dir / "euroc" / "V1_01_easy"
    if not (d / "groundtruth.tum").is_file():
        pytest.skip("EuRoC V1_01_easy not found under %s (set POSEFUSE_DATA_DIR)" % d)
    return d


class Program:
    """evaluate_trajectory, run with --save-results; returns the JSON text."""

    def __init__(self, path):
        self.path = path

    def run(self, args, tmp_path, expect_ok=True):
        out = tmp_path / ("results-%d.json" % len(list(tmp_path.glob("results-*.json"))))
        proc = subprocess.run([str(self.path)] + [str(a) for a in args] + ["--save-results", str(out)],
                              capture_output=True, text=True)
        if expect_ok:
            assert proc.returncode == 0, proc.stderr
            return out.read_text()
        return proc

    def json(self, args, tmp_path):
        return json.loads(self.run(args, tmp_path))


@pytest.fixture(scope="session")
def program():
    path = _program()
    if not path.is_file():
        pytest.skip("evaluate_trajectory not built at %s (build the examples, or set "
                    "POSEFUSE_EVALUATE_TRAJECTORY)" % path)
    return Program(path)


def rotation(axis_angle):
    """Rotation matrices (N, 3, 3) of rotation vectors (N, 3) (Rodrigues)."""
    import numpy as np

    v = np.atleast_2d(axis_angle)
    theta = np.linalg.norm(v, axis=1)
    k = np.where(theta[:, None] > 0, v / np.where(theta > 0, theta, 1)[:, None], 0.0)
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def kitti_like(n, seed=1, dt=0.1):
    """A KITTI-like drive (camera frame: x right, y down, z forward; road
    plane x-z) of n poses at 10 Hz and a drifting, noisy estimate of it.
    Returns (stamps (n,), gt poses (n, 4, 4), est poses (n, 4, 4))."""
    import numpy as np

    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    speed = 8.0 + 2.0 * np.sin(0.05 * t)                    # m/s
    yaw_rate = 0.08 * np.sin(0.02 * t) + 0.03 * np.sin(0.11 * t)
    yaw = np.cumsum(yaw_rate) * dt
    gt = np.tile(np.eye(4), (n, 1, 1))
    gt[:, :3, :3] = rotation(np.c_[np.zeros(n), yaw, np.zeros(n)])
    forward = gt[:, :3, 2]
    gt[:, :3, 3] = np.cumsum(forward * (speed * dt)[:, None], axis=0)
    gt[:, 1, 3] += 0.3 * np.sin(0.01 * t)                     # gentle height changes
    # Estimate: per-step relative-motion errors accumulate (drift), seen from
    # another world frame (rotated, shifted).
    est = np.empty_like(gt)
    est[0] = gt[0]
    rel = np.linalg.inv(gt[:-1]) @ gt[1:]
    noise = np.tile(np.eye(4), (n - 1, 1, 1))
    noise[:, :3, :3] = rotation(rng.normal(0, 2e-4, (n - 1, 3)))
    noise[:, :3, 3] = rng.normal(0, 0.01, (n - 1, 3))
    steps = rel @ noise
    for k in range(1, n):
        est[k] = est[k - 1] @ steps[k - 1]
    world = np.eye(4)
    world[:3, :3] = rotation(np.array([[0.02, 0.3, -0.01]]))[0]
    world[:3, 3] = [5.0, -1.0, 2.0]
    return t, gt, world @ est
