"""posefuse.__version__ is the project's one version, CMake's project(VERSION)."""
import pathlib
import re

import posefuse as pf

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_version_is_the_cmake_project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*posefuse\b[^)]*?\bVERSION\s+([0-9.]+)", text)
    assert m, "CMakeLists.txt has no project(posefuse VERSION ...)"
    assert pf.__version__ == m.group(1)
    assert pf._posefuse.__version__ == pf.__version__


def test_stubs_are_for_modules_that_exist():
    import importlib

    package = pathlib.Path(pf.__file__).resolve().parent
    stubs = sorted(p.stem for p in package.glob("*.pyi"))
    assert stubs, "no type stubs beside the package"
    for stem in stubs:
        name = "posefuse" if stem == "__init__" else "posefuse." + stem
        importlib.import_module(name)  # raises ModuleNotFoundError for a stub of nothing
