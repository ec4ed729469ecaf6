"""The native FMUs as FMI 3.0 co-simulation FMUs: built/native/fmi3/<Name>.fmu for AttitudeEstimator,
ImuSensor and MotionProfile (systems.fmi.native), which build_fmus copies into DIR/native/fmi3.

Each has the same model file and C core as its FMI 2.0 FMU, on the FMI 3.0 entry points of fmu_src/fmi3
(which run the plumbing's instances, values and FMU states of fmu_src/fmi2), built against the
fmi3 headers fmpy installs. Its modelDescription.xml is written from the same table of FMU
variables (systems.fmi.interface.model_description.model_description3): Real as Float64, Integer as Int32,
Enumerations as FMI 3.0 Enumerations (set and got as Int64), Boolean as itself, with the same names, value references, causalities, units
and start values, and `time`, FMI 3.0's independent variable, after them. The instantiation
token is a digest of everything the FMU is built from (is_current).
"""
from __future__ import annotations

import sys
from pathlib import Path

import fmpy

from attitude_fmu.systems.fmi import native

FMI3_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")  # what build_fmus copies into DIR/native/fmi3
FOLDER = "native/fmi3"  # under native.BUILT


def binary_path(name: str) -> str:
    """Where the FMU's binary for this platform lies in it (FMI 3.0: binaries/<platform tuple>/<identifier>)."""
    return f"binaries/{fmpy.platform_tuple}/{name}{fmpy.sharedLibraryExtension}"


def copy_fmi3_fmus(out, names=FMI3_NAMES, log=lambda m: print(m, file=sys.stderr)) -> list[Path]:
    """The named FMI 3.0 FMUs copied into the folder out; none where they are not built (log says why)."""
    return native.copy_fmus(out, names, FOLDER, log)


def is_current(fmu) -> bool:
    """Whether the FMI 3.0 FMU at path fmu is the one built from this package's sources (its token is theirs)."""
    return native.is_current(fmu, FOLDER)
