"""The model descriptions and metadata of every FMU the build makes (native FMI 2.0 and 3.0, and
the pythonfmu ones), held to what strict importers and engineers expect: fmpy's validation and
the FMU Manipulation Toolbox's check (the FMI schemas and the standard's semantic rules) clean; no
start value NaN; the choices Enumerations whose items the command line spells; the default
experiment, output dependencies, display units and quantities, version, copyright, license,
generation time, documentation/ and every header named in buildDescription.xml; a step other
than Ts answered with fmi2OK and noted once; an Enumeration value none of its items has refused."""
import math
import re
import shutil
import subprocess
import sys
import zipfile
from ctypes import byref
from datetime import datetime
from html.parser import HTMLParser
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64
from fmpy.validation import validate_fmu

from attitude_fmu.blocks.pipeline.online import OnlineEstimator
from attitude_fmu.build_fmu import project_version
from attitude_fmu.systems.fmi.interface import generate
from attitude_fmu.systems.cli.commands import build_parser
from attitude_fmu.systems.fmi.cosim import FmuRunner, start_values
from attitude_fmu.systems.simulation.motion import PROFILES

ROOT = Path(__file__).resolve().parent.parent
NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")
FMUS = [*NAMES, *(f"native/{n}" for n in NAMES), *(f"native/fmi3/{n}" for n in NAMES)]  # under fmu_dir
NATIVE = [f for f in FMUS if f.startswith("native/")]
INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]
TS = 0.01


def _description(fmu) -> ElementTree.Element:
    with zipfile.ZipFile(fmu) as zf:
        return ElementTree.fromstring(zf.read("modelDescription.xml"))


def _choices() -> dict[str, tuple[list[str], str]]:
    """The command line's choices (`attitude estimate`'s flags) and the motion profiles' names:
    variable name → (the names it takes, its default)."""
    estimate = next(a for a in build_parser()._actions if a.dest == "command").choices["estimate"]
    flags = {a.dest: (list(a.choices), a.default) for a in estimate._actions if a.choices}
    wanted = ("method", "heading", "gyro_offset", "gyr_samples", "acc_samples")
    return {**{name: flags[name] for name in wanted}, "profile": (list(PROFILES), "human")}


@pytest.mark.parametrize("path", FMUS)
def test_every_fmu_passes_fmpy_and_the_fmu_manipulation_toolbox_checks(fmu_dir, path):
    """fmpy.validate_fmu finds no problem; `fmutool -check` (the FMI schema of the FMU's version
    and the standard's rules on causality, variability, initial, start values and model
    structure) reports no error and no warning and exits 0."""
    fmu = fmu_dir / f"{path}.fmu"
    assert validate_fmu(str(fmu)) == [], path
    proc = subprocess.run([sys.executable, "-m", "fmu_manipulation_toolbox.cli.fmutool", "-input", str(fmu),
                           "-check"], capture_output=True, text=True, timeout=300)
    log = proc.stdout + proc.stderr
    assert proc.returncode == 0 and "compliant with FMI-" in log and "No semantic error" in log, log
    assert not [line for line in log.splitlines() if not line.startswith("INFO")], log


def test_the_toolbox_check_reports_a_broken_model_description(fmu_dir, tmp_path):
    """The check above can fail: an output listed with a dependency on itself and a duplicated
    variable name make `fmutool -check` exit non-zero."""
    source = fmu_dir / "native" / "MotionProfile.fmu"
    broken = tmp_path / "MotionProfile.fmu"
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(broken, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'name="omega_y"', b'name="omega_x"', 1)
            dst.writestr(item, data)
    proc = subprocess.run([sys.executable, "-m", "fmu_manipulation_toolbox.cli.fmutool", "-input", str(broken),
                           "-check"], capture_output=True, text=True, timeout=300)
    assert proc.returncode != 0 and "omega_x" in proc.stdout + proc.stderr


@pytest.mark.parametrize("path", FMUS)
def test_no_start_value_is_nan_and_the_choices_are_enumerations_with_the_command_lines_items(fmu_dir, path):
    """Every variable that has a start value has a number (no NaN "unset"); each choice is an
    Enumeration (no String variable is left) whose items are the command line's names, valued
    1, 2, ..., n, starting at the command line's default."""
    md = read_model_description(str(fmu_dir / f"{path}.fmu"))
    choices = _choices()
    for v in md.modelVariables:
        assert v.type != "String", v.name
        if v.start is not None and v.type != "Boolean":
            assert not math.isnan(float(v.start)), v.name
        if v.name in choices:
            names, default = choices[v.name]
            assert v.type == "Enumeration", v.name
            items = {i.name: int(i.value) for i in v.declaredType.items}
            assert sorted(items) == sorted(names) and sorted(items.values()) == list(range(1, len(names) + 1))
            assert int(v.start) == items[default], v.name
    assert {v.name for v in md.modelVariables if v.type == "Enumeration"} <= set(choices)


@pytest.mark.parametrize("path", FMUS)
def test_the_metadata_an_engineer_expects(fmu_dir, path):
    """A default experiment (0 to a stop time at the default Ts); every output listed in the model
    structure with no dependency on an input within the step; roll, pitch and yaw in rad shown in
    deg (the unit's display unit, an Angle type); quantities on the physical types; the project's
    version, copyright and MIT license; a generation time."""
    root = _description(fmu_dir / f"{path}.fmu")
    experiment = root.find("DefaultExperiment")
    assert float(experiment.get("startTime")) == 0.0 and float(experiment.get("stepSize")) == TS
    assert float(experiment.get("stopTime")) > 0.0
    fmi3 = root.get("fmiVersion") == "3.0"
    variables = list(root.find("ModelVariables"))
    outputs = [v for v in variables if v.get("causality") == "output"]
    listed = root.find("ModelStructure").findall("Output" if fmi3 else "Outputs/Unknown")
    assert len(listed) == len(outputs) > 0
    assert all(u.get("dependencies") == "" for u in listed)
    assert root.get("version") == project_version() and "attitude-fmu authors" in root.get("copyright")
    assert root.get("license").startswith("MIT")
    datetime.strptime(root.get("generationDateAndTime"), "%Y-%m-%dT%H:%M:%S%z")
    types = {t.get("name"): (t if fmi3 else t[0]) for t in root.find("TypeDefinitions")}
    units = {u.get("name"): u for u in root.find("UnitDefinitions")}
    for v in variables:
        typed = v if fmi3 else v[0]
        unit = typed.get("unit")
        if unit in ("rad", "rad/s", "m/s2", "uT"):
            declared = types[typed.get("declaredType")]
            assert declared.get("quantity") == {"rad": "Angle", "rad/s": "AngularVelocity", "m/s2": "Acceleration",
                                                "uT": "MagneticFluxDensity"}[unit], v.get("name")
    if "AttitudeEstimator" in path:
        deg = units["rad"].find("DisplayUnit")
        assert deg.get("name") == "deg" and float(deg.get("factor")) == pytest.approx(180 / math.pi, rel=1e-15)
        for name in ("roll", "pitch", "yaw"):
            typed = next(v if fmi3 else v[0] for v in variables if v.get("name") == name)
            assert types[typed.get("declaredType")].get("displayUnit") == "deg", name


def test_the_generation_time_is_source_date_epochs_so_a_build_repeats(monkeypatch):
    """With SOURCE_DATE_EPOCH set, every generated file (model description, sources, documentation)
    is the same at each generation, and the model description gives that time."""
    sources = {"models/MotionProfile.c": (ROOT / "fmu_src" / "models" / "MotionProfile.c").read_bytes()}
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1000000000")
    first = generate.generated_files("MotionProfile", "3.0", "9.9", sources)
    assert b'generationDateAndTime="2001-09-09T01:46:40Z"' in first["modelDescription.xml"]
    assert generate.generated_files("MotionProfile", "3.0", "9.9", sources) == first


class _Text(HTMLParser):
    """The text of the <code> elements and the links of an HTML page."""

    def __init__(self):
        super().__init__()
        self.code, self.links, self._in_code = [], [], False

    def handle_starttag(self, tag, attrs):
        self._in_code = tag == "code"
        self.links += [value for name, value in attrs if tag == "a" and name == "href"]

    def handle_data(self, data):
        if self._in_code:
            self.code.append(data)
            self._in_code = False


@pytest.mark.parametrize("path", FMUS)
def test_the_documentation_lists_every_variable_and_carries_the_license(fmu_dir, path):
    """documentation/index.html names every variable with its unit and says when inputs are taken
    and outputs hold; documentation/licenses/LICENSE is the project's LICENSE."""
    fmu = fmu_dir / f"{path}.fmu"
    md = read_model_description(str(fmu))
    with zipfile.ZipFile(fmu) as zf:
        page = zf.read("documentation/index.html").decode("utf-8")
        assert zf.read("documentation/licenses/LICENSE") == (ROOT / "LICENSE").read_bytes()
    parsed = _Text()
    parsed.feed(page)
    listed = [v for v in md.modelVariables if v.causality != "independent"]  # FMI 3.0's time aside
    assert parsed.code == [v.name for v in sorted(listed, key=lambda v: (
        ("input", "output", "parameter").index(v.causality), v.valueReference))]
    assert "licenses/LICENSE" in parsed.links and "t[k+1]" in page
    for v in md.modelVariables:
        if v.unit is not None:
            assert f"<td>{v.unit}" in page.replace("&#x27;", "'"), v.name


@pytest.mark.parametrize("path", NATIVE)
def test_build_description_names_every_header_the_sources_include(fmu_dir, path):
    """Every file a C or header file of sources/ includes in quotes is in sources/ (the include
    directory, or beside the including file), or is one of the FMI standard's headers;
    buildDescription.xml names each (the FMI 3.0 FMUs need FMI 2.0's headers too) and lists
    every C file. (Headers in angle brackets but the FMI ones are the C library's.)"""
    with zipfile.ZipFile(fmu_dir / f"{path}.fmu") as zf:
        sources = {n.removeprefix("sources/"): zf.read(n) for n in zf.namelist() if n.startswith("sources/")}
    build = ElementTree.fromstring(sources["buildDescription.xml"]).find("BuildConfiguration")
    described = build.get("description")
    assert sorted(f.get("name") for f in build.iter("SourceFile")) == sorted(p for p in sources if p.endswith(".c"))
    fmi_headers = set()
    for name, data in sources.items():
        if not name.endswith((".c", ".h")):
            continue
        for bracket, included in re.findall(rb'^\s*#\s*include\s*([<"])([^>"]+)[>"]', data, re.MULTILINE):
            header = included.decode()
            beside = (Path(name).parent / header).as_posix()
            if header.startswith(("fmi2", "fmi3")) and header not in sources and beside not in sources:
                fmi_headers.add(header)
            elif bracket == b'"':  # the FMU's own: in sources/
                assert header in sources or beside in sources, (name, header)
                assert Path(header).name in described, (name, header)
    assert fmi_headers and all(h in described for h in fmi_headers), fmi_headers
    if "fmi3" in path:
        assert {"fmi2Functions.h", "fmi3Functions.h"} <= fmi_headers and "FMI 2.0" in described


def _logged_fmi2(fmu, parameters):
    """An FMI 2.0 FMU instantiated with every log category on, initialised with parameters:
    (slave, value references, the messages (status, text) it logs, its folder)."""
    md = read_model_description(str(fmu))
    unzipped = extract(str(fmu))
    messages = []
    logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: messages.append(
        (status, message.decode())))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="strict")
    slave.instantiate(callbacks=fmi2CallbackFunctions(logger=logger), loggingOn=True)
    slave.setDebugLogging(True, [])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    variables = {v.name: v for v in md.modelVariables}
    for name, value in start_values(md, parameters).items():
        (slave.setInteger if isinstance(value, int) else slave.setReal)([variables[name].valueReference], [value])
    slave.exitInitializationMode()
    return slave, {n: v.valueReference for n, v in variables.items()}, messages, unzipped


@pytest.mark.parametrize("path", ["AttitudeEstimator", "native/AttitudeEstimator"])
def test_a_step_other_than_ts_returns_fmi2_ok_and_logs_nothing(fmu_dir, path):
    """A master that steps 0.01, 0.02, 0.005 and 0.013 s (the estimator's Ts 0.01 s): every doStep
    returns fmi2OK (no warning a strict importer would take for a failure), each running the samples of
    the Ts grid it reaches; no message but of status fmi2OK, none of the step size."""
    slave, vr, messages, unzipped = _logged_fmi2(fmu_dir / f"{path}.fmu", {"method": "tseng"})
    statuses, t = [], 0.0
    for h in [TS, 2 * TS, TS / 2, 0.013, TS] * 4:
        slave.setReal([vr[n] for n in INPUTS], [0.01, 0.0, -0.02, 0.1, 0.2, 9.8])
        statuses.append(slave.fmi2DoStep(slave.component, t, h, 1))
        t += h
    assert statuses == [0] * len(statuses)
    assert not [m for m in messages if "differs from Ts" in m[1] or m[0] != 0]
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


def test_the_fmi3_estimator_answers_another_step_with_fmi3_ok(fmu_dir):
    """FMI 3.0's doStep at 0.01, 0.03 and 0.0025 s (Ts 0.01 s): fmi3OK each time."""
    fmu = fmu_dir / "native" / "fmi3" / "AttitudeEstimator.fmu"
    md = read_model_description(str(fmu))
    unzipped = extract(str(fmu))
    slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="AttitudeEstimator", instanceName="s3")
    slave.instantiate()
    slave.enterInitializationMode(startTime=0.0)
    slave.exitInitializationMode()
    statuses, t = [], 0.0
    event, terminate, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
    for h in (TS, 0.03, TS / 4):
        statuses.append(slave.fmi3DoStep(slave.component, t, h, True, byref(event), byref(terminate), byref(early),
                                         byref(last)))
        t += h
    assert statuses == [0, 0, 0]
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


@pytest.mark.parametrize("path, name, value", [
    ("native/AttitudeEstimator", "method", 7), ("native/AttitudeEstimator", "acc_samples", 0),
    ("native/MotionProfile", "profile", 99), ("native/fmi3/AttitudeEstimator", "heading", 3),
    ("native/fmi3/MotionProfile", "profile", -5), ("native/fmi3/AttitudeEstimator", "method", 2**40 + 1),
])
def test_an_enumeration_value_none_of_its_items_has_is_refused_with_an_error(fmu_dir, path, name, value, capsys):
    """fmi2SetInteger (FMI 3.0: fmi3SetInt64, also beyond 32 bits) of a value outside 1 ... n:
    an error status, a message naming the items, the value unchanged."""
    fmu = fmu_dir / f"{path}.fmu"
    md = read_model_description(str(fmu))
    variable = next(v for v in md.modelVariables if v.name == name)
    unzipped = extract(str(fmu))
    three = md.fmiVersion == "3.0"
    slave = (FMU3Slave if three else FMU2Slave)(guid=md.guid, unzipDirectory=unzipped,
                                                 modelIdentifier=md.coSimulation.modelIdentifier, instanceName="e")
    slave.instantiate(loggingOn=True)
    with pytest.raises(FMICallException) as info:
        (slave.setInt64 if three else slave.setInteger)([variable.valueReference], [value])
    assert info.value.status == 3
    log = capsys.readouterr().out
    items = ", ".join(f"{i.value} {i.name}" for i in variable.declaredType.items)
    assert (f"{name} must be one of its items ({items}), got {value}" in log
            or value > 2**31 and "beyond the range" in log), log
    slave.reset()
    if three:
        slave.enterInitializationMode(startTime=0.0)
    else:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
    assert (slave.getInt64 if three else slave.getInteger)([variable.valueReference]) == [int(variable.start)]
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


@pytest.mark.parametrize("path", ["AttitudeEstimator", "native/AttitudeEstimator"])
def test_the_projects_master_and_fmpy_set_a_choice_by_its_item_name(fmu_dir, path):
    """systems.fmi.cosim takes the item names (FmuRunner's parameters; start_values for fmpy's
    simulate_fmu) and the FMU runs that method: blocks.pipeline.online's luinge, not wiener."""
    rng = np.random.default_rng(3)
    rows = np.column_stack([rng.normal(0.0, 0.3, (200, 3)), rng.normal(0.0, 0.5, (200, 3)) + [0.0, 0.0, 9.81]])
    expected = OnlineEstimator("luinge", gyro_offset=False)
    quat = []
    for row in rows:
        expected.step(row[:3], row[3:], TS)
        quat.append(expected.quat)
    runner = FmuRunner(fmu_dir / f"{path}.fmu", {"method": "luinge", "gyro_offset": "off"}, INPUTS, ["q_w", "q_x"])
    out, _ = runner.run(rows, TS)
    runner.close()
    assert np.abs(out - np.array(quat)[:, :2]).max() < 1e-9
    fmu = str(fmu_dir / f"{path}.fmu")
    given = start_values(read_model_description(fmu), {"method": "luinge", "gyro_offset": "off", "Ts": TS})
    assert given == {"method": 4, "gyro_offset": 2, "Ts": TS}
    signals = np.zeros(len(rows), dtype=[("time", float)] + [(n, float) for n in INPUTS])
    signals["time"] = np.arange(len(rows)) * TS
    for j, n in enumerate(INPUTS):
        signals[n] = rows[:, j]
    result = simulate_fmu(fmu, start_values=given, input=signals, step_size=TS, output_interval=TS,
                          stop_time=len(rows) * TS, output=["q_w", "q_x"])
    assert np.abs(np.column_stack([result["q_w"], result["q_x"]])[1:] - out).max() < 1e-9
