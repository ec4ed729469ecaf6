"""Model descriptions written from a table of variables (fmu_src.variables): the FMI 2.0
UnitDefinitions, ModelVariables and ModelStructure of every FMU the project builds
(pythonfmu's through fmu_support.ProjectSlave.to_xml), and the whole document of a native
one, FMI 2.0 (model_description) or 3.0 (model_description3; fmu_src/generate.py writes them).
Only the standard library is imported: the build runs it."""
from __future__ import annotations

import math
from xml.etree.ElementTree import Element, SubElement

from attitude_fmu.fmu_src.variables import BOOLEAN, INTEGER, OUT, REAL, STRING, UNITS, Variable

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
    """A start value as the model description writes it: Reals exactly (shortest round trip,
    NaN as XML Schema spells it), Booleans true/false."""
    if variable.type == REAL:
        return "NaN" if math.isnan(variable.start) else repr(float(variable.start))
    if variable.type == BOOLEAN:
        return "true" if variable.start else "false"
    return str(variable.start)


def unit_definitions(variables) -> Element:
    definitions = Element("UnitDefinitions")
    for name in sorted({v.unit for v in variables if v.unit is not None}):
        unit = SubElement(definitions, "Unit", name=name)
        if UNITS[name] is not None:
            SubElement(unit, "BaseUnit", {k: str(v) for k, v in UNITS[name].items()})
    return definitions


def model_variables(variables) -> Element:
    node = Element("ModelVariables")
    for v in variables:
        attributes = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
                      "causality": v.causality, "variability": v.variability}
        if v.initial is not None:
            attributes["initial"] = v.initial
        scalar = SubElement(node, "ScalarVariable", attributes)
        typed = SubElement(scalar, v.type, start=start_text(v))
        if v.unit is not None:
            typed.set("unit", v.unit)
    return node


def model_structure(variables) -> Element:
    """The outputs, by their 1-based index in ModelVariables; none has an initial unknown (they start exact)."""
    structure = Element("ModelStructure")
    outputs = [k + 1 for k, v in enumerate(variables) if v.causality == OUT]
    if outputs:
        node = SubElement(structure, "Outputs")
        for index in outputs:
            SubElement(node, "Unknown", index=str(index))
    return structure


def model_description(name: str, description: str, guid: str, variables, generation_tool: str,
                      source_files=()) -> Element:
    """The modelDescription.xml of an FMI 2.0 co-simulation FMU in C whose binary is named
    name (its model identifier): the variables of the table, the capabilities of the
    project's FMI plumbing (fmu_src/fmi2), its sources (paths under sources/)."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid, "description": description, "author": "attitude-fmu",
        "generationTool": generation_tool, "variableNamingConvention": "structured"})
    cosimulation = SubElement(root, "CoSimulation", {
        "modelIdentifier": name, "needsExecutionTool": "false", "canHandleVariableCommunicationStepSize": "true",
        "canInterpolateInputs": "false", "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"})
    if source_files:
        files = SubElement(cosimulation, "SourceFiles")
        for path in source_files:
            SubElement(files, "File", name=path)
    root.append(unit_definitions(variables))
    categories = SubElement(root, "LogCategories")
    for category, text in LOG_CATEGORIES.items():
        SubElement(categories, "Category", name=category, description=text)
    root.append(model_variables(variables))
    root.append(model_structure(variables))
    return root


FMI3_TYPES = {REAL: "Float64", INTEGER: "Int32"}  # the table's types that FMI 3.0 names otherwise


def time_variable(variables) -> Variable:
    """FMI 3.0's independent variable, after the table's variables."""
    return Variable("time", REAL, "independent", "continuous", 0.0, "simulation time", len(variables), "s")


def model_variables3(variables) -> Element:
    """FMI 3.0's ModelVariables of the table: Real as Float64, Integer as Int32, Boolean and String
    as themselves, with the same names, value references, causalities, units and start values,
    and `time` after them."""
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
    with the capabilities of fmu_src/fmi3."""
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
