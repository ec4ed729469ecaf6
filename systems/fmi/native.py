"""Building the native FMUs: FMI 2.0 co-simulation in C, with no Python in them.

A native FMU is the FMI plumbing of fmu_src/native/fmi2, a model file of
fmu_src/native/models and, for the estimator, the C core of fmu_src/native/core, compiled
with the system's C compiler ($CC, else Python's, else cc) into binaries/<platform>. It
carries its sources too (sources/, with the generated headers and buildDescription.xml), so
that an importer on another platform compiles it (`fmpy compile`). Its modelDescription.xml
and its variables' C header are written from the table of FMU variables
(fmu_src/variables.py), which the pythonfmu FMU of the same interface registers from: the
two can take each other's place. The guid is a digest of everything the FMU is built
from, so an FMU built from other sources is told apart (is_current).

    DIR/native/AttitudeEstimator.fmu    by python build_fmu.py (systems.fmi.build.build_fmus)
    DIR/native/ImuSensor.fmu            the sensor model and the motions, in C from the simulation's
    DIR/native/MotionProfile.fmu        twins (fmu_src/native/sim), the same interfaces as the pythonfmu ones
    NoOpEstimator.fmu                   AttitudeEstimator's interface, nothing behind it: the benchmark's baseline
"""
from __future__ import annotations

import hashlib
import os
import shlex
import subprocess
import sys
import sysconfig
import tempfile
import uuid
import zipfile
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, tostring

import fmpy

import attitude_fmu
from attitude_fmu.fmu_src.model_description import LOG_CATEGORIES, model_description, model_variables
from attitude_fmu.fmu_src.simulation_variables import imu_sensor, motion_profile
from attitude_fmu.fmu_src.variables import BOOLEAN, INTEGER, OUT, PAR, REAL, STRING, attitude_estimator
from attitude_fmu.systems.fmi import native_tables
from attitude_fmu.systems.fmi.native_tables import c_double, c_string

NATIVE_DIR = Path(attitude_fmu.__file__).resolve().parent / "fmu_src" / "native"
FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"  # the standard's fmi2*.h, as fmpy installs them
FLAGS = ("-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-Wall", "-Wextra")
GUID_NAMESPACE = uuid.UUID("6f0e2a4c-8b1d-4c55-9d3e-2f7a1b9c0d41")  # of the native FMUs' guids


@dataclass(frozen=True)
class NativeModel:
    """A native FMU: its interface (a table of fmu_src.variables), its description, and
    whether its model runs the estimator's C core, or the simulation's twins (fmu_src/native/sim
    with SIMULATION_CORE, the core's files they use)."""

    interface: object
    description: str
    core: bool
    simulation: bool = False


NATIVE_MODELS = {
    "AttitudeEstimator": NativeModel(attitude_estimator, "IMU attitude estimator (Rizun's optimal Wiener filter and "
                                     "peers); gravity up, ENU, q sensor->earth; in C, no Python", True),
    "NoOpEstimator": NativeModel(attitude_estimator, "AttitudeEstimator's interface; doStep does nothing "
                                 "(benchmark baseline)", False),
    "ImuSensor": NativeModel(imu_sensor, "IMU sensor model: gyro noise density, offset, scale and misalignment, "
                             "accelerometer noise and offset, magnetometer noise and hard iron; in C, no Python",
                             False, True),
    "MotionProfile": NativeModel(motion_profile, "Motion profiles with exact truth: ideal gyro, specific force, "
                                 "magnetic field, orientation; in C, no Python", False, True),
}
NATIVE_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")  # what build_fmus builds into DIR/native
SIMULATION_CORE = ("quaternion", "messages", "stages/timing")  # the core's files fmu_src/native/sim uses


class CompileError(RuntimeError):
    """The C compiler is missing or refused the sources; the message says which, with its output."""


def compiler() -> list[str]:
    """The C compiler's command: $CC, else the one Python was built with, else cc."""
    return shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")


def binary_path(name: str) -> str:
    """Where the FMU's binary for this platform lies in it (FMI 2.0: binaries/<platform>/<model identifier>)."""
    return f"binaries/{fmpy.platform}/{name}{fmpy.sharedLibraryExtension}"


def _initial(v) -> str:
    """The variable's initial in C, as FMI 2.0 defaults it where the table states none."""
    if v.initial is not None:
        return f"FMI2_{v.initial.upper()}"
    if v.causality == PAR:
        return "FMI2_EXACT"
    return "FMI2_CALCULATED" if v.causality == OUT else "FMI2_INITIAL_UNSET"


def _identifier(name: str) -> str:
    if not (name.isidentifier() and name.isascii()):
        raise ValueError(f"variable name {name!r} is not a C identifier")
    return name


def variables_header(name: str, guid: str) -> str:
    """The text of <name>_variables.h: the model's variables as the plumbing takes them
    (fmi2/fmi2_model.h: Fmi2Variable, by value reference) and the index of each among those
    of its type (REAL_<variable>, INTEGER_…, BOOLEAN_…, STRING_…), which the model file uses."""
    variables = NATIVE_MODELS[name].interface()
    if [v.value_reference for v in variables] != list(range(len(variables))):
        raise ValueError(f"{name}: the plumbing needs value references 0, 1, 2, … in the table's order")
    if len(LOG_CATEGORIES) > 32:
        raise ValueError("more log categories than fmi2/fmi2_model.h's FMI2_MAX_CATEGORIES")
    index, lines = {}, []
    for type_ in (REAL, INTEGER, BOOLEAN, STRING):
        names = [_identifier(v.name) for v in variables if v.type == type_]
        index.update((n, i) for i, n in enumerate(names))
        if names:
            lines += ["enum {", *(f"    {type_.upper()}_{n} = {i}," for i, n in enumerate(names)), "};"]
        lines.append(f"#define N_{type_.upper()}S {len(names)}")
    guard = f"{name.upper()}_VARIABLES_H"
    rows = []
    for v in variables:
        start = ("0.0", c_string(v.start)) if v.type == STRING else (c_double(float(v.start)), "NULL")
        rows.append(f"    {{{c_string(v.name)}, FMI2_{v.type.upper()}, FMI2_{v.causality.upper()}, "
                    f"FMI2_{v.variability.upper()}, {_initial(v)}, {v.type.upper()}_{v.name}, {start[0]}, {start[1]}}},"
                    f" /* {v.value_reference} */")
    return "\n".join([
        f"/* {name}_variables.h: the variables of {name}.fmu, generated by attitude_fmu.systems.fmi.native",
        " * from the table of FMU variables (fmu_src/variables.py) that writes its modelDescription.xml.",
        " * Do not edit: generate it again. */",
        f"#ifndef {guard}",
        f"#define {guard}",
        "",
        "#include <math.h> /* NAN */",
        "",
        '#include "fmi2/fmi2_model.h"',
        "",
        f"#define MODEL_IDENTIFIER {c_string(name)}",
        f"#define MODEL_GUID {c_string(guid)}",
        "",
        "/* the index of each variable among those of its type */",
        *lines,
        "",
        f"#define N_VARIABLES {len(variables)}",
        "/* by value reference */",
        "static const Fmi2Variable MODEL_VARIABLES[N_VARIABLES] = {",
        *rows,
        "};",
        "",
        f"#define N_LOG_CATEGORIES {len(LOG_CATEGORIES)}",
        "static const char *const MODEL_LOG_CATEGORIES[N_LOG_CATEGORIES] = {",
        *(f"    {c_string(c)}," for c in LOG_CATEGORIES),
        "};",
        "",
        "#endif",
        "",
    ])


def _tree_files(folder: Path, prefix: str = "") -> dict[str, bytes]:
    return {prefix + p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.suffix in (".c", ".h")}


def _fixed_sources(name: str) -> dict[str, bytes]:
    """The sources of the FMU but its variables header (paths under sources/): the plumbing
    (fmi2/), the model file (models/) and, for the estimator, the C core's files at the top
    (as they include each other: "pipeline/causal.h") with the generated af_params.h."""
    files = {}
    if NATIVE_MODELS[name].core:
        files.update(_tree_files(NATIVE_DIR / "core"))
        files[native_tables.HEADER] = native_tables.header_text().encode("ascii")
    if NATIVE_MODELS[name].simulation:
        files.update({f"{stem}{ext}": (NATIVE_DIR / "core" / f"{stem}{ext}").read_bytes()
                      for stem in SIMULATION_CORE for ext in (".c", ".h")})
        files.update(_tree_files(NATIVE_DIR / "sim", "sim/"))
    files.update(_tree_files(NATIVE_DIR / "fmi2", "fmi2/"))
    files[f"models/{name}.c"] = (NATIVE_DIR / "models" / f"{name}.c").read_bytes()
    return files


def guid(name: str) -> str:
    """The FMU's guid: a digest of its sources, its variables and its description."""
    digest = hashlib.sha256()
    for path, data in sorted(_fixed_sources(name).items()):
        digest.update(f"{path}\0{len(data)}\0".encode())
        digest.update(data)
    digest.update(tostring(model_variables(NATIVE_MODELS[name].interface())))
    digest.update(NATIVE_MODELS[name].description.encode())
    return "{" + str(uuid.uuid5(GUID_NAMESPACE, digest.hexdigest())) + "}"


def sources(name: str) -> dict[str, bytes]:
    """Every source file of the FMU, by its path under sources/ (generated headers included)."""
    files = _fixed_sources(name)
    files[f"{name}_variables.h"] = variables_header(name, guid(name)).encode("ascii")
    return files


def build_description(name: str, c_files) -> bytes:
    """sources/buildDescription.xml (FMI 3.0's format, which fmpy reads for FMI 2.0 FMUs too)."""
    root = Element("fmiBuildDescription", fmiVersion="3.0")
    config = SubElement(root, "BuildConfiguration", modelIdentifier=name,
                        description="a shared library of every C file listed; C99, with the FMI 2.0 headers "
                                    "(fmi2Functions.h) and this folder on the include path")
    files = SubElement(config, "SourceFileSet", language="C99")
    for path in c_files:
        SubElement(files, "SourceFile", name=path)
    SubElement(files, "IncludeDirectory", name=".")
    SubElement(config, "Library", name="m", external="true",
               description="the C math library (link with -lm where it is apart from the C library)")
    return tostring(root, xml_declaration=True, encoding="UTF-8")


def compile_binary(source_dir, output, flags=()) -> Path:
    """The .c files under source_dir (laid out as the FMU's sources/) compiled into the shared
    library output; flags are added to FLAGS (e.g. sanitizers). Raises CompileError."""
    source_dir, output = Path(source_dir), Path(output)
    c_files = sorted(str(p) for p in source_dir.rglob("*.c"))
    link = ["-Wl,--no-undefined"] if sys.platform.startswith("linux") and not flags else []
    command = [*compiler(), *FLAGS, *flags, f"-I{source_dir}", f"-I{FMI_HEADERS}", "-o", str(output), *c_files,
               *link, "-lm"]
    output.parent.mkdir(parents=True, exist_ok=True)
    try:
        subprocess.run(command, check=True, capture_output=True, text=True)
    except OSError as exc:
        raise CompileError(f"no C compiler ({shlex.join(command[:1])}: {exc.strerror or exc}); set CC to one") from None
    except subprocess.CalledProcessError as exc:
        raise CompileError(f"{shlex.join(command)} failed:\n{exc.stderr.strip()}") from None
    return output


def write_sources(name: str, folder) -> Path:
    """The FMU's sources written into folder (its sources/ layout); returns folder."""
    folder = Path(folder)
    for path, data in sources(name).items():
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        (folder / path).write_bytes(data)
    return folder


def _zip_entry(zf: zipfile.ZipFile, path: str, data: bytes) -> None:
    info = zipfile.ZipInfo(path, date_time=(1980, 1, 1, 0, 0, 0))  # the same sources give the same zip
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    zf.writestr(info, data)


def build_native_fmu(name: str, out) -> Path:
    """out/<name>.fmu, compiled for this platform, with its sources; raises CompileError."""
    files = sources(name)
    c_files = sorted(p for p in files if p.endswith(".c"))
    md = model_description(name, NATIVE_MODELS[name].description, guid(name), NATIVE_MODELS[name].interface(),
                           f"attitude-fmu {version('attitude-fmu')}", c_files)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="attitude_native_") as tmp:
        library = compile_binary(write_sources(name, Path(tmp) / "sources"), Path(tmp) / "binary")
        path = out / f"{name}.fmu"
        with zipfile.ZipFile(path, "w") as zf:
            _zip_entry(zf, "modelDescription.xml", tostring(md, xml_declaration=True, encoding="UTF-8"))
            _zip_entry(zf, binary_path(name), library.read_bytes())
            for source in sorted(files):
                _zip_entry(zf, f"sources/{source}", files[source])
            _zip_entry(zf, "sources/buildDescription.xml", build_description(name, c_files))
    return path


def build_native_fmus(out, names=NATIVE_NAMES, log=lambda m: print(m, file=sys.stderr)) -> list[Path]:
    """The named native FMUs built into the folder out; returns their paths. Without a
    working C compiler none is built and log says why (the pythonfmu FMUs do not need one)."""
    try:
        return [build_native_fmu(name, out) for name in names]
    except CompileError as exc:
        log(f"warning: the native FMUs ({', '.join(f'{n}.fmu' for n in names)}: in C, no Python) are not built "
            f"into {out}: {exc}")
        return []


def is_current(fmu) -> bool:
    """Whether the native FMU at path fmu was built from these sources (its guid is theirs)."""
    name = Path(fmu).stem
    try:
        md = fmpy.read_model_description(str(fmu), validate=False)
    except Exception:  # missing, not a zip, no model description: not current
        return False
    return md.guid == guid(name)
