"""SSP 1.0 packages of the diagram motion → IMU sensor → estimator, self-contained: the three
FMUs inside (resources/), of one chain, native (DIR/native/*.fmu, in C) or pythonfmu (DIR/*.fmu),
their parameters inline in the SSD; with the native estimator (DIR/native/AttitudeEstimator.fmu)
beside the estimator, fed the same sensor signals, where asked."""
from __future__ import annotations

import zipfile
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, register_namespace, tostring

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
# the standard's own prefixes: importers that match element names literally (libcosim) need them
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV)):
    register_namespace(_prefix, _uri)
XYZ = ("x", "y", "z")

# component name → (FMU, inputs, outputs)
COMPONENTS = {
    "motion": ("MotionProfile", [], [f"{s}_{a}" for s in ("omega", "f", "m") for a in XYZ]
               + ["qt_w", "qt_x", "qt_y", "qt_z"]),
    "imu": ("ImuSensor", [f"{s}_{a}" for s in ("omega", "f", "m") for a in XYZ],
            [f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in XYZ]),
    "estimator": ("AttitudeEstimator", [f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in XYZ],
                  ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw", "valid"]),
}
CONNECTIONS = [("motion", f"{s}_{a}", "imu", f"{s}_{a}") for s in ("omega", "f", "m") for a in XYZ] + [
    ("imu", f"{s}_{a}", "estimator", f"{s}_{a}") for s in ("gyr", "acc", "mag") for a in XYZ
]
# the native estimator: the pythonfmu one's interface, in C (systems.fmi.native)
NATIVE = ("native", "native/AttitudeEstimator", *COMPONENTS["estimator"][1:])
NATIVE_CONNECTIONS = [("imu", f"{s}_{a}", "native", f"{s}_{a}") for s in ("gyr", "acc", "mag") for a in XYZ]
SSV_TYPE = {str: "String", bool: "Boolean", int: "Integer", float: "Real"}
CHAINS = {"native": "native/", "python": ""}  # where under the FMU folder each chain's three FMUs are


def write_ssp(path, fmu_dir, parameters: dict[str, dict], stop_time: float, step_size: float,
              native: bool = False, chain: str = "python") -> Path:
    """Write an SSP with the three FMUs of the chain ("python": fmu_dir/*.fmu, "native":
    fmu_dir/native/*.fmu) and inline parameter values; with native, also the native estimator
    from fmu_dir/native, component "native", with the estimator's parameters unless parameters
    names its own.

    parameters: component name → {variable: value}; the value's Python type picks the SSV
    type (str String, bool Boolean, int Integer, float Real).
    """
    path, fmu_dir = Path(path), Path(fmu_dir)
    components = {name: (CHAINS[chain] + fmu, *rest) for name, (fmu, *rest) in COMPONENTS.items()}
    components.update({NATIVE[0]: NATIVE[1:]} if native else {})
    parameters = {**({"native": parameters.get("estimator", {})} if native else {}), **parameters}
    root = Element(f"{{{SSD}}}SystemStructureDescription", {"version": "1.0", "name": path.stem})
    system = SubElement(root, f"{{{SSD}}}System", {"name": "diagram"})
    elements = SubElement(system, f"{{{SSD}}}Elements")
    for name, (fmu, inputs, outputs) in components.items():
        component = SubElement(elements, f"{{{SSD}}}Component", {
            "name": name, "type": "application/x-fmu-sharedlibrary", "source": f"resources/{fmu}.fmu"})
        connectors = SubElement(component, f"{{{SSD}}}Connectors")
        for kind, names in (("input", inputs), ("output", outputs)):
            for connector in names:
                node = SubElement(connectors, f"{{{SSD}}}Connector", {"name": connector, "kind": kind})
                SubElement(node, f"{{{SSC}}}{'Boolean' if connector == 'valid' else 'Real'}")
        if parameters.get(name):
            binding = SubElement(SubElement(component, f"{{{SSD}}}ParameterBindings"), f"{{{SSD}}}ParameterBinding")
            values = SubElement(binding, f"{{{SSD}}}ParameterValues")
            pset = SubElement(values, f"{{{SSV}}}ParameterSet", {"version": "1.0", "name": name})
            params = SubElement(pset, f"{{{SSV}}}Parameters")
            for variable, value in parameters[name].items():
                parameter = SubElement(params, f"{{{SSV}}}Parameter", {"name": variable})
                text = str(value).lower() if isinstance(value, bool) else repr(value) if isinstance(value, float) else str(value)
                SubElement(parameter, f"{{{SSV}}}{SSV_TYPE[type(value)]}", {"value": text})
    connections = SubElement(system, f"{{{SSD}}}Connections")
    for start, start_connector, end, end_connector in CONNECTIONS + (NATIVE_CONNECTIONS if native else []):
        SubElement(connections, f"{{{SSD}}}Connection", {
            "startElement": start, "startConnector": start_connector,
            "endElement": end, "endConnector": end_connector})
    SubElement(root, f"{{{SSD}}}DefaultExperiment", {"startTime": "0", "stopTime": repr(float(stop_time))})
    annotation = SubElement(SubElement(root, f"{{{SSD}}}Annotations"), f"{{{SSC}}}Annotation",
                            {"type": "org.attitude-fmu.step"})
    SubElement(annotation, "Step", {"size": repr(float(step_size))})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", tostring(root, xml_declaration=True, encoding="UTF-8"))
        for fmu in dict.fromkeys(fmu for fmu, _, _ in components.values()):
            zf.write(fmu_dir / f"{fmu}.fmu", f"resources/{fmu}.fmu")
    return path
