"""The co-simulation master's stepping loop in C (systems/fmi/stepping.c), as the package's
build made it (built/stepping.so, systems.fmi.native), for systems.fmi.cosim: with native FMUs
a step then costs what the FMUs compute rather than a Python loop of FMI calls through fmpy
(verify's human × wiener, 120 s at 50 Hz on the native chain: 0.09 s of CPU against 0.5 s,
setup included)."""
from __future__ import annotations

import ctypes
from functools import cache

import numpy as np

from attitude_fmu.systems.fmi.native import NotBuilt, built

_VR = ctypes.c_uint
_FUNCTIONS = ("fmi2DoStep", "fmi2SetReal", "fmi2GetReal", "fmi2GetBoolean")


class SteppedComponent(ctypes.Structure):
    """stepping.c's SteppedComponent."""

    _fields_ = [("instance", ctypes.c_void_p), *((name, ctypes.c_void_p) for name in _FUNCTIONS),
                ("n_inputs", ctypes.c_size_t), ("input_vr", ctypes.POINTER(_VR)),
                ("input_from", ctypes.POINTER(ctypes.c_size_t)),
                ("n_reals", ctypes.c_size_t), ("real_vr", ctypes.POINTER(_VR)), ("real_at", ctypes.c_size_t),
                ("n_booleans", ctypes.c_size_t), ("boolean_vr", ctypes.POINTER(_VR)), ("boolean_at", ctypes.c_size_t)]


@cache
def library():
    """The loop's library loaded, kept for the process; None where the package's build did not make it."""
    try:
        lib = ctypes.CDLL(str(built("stepping.so")))
    except NotBuilt:
        return None
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
