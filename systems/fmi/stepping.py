"""The co-simulation master's stepping loop in C (systems/fmi/stepping.c), compiled with the
system's C compiler once per user and source (kept in the per-user cache, blocks.jit.user_cache),
for systems.fmi.cosim: with native FMUs a step then costs what the FMUs compute rather than a
Python loop of FMI calls through fmpy (verify's human × wiener, 120 s at 50 Hz on the native
chain: 0.09 s of CPU against 0.5 s, setup included)."""
from __future__ import annotations

import atexit
import ctypes
import hashlib
import os
import shutil
import subprocess
import sysconfig
import tempfile
from functools import cache
from pathlib import Path

import numpy as np

from attitude_fmu.blocks.jit import user_cache
from attitude_fmu.systems.fmi.native import FMI_HEADERS, compiler

SOURCE = Path(__file__).with_name("stepping.c")
_VR = ctypes.c_uint
_FUNCTIONS = ("fmi2DoStep", "fmi2SetReal", "fmi2GetReal", "fmi2GetBoolean")


class SteppedComponent(ctypes.Structure):
    """stepping.c's SteppedComponent."""

    _fields_ = [("instance", ctypes.c_void_p), *((name, ctypes.c_void_p) for name in _FUNCTIONS),
                ("n_inputs", ctypes.c_size_t), ("input_vr", ctypes.POINTER(_VR)),
                ("input_from", ctypes.POINTER(ctypes.c_size_t)),
                ("n_reals", ctypes.c_size_t), ("real_vr", ctypes.POINTER(_VR)), ("real_at", ctypes.c_size_t),
                ("n_booleans", ctypes.c_size_t), ("boolean_vr", ctypes.POINTER(_VR)), ("boolean_at", ctypes.c_size_t)]


def _command() -> list[str]:
    return [*compiler(), "-std=c99", "-O2", "-fPIC", "-shared", f"-I{FMI_HEADERS}"]


def library_path() -> Path:
    """Where the compiled loop is kept: the per-user cache, under a digest of the platform,
    the compiler's command, the source and the FMI headers it includes (a folder of its own
    where the cache cannot be written, removed at exit)."""
    digest = hashlib.sha256("\0".join([sysconfig.get_platform(), *_command()]).encode() + SOURCE.read_bytes())
    for header in sorted(FMI_HEADERS.glob("fmi2*.h")):
        digest.update(header.read_bytes())
    try:
        folder = user_cache() / "c"
        folder.mkdir(parents=True, exist_ok=True)
        if not os.access(folder, os.W_OK):
            raise PermissionError(folder)
    except (OSError, RuntimeError):
        folder = Path(tempfile.mkdtemp(prefix="attitude_stepping_"))
        atexit.register(shutil.rmtree, folder, True)
    return folder / f"stepping-{digest.hexdigest()[:20]}.so"


@cache
def library():
    """stepping.c compiled (where library_path has none yet) and loaded, kept for the
    process; None without a working C compiler."""
    out = library_path()
    if not out.exists():
        staged = out.with_name(f".{out.name}.{os.getpid()}")  # whole or not at all: other processes may build it too
        try:
            subprocess.run([*_command(), "-o", str(staged), str(SOURCE)], check=True, capture_output=True)
            os.replace(staged, out)
        except (OSError, subprocess.CalledProcessError):
            staged.unlink(missing_ok=True)
            return None
    lib = ctypes.CDLL(str(out))
    lib.stepping_run.restype = ctypes.c_size_t
    lib.stepping_run.argtypes = [ctypes.c_size_t, ctypes.POINTER(SteppedComponent), ctypes.c_double, ctypes.c_double,
                                 ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t,
                                 np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS"),
                                 ctypes.POINTER(ctypes.c_size_t), ctypes.POINTER(ctypes.c_int)]
    return lib


def _array(kind, values):
    return (kind * max(1, len(values)))(*values)


class Stepper:
    """The C loop over components (fmpy FMU2Slave instances, initialised), each with its
    (input value references, the row places of their sources), (Real output references, first
    place) and (Boolean output references, first place); run() fills rows of a record."""

    def __init__(self, lib, components):
        self.lib = lib
        self.keep = []  # the arrays the structures point into
        self.components = (SteppedComponent * len(components))()
        for s, (fmu, inputs, sources, reals, real_at, booleans, boolean_at) in zip(self.components, components):
            arrays = [_array(_VR, inputs), _array(ctypes.c_size_t, sources), _array(_VR, reals), _array(_VR, booleans)]
            self.keep.append(arrays)
            s.instance = fmu.component
            for name in _FUNCTIONS:
                setattr(s, name, ctypes.cast(getattr(fmu.dll, name), ctypes.c_void_p))
            s.n_inputs, s.input_vr, s.input_from = len(inputs), arrays[0], arrays[1]
            s.n_reals, s.real_vr, s.real_at = len(reals), arrays[2], real_at
            s.n_booleans, s.boolean_vr, s.boolean_at = len(booleans), arrays[3], boolean_at

    def run(self, record: np.ndarray, t0: float, h: float, first: int) -> tuple[int, int | None, int]:
        """Steps first … first + len(record) − 1 into record's rows: (steps done, the failed
        component's index or None, its status)."""
        failed, status = ctypes.c_size_t(), ctypes.c_int()
        done = self.lib.stepping_run(len(self.components), self.components, t0, h, first, len(record),
                                     record.shape[1], record, ctypes.byref(failed), ctypes.byref(status))
        return done, (failed.value if done < len(record) else None), status.value
