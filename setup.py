"""Builds posefuse's extension module with the project's own CMake build.

pyproject.toml holds the metadata; this file adds the package layout (the
package is python/posefuse) and what a static table cannot:
the version, read from CMakeLists.txt's project(... VERSION x.y.z ...) (the one
place it is set; CMake also compiles it into the module as __version__), and a
build_ext that configures the repository with CMake for the interpreter running
the build and builds the target _posefuse only.

Environment: CMAKE_BUILD_PARALLEL_LEVEL (jobs), CMAKE_GENERATOR, and
POSEFUSE_CMAKE_ARGS (extra -D options, split on spaces) are honoured.
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*posefuse\b[^)]*?\bVERSION\s+([0-9]+(?:\.[0-9]+)*)", text)
    if not m:
        raise RuntimeError("setup.py: CMakeLists.txt has no project(posefuse VERSION x.y.z)")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        if shutil.which("cmake") is None:
            raise RuntimeError("building posefuse needs CMake >= 3.21 (Debian: apt install cmake)")
        build_dir = Path(self.build_temp).resolve() / "cmake"
        build_dir.mkdir(parents=True, exist_ok=True)
        args = [
            "-S", str(ROOT), "-B", str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython3_EXECUTABLE={sys.executable}",
            "-DPOSEFUSE_BUILD_PYTHON=ON",
            "-DPOSEFUSE_BUILD_TESTS=OFF",
            "-DPOSEFUSE_BUILD_EXAMPLES=OFF",
            "-DPOSEFUSE_BUILD_BENCHMARKS=OFF",
            "-DPOSEFUSE_INSTALL=OFF",
        ]
        if "CMAKE_GENERATOR" not in os.environ and shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists():
            args += ["-G", "Ninja"]
        args += os.environ.get("POSEFUSE_CMAKE_ARGS", "").split()
        subprocess.run(["cmake", *args], check=True)
        build = ["cmake", "--build", str(build_dir), "--target", "_posefuse"]
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL")
        if jobs:
            build += ["--parallel", jobs]
        subprocess.run(build, check=True)
        name = self.get_ext_filename(ext.name).split(os.sep)[-1]
        built = build_dir / "posefuse" / Path(name).name
        if not built.exists():
            found = sorted((build_dir / "posefuse").glob("_posefuse*.so"))
            if not found:
                raise RuntimeError(f"CMake built no posefuse/_posefuse*.so in {build_dir}")
            built = found[0]
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


# Keep setuptools' own build and egg-info folders out of the CMake preset's build/.
BUILD = ROOT / "build-pip"
BUILD.mkdir(exist_ok=True)
setup(
    version=project_version(),
    package_dir={"": "python"},
    packages=["posefuse"],
    package_data={"posefuse": ["py.typed", "*.pyi"]},
    ext_modules=[Extension("posefuse._posefuse", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(BUILD)}, "egg_info": {"egg_base": str(BUILD)}},
)
