"""Builds the Python package with the project's CMake build, then installs
build/python/sandbox/ (the extension, lcm-gen's Python types, python/sandbox/).
An existing build folder (build/, or $SANDBOX_BUILD_DIR) is reused; without
one it is configured as scripts/setup does (which also installs the Debian
packages the build needs)."""
import os
import pathlib
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_ext import build_ext
from setuptools.dist import Distribution

ROOT = pathlib.Path(__file__).resolve().parent


class BuildWithCMake(build_ext):
    def run(self):
        build = pathlib.Path(os.environ.get("SANDBOX_BUILD_DIR", ROOT / "build"))
        if not (build / "CMakeCache.txt").exists():
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build)], check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "sandbox_python", "-j",
                        str(os.cpu_count() or 1)], check=True)
        package = build / "python" / "sandbox"
        if not any(package.glob("_sandbox*.so")):
            raise SystemExit(f"setup.py: {package} has no _sandbox extension after the build")
        shutil.copytree(package, pathlib.Path(self.build_lib) / "sandbox", dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("__pycache__"))


class BinaryDistribution(Distribution):
    def has_ext_modules(self):  # build_ext runs, and the wheel is a platform wheel
        return True


setup(packages=[], cmdclass={"build_ext": BuildWithCMake}, distclass=BinaryDistribution)
