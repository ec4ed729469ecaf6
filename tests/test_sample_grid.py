"""FMUs with a sample time run on its grid (issue 49, point 1): an exported discrete diagram and the native
ImuSensor with a latency, FMI 2.0 and 3.0, under a master that steps as strict masters do: time summed
step by step (60 s of 0.01 s ends at 59.99999999999663) and a final step of the shortfall, which must return
fmi2OK and leave the outputs as they were; steps of Ts/2 and 3·Ts give the outputs of the Ts grid at the
instants they share (inputs constant, so held inputs are the same inputs)."""
import control
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from attitude_fmu.systems.fmi.export.api import export_fmu
from tests import native

TS = 0.01
STOP = 60.0
BUILD = ("AF_WERROR=ON", *(("AF_SANITIZE=ON",) if native.sanitized_build() is not None else ()))


class Master:
    """One FMU (FMI 2.0 or 3.0) under fmpy, its Real inputs set before each step, its Real outputs (all but
    `valid`) read after;
    fmpy raises on a status of fmi2Error or worse, so a run that returns took every step."""

    def __init__(self, path, parameters=None):
        self.md = read_model_description(str(path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.unzipdir = extract(str(path))
        kind = FMU3Slave if self.md.fmiVersion.startswith("3") else FMU2Slave
        self.fmu = kind(guid=self.md.guid, unzipDirectory=self.unzipdir,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="grid")
        self.fmi3 = kind is FMU3Slave
        self.fmu.instantiate()
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        for name, value in (parameters or {}).items():
            self._set([name], [value])
        self.fmu.exitInitializationMode()
        self.outputs = [v.name for v in self.md.modelVariables
                        if v.causality == "output" and v.type in ("Real", "Float64")]

    def _set(self, names, values):
        refs = [self.variables[n].valueReference for n in names]
        (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)(refs, [float(v) for v in values])

    def step(self, t: float, h: float, inputs: dict) -> np.ndarray:
        if inputs:
            self._set(list(inputs), list(inputs.values()))
        self.fmu.doStep(t, h)
        refs = [self.variables[n].valueReference for n in self.outputs]
        return np.array((self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)(refs))

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def summed_run(path, parameters, inputs, first: float | None = None):
    """The strict master's run to STOP: steps of TS summed into t (after a first step of first, where given),
    then the shortfall; (outputs before the shortfall step, after it, the shortfall)."""
    master = Master(path, parameters)
    t, before = 0.0, None
    if first is not None:
        before = master.step(t, first, inputs)
        t += first
    while t + TS <= STOP:
        before = master.step(t, TS, inputs)
        t += TS
    shortfall = STOP - t
    assert 0.0 < shortfall < 1e-9, shortfall  # what OMSimulator's sum leaves
    after = master.step(t, shortfall, inputs)
    master.close()
    return before, after, shortfall


def grid_outputs(path, parameters, inputs, h: float, steps: int, first: float | None = None) -> np.ndarray:
    """The outputs after each of steps steps of h (after a first step of first, where given), time summed."""
    master = Master(path, parameters)
    t, rows = 0.0, []
    if first is not None:
        rows.append(master.step(t, first, inputs))
        t += first
    for _ in range(steps):
        rows.append(master.step(t, h, inputs))
        t += h
    master.close()
    return np.array(rows)


def _shares_the_grid(path, parameters, inputs, first=None):
    """Steps of TS/2 and 3·TS give the TS run's outputs at the instants they share."""
    offset = 0 if first is None else 1
    base = grid_outputs(path, parameters, inputs, TS, 60, first)
    half = grid_outputs(path, parameters, inputs, TS / 2, 120, first)
    triple = grid_outputs(path, parameters, inputs, 3 * TS, 20, first)
    np.testing.assert_allclose(half[offset + 1::2], base[offset:], rtol=0, atol=1e-12)
    np.testing.assert_allclose(triple[offset:], base[offset + 2::3], rtol=0, atol=1e-12)
    assert not np.allclose(base[offset:offset + 10], base[offset + 10:offset + 20])  # the outputs move


SENSOR_INPUTS = {"omega_x": 0.3, "omega_y": -0.2, "omega_z": 0.1, "f_x": 0.5, "f_y": -0.4, "f_z": 9.8}
SENSOR_PARAMETERS = {"latency": 0.013, "delta_n": 0.01, "acc_noise": 0.05, "mag_noise": 0.5}
# a steady turn about the vertical in a field the estimator sees turn against the gyro: its heading works on
ESTIMATOR_INPUTS = {"gyr_x": 0.02, "gyr_y": -0.01, "gyr_z": 0.05, "acc_x": 0.3, "acc_y": 0.2, "acc_z": 9.8,
                    "mag_x": 20.0, "mag_y": 5.0, "mag_z": -40.0}
# (the python backend's FMU, whose pythonfmu library a process cannot load twice: tests/test_export.py)
CASES = ["diagram 2.0", "diagram 3.0", "late-sensor native", "late-sensor native/fmi3",
         "late-sensor pythonfmu", "estimator native", "estimator native/fmi3", "estimator pythonfmu"]


@pytest.fixture(scope="module", params=CASES)
def fmu(request, fmu_dir, tmp_path_factory):
    """(path, parameters, constant inputs, first step or None) of each FMU with a sample time: a discrete
    diagram of two states exported natively (FMI 2.0 and 3.0); the ImuSensor with a latency
    and noise, each sample drawing its own (its first step, TS, sets its sample time; native FMI 2.0 and 3.0,
    pythonfmu); the estimator with the magnetometer's heading (native FMI 2.0 and 3.0, pythonfmu)."""
    kind, where = request.param.split()
    folder = fmu_dir if where == "pythonfmu" else fmu_dir / where
    if kind == "diagram":
        system = control.ss([[0.9, 0.1], [0.0, 0.8]], [[1.0], [0.5]], [[1.0, -1.0]], [[0.2]], TS, name="plant")
        path = tmp_path_factory.mktemp("grid") / "plant.fmu"
        return export_fmu(system, path, fmi_version=where, cmake_options=BUILD), {}, {"u[0]": 1.0}, None
    if kind == "late-sensor":
        return folder / "ImuSensor.fmu", SENSOR_PARAMETERS, SENSOR_INPUTS, TS
    return folder / "AttitudeEstimator.fmu", {}, ESTIMATOR_INPUTS, None


def test_the_shortfall_step_returns_ok_and_holds_the_outputs(fmu):
    """The estimator once moved its yaw by 6.6e-6 rad in the 3.4e-12 s step (its heading took any step as a
    full sample); the diagram and the late sensor ended in fmi2Error."""
    path, parameters, inputs, first = fmu
    before, after, _ = summed_run(path, parameters, inputs, first)
    np.testing.assert_allclose(after, before, rtol=0, atol=1e-12)


def test_steps_of_half_and_three_samples_run_the_samples_they_reach(fmu):
    path, parameters, inputs, first = fmu
    _shares_the_grid(path, parameters, inputs, first)


def test_the_pythonfmu_late_sensor_equals_the_native_one_on_mixed_steps(fmu_dir):
    """Steps of TS, 2·TS, TS/2 and the shortfall, inputs changing from step to step: the pythonfmu ImuSensor
    (which once refused any step after the first of another size) gives the native one's outputs."""
    steps = [TS, 2 * TS, TS / 2, TS / 2, TS, 3 * TS, TS / 2, TS / 2, TS] * 5
    rows = np.random.default_rng(3).normal(size=(len(steps), 6)) + [0, 0, 0, 0, 0, 9.8]
    runs = []
    for path in (fmu_dir / "ImuSensor.fmu", fmu_dir / "native" / "ImuSensor.fmu"):
        master, t, out = Master(path, SENSOR_PARAMETERS), 0.0, []
        for h, row in zip(steps, rows):
            out.append(master.step(t, h, dict(zip(SENSOR_INPUTS, row))))
            t += h
        master.close()
        runs.append(np.array(out))
    np.testing.assert_allclose(runs[0], runs[1], rtol=0, atol=1e-12)
