"""The C core (fmu_src/native/core) compiled into a shared library, for tests that hold each
C stage to its Python twin through ctypes."""
import ctypes
import os
import shlex
import subprocess
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORE = ROOT / "fmu_src" / "native" / "core"
FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-fPIC", "-shared")


def compiler() -> list[str]:
    """The C compiler: $CC, else Python's, else cc."""
    return shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")


def core_library(folder: Path, sources=None, include=()) -> ctypes.CDLL:
    """Every .c file under fmu_src/native/core (or the given ones) compiled into folder/core.so
    and loaded; the generated tables (af_params.h, systems.fmi.native_tables) are written into
    folder first; include: more header folders."""
    from attitude_fmu.systems.fmi.native_tables import write_headers

    sources = sorted(CORE.rglob("*.c")) if sources is None else list(sources)
    out = Path(folder) / "core.so"
    write_headers(folder)
    command = [*compiler(), *FLAGS, f"-I{CORE}", f"-I{folder}", *(f"-I{d}" for d in include), "-o", str(out),
               *map(str, sources), "-lm"]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return ctypes.CDLL(str(out))


def doubles(values) -> ctypes.Array:
    """A ctypes double array holding values (a sequence or a flat numpy array)."""
    values = [float(v) for v in values]
    return (ctypes.c_double * len(values))(*values)
