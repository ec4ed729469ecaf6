"""The SSP packages `attitude ssp` writes (systems.fmi.ssp), FMI 2.0 (native and pythonfmu) and FMI 3.0:
valid against the SSP 1.0 schema fmpy installs; parameters bound only as Real, Integer or Boolean
(the choices as their items' Integer values); annotations only where the schema allows them, of
the types OMSimulator and libcosim read, with the step; every connector and binding naming a
variable of its FMU of the matching type; what OMSimulator's SSP import checks (its sources,
named at omsimulator_refusals); libcosim runs them unchanged at their step, and the FMI 3.0
chain runs as the FMI 2.0 one."""
from __future__ import annotations

import io
import re
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave
from lxml import etree

from attitude_fmu.systems.fmi.interface.generate import MODELS
from attitude_fmu.systems.fmi.interface.variables import ENUMERATION, item_value
from attitude_fmu.systems.cli.commands import EXIT_BAD_INPUT, main
from attitude_fmu.systems.fmi.cosim import FmuRunner, cosimulate, cosimulate_libcosim
from attitude_fmu.systems.fmi.ssp import COMPONENTS, CONNECTIONS, write_ssp
from attitude_fmu.systems.fmi.verify import MOTION_SEED, STEP_S, write_verify_ssp

SCHEMA = Path(fmpy.__file__).parent / "ssp" / "schema"
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
      "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
      "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations"}
PROFILE, METHOD = "incline", "mahony"  # neither the FMUs' default
CHOICES = {"profile": PROFILE, "method": METHOD, "gyro_offset": "off"}  # what verify binds of the choices
# the SSV type of a binding (and the SSC type of a connector) → the FMU variable types it may name
TYPES = {"Real": {"Real", "Float64"}, "Boolean": {"Boolean"}, "Integer": {
    "Integer", "Int8", "Int16", "Int32", "Int64", "UInt8", "UInt16", "UInt32", "UInt64", "Enumeration"}}


@pytest.fixture(scope="module")
def packages(fmu_dir, tmp_path_factory) -> dict[str, Path]:
    """`attitude ssp` of one configuration for each chain: native FMI 2.0 (the default), pythonfmu, FMI 3.0."""
    out = tmp_path_factory.mktemp("ssp")
    args = ["--fmu-dir", str(fmu_dir), "--profile", PROFILE, "--method", METHOD]
    for chain, flags in (("native", []), ("python", ["--python"]), ("fmi3", ["--fmi-version", "3.0"])):
        assert main(["ssp", "--out", str(out / chain), *args, *flags]) == 0
    return {chain: out / chain / f"{PROFILE}_{METHOD}.ssp" for chain in ("native", "python", "fmi3")}


def _ssd(path) -> etree._Element:
    with zipfile.ZipFile(path) as zf:
        return etree.fromstring(zf.read("SystemStructure.ssd"))


def _name(element) -> str:
    """The element's name as written (prefix:local): what pugixml (OMSimulator) and boost's
    property tree (libcosim) match."""
    return f"{element.prefix}:{etree.QName(element).localname}"


def _model_descriptions(path, tmp_path) -> dict:
    """Component name → the model description of its FMU, read from the package."""
    with zipfile.ZipFile(path) as zf:
        zf.extractall(tmp_path / "unzipped")
    return {c.get("name"): read_model_description(str(tmp_path / "unzipped" / c.get("source")))
            for c in _ssd(path).iterfind("ssd:System/ssd:Elements/ssd:Component", NS)}


@pytest.mark.parametrize("chain", ["native", "python", "fmi3"])
def test_the_ssd_and_its_parameter_sets_are_valid_against_the_ssp_1_0_schema(packages, chain):
    ssd = _ssd(packages[chain])
    etree.XMLSchema(file=str(SCHEMA / "SystemStructureDescription.xsd")).assertValid(ssd)
    # the inline parameter sets are the schema's lax content of ParameterValues: each on its own
    values = etree.XMLSchema(file=str(SCHEMA / "SystemStructureParameterValues.xsd"))
    sets = ssd.findall(".//ssv:ParameterSet", NS)
    assert {s.get("name") for s in sets} >= {"motion", "estimator"}
    for pset in sets:
        values.assertValid(etree.ElementTree(etree.fromstring(etree.tostring(pset))))


@pytest.mark.parametrize("chain", ["native", "python", "fmi3"])
def test_every_connector_and_binding_names_a_variable_of_its_fmu_with_the_matching_type(packages, chain, tmp_path):
    """Read from each FMU's modelDescription.xml in the package: connectors are its inputs and
    outputs (all of them, each input fed by one connection from an output of the same type),
    bindings its parameters, and a choice is bound to the value of the item it names."""
    ssd = _ssd(packages[chain])
    mds = _model_descriptions(packages[chain], tmp_path)
    assert {md.fmiVersion for md in mds.values()} == {"3.0" if chain == "fmi3" else "2.0"}
    connectors = {}  # (component, connector) → (kind, type)
    for component in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        name, variables = component.get("name"), {v.name: v for v in mds[component.get("name")].modelVariables}
        for c in component.iterfind("ssd:Connectors/ssd:Connector", NS):
            (kind,) = c
            connectors[name, c.get("name")] = c.get("kind"), etree.QName(kind).localname
            assert variables[c.get("name")].causality == c.get("kind")
            assert variables[c.get("name")].type in TYPES[etree.QName(kind).localname]
        assert {c for n, c in connectors if n == name} == {
            v.name for v in variables.values() if v.causality in ("input", "output")}
        for p in component.iterfind(".//ssv:Parameter", NS):
            (value,) = p
            v, ssv_type = variables[p.get("name")], etree.QName(value).localname
            assert v.causality == "parameter" and v.type in TYPES[ssv_type], (name, v.name, v.type, ssv_type)
            if v.type == ENUMERATION:
                items = {item.name: int(item.value) for item in v.declaredType.items}
                assert int(value.get("value")) == items[CHOICES[v.name]]
    assert set(CHOICES) <= {p.get("name") for p in ssd.iterfind(".//ssv:Parameter", NS)}
    ends = []
    for c in ssd.iterfind("ssd:System/ssd:Connections/ssd:Connection", NS):
        start, end = connectors[c.get("startElement"), c.get("startConnector")], connectors[
            c.get("endElement"), c.get("endConnector")]
        assert start[0] == "output" and end[0] == "input" and start[1] == end[1]
        ends.append((c.get("endElement"), c.get("endConnector")))
    assert sorted(ends) == sorted(k for k, (kind, _) in connectors.items() if kind == "input")


@pytest.mark.parametrize("chain", ["native", "fmi3"])
def test_no_string_binding_and_the_choices_as_the_integers_of_their_items(packages, chain):
    """Every binding is Real, Integer or Boolean (libcosim and OMSimulator read no other
    together: OMSimulator no String, libcosim no Enumeration); each choice as its item's value in
    the project's tables (systems.fmi.interface.variables.item_value)."""
    ssd = _ssd(packages[chain])
    bound = {}
    for component in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        for p in component.iterfind(".//ssv:Parameter", NS):
            (value,) = p
            assert _name(value) in ("ssv:Real", "ssv:Integer", "ssv:Boolean")
            bound[p.get("name")] = (component.get("name"), _name(value), value.get("value"))
    assert b"ssv:String" not in etree.tostring(ssd)
    for variable, item in CHOICES.items():
        component, kind, value = bound[variable]
        table = {v.name: v for v in MODELS[COMPONENTS[component][0]].interface()}
        assert kind == "ssv:Integer" and int(value) == item_value(table[variable], item)


def test_an_unknown_parameter_or_item_is_refused_before_anything_is_written(fmu_dir, tmp_path):
    with pytest.raises(ValueError, match="AttitudeEstimator has no parameter 'methods'"):
        write_ssp(tmp_path / "a.ssp", fmu_dir, {"estimator": {"methods": "wiener"}}, 1.0, STEP_S, chain="native")
    with pytest.raises(ValueError, match="method must be one of"):
        write_ssp(tmp_path / "a.ssp", fmu_dir, {"estimator": {"method": "kalman"}}, 1.0, STEP_S, chain="native")
    assert not (tmp_path / "a.ssp").exists()


@pytest.mark.parametrize("chain", ["native", "python", "fmi3"])
def test_annotations_only_in_the_system_and_the_default_experiment_with_each_importers_step(packages, chain):
    """OMSimulator's fixed-step master in the System (org.openmodelica), libcosim's fixed-step
    algorithm in the DefaultExperiment (com.opensimulationplatform), both at verify's step; no
    other annotation, none at the top level."""
    ssd = _ssd(packages[chain])
    where = {(_name(a.getparent().getparent()), a.get("type")) for a in ssd.iterfind(".//ssc:Annotation", NS)}
    assert where == {("ssd:System", "org.openmodelica"), ("ssd:DefaultExperiment", "com.opensimulationplatform")}
    assert ssd.find("ssd:Annotations", NS) is None
    (master,) = ssd.findall("ssd:System/ssd:Annotations/ssc:Annotation/oms:Annotations/oms:SimulationInformation/"
                            "oms:FixedStepMaster", NS)
    (algorithm,) = ssd.findall("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation/osp:Algorithm/"
                               "osp:FixedStepAlgorithm", NS)
    assert float(master.get("stepSize")) == float(algorithm.get("baseStepSize")) == STEP_S
    # OMSimulator 3's Python API (OMSimulatorPython/system.py processElements): the master of the
    # FMUs that name none (all here), at the step
    assert master.getparent().attrib == {"name": "oms_ma_default", "method": "oms_ma", "fixedStepSize": str(STEP_S)}


OMS_IDENT = re.compile(r"[a-zA-Z][a-zA-Z0-9_-]*")  # ComRef.cpp re_ident


def omsimulator_refusals(path) -> list[str]:
    """What OMSimulator's SSP import (src/OMSimulatorLib of OpenModelica/OMSimulator, oms_importFile)
    would refuse in the package, by the checks of its sources:
    Scope.cpp importModel (SystemStructure.ssd; the SSD's name a valid identifier, ComRef.cpp
    re_ident, Model::NewModel); Model.cpp importFromSnapshot (the root's children: System, Units,
    Enumerations, DefaultExperiment only: "wrong xml schema detected") and getSystemType (the
    System's first ssc:Annotation of type org.openmodelica holds oms:Annotations/
    oms:SimulationInformation with a master, else no system type: addSystem fails);
    SystemWC.cpp importFromSSD_SimulationInformation and setSolverMethod (oms-ma, oms-mav,
    oms-mav2); System.cpp importFromSnapshot (the System's children; Elements of Components;
    type application/x-fmu-sharedlibrary; FMI 2.0 or 3.0 co-simulation FMUs by their
    modelDescription.xml); ComponentFMUCS.cpp and ComponentFMU3CS.cpp NewComponent (a
    Component's children: Connectors, ElementGeometry, ParameterBindings; names valid
    identifiers); Connector.cpp NewConnector (kind and type); Values.cpp importFromSnapshot and
    importStartValuesHelper (inline ParameterValues/ParameterSet/Parameters, each ssv:Real,
    ssv:Integer or ssv:Boolean: "Unknown ParameterBinding-type"); ComponentFMUCS.cpp setInteger
    and Variable.h isTypeInteger (an Integer binding names an Integer or Enumeration variable).
    Names are matched with their prefixes, as written (pugixml). OMSimulator 3's Python API
    (src/OMSimulatorPython: ssd.py, utils.py, system.py, connector.py) takes the same file: an
    ssd:System, each connection from an output connector to an input one of its elements (the
    test of the connectors), its master's step from oms:SimulationInformation's attributes."""
    refusals = []
    with zipfile.ZipFile(path) as zf:
        if "SystemStructure.ssd" not in zf.namelist():
            return ["no SystemStructure.ssd"]
        ssd = etree.fromstring(zf.read("SystemStructure.ssd"))
        fmus = {n: zf.read(n) for n in zf.namelist() if n.endswith(".fmu")}
    if _name(ssd) != "ssd:SystemStructureDescription" or ssd.get("version") not in ("Draft20180219", "1.0", "2.0"):
        refusals.append(f"root {_name(ssd)} version {ssd.get('version')}")
    if not OMS_IDENT.fullmatch(ssd.get("name") or ""):
        refusals.append(f"model name {ssd.get('name')!r}")
    refusals += [f"top level {_name(e)}" for e in ssd
                 if _name(e) not in ("ssd:System", "ssd:Units", "ssd:Enumerations", "ssd:DefaultExperiment")]
    for system in ssd.findall("ssd:System", NS):
        annotations = [a for a in system.findall("ssd:Annotations/*", NS) if _name(a) == "ssc:Annotation"][:1]
        info = [i for a in annotations if a.get("type") == "org.openmodelica" for o in a
                if _name(o) == "oms:Annotations" for i in o if _name(i) == "oms:SimulationInformation"]
        masters = [m for i in info for m in i if _name(m) in ("oms:FixedStepMaster", "oms:VariableStepMaster")]
        if not masters or masters[0].get("description") not in ("oms-ma", "oms-mav", "oms-mav2"):
            refusals.append("no system type (oms:SimulationInformation with a master)")
        refusals += [f"system child {_name(e)}" for e in system if _name(e) not in (
            "ssd:ElementGeometry", "ssd:ParameterBindings", "ssd:Connections", "ssd:Connectors", "ssd:Elements",
            "ssd:Annotations")]
        for component in system.findall("ssd:Elements/*", NS):
            name = component.get("name") or ""
            if _name(component) != "ssd:Component" or component.get("type") != "application/x-fmu-sharedlibrary":
                refusals.append(f"element {_name(component)} {component.get('type')}")
                continue
            if not OMS_IDENT.fullmatch(name):
                refusals.append(f"component name {name!r}")
            refusals += [f"{name}: child {_name(e)}" for e in component
                         if _name(e) not in ("ssd:Connectors", "ssd:ElementGeometry", "ssd:ParameterBindings")]
            source = component.get("source")
            if source not in fmus:
                refusals.append(f"{name}: no {source}")
                continue
            with zipfile.ZipFile(io.BytesIO(fmus[source])) as fmu:
                md = etree.fromstring(fmu.read("modelDescription.xml"))
            if md.get("fmiVersion") not in ("2.0", "3.0") or md.find("CoSimulation") is None:
                refusals.append(f"{name}: FMI {md.get('fmiVersion')} without co-simulation")
            types = {v.get("name"): [etree.QName(t).localname for t in v if etree.QName(t).localname not in (
                "Dimension", "Alias", "Annotations")] or [etree.QName(v).localname]
                for v in md.iter("ScalarVariable", "Float64", "Float32", "Int32", "Int64", "Boolean", "Enumeration")
                if v.get("name")}
            for c in component.findall("ssd:Connectors/*", NS):
                (kind,) = [_name(t) for t in c if _name(t).startswith("ssc:")] or ["none"]
                if c.get("kind") not in ("input", "output", "parameter", "calculatedParameter") or kind not in (
                        "ssc:Real", "ssc:Integer", "ssc:Boolean", "ssc:Enumeration"):
                    refusals.append(f"{name}.{c.get('name')}: connector {c.get('kind')} {kind}")
            for binding in component.findall("ssd:ParameterBindings/*", NS):
                parameters = [p for v in binding if _name(v) == "ssd:ParameterValues" for s in v
                              if _name(s) == "ssv:ParameterSet" for ps in s if _name(ps) == "ssv:Parameters"
                              for p in ps]
                for p in parameters:
                    value = [_name(t) for t in p]
                    fmu_type = (types.get(p.get("name")) or ["none"])[0]
                    if value not in (["ssv:Real"], ["ssv:Integer"], ["ssv:Boolean"]) or fmu_type not in TYPES[
                            value[0][4:]]:
                        refusals.append(f"{name}.{p.get('name')}: {value} for {fmu_type}")
    return refusals


def test_omsimulator_refusals_finds_what_omsimulator_rejected_in_the_former_ssp(packages, tmp_path):
    """The check finds the three faults OMSimulator reported in the SSPs this writer wrote before:
    a top-level annotation, String bindings, no system annotation it knows."""
    ssd = _ssd(packages["native"])
    system = ssd.find("ssd:System", NS)
    system.remove(system.find("ssd:Annotations", NS))
    etree.SubElement(etree.SubElement(ssd, f"{{{NS['ssd']}}}Annotations"), f"{{{NS['ssc']}}}Annotation",
                     type="org.attitude-fmu.step")
    ssd.find(".//ssv:Parameter[@name='method']/ssv:Integer", NS).tag = f"{{{NS['ssv']}}}String"
    old = tmp_path / "old.ssp"
    with zipfile.ZipFile(packages["native"]) as zf, zipfile.ZipFile(old, "w") as out:
        for n in zf.namelist():
            out.writestr(n, etree.tostring(ssd) if n == "SystemStructure.ssd" else zf.read(n))
    assert omsimulator_refusals(old) == ["top level ssd:Annotations",
                                         "no system type (oms:SimulationInformation with a master)",
                                         "estimator.method: ['ssv:String'] for Enumeration"]


@pytest.mark.parametrize("chain", ["native", "python", "fmi3"])
def test_omsimulator_would_import_the_package_as_it_is(packages, chain):
    assert omsimulator_refusals(packages[chain]) == []


def test_libcosim_runs_the_package_unchanged_at_its_step_each_component_as_fmpy(fmu_dir, tmp_path):
    """libcosim (CosimExecution.from_ssp_file without a step: the SSP's own) runs the native
    chain; the motion it records is our master's, and the sensor and the estimator, each under
    fmpy (FmuRunner) with the SSP's parameters on the inputs libcosim handed it, give libcosim's
    outputs: every Real and Integer binding came through (the choices at their defaults:
    libcosim ignores FMI 2.0 Enumeration variables, next test)."""
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.WARNING)
    parameters = {"motion": {"profile": "human", "seed": MOTION_SEED},
                  "imu": {"delta_n": 0.002, "acc_noise": 0.003, "seed": 5, "gyr_offset_z": 0.01},
                  "estimator": {"Ts": STEP_S, "delta_n": 0.002}}
    ssp = write_ssp(tmp_path / "human.ssp", fmu_dir, parameters, 2.0, STEP_S, chain="native")
    ex = CosimExecution.from_ssp_file(str(ssp))
    assert ex.step(10) and ex.status().current_time == 10 * round(STEP_S * 1e9)
    del ex
    theirs = cosimulate_libcosim(ssp, 2.0, STEP_S)
    ours = cosimulate(ssp, 2.0, STEP_S)
    motion = COMPONENTS["motion"][2]
    for n in motion:  # libcosim's time in integer nanoseconds: the same time points to rounding
        assert np.abs(theirs[f"motion.{n}"] - ours[f"motion.{n}"]).max() <= 1e-12 * np.abs(ours[f"motion.{n}"]).max()
    assert not np.array_equal(theirs["imu.gyr_x"], ours["imu.gyr_x"])  # one step later: the check below is not ours
    for name in ("imu", "estimator"):
        fmu, inputs, outputs = COMPONENTS[name]
        real = [n for n in outputs if n != "valid"]
        runner = FmuRunner(fmu_dir / "native" / f"{fmu}.fmu", parameters[name], inputs, real)
        try:
            out, valid = runner.run(np.column_stack([theirs[f"{name}.{n}"] for n in inputs]), STEP_S)
        finally:
            runner.close()
        assert np.abs(out - np.column_stack([theirs[f"{name}.{n}"] for n in real])).max() <= 1e-12
        if name == "estimator":
            assert np.array_equal(valid, theirs["estimator.valid"]) and valid[5:].all()


def test_libcosim_leaves_the_choices_at_their_start_values(fmu_dir, tmp_path):
    """libcosim ignores FMI 2.0 Enumeration variables (src/cosim/fmi/v2/fmu.cpp, since 2019): it
    runs the package, warns of the bindings it cannot apply and keeps their start values, the
    profile human here where incline is bound (the README says so)."""
    pytest.importorskip("libcosimpy")
    ssp = write_verify_ssp(tmp_path / "incline.ssp", fmu_dir, PROFILE, "wiener", "native")
    theirs = cosimulate_libcosim(ssp, 2.0, STEP_S)
    human = cosimulate(write_ssp(tmp_path / "human.ssp", fmu_dir, {"motion": {"profile": "human", "seed": MOTION_SEED}},
                                 2.0, STEP_S, chain="native"), 2.0, STEP_S)
    incline = cosimulate(ssp, 2.0, STEP_S)
    assert np.abs(theirs["motion.qt_x"] - human["motion.qt_x"]).max() <= 1e-12
    assert not np.array_equal(theirs["motion.qt_x"], incline["motion.qt_x"])


def _run_fmi3(path, stop_time: float, step: float, tmp_path) -> dict[str, np.ndarray]:
    """The FMI 3.0 package under fmpy's FMU3Slave, each component's SSP bindings set in
    initialisation mode by the variable's type, stepped in the order of CONNECTIONS with each
    input set from its source's output of the same step (our master's scheme, cosim.cosimulate):
    "component.output" per step."""
    ssd = _ssd(path)
    mds = _model_descriptions(path, tmp_path)
    slaves, variables = {}, {}
    for component in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        name, md = component.get("name"), mds[component.get("name")]
        variables[name] = {v.name: v for v in md.modelVariables}
        unzipped = extract(str(tmp_path / "unzipped" / component.get("source")), str(tmp_path / name))
        slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipped,
                          modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        slave.instantiate()
        slave.enterInitializationMode(startTime=0.0)
        for p in component.iterfind(".//ssv:Parameter", NS):
            (value,) = p
            v = variables[name][p.get("name")]
            setter = {"Float64": slave.setFloat64, "Int32": slave.setInt32, "Int64": slave.setInt64,
                      "Enumeration": slave.setInt64, "Boolean": slave.setBoolean}[v.type]
            text = value.get("value")
            setter([v.valueReference], [float(text) if v.type == "Float64" else text == "true" if v.type == "Boolean"
                                        else int(text)])
        slave.exitInitializationMode()
        slaves[name] = slave
    order = list(dict.fromkeys(n for c in CONNECTIONS for n in (c[0], c[2])))
    n = int(round(stop_time / step))
    record = {f"{c}.{o}": np.empty(n) for c in order for o in COMPONENTS[c][2] if o != "valid"}
    for k in range(n):
        for c in order:
            feeds = [(variables[c][end].valueReference, record[f"{start}.{out}"][k])
                     for start, out, to, end in CONNECTIONS if to == c]
            if feeds:
                slaves[c].setFloat64([vr for vr, _ in feeds], [v for _, v in feeds])
            slaves[c].doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
            outs = [o for o in COMPONENTS[c][2] if o != "valid"]
            for o, v in zip(outs, slaves[c].getFloat64([variables[c][o].valueReference for o in outs])):
                record[f"{c}.{o}"][k] = v
    for slave in slaves.values():
        slave.terminate()
        slave.freeInstance()
    return record


def test_the_fmi_3_0_package_runs_as_the_fmi_2_0_one(packages, tmp_path):
    """No SSP master here runs FMI 3.0 (libcosim reads FMI 1.0 and 2.0 only; fmpy's simulate_ssp
    FMI 2.0): the FMI 3.0 package under fmpy's FMU3Slave with its own bindings (the choices as
    Int64 item values) gives the FMI 2.0 package's outputs under our master, to the last bit."""
    theirs = _run_fmi3(packages["fmi3"], 2.0, STEP_S, tmp_path)
    ours = cosimulate(packages["native"], 2.0, STEP_S)
    for name in theirs:
        assert np.array_equal(theirs[name], ours[name]), name


def test_attitude_ssp_refuses_the_pythonfmu_chain_as_fmi_3_0(fmu_dir, tmp_path, capsys):
    args = ["ssp", "--out", str(tmp_path), "--fmu-dir", str(fmu_dir), "--python", "--fmi-version", "3.0"]
    assert main(args) == EXIT_BAD_INPUT
    assert "pythonfmu FMUs are FMI 2.0 only" in capsys.readouterr().err and not list(tmp_path.iterdir())
