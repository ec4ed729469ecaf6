"""FMI 2.0 model descriptions written from a table of variables (fmu_src.variables): the
UnitDefinitions, ModelVariables and ModelStructure of every FMU the project builds
(pythonfmu's through fmu_support.ProjectSlave.to_xml), and the whole document of a native
one (model_description)."""
from __future__ import annotations

import math
from xml.etree.ElementTree import Element, SubElement

from attitude_fmu.fmu_src.variables import BOOLEAN, OUT, REAL, UNITS

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
    project's FMI plumbing (fmu_src/native/fmi2), its sources (paths under sources/)."""
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
