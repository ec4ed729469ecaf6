"""Outputs at the start time (issue 49, point 2): what a Jacobi master (OMSimulator, libcosim) reads before the
first step. MotionProfile gives the motion at the start time and ImuSensor its model of its inputs, in
Initialization Mode (after the inputs are set there) and after it, for the native FMUs (FMI 2.0 and 3.0) and
the pythonfmu ones; their model descriptions say so (initial="calculated", no start, initial unknowns;
tests/test_model_description.py runs fmpy's and fmutool's checkers on them). Under the Jacobi test master (systems.fmi.cosim, master="jacobi") `attitude
verify`'s rows hold their bounds, but for the motions that turn at their start (the master's hold of that
instant: one sample of rotation, shown against its closed form)."""
import math

import control
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from attitude_fmu.systems.fmi.export.api import export_fmu
from attitude_fmu.systems.fmi.interface.simulation_variables import imu_sensor, motion_profile
from attitude_fmu.systems.fmi.verify import JACOBI_LAG, STEP_S, verify
from attitude_fmu.systems.simulation.motion import PROFILES

FLAVOURS = ["native", "native/fmi3", "pythonfmu"]
MOTION_OUT = [v.name for v in motion_profile() if v.causality == "output"]
SENSOR_OUT = [v.name for v in imu_sensor() if v.causality == "output"]


class Initialising:
    """An FMU (FMI 2.0 or 3.0) under fmpy, instantiated and in Initialization Mode at start (s)."""

    def __init__(self, path, start: float = 0.0):
        self.md = read_model_description(str(path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        kind = FMU3Slave if self.md.fmiVersion.startswith("3") else FMU2Slave
        self.fmi3 = kind is FMU3Slave
        self.fmu = kind(guid=self.md.guid, unzipDirectory=extract(str(path)),
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="start")
        self.fmu.instantiate()
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=start)
        else:
            self.fmu.setupExperiment(startTime=start)
            self.fmu.enterInitializationMode()

    def set(self, values: dict):
        for name, value in values.items():
            v = self.variables[name]
            if v.type in ("Enumeration",):
                (self.fmu.setInt64 if self.fmi3 else self.fmu.setInteger)([v.valueReference], [value])
            else:
                (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)([v.valueReference], [float(value)])

    def get(self, names) -> np.ndarray:
        refs = [self.variables[n].valueReference for n in names]
        return np.array((self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)(refs))

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def _folder(fmu_dir, flavour):
    return fmu_dir if flavour == "pythonfmu" else fmu_dir / flavour


def _motion_outputs(path, profile: int, start: float, step: float | None):
    """(outputs read in Initialization Mode, after its exit, after a first step of step s or None)."""
    fmu = Initialising(path, start)
    fmu.set({"profile": profile})
    during = fmu.get(MOTION_OUT)
    fmu.fmu.exitInitializationMode()
    after = fmu.get(MOTION_OUT)
    stepped = None
    if step is not None:
        fmu.fmu.doStep(start, step)
        stepped = fmu.get(MOTION_OUT)
    fmu.close()
    return during, after, stepped


@pytest.mark.parametrize("flavour", FLAVOURS)
def test_motion_outputs_are_the_motion_at_the_start_time(fmu_dir, flavour):
    """For every profile, at start times 0 and 3.7 s: the outputs read in Initialization Mode equal those
    after it; the orientation and field equal those after a 1e-9 s step within 1e-12 and what the motion turns
them in that time (|ω|·1e-9 rad); the rate and specific
    force are the limit of the first step's as it shrinks: its gap falls tenfold from 1e-3 s to 1e-4 s (a
    one-sided mean: the gap is h/2 times the derivative) and is within the 1e-9 s step's own rounding at
    1e-9 s (its difference quotient's: 4 eps (1 + t)/1e-9 relative). Before the change every output was the level-at-rest start value."""
    path = _folder(fmu_dir, flavour) / "MotionProfile.fmu"
    kinematic = [n.startswith(("omega", "f_")) for n in MOTION_OUT]
    exact = [not k for k in kinematic]
    for k, name in enumerate(PROFILES):
        for start in (0.0, 3.7):
            during, after, tiny = _motion_outputs(path, k + 1, start, 1e-9)
            np.testing.assert_array_equal(during, after, err_msg=f"{name} at {start}")
            turn = np.linalg.norm(after[:3]) * 1e-9  # rad the motion turns in 1e-9 s: q moves half that, m all
            field = np.linalg.norm(after[MOTION_OUT.index("m_x"):][:3])
            np.testing.assert_allclose(tiny[exact], after[exact], rtol=0, atol=turn * (1 + field) + 1e-12,
                                       err_msg=name)
            rounding = 4 * np.finfo(float).eps * (1 + start) / 1e-9 * (1 + np.abs(after[kinematic]))
            assert (np.abs(tiny[kinematic] - after[kinematic]) <= rounding).all(), (name, start, tiny, after)
            if name == "human":  # its rate and acceleration are constant within a cell of its grid
                continue
            gaps = [np.abs(_motion_outputs(path, k + 1, start, h)[2] - after)[kinematic].max() for h in (1e-3, 1e-4)]
            assert gaps[1] <= 0.15 * gaps[0] + 1e-9, (name, start, gaps)
    truth = PROFILES["coning"].motion()
    _, after, _ = _motion_outputs(path, list(PROFILES).index("coning") + 1, 0.0, None)
    np.testing.assert_allclose(after[MOTION_OUT.index("qt_w"):][:4], truth.start_quat(), rtol=0, atol=1e-15)
    assert np.linalg.norm(after[MOTION_OUT.index("f_x"):][:3]) == pytest.approx(truth.g, abs=1e-9)  # at rest


@pytest.mark.parametrize("flavour", FLAVOURS)
def test_sensor_outputs_are_its_model_of_its_inputs_before_the_first_step(fmu_dir, flavour):
    """Inputs set in Initialization Mode come out through the sensor's offsets (no noise: no sample drawn
    yet), read there and after it, with a latency too."""
    fmu = Initialising(_folder(fmu_dir, flavour) / "ImuSensor.fmu")
    offsets = {"gyr_offset_x": 0.01, "gyr_offset_y": -0.02, "gyr_offset_z": 0.03, "acc_offset_x": 0.1,
               "acc_offset_y": -0.2, "acc_offset_z": 0.3, "mag_offset_x": 1.0, "mag_offset_y": -2.0,
               "mag_offset_z": 3.0}
    inputs = {"omega_x": 0.5, "omega_y": -0.25, "omega_z": 0.125, "f_x": -0.17, "f_y": 8.25, "f_z": 5.3,
              "m_x": 20.0, "m_y": 5.0, "m_z": -40.0}
    fmu.set({**offsets, **inputs, "delta_n": 0.01, "acc_noise": 0.05, "mag_noise": 0.5, "latency": 0.013})
    expected = np.array(list(inputs.values())) + np.array(list(offsets.values()))
    np.testing.assert_allclose(fmu.get(SENSOR_OUT), expected, rtol=0, atol=1e-15)
    fmu.fmu.exitInitializationMode()
    np.testing.assert_allclose(fmu.get(SENSOR_OUT), expected, rtol=0, atol=1e-15)
    fmu.close()


def test_refused_parameters_leave_the_start_values_until_the_exit_says_why(fmu_dir):
    """In Initialization Mode a profile's parameter out of range is no error yet (the importer may still
    change it): the outputs keep their start values; fmi2ExitInitializationMode refuses it."""
    fmu = Initialising(fmu_dir / "native" / "MotionProfile.fmu")
    fmu.set({"profile": list(PROFILES).index("coning") + 1, "coning_rate": 1e12})
    start = [v.start for v in motion_profile() if v.causality == "output"]
    np.testing.assert_array_equal(fmu.get(MOTION_OUT), start)
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        fmu.fmu.exitInitializationMode()
    fmu.fmu.freeInstance()


@pytest.mark.parametrize("fmi_version", ["2.0", "3.0"])
def test_exported_diagram_outputs_are_sample_0s_before_the_first_step(tmp_path, fmi_version):
    """A discrete state space exported with x0 = (1, -2) and feedthrough: before the first step its output is
    C x0 + D u with the input set in Initialization Mode, and the first step gives it again (the FMU's
    outputs after a step are those of the sample it began at)."""
    system = control.ss([[0.9, 0.1], [0.0, 0.8]], [[1.0], [0.5]], [[1.0, -1.0]], [[0.2]], 0.01, name="plant")
    path = export_fmu(system, tmp_path / "plant.fmu", x0=[1.0, -2.0], fmi_version=fmi_version,
                      cmake_options=("AF_WERROR=ON",))
    fmu = Initialising(path)
    fmu.set({"u[0]": 4.0})
    expected = 1.0 * 1.0 - 1.0 * -2.0 + 0.2 * 4.0
    assert fmu.get(["y[0]"])[0] == pytest.approx(expected, abs=1e-15)
    fmu.fmu.exitInitializationMode()
    assert fmu.get(["y[0]"])[0] == pytest.approx(expected, abs=1e-15)
    fmu.fmu.doStep(0.0, 0.01)
    assert fmu.get(["y[0]"])[0] == pytest.approx(expected, abs=1e-15)
    fmu.fmu.doStep(0.01, 0.01)
    assert fmu.get(["y[0]"])[0] != pytest.approx(expected, abs=1e-3)  # the state moved: x1 = A x0 + B u
    fmu.close()


@pytest.mark.parametrize("flavour", FLAVOURS)
def test_model_descriptions_declare_the_calculated_outputs(fmu_dir, flavour):
    """MotionProfile's and ImuSensor's outputs are initial="calculated" with no start and are the initial
    unknowns; the estimator's stay exact."""
    for name, calculated in (("MotionProfile", True), ("ImuSensor", True), ("AttitudeEstimator", False)):
        md = read_model_description(str(_folder(fmu_dir, flavour) / f"{name}.fmu"))
        outputs = [v for v in md.modelVariables if v.causality == "output"]
        assert all((v.initial == "calculated") == calculated for v in outputs), name
        assert all((v.start is None) == calculated for v in outputs), name
        assert {u.variable.name for u in md.initialUnknowns} == ({v.name for v in outputs} if calculated
                                                                       else set()), name


def test_verify_under_the_jacobi_master(fmu_dir):
    """`attitude verify --master jacobi`'s exact rows: step_rotation, at rest at its start, holds 1e-6°.
    coning turns from its start at |ω(0)| rad/s: the master hands the start instant down a chain of two
    connections twice, so the estimator turns once by |ω(0)|·Ts that the motion never made; its largest
    error is that sample's rotation (the closed form's), and the filters' correction pulls it back (RMS
    over the measured span far below it). The rows ran through the shortfall step of summed time."""
    rows = {(r["profile"], r["method"]): r for r in verify(fmu_dir, ["step_rotation", "coning"],
                                                           ["wiener", "first_order"], progress=False,
                                                           master="jacobi")}
    for method in ("wiener", "first_order"):
        assert rows["step_rotation", method]["pass"], rows["step_rotation", method]
        assert rows["step_rotation", method]["master"] == "jacobi"
    gyr, _, _ = PROFILES["coning"].motion().at(0.0, 0.0)
    hold_deg = math.degrees(np.linalg.norm(gyr[0]) * STEP_S)
    assert JACOBI_LAG == 2
    for method in ("wiener", "first_order"):
        row = rows["coning", method]
        assert row["valid"] and not row["pass"]
        assert 0.5 * hold_deg < row["max_deg"] <= 1.001 * hold_deg, (row, hold_deg)
        assert row["rms_deg"] < 0.5 * hold_deg, row
