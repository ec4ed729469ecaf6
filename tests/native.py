"""The CMake targets the tests need (CMakeLists.txt), built into folders of their own, and
tests run again on the sanitized build.

    build(["fmi_runner", "fmus"], sanitize=True)    → the folder, built (ROOT/build/tests-sanitized)

build configures a folder once (this Python, AF_WERROR and AF_TESTS on, AF_SANITIZE as asked:
the address and undefined-behaviour sanitizers on every C and C++ target, -fno-sanitize-recover=all)
and builds the targets asked for into it; later calls build more targets into the same folder.
What each target gives, under the folder:

    _core            _core.<abi>.so: the extension module attitude_fmu._core (use_core loads it)
    fmus             built/native/{AttitudeEstimator,ImuSensor,MotionProfile,NoOpEstimator}.fmu,
                     built/native/fmi3/AttitudeEstimator.fmu (tests.golden.fmu_cases(folder / "built"))
    fmi2_guard       built/fmi2_guard.so: the pythonfmu FMUs' binary
    stepping         built/stepping.so: the co-simulation master's loop
    fmi_bench        built/fmi_bench: the C host of `attitude bench --fmu`
    fmi_host         tests/fmi_host: a minimal FMI 2.0 importer with no Python (tests/fmi_host.c)
    fmi_runner       tests/fmi_runner: a scripted one (tests/fmi_runner.c)
    crash_at_exit    tests/crash_at_exit.so: a library that aborts the process that loaded it at its exit

A sanitized executable (fmi_host, fmi_runner) runs as it is; a process that loads a sanitized
library (an FMU's binary, the guard, the extension module) must preload the sanitizer's runtime
first: preload(folder) names it, sanitized_pytest does it for a whole test file.
"""
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SANITIZE = "ATTITUDE_SANITIZED_BUILD"  # set in the sanitized run (sanitized_pytest): the sanitized build's folder


def folder_for(sanitize: bool) -> Path:
    """The tests' build folder, with or without the sanitizers (under the clone's build/)."""
    return ROOT / "build" / ("tests-sanitized" if sanitize else "tests")


def build(targets, folder=None, sanitize: bool = False) -> Path:
    """The targets built into folder (default folder_for(sanitize)), configured for the tests;
    returns the folder. Raises subprocess.CalledProcessError where CMake or the compiler fails."""
    from attitude_fmu.build_fmu import cmake_build

    options = ("AF_WERROR=ON", "AF_TESTS=ON", f"AF_SANITIZE={'ON' if sanitize else 'OFF'}")
    return cmake_build(folder or folder_for(sanitize), list(targets), options, source=ROOT)


def preload(folder) -> list[str]:
    """The runtimes a process must preload to load the sanitized libraries of folder (the address
    sanitizer's, then the C++ library, for the extension module's exceptions); [] where the
    compiler names none (or folder is not a sanitized build)."""
    path = Path(folder) / "sanitizer_preload.txt"
    lines = path.read_text().split() if path.is_file() else []
    return lines if lines and "asan" in Path(lines[0]).name else []


def sanitized_build() -> Path | None:
    """In the sanitized run (sanitized_pytest): the sanitized build's folder; else None."""
    folder = os.environ.get(SANITIZE)
    return Path(folder) if folder else None


def use_core(folder) -> None:
    """attitude_fmu._core, in this process, the extension module built in folder."""
    import attitude_fmu

    path = next(Path(folder).glob("_core*.so"))
    spec = importlib.util.spec_from_file_location("attitude_fmu._core", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["attitude_fmu._core"] = module
    spec.loader.exec_module(module)
    attitude_fmu._core = module


def sanitized_pytest(test_file, *args, targets=("_core", "fmus"), timeout: float = 600
                     ) -> subprocess.CompletedProcess | None:
    """pytest on test_file (args: more of its options, e.g. -k) in a fresh interpreter on the
    sanitized build of targets: attitude_fmu._core is that build's (use_core), the sanitizer's
    runtime is preloaded, $ATTITUDE_SANITIZED_BUILD names the folder (sanitized_build: the
    tests take the sanitized FMUs from its built/), and any report fails the run. None where
    the compiler names no sanitizer runtime."""
    folder = build(targets, sanitize=True)
    runtimes = preload(folder)
    if not runtimes:
        return None
    env = {**os.environ, SANITIZE: str(folder), "LD_PRELOAD": " ".join(runtimes),
           "ASAN_OPTIONS": "detect_leaks=0", "UBSAN_OPTIONS": "print_stacktrace=1"}
    # --capture=sys: a sanitizer writes to file descriptor 2, which pytest would otherwise swallow
    command = [sys.executable, "-m", "tests.native", str(folder), "-q", "--capture=sys", "-p", "no:cacheprovider",
               str(test_file), *args]
    return subprocess.run(command, check=False, cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)


if __name__ == "__main__":  # python -m tests.native FOLDER PYTEST_ARGS...: pytest on FOLDER's attitude_fmu._core
    import pytest

    use_core(sys.argv[1])
    sys.exit(pytest.main(sys.argv[2:]))
