"""The generated files of a native FMU, written by the build (CMakeLists.txt, af_fmu) into the
FMU's staging folder, beside its sources:

    python systems/fmi/interface/generate.py NAME FMI STAGE VERSION DEST=SOURCE...

NAME is a model of MODELS (its C model file, NAME.c in fmu_src/models), FMI "2.0" or "3.0",
VERSION the project's (the generation tool's), each DEST=SOURCE a source file and its path
under the FMU's sources/ folder (as the files include each other: that folder is the one
include directory, as `fmpy compile` builds it). Writes into STAGE:

    modelDescription.xml              from the table of FMU variables (systems/fmi/interface/variables.py)
    sources/DEST...                   the sources, copied
    sources/NAME_variables.h          the variables as the plumbing takes them (fmi2/fmi2_model.h)
    sources/buildDescription.xml      every C file and header, for importers that build the FMU themselves
    documentation/index.html          the variables and the time convention (systems/fmi/interface/documentation.py)
    documentation/licenses/LICENSE    the project's license

The generation time in modelDescription.xml is SOURCE_DATE_EPOCH's where the environment sets it.

The guid (FMI 3.0: instantiation token) is a digest of the sources, the variables and the
description, so an FMU built from other sources is told apart (systems.fmi.native.is_current).
Only the standard library is needed: the package's folder is loaded as attitude_fmu without
its dependencies.
"""
from __future__ import annotations

import hashlib
import importlib.util
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, tostring

if __package__ in (None, ""):  # run as a script by the build: this clone's folder as attitude_fmu
    _root = Path(__file__).resolve().parents[3]
    _spec = importlib.util.spec_from_file_location("attitude_fmu", _root / "__init__.py",
                                                   submodule_search_locations=[str(_root)])
    sys.modules["attitude_fmu"] = importlib.util.module_from_spec(_spec)
    _spec.loader.exec_module(sys.modules["attitude_fmu"])

from attitude_fmu.systems.fmi.interface.documentation import documentation_files  # noqa: E402
from attitude_fmu.systems.fmi.interface.escaping import c_double, c_identifier, c_string, xml_tree  # noqa: E402
from attitude_fmu.systems.fmi.interface.model_description import (  # noqa: E402
    LOG_CATEGORIES,
    model_description,
    model_description3,
    model_variables,
    model_variables3,
)
from attitude_fmu.systems.fmi.interface.simulation_variables import imu_sensor, motion_profile  # noqa: E402
from attitude_fmu.systems.fmi.interface.variables import (  # noqa: E402
    BOOLEAN,
    ENUMERATION,
    INTEGER,
    OUT,
    PAR,
    REAL,
    STRING,
    attitude_estimator,
)

HELD_AS = {REAL: REAL, INTEGER: INTEGER, BOOLEAN: BOOLEAN, STRING: STRING, ENUMERATION: INTEGER}  # the values' type
GUID_NAMESPACE = uuid.UUID("6f0e2a4c-8b1d-4c55-9d3e-2f7a1b9c0d41")  # of the native FMUs' guids


@dataclass(frozen=True)
class NativeModel:
    """A native FMU's interface (a table of systems.fmi.interface.variables), description and, where it is not
    documentation.CONVENTIONS', its time convention."""

    interface: object
    description: str
    convention: str | None = None


MODELS = {
    "AttitudeEstimator": NativeModel(attitude_estimator, "IMU attitude estimator (Rizun's optimal Wiener filter and "
                                     "peers); gravity up, ENU, q sensor->earth; in C, no Python"),
    "NoOpEstimator": NativeModel(attitude_estimator, "AttitudeEstimator's interface; doStep does nothing "
                                 "(benchmark baseline)"),
    "ImuSensor": NativeModel(imu_sensor, "IMU sensor model: gyro noise density, offset, scale and misalignment, "
                             "accelerometer noise and offset, magnetometer noise, hard and soft iron; in C, no Python"),
    "MotionProfile": NativeModel(motion_profile, "Motion profiles with exact truth: ideal gyro, specific force, "
                                 "magnetic field, orientation; in C, no Python"),
}


def _initial(v) -> str:
    """The variable's initial in C, as FMI 2.0 defaults it where the table states none."""
    if v.initial is not None:
        return f"FMI2_{v.initial.upper()}"
    if v.causality == PAR:
        return "FMI2_EXACT"
    return "FMI2_CALCULATED" if v.causality == OUT else "FMI2_INITIAL_UNSET"


def variables_header(name: str, guid: str, model: NativeModel | None = None) -> str:
    """The text of <name>_variables.h: the model's variables (model, default MODELS[name]) as the
    plumbing takes them (fmi2/fmi2_model.h: Fmi2Variable, by value reference; an FMI 3.0 array as
    its elements, name[i,j], one value reference each) and the index of each among those of its type
    (REAL_<variable>, INTEGER_…, BOOLEAN_…, STRING_…; an Enumeration's among the integers, its item
    names in ITEMS_<variable>), which the model file uses; where a name is no C identifier (an
    exported diagram's u[0], an array's elements), the counts N_REALS, … alone."""
    variables = (model or MODELS[name]).interface()
    indexed = all(v.name.isidentifier() and v.name.isascii() and not v.dimensions for v in variables)
    if [v.value_reference for v in variables] != [sum(w.size for w in variables[:k]) for k in range(len(variables))]:
        raise ValueError(f"{name}: the plumbing needs value references 0, 1, 2, … in the table's order")
    if len(LOG_CATEGORIES) > 32:
        raise ValueError("more log categories than fmi2/fmi2_model.h's FMI2_MAX_CATEGORIES")
    scalars = [(v, k, element, start) for v in variables for k, (element, start) in enumerate(v.elements())]
    lines, items, counts = [], [], dict.fromkeys((REAL, INTEGER, BOOLEAN, STRING), 0)
    for type_ in counts:
        names = [c_identifier(v.name, 'a variable name') if indexed else v.name for v, *_ in scalars if HELD_AS[v.type] == type_]
        if names and indexed:
            lines += ["enum {", *(f"    {type_.upper()}_{n} = {i}," for i, n in enumerate(names)), "};"]
        lines.append(f"#define N_{type_.upper()}S {len(names)}")
    rows = []
    for v, k, element, value in scalars:
        start = ("0.0", c_string(value)) if v.type == STRING else (c_double(float(value)), "NULL")
        if v.type == ENUMERATION:
            items.append(f"static const char *const ITEMS_{v.name}[{len(v.items)}] = "
                         f"{{{', '.join(c_string(item) for item in v.items)}}};")
        enumeration = (f"ITEMS_{v.name}", str(len(v.items))) if v.type == ENUMERATION else ("NULL", "0")
        index = f"{HELD_AS[v.type].upper()}_{v.name}" if indexed else str(counts[HELD_AS[v.type]])
        counts[HELD_AS[v.type]] += 1
        rows.append(f"    {{{c_string(element)}, FMI2_{v.type.upper()}, FMI2_{v.causality.upper()}, "
                    f"FMI2_{v.variability.upper()}, {_initial(v)}, {index}, "
                    f"{start[0]}, {start[1]}, {', '.join(enumeration)}, {v.size if k == 0 else 0}}}, "
                    f"/* {v.value_reference + k} */")
    guard = f"{name.upper()}_VARIABLES_H"
    return "\n".join([
        f"/* {name}_variables.h: the variables of {name}.fmu, generated by systems/fmi/interface/generate.py from the",
        " * table of FMU variables (systems/fmi/interface/variables.py) that writes its modelDescription.xml.",
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
        "/* the index of each variable among the values of its type (an Enumeration's among the integers) */",
        *lines,
        "",
        *(["/* each Enumeration's item names, of the values 1, 2, ... */", *items, ""] if items else []),
        f"#define N_VARIABLES {len(scalars)}",
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


def guid(name: str, fmi: str, sources: dict[str, bytes], model: NativeModel | None = None) -> str:
    """The FMU's guid (FMI 3.0: instantiation token): a digest of its sources (path under
    sources/ → contents; the generated variables header aside), its variables and its description
    (model, default MODELS[name])."""
    model = model or MODELS[name]
    digest = hashlib.sha256(b"fmi3" if fmi == "3.0" else b"")
    for path, data in sorted(sources.items()):
        digest.update(f"{path}\0{len(data)}\0".encode())
        digest.update(data)
    variables = (model_variables3 if fmi == "3.0" else model_variables)(model.interface())
    digest.update(tostring(variables))
    digest.update(model.description.encode())
    return "{" + str(uuid.uuid5(GUID_NAMESPACE, digest.hexdigest())) + "}"


# the FMI standard's headers the sources include, by FMI version: not in the FMU (an importer has them);
# the FMI 3.0 FMUs need FMI 2.0's too, as their entry points run on the FMI 2.0 plumbing (fmi2/fmi2_model.h)
FMI_HEADERS = {"2.0": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")}
FMI_HEADERS["3.0"] = ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h", *FMI_HEADERS["2.0"])


def build_description(name: str, fmi: str, c_files, headers) -> bytes:
    """sources/buildDescription.xml (FMI 3.0's format, which fmpy reads for FMI 2.0 FMUs too): the
    C files, and in the configuration's description every header they include (the format has no
    element for headers): the FMI standard's (FMI_HEADERS) and the FMU's own (headers, in sources/)."""
    root = Element("fmiBuildDescription", fmiVersion="3.0")
    config = SubElement(root, "BuildConfiguration", modelIdentifier=name, description=(
        f"a shared library of every C file listed; C99, with this folder and the FMI standard's headers on the "
        f"include path. The headers the sources include: the FMI standard's {', '.join(FMI_HEADERS[fmi])} (not in "
        f"this FMU{'; FMI 2.0 ones too: the FMI 3.0 functions run on an FMI 2.0 plumbing' if fmi == '3.0' else ''})"
        f" and this folder's {', '.join(headers)}"))
    files = SubElement(config, "SourceFileSet", language="C99")
    for path in c_files:
        SubElement(files, "SourceFile", name=path)
    SubElement(files, "IncludeDirectory", name=".")
    SubElement(config, "Library", name="m", external="true",
               description="the C math library (link with -lm where it is apart from the C library)")
    return tostring(xml_tree(root, f"{name}'s buildDescription.xml"), xml_declaration=True, encoding="UTF-8")


def generated_files(name: str, fmi: str, version: str, sources: dict[str, bytes], model: NativeModel | None = None,
                    step: float | None = None) -> dict[str, bytes]:
    """The FMU's files by their path in it but its binary: modelDescription.xml and sources/ (the
    given sources, the variables header, buildDescription.xml) of the model (default MODELS[name]);
    step: the DefaultExperiment's step size (s; None: the project's default)."""
    if fmi not in ("2.0", "3.0"):
        raise ValueError(f"FMI version {fmi!r}: 2.0 or 3.0")
    model = model or MODELS[name]
    token = guid(name, fmi, sources, model)
    files = {**sources, f"{name}_variables.h": variables_header(name, token, model).encode("ascii")}
    c_files = sorted(p for p in files if p.endswith(".c"))
    if fmi == "3.0":
        md = model_description3(name, model.description, token, model.interface(), version, step=step)
    else:
        md = model_description(name, model.description, token, model.interface(), version, c_files, step=step)
    files["buildDescription.xml"] = build_description(name, fmi, c_files, sorted(p for p in files if p.endswith(".h")))
    xml_tree(md, f"{name}'s modelDescription.xml")
    return {"modelDescription.xml": tostring(md, xml_declaration=True, encoding="UTF-8"),
            **{f"sources/{path}": data for path, data in files.items()},
            **documentation_files(name, model.description, fmi, version, model.interface(), model.convention)}


def write_stage(stage, files: dict[str, bytes]) -> None:
    """files (path → contents) written into the folder stage; its sources/ and documentation/
    keep no other file."""
    stage = Path(stage)
    for path in sorted((p for folder in ("sources", "documentation") for p in (stage / folder).rglob("*")),
                       reverse=True):  # files before their folders
        if path.is_file() and path.relative_to(stage).as_posix() not in files:
            path.unlink()
        elif path.is_dir() and not any(path.iterdir()):
            path.rmdir()
    for path, data in files.items():
        target = stage / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)


def main(argv) -> int:
    if len(argv) < 5 or argv[0] not in MODELS:
        sys.exit(__doc__)
    name, fmi, stage, version, *pairs = argv
    sources = {}
    for pair in pairs:
        dest, _, source = pair.partition("=")
        sources[dest] = Path(source).read_bytes()
    write_stage(stage, generated_files(name, fmi, version, sources))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
