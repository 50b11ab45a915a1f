"""setuptools backend for `pip install .`: builds tessera._core with the project's CMake.

Metadata lives in pyproject.toml. This file only adds the compiled module: it
configures the whole project with everything but the library and the Python
module switched off, builds the target tessera_python, and lets CMake link the
module straight into the folder setuptools packs (TESSERA_PYTHON_PACKAGE_DIR).
The pure-Python files are copied by setuptools itself. Build files go to
build-pip/ (kept between runs, so a second install only rebuilds what changed),
away from the CMake build folder build/.
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


def cmake_project_version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(tessera\s+VERSION\s+([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    """An extension whose sources CMake knows; setuptools only names it."""

    def __init__(self, name: str, target: str):
        super().__init__(name, sources=[])
        self.target = target


class CMakeBuild(build_ext):
    def build_extension(self, ext: CMakeExtension) -> None:
        package_dir = Path(self.get_ext_fullpath(ext.name)).resolve().parent
        build_dir = Path(self.build_temp).resolve() / "cmake"
        args = [
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DTESSERA_PYTHON_PACKAGE_DIR={package_dir}",
            "-DTESSERA_BUILD_PYTHON=ON",
            "-DTESSERA_BUILD_APPS=OFF",
            "-DTESSERA_BUILD_TESTS=OFF",
            "-DTESSERA_BUILD_BENCH=OFF",
            "-DTESSERA_BUILD_EXAMPLES=OFF",
        ]
        try:  # pybind11 from pip (build isolation) has its CMake files in the package
            import pybind11

            args.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except ImportError:
            pass  # Debian's pybind11-dev is found by CMake on its own
        if shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists():
            args += ["-G", "Ninja"]
        jobs = str(self.parallel or os.cpu_count() or 2)
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), *args], check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", ext.target, "-j", jobs], check=True)


setup(
    version=cmake_project_version(),
    ext_modules=[CMakeExtension("tessera._core", target="tessera_python")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build-pip"}},
)
