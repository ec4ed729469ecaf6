"""Model descriptions written from a table of variables (systems.fmi.interface.variables): the FMI 2.0
UnitDefinitions, TypeDefinitions, DefaultExperiment, ModelVariables and ModelStructure and the
metadata of every FMU the project builds (pythonfmu's through fmu_support.ProjectSlave.to_xml),
and the whole document of a native one, FMI 2.0 (model_description) or 3.0 (model_description3;
systems/fmi/interface/generate.py writes them). Only the standard library is imported: the build runs it."""
from __future__ import annotations

import os
import time
from xml.etree.ElementTree import Element, SubElement

from attitude_fmu.systems.fmi.interface.escaping import xml_double
from attitude_fmu.systems.fmi.interface.variables import (
    BOOLEAN,
    DISPLAY_UNITS,
    ENUMERATION,
    INTEGER,
    OUT,
    QUANTITIES,
    REAL,
    STRING,
    UNITS,
    Variable,
)

AUTHOR = "attitude-fmu"
COPYRIGHT = "Copyright (c) 2026 The attitude-fmu authors"  # as the project's LICENSE says it
LICENSE = "MIT (documentation/licenses/LICENSE)"
# the default experiment of every FMU: stepSize the estimator's default Ts (s), a stop time (s)
DEFAULT_STEP, DEFAULT_STOP = 0.01, 10.0

# the categories the native FMUs log in: pythonfmu's (the status of a message) and a trace of
# the FMI calls, for debug logging
LOG_CATEGORIES = {
    "logStatusWarning": "Log messages with fmi2Warning status.",
    "logStatusDiscard": "Log messages with fmi2Discard status.",
    "logStatusError": "Log messages with fmi2Error status.",
    "logStatusFatal": "Log messages with fmi2Fatal status.",
    "logCalls": "Every FMI call with its arguments (debug logging).",
    "logAll": "Log all messages.",
}


def start_text(variable) -> str:
    """A start value as the model description writes it: Reals exactly as xs:double spells them
    (escaping.xml_double; an array's elements separated by spaces), Booleans true/false,
    Enumerations by their value."""
    if variable.type == REAL:
        values = variable.start if variable.dimensions else (variable.start,)
        return " ".join(map(xml_double, values))
    if variable.type == BOOLEAN:
        return "true" if variable.start else "false"
    return str(variable.start)


def metadata(version: str) -> dict[str, str]:
    """The fmiModelDescription attributes that say what an FMU is (FMI 2.0 and 3.0 alike):
    author, version (the project's), copyright, license and the generation time, the
    environment's SOURCE_DATE_EPOCH (s since 1970) where set, so that a build can be repeated
    byte for byte."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    stamp = time.gmtime(int(epoch) if epoch else None)
    return {"author": AUTHOR, "version": version, "copyright": COPYRIGHT, "license": LICENSE,
            "generationDateAndTime": time.strftime("%Y-%m-%dT%H:%M:%SZ", stamp)}


def default_experiment(step: float | None = None) -> Element:
    """0 s to DEFAULT_STOP at step (s; None: DEFAULT_STEP)."""
    return Element("DefaultExperiment", startTime="0.0", stopTime=repr(DEFAULT_STOP),
                   stepSize=repr(float(step or DEFAULT_STEP)))


def unit_definitions(variables) -> Element:
    """Every unit the variables have, with its SI base units and its display units (rad: deg)."""
    definitions = Element("UnitDefinitions")
    for name in sorted({v.unit for v in variables if v.unit is not None}):
        unit = SubElement(definitions, "Unit", name=name)
        if UNITS[name] is not None:
            SubElement(unit, "BaseUnit", {k: str(v) for k, v in UNITS[name].items()})
        if name in DISPLAY_UNITS:
            display, factor = DISPLAY_UNITS[name]
            SubElement(unit, "DisplayUnit", name=display, factor=repr(factor))
    return definitions


def _quantity(v: Variable) -> str | None:
    """The physical quantity of a Real variable (QUANTITIES by its unit), its declared type's name."""
    return QUANTITIES.get(v.unit) if v.type == REAL else None


def _enumerations(variables) -> list[Variable]:
    return [v for v in variables if v.type == ENUMERATION]


def _items(node: Element, v: Variable) -> None:
    for value, item in enumerate(v.items, 1):
        SubElement(node, "Item", name=item, value=str(value))


def type_definitions(variables) -> Element:
    """FMI 2.0's SimpleTypes: a Real type per physical quantity of the variables (QUANTITIES:
    its unit and display unit) and each Enumeration's items."""
    definitions = Element("TypeDefinitions")
    for unit, quantity in sorted(QUANTITIES.items(), key=lambda kv: kv[1]):
        if any(_quantity(v) == quantity for v in variables):
            real = SubElement(SubElement(definitions, "SimpleType", name=quantity), "Real", quantity=quantity,
                              unit=unit)
            if unit in DISPLAY_UNITS:
                real.set("displayUnit", DISPLAY_UNITS[unit][0])
    for v in _enumerations(variables):
        _items(SubElement(SubElement(definitions, "SimpleType", name=v.declared_type), "Enumeration"), v)
    return definitions


def model_variables(variables) -> Element:
    """FMI 2.0's ModelVariables of the table (scalars only: FMI 2.0 has no arrays)."""
    node = Element("ModelVariables")
    for v in variables:
        if v.dimensions:
            raise ValueError(f"{v.name}: FMI 2.0 has no array variables (give its elements as scalars)")
        attributes = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
                      "causality": v.causality, "variability": v.variability}
        if v.initial is not None:
            attributes["initial"] = v.initial
        scalar = SubElement(node, "ScalarVariable", attributes)
        typed = SubElement(scalar, v.type)
        if v.type == ENUMERATION:
            typed.set("declaredType", v.declared_type)
        elif _quantity(v) is not None:
            typed.set("declaredType", _quantity(v))
        if v.unit is not None:
            typed.set("unit", v.unit)
        if v.initial != "calculated":  # FMI 2.0 gives a calculated variable no start
            typed.set("start", start_text(v))
    return node


def model_structure(variables) -> Element:
    """The outputs, by their 1-based index in ModelVariables. No output depends on an input within
    a step (dependencies=""): the outputs after doStep(t, h) come from the inputs held over it, set
    before it. The calculated outputs (those at the start time: Table.real) are the initial
    unknowns, each depending on every known (inputs and parameters: no dependencies attribute)."""
    structure = Element("ModelStructure")
    for section, chosen, fixed in (("Outputs", lambda v: v.causality == OUT, {"dependencies": ""}),
                                   ("InitialUnknowns", lambda v: v.initial == "calculated", {})):
        indices = [k + 1 for k, v in enumerate(variables) if chosen(v)]
        if indices:
            node = SubElement(structure, section)
            for index in indices:
                SubElement(node, "Unknown", index=str(index), **fixed)
    return structure


def model_description(name: str, description: str, guid: str, variables, version: str, source_files=(),
                      step: float | None = None) -> Element:
    """The modelDescription.xml of an FMI 2.0 co-simulation FMU in C whose binary is named
    name (its model identifier): the variables of the table, the capabilities of the
    project's FMI plumbing (fmu_src/fmi2), its sources (paths under sources/), the metadata of
    the project's version; step: the DefaultExperiment's (default_experiment)."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid, "description": description,
        "generationTool": f"attitude-fmu {version}", "variableNamingConvention": "structured", **metadata(version)})
    cosimulation = SubElement(root, "CoSimulation", {
        "modelIdentifier": name, "needsExecutionTool": "false", "canHandleVariableCommunicationStepSize": "true",
        "canInterpolateInputs": "false", "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"})
    if source_files:
        files = SubElement(cosimulation, "SourceFiles")
        for path in source_files:
            SubElement(files, "File", name=path)
    root.extend(d for d in (unit_definitions(variables), type_definitions(variables)) if len(d))  # none empty
    root.append(log_categories())
    root.append(default_experiment(step))
    root.append(model_variables(variables))
    root.append(model_structure(variables))
    return root


def log_categories() -> Element:
    categories = Element("LogCategories")
    for category, text in LOG_CATEGORIES.items():
        SubElement(categories, "Category", name=category, description=text)
    return categories


FMI3_TYPES = {REAL: "Float64", INTEGER: "Int32"}  # the table's types that FMI 3.0 names otherwise


def time_variable(variables) -> Variable:
    """FMI 3.0's independent variable, after the table's variables."""
    return Variable("time", REAL, "independent", "continuous", 0.0, "simulation time",
                    sum(v.size for v in variables), "s")


def type_definitions3(variables) -> Element:
    """FMI 3.0's TypeDefinitions: a Float64Type per physical quantity of the variables and an
    EnumerationType per Enumeration (as FMI 2.0's, type_definitions)."""
    definitions = Element("TypeDefinitions")
    for simple in type_definitions(variables):
        (typed,) = simple
        if typed.tag == "Real":
            SubElement(definitions, "Float64Type", name=simple.get("name"), **typed.attrib)
        else:
            enumeration = SubElement(definitions, "EnumerationType", name=simple.get("name"))
            enumeration.extend(typed)
    return definitions


def model_variables3(variables) -> Element:
    """FMI 3.0's ModelVariables of the table: Real as Float64, Integer as Int32, Boolean, String
    and Enumeration as themselves, with the same names, value references, causalities, units,
    declared types and start values, an array with its Dimensions, and `time` after them."""
    node = Element("ModelVariables")
    for v in (*variables, time_variable(variables)):
        attributes = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
                      "causality": v.causality, "variability": v.variability}
        if v.initial is not None:
            attributes["initial"] = v.initial
        if v.type == ENUMERATION:
            attributes["declaredType"] = v.declared_type
        elif _quantity(v) is not None:
            attributes["declaredType"] = _quantity(v)
        if v.type != STRING and v.causality != "independent" and v.initial != "calculated":
            attributes["start"] = start_text(v)
        if v.unit is not None:
            attributes["unit"] = v.unit
        typed = SubElement(node, FMI3_TYPES.get(v.type, v.type), attributes)
        if v.type == STRING:
            SubElement(typed, "Start", value=start_text(v))
        for extent in v.dimensions:
            SubElement(typed, "Dimension", start=str(extent))
    return node


def model_description3(name: str, description: str, instantiation_token: str, variables, version: str,
                       step: float | None = None) -> Element:
    """The modelDescription.xml of an FMI 3.0 co-simulation FMU in C whose binary is named name,
    with the capabilities of fmu_src/fmi3 and the metadata of the project's version. No output
    depends on an input within a step; the calculated outputs are initial unknowns (model_structure)."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": name, "instantiationToken": instantiation_token,
        "description": description, "generationTool": f"attitude-fmu {version}",
        "variableNamingConvention": "structured", **metadata(version)})
    SubElement(root, "CoSimulation", {
        "modelIdentifier": name, "needsExecutionTool": "false", "canBeInstantiatedOnlyOncePerProcess": "false",
        "canGetAndSetFMUState": "true", "canSerializeFMUState": "true", "providesDirectionalDerivatives": "false",
        "providesAdjointDerivatives": "false", "canHandleVariableCommunicationStepSize": "true",
        "maxOutputDerivativeOrder": "0", "providesIntermediateUpdate": "false",
        "canReturnEarlyAfterIntermediateUpdate": "false", "hasEventMode": "false"})
    root.extend(d for d in (unit_definitions([*variables, time_variable(variables)]),
                            type_definitions3([*variables, time_variable(variables)])) if len(d))  # none empty
    root.append(log_categories())
    root.append(default_experiment(step))
    root.append(model_variables3(variables))
    structure = SubElement(root, "ModelStructure")
    for v in variables:
        if v.causality == OUT:
            SubElement(structure, "Output", valueReference=str(v.value_reference), dependencies="")
    for v in variables:
        if v.initial == "calculated":
            SubElement(structure, "InitialUnknown", valueReference=str(v.value_reference))
    return root
