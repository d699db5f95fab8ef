"""`pip install .` into a fresh virtual environment (Debian's python3, its
setuptools and numpy through --system-site-packages; offline, so without
build isolation) reusing the project's build folder: the installed package
is imported from the environment, not the build, and scans as the build's does."""
import os
import pathlib
import subprocess
import sys

import sandbox

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("SANDBOX", "build/sandbox")).resolve().parent


def test_pip_install_into_a_fresh_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["SANDBOX_BUILD_DIR"] = str(BUILD)
    result = subprocess.run([str(venv / "bin/pip"), "install", "--no-build-isolation", "--no-index",
                             "--no-cache-dir", str(ROOT)], capture_output=True, text=True, env=env,
                            timeout=1200)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    probe = ("import sandbox; print(sandbox.__file__); "
             "print(repr(sandbox.World().ray((3, 4, 70))['range']))")
    result = subprocess.run([str(venv / "bin/python"), "-c", probe], capture_output=True,
                            text=True, env=env, cwd=tmp_path, check=True)
    location, distance = result.stdout.split()
    assert location.startswith(str(venv)), location
    assert float(distance) == sandbox.World().ray((3, 4, 70))["range"]
