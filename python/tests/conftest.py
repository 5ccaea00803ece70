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
from drives import kitti_like, rotation  # noqa: F401  (the tests import them from here)

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


