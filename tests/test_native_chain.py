"""The native co-simulation chain: MotionProfile.fmu and ImuSensor.fmu in C against the batch
motion and sensor (and the pythonfmu FMUs of the same interfaces), the FMI 3.0 estimator against the FMI 2.0 one,
the native chain against the pythonfmu chain with the same seeds, the SSPs `attitude ssp`
writes under libcosim and fmpy's SSP reader, and the master's C stepping loop against its
Python one."""
import json
import math
import shutil

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave
from fmpy.ssp.ssd import read_ssd
from fmpy.validation import validate_fmu

from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.systems.fmi.interface.simulation_variables import motion_profile
from attitude_fmu.systems.fmi.interface.variables import item_value
from attitude_fmu.systems.fmi import stepping
from attitude_fmu.systems.fmi import verify as verify_module
from attitude_fmu.systems.fmi.cosim import (
    FmuRunner,
    cosimulate,
    cosimulate_libcosim,
    enumeration_value,
    load_slave,
    set_value,
)
from attitude_fmu.systems.fmi.ssp import write_ssp
from attitude_fmu.systems.simulation.motion import PROFILES, HumanMotion, Motion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0
NATIVE_FMUS = ("native/AttitudeEstimator", "native/ImuSensor", "native/MotionProfile", "native/fmi3/AttitudeEstimator",
               "native/fmi3/ImuSensor", "native/fmi3/MotionProfile")
TRUTH = [f"{s}_{a}" for s in ("omega", "f", "m") for a in "xyz"] + [f"qt_{c}" for c in "wxyz"]
SENSOR_IN = [f"{s}_{a}" for s in ("omega", "f", "m") for a in "xyz"]
SENSOR_OUT = [f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in "xyz"]
ESTIMATOR_OUT = ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw", "gyr_offset_x",
                 "gyr_offset_y", "gyr_offset_z", "mag_offset_x", "mag_offset_y", "mag_offset_z", "mag_delay_used"]


@pytest.mark.parametrize("name", ["AttitudeEstimator", "ImuSensor", "MotionProfile"])
def test_every_native_fmu_validates_and_fmi3_has_the_fmi2_variables(fmu_dir, name):
    for path in NATIVE_FMUS:
        assert validate_fmu(str(fmu_dir / f"{path}.fmu")) == [], path
    two = read_model_description(str(fmu_dir / "native" / f"{name}.fmu"))
    three = read_model_description(str(fmu_dir / "native" / "fmi3" / f"{name}.fmu"))
    assert three.fmiVersion == "3.0" and three.coSimulation.modelIdentifier == name
    kinds = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "Enumeration": "Enumeration"}
    rows = [(v.name, v.valueReference, v.causality, v.variability, v.start) for v in two.modelVariables]
    assert [(v.name, v.valueReference, v.causality, v.variability, v.start) for v in three.modelVariables[:-1]] == rows
    assert [kinds[v.type] for v in two.modelVariables] == [v.type for v in three.modelVariables[:-1]]
    items = [[(i.name, i.value) for i in v.declaredType.items] if v.type == "Enumeration" else None
             for v in two.modelVariables]
    assert [[(i.name, i.value) for i in v.declaredType.items] if v.type == "Enumeration" else None
            for v in three.modelVariables[:-1]] == items
    time = three.modelVariables[-1]
    assert (time.name, time.causality, time.valueReference) == ("time", "independent", len(rows))


def _run(fmu, parameters, inputs, input_names, outputs, h=1 / FS):
    runner = FmuRunner(fmu, parameters, input_names, outputs)
    try:
        return runner.run(inputs, h)[0]
    finally:
        runner.close()


@pytest.mark.parametrize("name", list(PROFILES))
def test_the_motion_fmus_equal_the_batch_motion(fmu_dir, name):
    """Every profile, its parameters changed: the native MotionProfile.fmu and the pythonfmu one
    equal the profile's batch generation (the human one with the same seed) within 1e-12 of
    each quantity's scale over 8 s (the human motion within 1e-10: on its changed grid of
    0.3 s the FMUs' steps end inside a cell, whose rotation they take over the step's part of
    it, where the batch path turns whole samples: the same motion, rounded otherwise). A closed
    form is sampled at the master's times, the steps summed (off k/fs by up to 1.3e-13 s, which
    running's angular acceleration would turn into 2e-12 rad/s)."""
    prof = PROFILES[name]
    changed = {p.name: 0.8 * p.default + 0.3 for p in prof.params}
    motion = prof.motion(changed, g=9.79).generate(8.0, FS, seed=5)
    if name != "human":
        gyr, acc, quat = prof.motion(changed, g=9.79).at(np.cumsum(np.full(len(motion.t), 1.0 / FS)), 1.0 / FS)
        motion = Motion(FS, quat, gyr, acc)
    expected = np.hstack([motion.gyr, motion.acc, motion.mag, motion.quat])
    parameters = {"profile": name, "seed": 5, "g": 9.79, **{f"{name}_{k}": v for k, v in changed.items()}}
    for fmu in ("native/MotionProfile", "MotionProfile"):
        got = _run(fmu_dir / f"{fmu}.fmu", parameters, np.empty((len(expected), 0)), [], TRUTH)
        for columns in (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 13)):
            scale = max(1.0, np.abs(expected[:, columns]).max())
            tolerance = 1e-10 if name == "human" else 1e-12
            assert np.abs(got[:, columns] - expected[:, columns]).max() < tolerance * scale, (fmu, columns)


@pytest.mark.parametrize("latency", [0.0, 0.0234])
def test_the_sensor_fmus_equal_imu_model_apply(fmu_dir, latency):
    """Noise, offsets, scale and misalignment, latency, magnetometer noise, hard and soft iron: the
    native ImuSensor.fmu and the pythonfmu one equal ImuModel.apply and apply_mag with the same
    seed within 1e-12 on 10 s of human motion."""
    scale = ((0.01, -0.002, 0.0), (0.003, 0.0, 0.005), (0.0, 0.004, -0.02))
    imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.01, -0.02, 0.03), gyr_scale=scale, acc_noise=0.01,
                   acc_offset=(0.1, -0.2, 0.3), latency=latency, mag_noise=0.5, mag_offset=(8.0, -3.0, 12.0),
                   mag_soft_iron=((0.05, 0.02, -0.01), (0.02, -0.06, 0.03), (-0.01, 0.03, 0.04)))
    motion = HumanMotion().generate(10.0, FS, seed=3)
    gyr, acc = imu.apply(motion, seed=9)
    expected = np.hstack([gyr, acc, imu.apply_mag(motion, seed=9)])
    parameters = {"delta_n": imu.delta_n, "acc_noise": imu.acc_noise, "latency": latency, "mag_noise": imu.mag_noise,
                  "seed": 9, **{f"{v}_{c}": x for v in ("gyr_offset", "acc_offset", "mag_offset")
                                for c, x in zip("xyz", getattr(imu, v))},
                  **{f"{m}_{r}_{c}": getattr(imu, m)[i][j] for m in ("gyr_scale", "mag_soft_iron")
                     for i, r in enumerate("xyz") for j, c in enumerate("xyz")}}
    for fmu in ("native/ImuSensor", "ImuSensor"):
        got = _run(fmu_dir / f"{fmu}.fmu", parameters, np.hstack([motion.gyr, motion.acc, motion.mag]), SENSOR_IN,
                   SENSOR_OUT)
        assert np.abs(got - expected).max() < 1e-12 * np.abs(expected).max(), fmu


def _refusal(fmu, parameters) -> str:
    """The error the FMU logs when initialised with parameters (it must refuse them)."""
    md = read_model_description(str(fmu))
    variables = {v.name: v for v in md.modelVariables}
    unzipped = extract(str(fmu))
    messages = []
    logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: messages.append(message.decode()))
    slave = load_slave(md, unzipped, "refusal")
    slave.instantiate(callbacks=fmi2CallbackFunctions(logger=logger))
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    for name, value in parameters.items():
        set_value(slave, variables[name], value)
    with pytest.raises(FMICallException):
        slave.exitInitializationMode()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    return [m for m in messages if "invalid parameter" in m][-1]


@pytest.mark.parametrize("fmu, parameters", [
    ("MotionProfile", {"profile": "coning", "coning_rate": math.inf}),
    ("MotionProfile", {"profile": "human", "human_omega_c": 0.0}),
    ("MotionProfile", {"profile": "human", "seed": -1}),
    ("ImuSensor", {"acc_noise": -0.1}),
    ("ImuSensor", {"gyr_scale_y_z": math.nan}),
    ("ImuSensor", {"seed": -3}),
])
def test_the_native_fmus_refuse_what_the_pythonfmu_ones_refuse_in_their_words(fmu_dir, fmu, parameters):
    assert _refusal(fmu_dir / "native" / f"{fmu}.fmu", parameters) == _refusal(fmu_dir / f"{fmu}.fmu", parameters)


def test_the_native_sensor_refuses_a_latency_longer_than_its_delay_line_at_the_first_step(fmu_dir, capsys):
    runner = FmuRunner(fmu_dir / "native" / "ImuSensor.fmu", {"latency": 11.0}, [f"f_{c}" for c in "xyz"], ["acc_z"])
    with pytest.raises(FMICallException) as info:
        runner.step([0.0, 0.0, 9.81], 0.01)
    assert info.value.status == 3
    runner.fmu.freeInstance()
    assert "latency 11.0 s at 100.0 Hz is longer than the delay line's 1021 samples" in capsys.readouterr().out


def _fmi3_slave(fmu, parameters):
    """An FMI 3.0 FMU under fmpy, initialised with parameters (Float64, Int32, or Enumeration by
    item name, set with fmi3SetInt64 as FMI 3.0 sets Enumerations): (slave, value references,
    its folder)."""
    md = read_model_description(str(fmu))
    unzipped = extract(str(fmu))
    slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="three")
    slave.instantiate()
    slave.enterInitializationMode(startTime=0.0)
    for v in md.modelVariables:
        if v.name in parameters:
            value = parameters[v.name]
            if v.type == "Enumeration":
                slave.setInt64([v.valueReference], [enumeration_value(v, value)])
            elif v.type == "Int32":
                slave.setInt32([v.valueReference], [value])
            else:
                slave.setFloat64([v.valueReference], [value])
    slave.exitInitializationMode()
    return slave, {v.name: v.valueReference for v in md.modelVariables}, unzipped


def _fmi3_run(fmu, parameters, inputs, h):
    """The FMI 3.0 estimator under fmpy: outputs and valid per step, then the time it reports."""
    slave, variables, unzipped = _fmi3_slave(fmu, parameters)
    vin, vout = [variables[n] for n in SENSOR_OUT], [variables[n] for n in ESTIMATOR_OUT]
    out, valid = np.empty((len(inputs), len(vout))), np.empty(len(inputs), dtype=bool)
    for k, row in enumerate(inputs):
        slave.setFloat64(vin, list(row))
        slave.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
        out[k], valid[k] = slave.getFloat64(vout), slave.getBoolean([variables["valid"]])[0]
        if k == len(inputs) // 2:  # an FMU state saved halfway, serialised and restored at the end
            state = slave.deserializeFMUState(slave.serializeFMUState(slave.getFMUState()))
            at = k
    time = slave.getFloat64([variables["time"]])[0]
    slave.setFMUState(state)
    slave.setFloat64(vin, list(inputs[at + 1]))
    slave.doStep(currentCommunicationPoint=(at + 1) * h, communicationStepSize=h)
    again = np.array(slave.getFloat64(vout))
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    return out, valid, time, again, at


@pytest.mark.parametrize("parameters", [
    {"method": "wiener", "Ts": 0.01},
    {"method": "tseng_adaptive", "gyr_samples": "point", "latency": 0.004, "gyro_offset": "off"},
    {"method": "luinge", "acc_samples": "mean", "heading": "gyro", "Ts": 0.02},
])
def test_the_fmi3_estimator_equals_the_fmi2_one(fmu_dir, parameters):
    """Under fmpy, on 20 s of a noisy sensor with a magnetometer with hard iron: every output and
    valid of the FMI 3.0 FMU within 1e-12 of the FMI 2.0 one's, step by step (one of them
    re-discretised for another step size); its FMU state round trip and its time work."""
    imu = ImuModel(delta_n=math.radians(0.05), acc_noise=0.01, mag_noise=0.3, mag_offset=(6.0, -2.0, 3.0))
    motion = HumanMotion(delta_v=0.3).generate(20.0, FS, seed=4)
    inputs = np.hstack([*imu.apply(motion, seed=5), imu.apply_mag(motion, seed=5)])
    runner = FmuRunner(fmu_dir / "native" / "AttitudeEstimator.fmu", parameters, SENSOR_OUT, ESTIMATOR_OUT)
    two, valid_two = runner.run(inputs, 1 / FS)
    runner.close()
    three, valid_three, time, again, at = _fmi3_run(fmu_dir / "native" / "fmi3" / "AttitudeEstimator.fmu",
                                                    parameters, inputs, 1 / FS)
    assert np.array_equal(valid_two, valid_three) and valid_two[10:].all()
    assert np.abs(three - two).max() <= 1e-12
    assert time == pytest.approx(len(inputs) / FS, rel=1e-12)
    assert np.array_equal(again, three[at + 1])


@pytest.mark.parametrize("name, parameters, inputs, outputs", [
    ("MotionProfile", {"profile": "coning", "coning_rate": 0.7}, [], ["omega_x", "f_y", "m_z", "qt_w", "qt_z"]),
    ("MotionProfile", {"profile": "human", "seed": 5}, [], ["omega_z", "f_x", "qt_x"]),
    ("ImuSensor", {"delta_n": 0.002, "acc_offset_x": 0.1, "mag_noise": 0.3, "seed": 7}, SENSOR_IN, SENSOR_OUT),
])
def test_the_fmi3_sensor_and_motion_equal_the_fmi2_ones(fmu_dir, name, parameters, inputs, outputs):
    """The FMI 3.0 MotionProfile (its profile an Enumeration set by fmi3SetInt64) and ImuSensor
    under fmpy give the FMI 2.0 ones' outputs within 1e-12, step by step."""
    data = np.random.default_rng(11).normal(size=(300, len(inputs))) + (9.81 if inputs else 0.0)
    runner = FmuRunner(fmu_dir / "native" / f"{name}.fmu", parameters, inputs, outputs)
    two = np.array([runner.step(row, 1 / FS)[0] for row in data]) if inputs else runner.run(np.empty((300, 0)),
                                                                                            1 / FS)[0]
    runner.close()
    slave, variables, unzipped = _fmi3_slave(fmu_dir / "native" / "fmi3" / f"{name}.fmu", parameters)
    three, t = np.empty_like(two), 0.0
    for k, row in enumerate(data):
        if inputs:
            slave.setFloat64([variables[n] for n in inputs], list(row))
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=1 / FS)
        t += 1 / FS  # as FmuRunner keeps time
        three[k] = slave.getFloat64([variables[n] for n in outputs])
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    assert np.abs(three - two).max() <= 1e-12 and np.abs(two).max() > 0


@pytest.mark.parametrize("profile, method", list(zip(verify_module.SCENARIOS, [*METHODS, *METHODS])))
def test_the_native_and_the_pythonfmu_chains_agree_within_1e_9(fmu_dir, tmp_path, profile, method):
    """Every profile (each with another method): verify's configuration run for 6 s on each chain,
    with the same seeds: every Real output of the estimators within 1e-9 (the Euler angles aside:
    chain_difference), valid equal."""
    out = {chain: cosimulate(verify_module.write_verify_ssp(tmp_path / f"{chain}.ssp", fmu_dir, profile, method,
                                                            chain), 6.0, verify_module.STEP_S)
           for chain in ("native", "python")}
    diff, valid_equal = verify_module.chain_difference(out["native"], out["python"])
    assert diff <= 1e-9 and valid_equal


def test_the_c_stepping_loop_equals_the_python_one(fmu_dir, tmp_path, monkeypatch):
    ssp = verify_module.write_verify_ssp(tmp_path / "h.ssp", fmu_dir, "human", "mahony")
    fast = cosimulate(ssp, 4.0, verify_module.STEP_S)
    monkeypatch.setattr(stepping, "library", lambda: None)
    slow = cosimulate(ssp, 4.0, verify_module.STEP_S)
    assert fast.keys() == slow.keys()
    assert all(np.array_equal(fast[k], slow[k]) and fast[k].dtype == slow[k].dtype for k in fast)


def test_fmpy_reads_the_ssp_but_runs_it_without_its_parameters(fmu_dir, tmp_path):
    """fmpy's SSP reader takes the file as it is (components, sources, connections, parameter
    bindings); its simulate_ssp runs it but leaves the SSD's bindings out (docs/guide/fmus.md):
    the estimator keeps its start value Ts = 0.01 s, the motion its profile human."""
    from fmpy.ssp.simulation import simulate_ssp

    path = verify_module.write_verify_ssp(tmp_path / "incline_wiener.ssp", fmu_dir, "incline", "wiener")
    ssd = read_ssd(str(path))
    assert [(e.name, e.source) for e in ssd.system.elements] == [
        ("motion", "resources/native/MotionProfile.fmu"), ("imu", "resources/native/ImuSensor.fmu"),
        ("estimator", "resources/native/AttitudeEstimator.fmu")]
    assert len(ssd.system.connections) == 18
    bound = {(e.name, p.name): p.value for e in ssd.system.elements for b in e.parameterBindings
             for s in b.parameterValues for p in s.parameters}
    profile = next(v for v in motion_profile() if v.name == "profile")
    assert bound[("motion", "profile")] == str(item_value(profile, "incline")) and bound[("estimator", "Ts")] == "0.02"
    result = simulate_ssp(str(path), stop_time=1.0, step_size=verify_module.STEP_S)
    assert len(result) == 50 and np.abs(result["motion.omega_x"]).max() > 0  # incline does not rotate: human ran


def test_attitude_ssp_without_native_fmus_says_how_to_get_them(tmp_path):
    from attitude_fmu.systems.fmi.verify import write_verify_ssps

    with pytest.raises(RuntimeError, match="need a C compiler; --python"):
        write_verify_ssps(tmp_path, tmp_path / "out", ["incline"], ["wiener"], "native")


def test_the_c_stepping_loop_reports_the_component_that_failed(fmu_dir, tmp_path):
    """A sensor latency longer than the native delay line is refused at the first step: the run
    stops there and says which component failed."""
    bad = write_ssp(tmp_path / "late.ssp", fmu_dir, {"imu": {"latency": 30.0}}, 1.0, 0.01, chain="native")
    with pytest.raises(RuntimeError, match="component imu failed at t = 0 s"):
        cosimulate(bad, 1.0, 0.01)
