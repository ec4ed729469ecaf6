"""The native estimator as an FMI 3.0 co-simulation FMU: DIR/native/fmi3/AttitudeEstimator.fmu.

The same model file and C core as the FMI 2.0 FMU (systems.fmi.native), on the FMI 3.0 entry
points of fmu_src/native/fmi3 (which run the plumbing's instances, values and FMU states of
fmu_src/native/fmi2), compiled against the fmi3 headers fmpy installs. Its modelDescription.xml
is written from the same table of FMU variables: Real as Float64, Integer as Int32, Boolean and
String as themselves, with the same names, value references, causalities, units and start
values, and `time`, FMI 3.0's independent variable, after them. The instantiation token is a
digest of everything the FMU is built from (is_current).
"""
from __future__ import annotations

import hashlib
import sys
import tempfile
import uuid
import zipfile
from importlib.metadata import version
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, tostring

import fmpy

from attitude_fmu.fmu_src.model_description import LOG_CATEGORIES, start_text, unit_definitions
from attitude_fmu.fmu_src.variables import INTEGER, OUT, REAL, STRING, Variable
from attitude_fmu.systems.fmi import native

FMI3_NAMES = ("AttitudeEstimator",)  # what build_fmus builds into DIR/native/fmi3
FMI3_TYPES = {REAL: "Float64", INTEGER: "Int32"}  # the table's types that FMI 3.0 names otherwise
# the FMI 2.0 entry points, which the FMI 3.0 FMU replaces by fmi3/functions.c
FMI2_ENTRY_POINTS = "fmi2/functions.c"


def time_variable(variables) -> Variable:
    """FMI 3.0's independent variable, after the table's variables."""
    return Variable("time", REAL, "independent", "continuous", 0.0, "simulation time", len(variables), "s")


def _fixed_sources(name: str) -> dict[str, bytes]:
    files = {path: data for path, data in native.sources(name).items()
             if path != FMI2_ENTRY_POINTS and path != f"{name}_variables.h"}
    files.update({f"fmi3/{p.name}": p.read_bytes() for p in sorted((native.NATIVE_DIR / "fmi3").glob("*.[ch]"))})
    return files


def token(name: str) -> str:
    """The FMU's instantiation token: a digest of its sources, variables and description."""
    digest = hashlib.sha256(b"fmi3")
    for path, data in sorted(_fixed_sources(name).items()):
        digest.update(f"{path}\0{len(data)}\0".encode())
        digest.update(data)
    digest.update(tostring(model_variables3(native.NATIVE_MODELS[name].interface())))
    digest.update(native.NATIVE_MODELS[name].description.encode())
    return "{" + str(uuid.uuid5(native.GUID_NAMESPACE, digest.hexdigest())) + "}"


def sources(name: str) -> dict[str, bytes]:
    """Every source file of the FMU by its path under sources/, the variables header with its token."""
    files = _fixed_sources(name)
    files[f"{name}_variables.h"] = native.variables_header(name, token(name)).encode("ascii")
    return files


def model_variables3(variables) -> Element:
    node = Element("ModelVariables")
    for v in (*variables, time_variable(variables)):
        attributes = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
                      "causality": v.causality, "variability": v.variability}
        if v.initial is not None:
            attributes["initial"] = v.initial
        if v.type != STRING and v.causality != "independent":
            attributes["start"] = start_text(v)
        if v.unit is not None:
            attributes["unit"] = v.unit
        typed = SubElement(node, FMI3_TYPES.get(v.type, v.type), attributes)
        if v.type == STRING:
            SubElement(typed, "Start", value=start_text(v))
    return node


def model_description3(name: str, description: str, instantiation_token: str, variables,
                       generation_tool: str) -> Element:
    """The modelDescription.xml of an FMI 3.0 co-simulation FMU in C whose binary is named name,
    with the capabilities of fmu_src/native/fmi3."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": name, "instantiationToken": instantiation_token,
        "description": description, "author": "attitude-fmu", "generationTool": generation_tool,
        "variableNamingConvention": "structured"})
    SubElement(root, "CoSimulation", {
        "modelIdentifier": name, "needsExecutionTool": "false", "canBeInstantiatedOnlyOncePerProcess": "false",
        "canGetAndSetFMUState": "true", "canSerializeFMUState": "true", "providesDirectionalDerivatives": "false",
        "providesAdjointDerivatives": "false", "canHandleVariableCommunicationStepSize": "true",
        "maxOutputDerivativeOrder": "0", "providesIntermediateUpdate": "false",
        "canReturnEarlyAfterIntermediateUpdate": "false", "hasEventMode": "false"})
    root.append(unit_definitions([*variables, time_variable(variables)]))
    categories = SubElement(root, "LogCategories")
    for category, text in LOG_CATEGORIES.items():
        SubElement(categories, "Category", name=category, description=text)
    root.append(model_variables3(variables))
    structure = SubElement(root, "ModelStructure")
    for v in variables:
        if v.causality == OUT:
            SubElement(structure, "Output", valueReference=str(v.value_reference))
    return root


def binary_path(name: str) -> str:
    """Where the FMU's binary for this platform lies in it (FMI 3.0: binaries/<platform tuple>/<identifier>)."""
    return f"binaries/{fmpy.platform_tuple}/{name}{fmpy.sharedLibraryExtension}"


def build_fmi3_fmu(name: str, out) -> Path:
    """out/<name>.fmu (FMI 3.0), compiled for this platform, with its sources; raises native.CompileError."""
    files = sources(name)
    c_files = sorted(p for p in files if p.endswith(".c"))
    model = native.NATIVE_MODELS[name]
    md = model_description3(name, model.description, token(name), model.interface(),
                            f"attitude-fmu {version('attitude-fmu')}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="attitude_fmi3_") as tmp:
        folder = Path(tmp) / "sources"
        for path, data in files.items():
            (folder / path).parent.mkdir(parents=True, exist_ok=True)
            (folder / path).write_bytes(data)
        library = native.compile_binary(folder, Path(tmp) / "binary")
        path = out / f"{name}.fmu"
        with zipfile.ZipFile(path, "w") as zf:
            native._zip_entry(zf, "modelDescription.xml", tostring(md, xml_declaration=True, encoding="UTF-8"))
            native._zip_entry(zf, binary_path(name), library.read_bytes())
            for source in sorted(files):
                native._zip_entry(zf, f"sources/{source}", files[source])
            native._zip_entry(zf, "sources/buildDescription.xml", native.build_description(name, c_files))
    return path


def build_fmi3_fmus(out, names=FMI3_NAMES, log=lambda m: print(m, file=sys.stderr)) -> list[Path]:
    """The named FMI 3.0 FMUs built into the folder out; none without a working C compiler (log says why)."""
    try:
        return [build_fmi3_fmu(name, out) for name in names]
    except native.CompileError as exc:
        log(f"warning: the FMI 3.0 FMUs ({', '.join(f'{n}.fmu' for n in names)}) are not built into {out}: {exc}")
        return []


def is_current(fmu) -> bool:
    """Whether the FMI 3.0 FMU at path fmu was built from these sources (its token is theirs)."""
    try:
        md = fmpy.read_model_description(str(fmu), validate=False)
    except Exception:  # missing, not a zip, no model description: not current
        return False
    return md.fmiVersion == "3.0" and md.instantiationToken == token(Path(fmu).stem)
