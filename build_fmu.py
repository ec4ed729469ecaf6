"""Build the project's FMUs: python build_fmu.py [--out DIR] [--platforms PLATFORMS] (default dist/,
host): the pythonfmu FMUs into DIR, the native ones (in C, no Python) into DIR/native, their FMI 3.0
versions into DIR/native/fmi3. With --platforms all (or a comma-separated list of FMI 3.0 platform
tuples, e.g. x86_64-windows,aarch64-linux) the native FMUs also hold the binaries of those platforms,
cross-compiled by CMake with zig's compiler (pip install ziglang; systems.fmi.platforms).

Run from a clone, it first builds the clone with CMake (CMakeLists.txt, in the folder build/,
with this Python, which needs fmpy and nanobind) and installs what is built into the clone's
folder, the package attitude_fmu: the extension module and built/ (systems.fmi.native).
Installed, it is attitude_fmu.build_fmu (python -m attitude_fmu.build_fmu), and the package's
build made those already.
"""
from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent


def _package():
    """attitude_fmu: the package this file belongs to, or, run as a script, this clone's folder under that name."""
    if __package__:
        return sys.modules[__package__]
    spec = importlib.util.spec_from_file_location("attitude_fmu", ROOT / "__init__.py",
                                                  submodule_search_locations=[str(ROOT)])
    package = importlib.util.module_from_spec(spec)
    sys.modules["attitude_fmu"] = package
    spec.loader.exec_module(package)
    return package


def _tool(name: str) -> str | None:
    """A build tool's command: on PATH, else beside this Python (where pip installs cmake and ninja in a
    virtual environment)."""
    beside = Path(sys.executable).with_name(name)
    return shutil.which(name) or (str(beside) if beside.is_file() else None)


def cmake_build(build_dir, targets=(), options=(), source=ROOT, quiet: bool = False) -> Path:
    """CMake's build of the clone at source in build_dir: configured first where it is not yet (with
    this Python, Ninja where there is one, the -D options), then the targets built (every one
    without). Raises subprocess.CalledProcessError (quiet: CMake's and the compiler's output kept
    for its output instead of shown); returns build_dir. A configuration that fails is not kept (nor
    one an earlier failure left half done): the next run configures afresh."""
    cmake, build_dir = _tool("cmake"), Path(build_dir)
    if cmake is None:
        raise FileNotFoundError("building a clone needs CMake: pip install cmake ninja")
    output = {"capture_output": True, "text": True} if quiet else {}
    if not _configured(build_dir):
        ninja = _tool("ninja")
        generator = ["-G", "Ninja", f"-DCMAKE_MAKE_PROGRAM={ninja}"] if ninja else []
        (build_dir / "CMakeCache.txt").unlink(missing_ok=True)
        try:
            subprocess.run([cmake, "-S", str(source), "-B", str(build_dir), *generator,
                            f"-DPython_EXECUTABLE={sys.executable}", *(f"-D{o}" for o in options)], check=True,
                           **output)
        except BaseException:  # a failure or a signal: no half-configured folder for the next run to trip on
            (build_dir / "CMakeCache.txt").unlink(missing_ok=True)
            raise
    subprocess.run([cmake, "--build", str(build_dir), *(a for t in targets for a in ("--target", t))], check=True,
                   **output)
    return build_dir


def _configured(build_dir: Path) -> bool:
    """Whether CMake's configuration of build_dir completed: its cache and its generator's build file."""
    return (build_dir / "CMakeCache.txt").is_file() and any(
        (build_dir / name).is_file() for name in ("build.ninja", "Makefile"))


def project_version() -> str:
    """The project's version: pyproject.toml's in a clone, else the installed distribution's."""
    pyproject = ROOT / "pyproject.toml"
    if pyproject.is_file():
        return re.search(r'^version = "([^"]+)"', pyproject.read_text(encoding="utf-8"), re.MULTILINE).group(1)
    return importlib.metadata.version("attitude-fmu")


def build_clone(build_dir=ROOT / "build") -> None:
    """The clone built by CMake in build_dir, and what the build installs (the extension module,
    built/) put into the clone's folder, each file replaced whole (systems.recordings.output.copy_file):
    a process may have the old one loaded."""
    from attitude_fmu.systems.recordings.output import copy_file

    missing = [name for name in ("nanobind", "fmpy") if importlib.util.find_spec(name) is None]
    if missing:
        raise RuntimeError(f"building the clone needs {' and '.join(missing)} in this Python ({sys.executable}): "
                           f"pip install {' '.join(missing)}; or let the installed package build them: python -m "
                           "attitude_fmu.build_fmu")
    staged = Path(cmake_build(build_dir)) / "install"
    shutil.rmtree(staged, ignore_errors=True)
    subprocess.run([_tool("cmake"), "--install", str(build_dir), "--prefix", str(staged)], check=True)
    for path in sorted(p for p in staged.rglob("*") if p.is_file()):
        target = ROOT / path.relative_to(staged)
        target.parent.mkdir(parents=True, exist_ok=True)
        copy_file(path, target)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Build AttitudeEstimator.fmu, ImuSensor.fmu and MotionProfile.fmu "
                                                 "(pythonfmu), the same in C (native/) and as FMI 3.0 (native/fmi3/).")
    parser.add_argument("--out", type=Path, default=Path("dist"), help="output directory (default dist/)")
    parser.add_argument("--platforms", default="host",
                        help="the native FMUs' platforms besides this one: host (none, the default), all "
                             "(x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin; Linux "
                             "binaries for glibc 2.17) or a comma-separated list of those")
    args = parser.parse_args(argv)
    package = _package()
    from attitude_fmu.systems.fmi.platforms import parse_platforms
    from attitude_fmu.systems.recordings.output import interrupting

    try:
        platforms = parse_platforms(args.platforms)
    except ValueError as exc:
        parser.error(str(exc))
    try:
        with interrupting():  # SIGTERM, SIGHUP, SIGINT: temporary folders and files removed, outputs as they were
            if not __package__ and (ROOT / "CMakeLists.txt").is_file():  # a clone
                build_clone()
            for path in package.build_fmus(args.out, platforms=platforms):
                print(path)
    except subprocess.CalledProcessError as exc:
        print(f"build_fmu: error: {Path(exc.cmd[0]).name} failed (exit {exc.returncode}); its output above says why",
              file=sys.stderr)
        return 2
    except (ValueError, OSError, RuntimeError) as exc:
        print(f"build_fmu: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"build_fmu: interrupted by {signal.Signals(signum).name}; no output was left half-written",
              file=sys.stderr)
        return 128 + signum
    return 0


if __name__ == "__main__":
    sys.exit(main())
