"""setuptools' build (pyproject.toml holds the project) with one step more: the kernels of the
command line's first run compiled ahead into the wheel's kernel_cache/
(systems/cli/first_run.py), which blocks.jit hands to the per-user cache on first use."""
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithKernels(build_py):
    """build_py (without this file, which sits in the package's folder), then the kernels
    compiled from the built package's own files."""

    def find_package_modules(self, package, package_dir):
        return [m for m in super().find_package_modules(package, package_dir)
                if not (package == "attitude_fmu" and m[1] == "setup")]

    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):  # an editable install compiles where it runs
            return
        package = Path(self.build_lib) / "attitude_fmu"
        with tempfile.TemporaryDirectory(prefix="attitude_fmu_kernels_") as cache:
            path = os.pathsep.join(filter(None, [self.build_lib, os.environ.get("PYTHONPATH")]))  # the build env's too
            env = {**os.environ, "PYTHONPATH": path}
            env.pop("NUMBA_CACHE_DIR", None)
            run = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.first_run", cache], env=env,
                                 capture_output=True, text=True)
            if run.returncode:
                reason = (run.stderr.strip().splitlines() or ["no message"])[-1]
                print(f"warning: kernels not compiled ahead ({reason}); the first run compiles them", file=sys.stderr)
                return
            shutil.copytree(cache, package / "kernel_cache", dirs_exist_ok=True)


setup(cmdclass={"build_py": BuildWithKernels})
