"""SSP 1.0 packages of the diagram motion → IMU sensor → estimator, self-contained: the three
FMUs inside (resources/), of one chain, native FMI 2.0 (DIR/native/*.fmu, in C), native FMI 3.0
(DIR/native/fmi3/*.fmu) or pythonfmu (DIR/*.fmu), their parameters inline in the SSD; with the
native estimator (DIR/native/AttitudeEstimator.fmu) beside the estimator, fed the same sensor
signals, where asked.

The SSD is valid against the SSP 1.0 schema and holds only what both OMSimulator and libcosim
read: connectors of type Real or Boolean, parameter values of type Real, Integer or Boolean
(an Enumeration parameter as its item's Integer value, systems.fmi.interface.variables.item_value), and the
communication step in each one's annotation where the schema allows annotations: OMSimulator's
fixed-step master (org.openmodelica, as its SSP import and its Python API read it) in the System,
libcosim's fixed-step algorithm (com.opensimulationplatform) in the DefaultExperiment.
"""
from __future__ import annotations

import re
import zipfile
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, register_namespace, tostring

from attitude_fmu.systems.fmi.interface.generate import MODELS
from attitude_fmu.systems.fmi.interface.variables import BOOLEAN, ENUMERATION, IN, INTEGER, OUT, PAR, REAL, item_value
from attitude_fmu.systems.fmi.fmi3 import FOLDER as FMI3_FOLDER
from attitude_fmu.systems.recordings.output import replaced

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
# the prefixes the standard and the tools write: OMSimulator and libcosim match element names literally
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV), ("oms", OMS), ("osp", OSP)):
    register_namespace(_prefix, _uri)
XYZ = ("x", "y", "z")
SSV_TYPE = {REAL: "Real", INTEGER: "Integer", BOOLEAN: "Boolean", ENUMERATION: "Integer"}  # by FMU variable type
CONNECTOR_TYPE = {REAL: "Real", BOOLEAN: "Boolean"}
IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")  # OMSimulator's names of models (the SSD's name)


def _interface(fmu: str) -> tuple[str, list[str], list[str]]:
    """(FMU, its inputs, its outputs) from its table of variables (systems.fmi.interface.generate.MODELS)."""
    table = MODELS[fmu].interface()
    return fmu, [v.name for v in table if v.causality == IN], [v.name for v in table if v.causality == OUT]


# component name → (FMU, inputs, outputs)
COMPONENTS = {name: _interface(fmu) for name, fmu in
              (("motion", "MotionProfile"), ("imu", "ImuSensor"), ("estimator", "AttitudeEstimator"))}
CONNECTIONS = [("motion", f"{s}_{a}", "imu", f"{s}_{a}") for s in ("omega", "f", "m") for a in XYZ] + [
    ("imu", f"{s}_{a}", "estimator", f"{s}_{a}") for s in ("gyr", "acc", "mag") for a in XYZ
]
# the native estimator: the pythonfmu one's interface, in C (systems.fmi.native)
NATIVE = ("native", "native/AttitudeEstimator", *COMPONENTS["estimator"][1:])
NATIVE_CONNECTIONS = [("imu", f"{s}_{a}", "native", f"{s}_{a}") for s in ("gyr", "acc", "mag") for a in XYZ]
# where under the FMU folder each chain's three FMUs are
CHAINS = {"native": "native/", "python": "", "fmi3": f"{FMI3_FOLDER}/"}


def parameter_value(fmu: str, variable: str, value) -> tuple[str, str]:
    """(SSV type, value text) of a parameter of the FMU: its type in the FMU's table; an
    Enumeration's value given by item name (as the command line spells it), bound as its Integer."""
    table = {v.name: v for v in MODELS[fmu].interface()}
    if variable not in table or table[variable].causality != PAR:
        raise ValueError(f"{fmu} has no parameter {variable!r}")
    v = table[variable]
    if v.type not in SSV_TYPE:
        raise ValueError(f"{fmu}.{variable} is a {v.type}, which the SSP's importers cannot bind")
    if v.type == ENUMERATION:
        text = str(item_value(v, value))
    elif v.type == BOOLEAN:
        text = str(bool(value)).lower()
    elif v.type == INTEGER:
        if isinstance(value, bool) or int(value) != value:
            raise ValueError(f"{fmu}.{variable} is an Integer; got {value!r}")
        text = str(int(value))
    else:
        text = repr(float(value))
    return SSV_TYPE[v.type], text


def _annotation(parent: Element, kind: str) -> Element:
    """A new ssc:Annotation of the type kind in parent's ssd:Annotations."""
    return SubElement(SubElement(parent, f"{{{SSD}}}Annotations"), f"{{{SSC}}}Annotation", {"type": kind})


def write_ssp(path, fmu_dir, parameters: dict[str, dict], stop_time: float, step_size: float,
              native: bool = False, chain: str = "python") -> Path:
    """Write an SSP with the three FMUs of the chain ("python": fmu_dir/*.fmu, "native":
    fmu_dir/native/*.fmu, "fmi3": fmu_dir/native/fmi3/*.fmu) and inline parameter values;
    with native, also the native estimator from fmu_dir/native, component "native", with the
    estimator's parameters unless parameters names its own.

    parameters: component name → {variable: value}, each bound with the variable's type in the
    FMU (an Enumeration by item name, written as its Integer value); stop_time, step_size: the
    default experiment and the communication step, s. The SSD's name is the file's stem, as an
    identifier (other characters as "_").
    """
    path, fmu_dir = Path(path), Path(fmu_dir)
    components = {name: (CHAINS[chain] + fmu, *rest) for name, (fmu, *rest) in COMPONENTS.items()}
    components.update({NATIVE[0]: NATIVE[1:]} if native else {})
    parameters = {**({"native": parameters.get("estimator", {})} if native else {}), **parameters}
    name = re.sub(r"[^A-Za-z0-9_-]", "_", path.stem)
    root = Element(f"{{{SSD}}}SystemStructureDescription",
                   {"version": "1.0", "name": name if IDENT.fullmatch(name) else f"ssp_{name}"})
    system = SubElement(root, f"{{{SSD}}}System", {"name": "diagram"})
    elements = SubElement(system, f"{{{SSD}}}Elements")
    for component_name, (fmu, inputs, outputs) in components.items():
        model = fmu.rsplit("/", 1)[-1]
        kinds = {v.name: v.type for v in MODELS[model].interface()}
        component = SubElement(elements, f"{{{SSD}}}Component", {
            "name": component_name, "type": "application/x-fmu-sharedlibrary", "source": f"resources/{fmu}.fmu"})
        connectors = SubElement(component, f"{{{SSD}}}Connectors")
        for kind, names in (("input", inputs), ("output", outputs)):
            for connector in names:
                node = SubElement(connectors, f"{{{SSD}}}Connector", {"name": connector, "kind": kind})
                SubElement(node, f"{{{SSC}}}{CONNECTOR_TYPE[kinds[connector]]}")
        if parameters.get(component_name):
            binding = SubElement(SubElement(component, f"{{{SSD}}}ParameterBindings"), f"{{{SSD}}}ParameterBinding")
            values = SubElement(binding, f"{{{SSD}}}ParameterValues")
            pset = SubElement(values, f"{{{SSV}}}ParameterSet", {"version": "1.0", "name": component_name})
            params = SubElement(pset, f"{{{SSV}}}Parameters")
            for variable, value in parameters[component_name].items():
                ssv_type, text = parameter_value(model, variable, value)
                SubElement(SubElement(params, f"{{{SSV}}}Parameter", {"name": variable}), f"{{{SSV}}}{ssv_type}",
                           {"value": text})
    connections = SubElement(system, f"{{{SSD}}}Connections")
    for start, start_connector, end, end_connector in CONNECTIONS + (NATIVE_CONNECTIONS if native else []):
        SubElement(connections, f"{{{SSD}}}Connection", {
            "startElement": start, "startConnector": start_connector,
            "endElement": end, "endConnector": end_connector})
    step = repr(float(step_size))
    # OMSimulator's SSP import reads the master from the FixedStepMaster inside (its relative
    # tolerance, OMSimulator's default, goes to fmi2SetupExperiment); its Python API (OMSimulator 3)
    # the attributes: a master of this name runs the co-simulation FMUs that name none
    oms = SubElement(SubElement(_annotation(system, "org.openmodelica"), f"{{{OMS}}}Annotations"),
                     f"{{{OMS}}}SimulationInformation", {"name": "oms_ma_default", "method": "oms_ma",
                                                          "fixedStepSize": step})
    SubElement(oms, f"{{{OMS}}}FixedStepMaster", {"description": "oms-ma", "stepSize": step,
                                                    "relativeTolerance": "0.0001"})
    experiment = SubElement(root, f"{{{SSD}}}DefaultExperiment",
                            {"startTime": "0.0", "stopTime": repr(float(stop_time))})
    SubElement(SubElement(_annotation(experiment, "com.opensimulationplatform"), f"{{{OSP}}}Algorithm"),
               f"{{{OSP}}}FixedStepAlgorithm", {"baseStepSize": step})
    with replaced(path) as fh, zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", tostring(root, xml_declaration=True, encoding="UTF-8"))
        for fmu in dict.fromkeys(fmu for fmu, _, _ in components.values()):
            zf.write(fmu_dir / f"{fmu}.fmu", f"resources/{fmu}.fmu")
    return path
