"""The native AttitudeEstimator.fmu (in C, no Python: its own configuration, design and
discretisation on the C core): the outputs of blocks.pipeline.online's step (the same core
behind Python's c2d) on every configuration, in a C host (plain and built with sanitizers),
under fmpy and libcosim; the FMI state machine, FMU states, logging; what its binary links and
what its zip holds; its source FMU compiled by fmpy; the package without its native FMUs."""
import itertools
import math
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from elftools.elf.dynamic import DynamicSection
from elftools.elf.elffile import ELFFile
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.causal import MAX_ACC_M_S2, MAX_GYR_RAD_S, valid_sample
from attitude_fmu.blocks.pipeline.online import OnlineEstimator
from attitude_fmu.blocks.stages.timing import grid_samples
from attitude_fmu.systems.fmi.interface.variables import ENUMERATION, attitude_estimator
from attitude_fmu.systems.fmi import native
from attitude_fmu.systems.fmi.build import build_fmus
from attitude_fmu.systems.fmi.cosim import cosimulate_libcosim
from attitude_fmu.systems.fmi.ssp import write_ssp
from tests import native as c_build
from tests.test_real_data import _turns_with_field

ROOT = Path(__file__).resolve().parent.parent
BROAD = Path(os.environ.get("BROAD_DIR", ROOT.parent / "shared" / "broad"))
INPUTS = [f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in "xyz"]
OUTPUTS = ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw", *(f"gyr_offset_{a}" for a in "xyz"),
           *(f"mag_offset_{a}" for a in "xyz"), "mag_delay_used"]
START = np.array([1.0, 0, 0, 0, 0, 0, 1.0, *[0.0] * 10])  # the outputs' start values
TS = 0.01
CONFIGS = [dict(zip(("method", "heading", "gyro_offset", "gyr_samples", "acc_samples", "latency"), c))
           for c in itertools.product(sorted(METHODS), ("mag", "gyro"), ("on", "off"), ("mean", "point"),
                                      ("point", "mean"), (0.0, 0.004))]
BAD_ROWS = {300: ("gyr_x", math.nan), 450: ("acc_z", math.inf), 600: ("gyr_y", 1.01 * MAX_GYR_RAD_S),
            750: ("acc_x", -1.01 * MAX_ACC_M_S2), 1050: ("gyr_z", -math.inf)}
SANITIZER_REPORTS = ("AddressSanitizer", "LeakSanitizer", "runtime error", "UndefinedBehaviorSanitizer")


def stream(duration: float = 13.0, fast: float = 10.0, delay: int = 4):
    """Rows (t, h, gyr, acc, mag) of turning motion with a rest, a 0.2 °/s gyro offset, hard iron
    (12, −7, 4) µT and a magnetometer `delay` samples late: at TS up to `fast` s, then at 2·TS
    (the gyro's mean over both, the others at the later sample). The first three samples have
    no accelerometer (not started); BAD_ROWS carry a non-finite or out-of-range value; the
    magnetometer has no sample (NaN) for 0.1 s and is all 0 once."""
    _, gyr, acc, mag = _turns_with_field(rest=(2.0, 6.0), duration=duration)
    mag = np.vstack([np.repeat(mag[:1], delay, axis=0), mag[:-delay]]) + np.array([12.0, -7.0, 4.0])
    n = int(round(fast / TS))
    slow = (len(gyr) - n) // 2
    gyr = np.vstack([gyr[:n], 0.5 * (gyr[n:n + 2 * slow:2] + gyr[n + 1:n + 2 * slow:2])])
    acc = np.vstack([acc[:n], acc[n + 1:n + 2 * slow:2]])
    mag = np.vstack([mag[:n], mag[n + 1:n + 2 * slow:2]])
    h = np.r_[np.full(n, TS), np.full(slow, 2 * TS)]
    rows = np.column_stack([np.r_[0.0, np.cumsum(h)[:-1]], h, gyr, acc, mag])
    rows[:3, 5:8] = 0.0
    for k, (name, value) in BAD_ROWS.items():
        rows[k, 2 + INPUTS.index(name)] = value
    rows[500:510, 8:11] = math.nan
    rows[550, 8:11] = 0.0
    return rows


def reference(config: dict, rows, params=None):
    """blocks.pipeline.online's step on the rows (t, h, inputs) with the FMU's configuration, on the TS
    grid: each row runs the samples of TS its step reaches (blocks.stages.timing.grid_samples; a step of
    2·TS two, on the same inputs). The outputs (held where a sample is not taken), valid, and the status
    the FMU returns (1: a warning for an input not taken that is invalid)."""
    est = OnlineEstimator(config["method"], params, heading=config["heading"] == "mag",
                          gyro_offset=config["gyro_offset"] == "on", latency=config["latency"],
                          gyr_samples=config["gyr_samples"], acc_samples=config["acc_samples"])
    out, valid, status = np.empty((len(rows), len(OUTPUTS))), np.empty(len(rows), bool), np.zeros(len(rows))
    last, taken = START, False
    for k, (t, h, *u) in enumerate(rows):
        status[k] = 0
        for _ in range(int(grid_samples(0.0, TS, t, h))):
            taken = est.step(u[0:3], u[3:6], TS, u[6:9])
            if taken:
                last = np.r_[est.quat, est.up, est.euler, est.offset, est.mag_offset, est.mag_delay]
            elif not valid_sample(u[0:3], u[3:6]):
                status[k] = 1
        valid[k] = taken
        out[k] = last
    return out, valid, status


def assert_equal(result, expected, label=""):
    (out, valid, status), (ref, ref_valid, ref_status) = result, expected
    assert len(out) == len(ref), label
    assert np.array_equal(status, ref_status), (label, np.flatnonzero(status != ref_status)[:5])
    assert np.array_equal(valid, ref_valid), (label, np.flatnonzero(valid != ref_valid)[:5])
    assert np.abs(out - ref).max() < 1e-9, (label, np.abs(out - ref).max(axis=0))


@pytest.fixture(scope="module")
def fmus(fmu_dir):
    """The native estimator as build_fmus copies it, and the no-op FMU of the same interface (built/)."""
    return {"AttitudeEstimator": fmu_dir / "native" / "AttitudeEstimator.fmu",
            "NoOpEstimator": native.built("native/NoOpEstimator.fmu")}


@pytest.fixture(scope="module")
def md(fmus):
    return read_model_description(str(fmus["AttitudeEstimator"]))


@pytest.fixture(scope="module")
def vr(md):
    return {v.name: v.valueReference for v in md.modelVariables}


@pytest.fixture(scope="module")
def unzipped(fmus, tmp_path_factory):
    return Path(extract(str(fmus["AttitudeEstimator"]), str(tmp_path_factory.mktemp("unzipped"))))


@pytest.fixture(scope="module")
def rows():
    return stream()


@pytest.fixture(scope="module")
def references(rows):
    return [reference(config, rows) for config in CONFIGS]


@pytest.fixture(scope="module")
def runner():
    """tests/fmi_runner.c, a CMake target (tests/native.py)."""
    return {"plain": c_build.build(["fmi_runner"]) / "tests" / "fmi_runner"}


@pytest.fixture(scope="module")
def sanitized(tmp_path_factory):
    """tests/fmi_runner.c and the native estimator built with the address and undefined-behaviour
    sanitizers (and -Werror: the sources are -Wall -Wextra clean): (the runner, the FMU's binary)."""
    folder = c_build.build(["fmi_runner", "fmus"], sanitize=True)
    unzipped = Path(extract(str(folder / "built" / "native" / "AttitudeEstimator.fmu"),
                            str(tmp_path_factory.mktemp("sanitized"))))
    return folder / "tests" / "fmi_runner", unzipped / native.binary_path("AttitudeEstimator")


def run_script(runner, lines, folder, sanitized=False):
    """The runner on a script of lines; (statuses of its FMI calls in order, the whole stdout, stderr)."""
    script = Path(folder) / "script.txt"
    script.write_text("\n".join(lines) + "\n")
    env = {**os.environ, "ASAN_OPTIONS": "detect_leaks=1:halt_on_error=1", "UBSAN_OPTIONS": "print_stacktrace=1"}
    proc = subprocess.run([str(runner), str(script)], capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    if sanitized:
        assert not [r for r in SANITIZER_REPORTS if r in proc.stderr], proc.stderr[-3000:]
    return proc.stdout.split("\n"), proc.stdout, proc.stderr


def configure(vr, config, params=None):
    """Runner lines: back to the start, the configuration's parameters, initialised."""
    lines = ["reset", "setup", "enter"]
    lines += [f"integer {vr[k]} {ITEMS[k].index(config[k]) + 1}" for k in ITEMS]
    lines += [f"real {vr[name]} {value!r}" for name, value in {"latency": config["latency"], **(params or {})}.items()]
    return lines + ["exit"]


# the choices (Enumerations): their item names, of the values 1, 2, ...
ITEMS = {v.name: v.items for v in attitude_estimator() if v.type == ENUMERATION}


def initialise(fmu, vr, config):
    """An fmpy FMU2Slave back at the start and initialised with the configuration."""
    fmu.reset()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setInteger([vr[k] for k in ITEMS], [ITEMS[k].index(config[k]) + 1 for k in ITEMS])
    fmu.setReal([vr["latency"]], [config["latency"]])
    fmu.exitInitializationMode()


def fmpy_run(fmu, vr, rows):
    """rows (t, h, inputs) through an initialised FMU2Slave: (outputs, valid)."""
    vin, vout = [vr[n] for n in INPUTS], [vr[n] for n in OUTPUTS]
    out, valid = np.empty((len(rows), len(OUTPUTS))), np.empty(len(rows), bool)
    for k, (t, h, *u) in enumerate(rows):
        fmu.setReal(vin, u)
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        out[k], valid[k] = fmu.getReal(vout), fmu.getBoolean([vr["valid"]])[0]
    return out, valid


def replay_configs(runner, binary, md, vr, configs, rows, folder, sanitized=False, params=None):
    """Every configuration replayed on rows by one instance of the runner, fmi2Reset between them:
    (outputs, valid, status) of each."""
    folder = Path(folder)
    data = folder / "rows.bin"
    np.ascontiguousarray(rows, dtype=float).tofile(data)
    lines = [f"load {binary}", f"instantiate {md.guid} {Path(binary).parent.as_uri()} 0"]
    outs = []
    for i, config in enumerate(configs):
        outs.append(folder / f"out{i}.bin")
        outs[-1].unlink(missing_ok=True)
        lines += configure(vr, config, params)
        lines.append(f"replay {data} {outs[-1]} 9 {' '.join(str(vr[n]) for n in INPUTS)} {len(OUTPUTS)} "
                     f"{' '.join(str(vr[n]) for n in OUTPUTS)} 1 {vr['valid']}")
    lines += ["free", "unload"]
    _, stdout, _ = run_script(runner, lines, folder, sanitized)
    assert stdout.count("exit 0") == len(configs), stdout[-2000:]
    results = []
    for out in outs:
        table = np.fromfile(out).reshape(-1, 2 + len(OUTPUTS))
        results.append((table[:, 1:-1], table[:, -1] == 1.0, table[:, 0]))
    return results


def test_every_configuration_in_a_c_host_equals_the_python_step(runner, unzipped, md, vr, rows, references, tmp_path):
    """Every method × heading × gyro_offset × gyr_samples × acc_samples × latency, on a stream
    with a rest, a gyro offset, hard iron, a late magnetometer, a changed step size midway,
    non-finite and out-of-range inputs: the FMU's binary in a C host with no Python gives every
    output of blocks.pipeline.online's step within 1e-9, its valid and the status it implies."""
    binary = unzipped / native.binary_path("AttitudeEstimator")
    results = replay_configs(runner["plain"], binary, md, vr, CONFIGS, rows, tmp_path)
    for config, result, expected in zip(CONFIGS, results, references):
        assert_equal(result, expected, config)
    out, valid, status = results[0]
    for k in BAD_ROWS:  # held, not valid, a warning; taken again on the next sample
        assert not valid[k] and status[k] == 1 and np.array_equal(out[k], out[k - 1]) and valid[k + 1]
    assert not valid[:3].any() and not status[:3].any()  # no accelerometer yet: not started, no warning
    assert set(np.flatnonzero(status)) == set(BAD_ROWS)  # the step size's change midway: fmi2OK
    assert np.abs(out[-1, 10:13]).max() > 0  # the gyro offset estimated


@pytest.mark.slow
def test_the_binary_built_with_sanitizers_runs_every_configuration_without_a_report(sanitized, md, vr, rows, references,
                                                                                    tmp_path):
    """The same replay, the FMI robustness script and 1000 instance cycles with the estimator's
    sources built with -fsanitize=address,undefined in a C host built alike (no LD_PRELOAD):
    no sanitizer report, no leak, and the same results."""
    sanitized_runner, sanitized_binary = sanitized
    configs = CONFIGS[::4]  # every method with each option at both values; sanitizers are slow
    results = replay_configs(sanitized_runner, sanitized_binary, md, vr, configs, rows, tmp_path, sanitized=True)
    for config, result, expected in zip(configs, results, references[::4]):
        assert_equal(result, expected, config)
    script, expected_statuses = robustness_script(md, vr, sanitized_binary)
    statuses, _, _ = run_script(sanitized_runner, script, tmp_path, sanitized=True)
    assert [line for line in statuses if line and not line.startswith("get_real")] == expected_statuses


def robustness_script(md, vr, binary):
    """Runner lines that call in wrong states, set what may not be set, give invalid parameters,
    save and restore a state and cycle 1000 instances; and the status lines they must print."""
    guid, uri, steps, expected = md.guid, Path(binary).parent.as_uri(), [], []

    def call(line, status):
        steps.append(line)
        expected.append(f"{line.split()[0]} {status}")

    def initialised(*sets):
        for line in ("reset", "setup", "enter", *sets, "exit"):
            call(line, 0)

    steps.append(f"load {binary}")
    call(f"instantiate {guid} {uri} 0", 0)
    call("step 0 0.01", 3)  # before initialisation
    call("reset", 0)
    call("exit", 3)  # not in initialization mode
    call("reset", 0)
    call("setup", 0)
    call("enter", 0)
    call(f"real {vr['method']} 1.0", 3)  # a Real set on an Enumeration
    initialised()
    call(f"real {vr['Ts']} 0.02", 3)  # a fixed parameter after initialisation
    initialised()
    call(f"real {vr['q_w']} 0.5", 3)  # an output after initialisation
    initialised(f"integer {vr['method']} {ITEMS['method'].index('mahony') + 1}")
    call(f"real {vr['gyr_x']} 0.1", 0)
    call("step 0 0.01", 0)
    call("save", 0)
    call("step 0.01 0.01", 0)
    steps.append(" ".join(["get_real", *(str(vr[n]) for n in OUTPUTS)]))
    call("restore", 0)
    call("step 0.01 0.01", 0)
    steps.append(" ".join(["get_real", *(str(vr[n]) for n in OUTPUTS)]))
    call("terminate", 0)
    call("step 0.02 0.01", 3)  # after fmi2Terminate
    for name, value in INVALID:
        call("reset", 0)
        call("setup", 0)
        call("enter", 0)
        call(f"real {vr[name]} {value}", 0)
        call("exit", 3)
    for name, value in OUT_OF_ITEMS:  # refused when set
        call("reset", 0)
        call("setup", 0)
        call("enter", 0)
        call(f"integer {vr[name]} {value}", 3)
    call("free", 0)
    call(f"cycles 1000 {guid} {uri} 0.01", 0)
    steps.append("unload")
    return steps, expected


INVALID = [("delta_n", -1.0), ("delta_n", math.inf), ("delta_v", -math.inf), ("delta_n", 1e300), ("Ts", 0.0),
           ("latency", 5.0), ("k_P", 2.0), ("tau_heading", -3.0)]
OUT_OF_ITEMS = [("method", 7), ("method", 0), ("heading", 3), ("gyro_offset", -1), ("gyr_samples", 2**31 - 1)]


def test_wrong_calls_and_invalid_parameters_end_in_fmi2_error_with_a_message(runner, unzipped, md, vr, tmp_path):
    """A C host with no Python: doStep before initialisation and after fmi2Terminate, a Real set
    on an Enumeration, a fixed parameter or an output set after initialisation, and invalid
    parameters (negative or non-finite densities, values beyond their plausible range such as
    1e300, a choice none of whose items has the value) end in fmi2Error with a log message, as
    blocks.pipeline.online words its refusals (a choice's: naming the items); fmi2Reset leads on.
    A state saved and restored steps on as before; 1000 instantiate → step → terminate → free
    cycles, then main returns 0."""
    binary = unzipped / native.binary_path("AttitudeEstimator")
    script, expected = robustness_script(md, vr, binary)
    lines, _, log = run_script(runner["plain"], script, tmp_path)
    assert [line for line in lines if line and not line.startswith("get_real")] == expected
    first, second = (line.split()[2:] for line in lines if line.startswith("get_real"))
    assert first == second
    for text in ("fmi2DoStep is not allowed in the state instantiated", "fmi2DoStep is not allowed in the state terminated",
                 "fmi2ExitInitializationMode is not allowed in the state instantiated",
                 f"value reference {vr['method']} is method, an Enumeration variable", "Ts is a fixed parameter",
                 "q_w is a continuous output", "invalid parameter: Ts must be a finite positive number of seconds, got 0.0",
                 "fmi2SetInteger: method must be one of its items (1 wiener, 2 tseng, 3 tseng_adaptive, 4 luinge, "
                 "5 mahony, 6 first_order), got 7",
                 "fmi2SetInteger: heading must be one of its items (1 mag, 2 gyro), got 3"):
        assert text in log, text
    assert log.count("must be one of its items") == len(OUT_OF_ITEMS)
    for name, value in INVALID:
        if name == "Ts":  # the FMU's own check
            continue
        given = dict(method="wiener", params=None, heading=True, gyro_offset=True)  # the FMU's defaults
        given.update({name: value} if name == "latency" else {"params": {name: value}})
        with pytest.raises(ValueError) as refusal:
            OnlineEstimator(**given)
        assert f"invalid parameter: {refusal.value}" in log, name
    assert log.count("invalid parameter:") == len(INVALID)


def test_fmpy_with_one_instance_reset_between_configurations_equals_the_python_step(unzipped, md, vr, rows, references):
    """fmpy's FMU2Slave, one instance and fmi2Reset between configurations: every output of
    blocks.pipeline.online's step within 1e-9, for every method, each option at both values."""
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier="AttitudeEstimator",
                    instanceName="fmpy")
    fmu.instantiate()
    for index in range(0, len(CONFIGS), 7):
        initialise(fmu, vr, CONFIGS[index])
        out, valid = fmpy_run(fmu, vr, rows)
        ref, ref_valid, _ = references[index]
        assert np.array_equal(valid, ref_valid), CONFIGS[index]
        assert np.abs(out - ref).max() < 1e-9, CONFIGS[index]
    fmu.terminate()
    fmu.freeInstance()


def test_the_model_description_validates_and_matches_the_pythonfmu_fmu(fmus, md, fmu_dir):
    """fmpy.validate_fmu finds no problem in either native FMU; the native estimator's
    variables are the pythonfmu FMU's: names, value references, types, causalities,
    variabilities, initial, units, start values, descriptions (so an SSP may take either)."""
    for path in fmus.values():
        assert validate_fmu(str(path)) == [], path
    theirs = read_model_description(str(fmu_dir / "AttitudeEstimator.fmu"))

    def table(description):
        return [(v.name, v.valueReference, v.type, v.causality, v.variability, v.initial, v.unit, str(v.start),
                 v.description) for v in description.modelVariables]
    assert table(md) == table(theirs)
    assert len(md.modelVariables) == 77 and md.coSimulation.canGetAndSetFMUstate
    assert [u.name for u in md.unitDefinitions] == [u.name for u in theirs.unitDefinitions]
    assert md.guid != theirs.guid


def test_the_binary_links_only_the_c_library_and_libm_and_the_fmu_holds_no_path_and_no_python(fmus, unzipped):
    with open(unzipped / native.binary_path("AttitudeEstimator"), "rb") as f:
        dynamic = next(s for s in ELFFile(f).iter_sections() if isinstance(s, DynamicSection))
        tags = [(t.entry.d_tag, getattr(t, "needed", None)) for t in dynamic.iter_tags()]
    needed = {name for tag, name in tags if tag == "DT_NEEDED"}
    assert needed <= {"libc.so.6", "libm.so.6"} and "libc.so.6" in needed, needed
    assert not [tag for tag, _ in tags if tag in ("DT_RPATH", "DT_RUNPATH")]
    places = {str(ROOT), sys.prefix, sys.base_prefix, tempfile.gettempdir(), str(Path.home()), "/usr/", "/home/"}
    for path in fmus.values():
        with zipfile.ZipFile(path) as zf:
            assert not [n for n in zf.namelist() if n.endswith((".py", ".pyc", ".pyd"))]
            for name in zf.namelist():
                data = zf.read(name)
                assert not [p for p in places if p.encode() in data], (path.name, name)
            assert "sources/buildDescription.xml" in zf.namelist() and "sources/af_params.h" in zf.namelist() \
                or path.stem == "NoOpEstimator"


def test_it_runs_extracted_under_spaces_and_non_ascii_read_only(fmus, md, vr, runner, rows, references, tmp_path):
    """Extracted under a folder whose name has spaces and non-ASCII characters, its files and
    folders made read-only: fmpy and a C host run it and compute the Python step."""
    folder = tmp_path / "FMUs mit Ümläuten ñ 測試" / "AttitudeEstimator"
    extract(str(fmus["AttitudeEstimator"]), str(folder))
    for path in [folder, *folder.rglob("*")]:
        path.chmod(path.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
    try:
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier="AttitudeEstimator",
                        instanceName="read-only")
        fmu.instantiate()
        initialise(fmu, vr, CONFIGS[0])
        out, valid = fmpy_run(fmu, vr, rows[:300])
        assert np.array_equal(valid, references[0][1][:300]) and np.abs(out - references[0][0][:300]).max() < 1e-9
        fmu.terminate()
        fmu.freeInstance()
        work = tmp_path / "work"
        work.mkdir()
        (result,) = replay_configs(runner["plain"], folder / native.binary_path("AttitudeEstimator"), md, vr,
                                   [CONFIGS[0]], rows[:300], work)
        assert_equal(result, tuple(r[:300] for r in references[0]))
    finally:
        for path in [folder, *folder.rglob("*")]:
            path.chmod(path.stat().st_mode | stat.S_IWUSR)


def test_fmu_states_roll_back_and_serialise_and_foreign_bytes_are_refused(fmus, md, vr, unzipped, rows, capsys):
    """fmi2GetFMUstate / fmi2SetFMUstate roll the estimator back: stepping on from a restored
    state, directly or through its serialised bytes, repeats the same outputs bit for bit.
    Bytes changed by one bit, cut short, or written by another FMU (the no-op's) are refused
    with fmi2Error and a message."""
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier="AttitudeEstimator", instanceName="s")
    fmu.instantiate()
    initialise(fmu, vr, CONFIGS[0])
    fmpy_run(fmu, vr, rows[:400])
    state = fmu.getFMUstate()
    data = fmu.serializeFMUstate(state)
    ahead = fmpy_run(fmu, vr, rows[400:600])[0]
    fmu.setFMUstate(state)
    assert np.array_equal(fmpy_run(fmu, vr, rows[400:600])[0], ahead)
    fmu.setFMUstate(fmu.deSerializeFMUstate(data))
    assert np.array_equal(fmpy_run(fmu, vr, rows[400:600])[0], ahead)
    tampered = bytearray(data)
    tampered[len(data) // 2] ^= 1
    noop_md = read_model_description(str(fmus["NoOpEstimator"]))
    noop = FMU2Slave(guid=noop_md.guid, unzipDirectory=extract(str(fmus["NoOpEstimator"])),
                     modelIdentifier="NoOpEstimator", instanceName="noop")
    noop.instantiate()
    foreign = noop.serializeFMUstate(noop.getFMUstate())
    capsys.readouterr()
    for bad in (bytes(tampered), data[:-8], foreign):
        fmu.reset()
        with pytest.raises(FMICallException, match="fmi2DeSerializeFMUstate"):
            fmu.deSerializeFMUstate(bad)
    log = capsys.readouterr().out
    assert "checksum" in log and "bytes of another size" in log
    fmu.freeInstance()
    noop.freeInstance()


def test_debug_logging_by_category_and_warnings_always(md, vr, unzipped):
    """Warnings and errors reach the importer's logger with debug logging off; the trace of the
    FMI calls (logCalls) only with it on, for the categories fmi2SetDebugLogging names."""
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    messages = []
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: messages.append(
        (status, category.decode(), message.decode())))
    from fmpy import calloc, free
    from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2StepFinishedTYPE
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    callbacks.stepFinished = fmi2StepFinishedTYPE()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier="AttitudeEstimator", instanceName="l")
    fmu.instantiate(callbacks=callbacks, loggingOn=False)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr["gyr_x"]], [math.nan])
    fmu.doStep(0.0, TS)
    assert messages == [(1, "logStatusWarning", "t=0: non-finite input; estimate held")]
    fmu.setDebugLogging(True, ["logCalls"])
    fmu.doStep(TS, TS)
    assert (0, "logCalls", "fmi2DoStep") in messages
    fmu.setDebugLogging(False, ["logCalls"])
    messages.clear()
    fmu.setReal([vr["gyr_x"]], [0.0])
    fmu.doStep(2 * TS, TS)
    assert messages == []
    fmu.setDebugLogging(True, ["logEverything"])
    assert messages[-1] == (1, "logStatusWarning", 'fmi2SetDebugLogging: unknown log category "logEverything" ignored')
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.slow
def test_fmpy_compiles_the_source_fmu_into_a_working_binary(fmus, md, vr, rows, references, tmp_path):
    """The FMU's sources/ and buildDescription.xml are all an importer on another platform needs:
    fmpy's compile step (CMake) builds a binary from them alone that gives the Python step."""
    pytest.importorskip("fmpy.build")
    if shutil.which("cmake") is None:
        pytest.skip("fmpy's compile step needs CMake")
    from fmpy.build import build_platform_binary

    folder = Path(extract(str(fmus["AttitudeEstimator"]), str(tmp_path / "source")))
    shutil.rmtree(folder / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(folder, build_dir=tmp_path / "build")
    assert (folder / native.binary_path("AttitudeEstimator")).is_file()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier="AttitudeEstimator", instanceName="c")
    fmu.instantiate()
    initialise(fmu, vr, CONFIGS[0])
    out, valid = fmpy_run(fmu, vr, rows[:500])
    fmu.terminate()
    fmu.freeInstance()
    assert np.array_equal(valid, references[0][1][:500])
    assert np.abs(out - references[0][0][:500]).max() < 1e-9


def test_libcosim_runs_an_ssp_with_the_native_estimator_and_it_computes_the_python_step(fmu_dir, tmp_path):
    """libcosim (its own SSP reader, FMI Library, master) runs the diagram with the native
    estimator beside the pythonfmu one: its outputs, on the inputs libcosim handed it, are
    blocks.pipeline.online's within 1e-9, and equal the pythonfmu estimator's. libcosim ignores
    FMI Enumeration variables (it warns): the choices stay at their start values here."""
    pytest.importorskip("libcosimpy")
    ssp = write_ssp(tmp_path / "human.ssp", fmu_dir, {
        "motion": {"seed": 3},
        "imu": {"delta_n": math.radians(0.1), "seed": 4, "gyr_offset_z": 0.01, "mag_noise": 0.2, "mag_offset_x": 9.0},
        "estimator": {"tau_heading": 2.0, "latency": 0.004}}, 8.0, TS, native=True)
    out = cosimulate_libcosim(ssp, 8.0, TS)
    received = np.column_stack([out[f"native.{n}"] for n in INPUTS])
    config = {"method": "wiener", "heading": "mag", "gyro_offset": "on", "gyr_samples": "mean",
              "acc_samples": "point", "latency": 0.004}
    ref, valid, _ = reference(config, np.column_stack([np.arange(len(received)) * TS, np.full(len(received), TS),
                                                       received]), {"tau_heading": 2.0})
    assert np.array_equal(out["native.valid"], valid) and valid[5:].all()
    estimated = np.column_stack([out[f"native.{n}"] for n in OUTPUTS])
    assert np.abs(estimated - ref).max() < 1e-9
    assert np.abs(estimated - np.column_stack([out[f"estimator.{n}"] for n in OUTPUTS])).max() < 1e-9


def test_a_broad_recording_and_a_long_stream_give_the_python_step(runner, unzipped, md, vr, tmp_path):
    """Each method at the FMU's defaults (heading from the magnetometer, gyro offset on) on 90 s of
    the simulated stream, where the hard iron is found, and on
    12 s of a BROAD recording (at its own sample time) when ../shared/broad has it."""
    default = {"heading": "mag", "gyro_offset": "on", "gyr_samples": "mean", "acc_samples": "point", "latency": 0.0}
    configs = [{"method": m, **default} for m in sorted(METHODS)]
    long_rows = stream(duration=90.0, fast=90.0)
    binary = unzipped / native.binary_path("AttitudeEstimator")
    for config, result in zip(configs, replay_configs(runner["plain"], binary, md, vr, configs, long_rows, tmp_path)):
        expected = reference(config, long_rows)
        assert_equal(result, expected, config)
        assert np.abs(result[0][-1, 13:16] - [12.0, -7.0, 4.0]).max() < 1.0  # the hard iron found
    recordings = sorted(BROAD.glob("*.mat"))
    if not recordings:
        pytest.skip(f"no BROAD recordings in {BROAD}")
    from attitude_fmu.systems.recordings.reading import read_recording

    rec = read_recording(recordings[0])
    n = int(12 * rec.fs)
    ts = 1.0 / rec.fs
    rows = np.column_stack([np.arange(n) * ts, np.full(n, ts), rec.gyr[:n], rec.acc[:n], rec.mag[:n]])
    broad = tmp_path / "broad"
    broad.mkdir()
    global TS
    saved, TS = TS, ts  # the FMU's Ts set to the recording's: no step-size warning
    try:
        results = replay_configs(runner["plain"], binary, md, vr, configs, rows, broad, params={"Ts": ts})
        for config, result in zip(configs, results):
            assert_equal(result, reference(config, rows), config)
    finally:
        TS = saved


def test_a_robot_wrist_s_lever_arm_is_removed_in_the_fmu_as_in_the_python_step(runner, unzipped, md, vr, tmp_path):
    """robot_arm (systems.simulation.scenarios), its first 40 s at 125 Hz, where the gyro-offset stage's
    online lever arm is taken from 10.2 s on: the FMU at its defaults (wiener, 6D and 9D) gives the python
    step's outputs, which differ from those without the arm (tau_arm 0) by more than rounding."""
    from attitude_fmu.systems.simulation.scenarios import scenario

    rec = scenario("robot_arm").recording(name="robot_arm")
    ts, n = 1.0 / rec.fs, int(40 * rec.fs)
    rows = np.column_stack([np.arange(n) * ts, np.full(n, ts), rec.gyr[:n], rec.acc[:n], rec.mag[:n]])
    default = {"method": "wiener", "gyro_offset": "on", "gyr_samples": "mean", "acc_samples": "point", "latency": 0.0}
    configs = [{**default, "heading": heading} for heading in ("gyro", "mag")]
    global TS
    saved, TS = TS, ts  # the FMU's Ts set to the recording's
    try:
        binary = unzipped / native.binary_path("AttitudeEstimator")
        results = replay_configs(runner["plain"], binary, md, vr, configs, rows, tmp_path, params={"Ts": ts})
        for config, result in zip(configs, results):
            assert_equal(result, reference(config, rows), config)
            without = reference(config, rows, {"tau_arm": 0.0})[0]
            assert np.abs(result[0][:, :4] - without[:, :4]).max() > 1e-4, config
    finally:
        TS = saved


def test_where_the_build_made_no_native_fmus_the_pythonfmu_ones_still_build_and_a_warning_says_why(tmp_path,
                                                                                                     monkeypatch):
    monkeypatch.setattr(native, "BUILT", tmp_path / "nothing built")
    said = []
    assert native.copy_fmus(tmp_path / "native", native.NATIVE_NAMES, log=said.append) == []
    assert ("the native FMUs (AttitudeEstimator.fmu, ImuSensor.fmu, MotionProfile.fmu: in C, no Python) are not "
            "copied") in said[0]
    assert "pip install ." in said[0] and "python build_fmu.py" in said[0]
    assert [p.name for p in build_fmus(tmp_path, ("MotionProfile",))] == ["MotionProfile.fmu"]
    assert not (tmp_path / "native" / "AttitudeEstimator.fmu").exists()


def test_a_native_fmu_of_another_build_is_not_current(fmus, tmp_path):
    """Its guid is a digest of what it is built from: one of another build is not current
    (ensure_built replaces it)."""
    fresh = fmus["NoOpEstimator"]
    assert native.is_current(fresh)
    stale = tmp_path / "NoOpEstimator.fmu"
    guid = read_model_description(str(fresh)).guid
    with zipfile.ZipFile(fresh) as src, zipfile.ZipFile(stale, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(guid.encode(), b"{00000000-0000-0000-0000-000000000000}")
            dst.writestr(item, data)
    assert not native.is_current(stale) and not native.is_current(tmp_path / "missing.fmu")
