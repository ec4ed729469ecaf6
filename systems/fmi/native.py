"""The native FMUs (FMI 2.0 co-simulation in C, with no Python in them) and the other C
artefacts the package runs, as the build made them (CMakeLists.txt) and installed them under
the package's folder, in BUILT:

    built/native/AttitudeEstimator.fmu      the estimator's C core on the FMI plumbing of fmu_src/fmi2
    built/native/ImuSensor.fmu              the sensor model and the motions, in C from the simulation's
    built/native/MotionProfile.fmu          core (systems/simulation/core), the same interfaces as the pythonfmu ones
    built/native/NoOpEstimator.fmu          AttitudeEstimator's interface, nothing behind it: the benchmark's baseline
    built/native/fmi3/<Name>.fmu            the estimator, the sensor and the motion as FMI 3.0 (systems.fmi.fmi3)
    built/fmi2_guard.so                     the pythonfmu FMUs' binary (systems.fmi.build)
    built/stepping.so                       the co-simulation master's stepping loop (systems.fmi.stepping)
    built/fmi_bench                         the C host of `attitude bench --fmu` (systems.evaluation.bench)

Each FMU carries its sources (sources/, generated headers and buildDescription.xml included),
so that an importer on another platform builds it (`fmpy compile`); its modelDescription.xml
and variables header are written from the table of FMU variables (systems/fmi/interface/variables.py) by
systems/fmi/interface/generate.py, so it and the pythonfmu FMU of the same interface can take each other's
place. Its guid is a digest of everything it is built from: an FMU built from other sources
is told apart (is_current). `pip install` builds and installs them all; in a clone,
`python build_fmu.py` (or `cmake --install BUILD_FOLDER --prefix .`) puts them into it.
"""
from __future__ import annotations

import sys
from pathlib import Path

import fmpy

import attitude_fmu

BUILT = Path(attitude_fmu.__file__).resolve().parent / "built"
NATIVE_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")  # what build_fmus copies into DIR/native


class NotBuilt(FileNotFoundError):
    """A C artefact the build makes is not in the package's folder; the message says how to make it."""


def built(relative: str) -> Path:
    """The artefact at relative under BUILT (e.g. "stepping.so"); NotBuilt where it is missing."""
    path = BUILT / relative
    if not path.exists():
        raise NotBuilt(f"{path} is not built: the package's build makes it (pip install .); "
                       "in a clone: python build_fmu.py")
    return path


def binary_path(name: str) -> str:
    """Where the FMU's binary for this platform lies in it (FMI 2.0: binaries/<platform>/<model identifier>)."""
    return f"binaries/{fmpy.platform}/{name}{fmpy.sharedLibraryExtension}"


def identity(fmu) -> str | None:
    """The guid of the FMU at path fmu (FMI 3.0: its instantiation token); None where it has none
    (missing, not a zip, no model description)."""
    try:
        md = fmpy.read_model_description(str(fmu), validate=False)
    except Exception:
        return None
    return md.instantiationToken if md.fmiVersion == "3.0" else md.guid


def is_current(fmu, folder: str = "native") -> bool:
    """Whether the FMU at path fmu is the one built from this package's sources: its guid is that
    of built/<folder>/<its name>.fmu."""
    try:
        own = built(f"{folder}/{Path(fmu).stem}.fmu")
    except NotBuilt:
        return False
    return identity(fmu) is not None and identity(fmu) == identity(own)


def copy_fmus(out, names, folder: str = "native", log=lambda m: print(m, file=sys.stderr)) -> list[Path]:
    """The named FMUs of built/<folder> copied into the folder out; returns their paths. Where
    they are not built none is copied and log says why (the pythonfmu FMUs do not need them)."""
    if not names:
        return []
    try:
        sources = [built(f"{folder}/{name}.fmu") for name in names]
    except NotBuilt as exc:
        log(f"warning: the native FMUs ({', '.join(f'{n}.fmu' for n in names)}: in C, no Python) are not copied "
            f"into {out}: {exc}")
        return []
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    from attitude_fmu.systems.recordings.output import copy_file

    return [copy_file(source, out / source.name) for source in sources]
