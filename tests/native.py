"""The C core (fmu_src/native/core) compiled into a shared library, for tests that hold each
C stage to its Python twin through ctypes."""
import ctypes
import os
import shlex
import subprocess
import sys
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORE = ROOT / "fmu_src" / "native" / "core"
FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-fPIC", "-shared")
SANITIZE = "ATTITUDE_NATIVE_SANITIZE"  # set (sanitized_pytest): core_library builds with SANITIZERS
SANITIZERS = ("-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer")


def compiler() -> list[str]:
    """The C compiler: $CC, else Python's, else cc."""
    return shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")


def core_library(folder: Path, sources=None, include=()) -> ctypes.CDLL:
    """Every .c file under fmu_src/native/core (or the given ones) compiled into folder/core.so
    and loaded; the generated tables (af_params.h, systems.fmi.native_tables) are written into
    folder first; include: more header folders. With $ATTITUDE_NATIVE_SANITIZE set, built with
    the address and undefined-behaviour sanitizers (sanitized_pytest)."""
    from attitude_fmu.systems.fmi.native_tables import write_headers

    sources = sorted(CORE.rglob("*.c")) if sources is None else list(sources)
    out = Path(folder) / "core.so"
    write_headers(folder)
    sanitizers = SANITIZERS if os.environ.get(SANITIZE) else ()
    command = [*compiler(), *FLAGS, *sanitizers, f"-I{CORE}", f"-I{folder}", *(f"-I{d}" for d in include),
               "-o", str(out), *map(str, sources), "-lm"]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return ctypes.CDLL(str(out))


def sanitized_pytest(test_file, *args, timeout: float = 600) -> subprocess.CompletedProcess | None:
    """pytest on test_file (args: more of its options, e.g. -k) in a fresh interpreter whose
    core_library builds with SANITIZERS, the address sanitizer's runtime preloaded (a library
    loaded into Python needs it first; the C++ runtime after it, for the extension modules
    that throw C++ exceptions); any report fails the run. None where the compiler names no
    such runtime."""
    def runtime(name):
        path = subprocess.run([*compiler(), f"-print-file-name={name}"], check=False, capture_output=True,
                              text=True).stdout.strip()
        return path if Path(path).is_absolute() and Path(path).exists() else None

    asan, cxx = runtime("libasan.so"), runtime("libstdc++.so.6")
    if asan is None:
        return None
    env = {**os.environ, SANITIZE: "1", "LD_PRELOAD": " ".join(p for p in (asan, cxx) if p),
           "ASAN_OPTIONS": "detect_leaks=0", "UBSAN_OPTIONS": "print_stacktrace=1"}
    # --capture=sys: a sanitizer writes to file descriptor 2, which pytest would otherwise swallow
    command = [sys.executable, "-m", "pytest", "-q", "--capture=sys", "-p", "no:cacheprovider", str(test_file), *args]
    return subprocess.run(command, check=False, cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)


def doubles(values) -> ctypes.Array:
    """A ctypes double array holding values (a sequence or a flat numpy array)."""
    values = [float(v) for v in values]
    return (ctypes.c_double * len(values))(*values)
