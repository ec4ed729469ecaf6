"""MotionProfile.fmu (native, FMI 2.0 and 3.0) does not depend on how the master partitions time:
stepped at 0.01, 0.002 and 1e-4 s, every profile gives the same orientation and field at the common
times, and its interval outputs (the rate that turns the orientation over the step, the specific force
of the step's mean acceleration, docs/conventions.md) over a coarse step are those the finer steps
compose to (their rotations chained, their earth-frame accelerations averaged), all within 1e-9;
steps of 1e-9 and 1.7e-13 s give finite outputs, the human motion's those of its grid cell. Every
parameter is checked against its plausible range (systems/simulation/profile_table.py, the C core's table
generated from it: one check for the FMU and the Python profiles), and a step whose arithmetic overflows is
refused with fmi2Error, the outputs kept."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave, fmi3LogMessageCallback
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.fmi.native import built
from attitude_fmu.systems.simulation.motion import PROFILES, profile
from attitude_fmu.systems.simulation.profile_table import PROFILES as TABLE
from tests import native

G = 9.81  # the FMU's default g, m/s²
STEPS = (0.01, 0.002, 1e-4)  # s
DURATION = 0.3  # s: 300 cells of the human motion's grid, 30 coarse steps
TRUTH = ["omega_x", "omega_y", "omega_z", "f_x", "f_y", "f_z", "m_x", "m_y", "m_z", "qt_w", "qt_x", "qt_y", "qt_z"]
VERSIONS = ("2.0", "3.0")
REFUSED = r"status 3 \(error\)"  # fmpy's words for fmi2Error, fmi3Error
FMUS = {"2.0": "native/MotionProfile.fmu", "3.0": "native/fmi3/MotionProfile.fmu"}  # in built/


def fmu_path(version: str) -> Path:
    """The native MotionProfile of the version: the package's, or in the sanitized run (tests/native.py)
    the sanitized build's."""
    sanitized = native.sanitized_build()
    return sanitized / "built" / FMUS[version] if sanitized else built(FMUS[version])


class Motion:
    """A native MotionProfile of one FMI version through fmpy, its log kept."""

    def __init__(self, fmu: Path, folder: Path, version: str):
        self.md = read_model_description(str(fmu))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.items = [item.name for item in self.variables["profile"].declaredType.items]
        self.log: list[str] = []
        unzipped = extract(str(fmu), str(folder))
        if version == "2.0":
            self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier="MotionProfile")
            self._logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: self.log.append(
                message.decode()))
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = self._logger
            self.fmu.instantiate(callbacks=callbacks, loggingOn=True)
        else:
            self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier="MotionProfile")
            self._logger = fmi3LogMessageCallback(lambda env, status, category, message: self.log.append(
                message.decode()))
            self.fmu.instantiate(loggingOn=True, logMessage=self._logger)
        self.version = version

    def start(self, name: str, params: dict | None = None, seed: int = 3, start_time: float = 0.0) -> None:
        """Back at start_time (s), initialised with the profile name and parameter values (FMU
        names); fmpy's exception where the FMU refuses."""
        self.fmu.reset()
        v = self.version == "2.0"
        if v:
            self.fmu.setupExperiment(startTime=start_time)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=start_time)
        profile_vr, seed_vr = self.variables["profile"].valueReference, self.variables["seed"].valueReference
        (self.fmu.setInteger if v else self.fmu.setInt64)([profile_vr], [self.items.index(name) + 1])
        (self.fmu.setInteger if v else self.fmu.setInt32)([seed_vr], [seed])
        for key, value in (params or {}).items():
            (self.fmu.setReal if v else self.fmu.setFloat64)([self.variables[key].valueReference], [value])
        self.fmu.exitInitializationMode()

    def step(self, t: float, h: float) -> np.ndarray:
        """doStep(t, h), then the outputs (TRUTH)."""
        self.fmu.doStep(t, h)
        return self.outputs()

    def outputs(self) -> np.ndarray:
        get = self.fmu.getReal if self.version == "2.0" else self.fmu.getFloat64
        return np.array(get([self.variables[n].valueReference for n in TRUTH]))

    def run(self, h: float, n: int) -> np.ndarray:
        """n steps of h from 0 (the k-th at k·h): the outputs after each."""
        return np.array([self.step(k * h, h) for k in range(n)])


@pytest.fixture(scope="module", params=VERSIONS)
def motion(request, tmp_path_factory):
    m = Motion(fmu_path(request.param), tmp_path_factory.mktemp("motion"), request.param)
    yield m
    m.fmu.freeInstance()


def _composed(rows: np.ndarray, h: float, per: int) -> tuple[np.ndarray, np.ndarray]:
    """The interval outputs of steps of per·h composed from the rows of steps of h: the rotation
    vector of the chained rotations over per·h, and R(end)ᵀ(mean earth-frame acceleration + g ẑ)."""
    n = len(rows) // per
    turns = Rotation.from_rotvec(rows[:, 0:3] * h)
    quat = Rotation.from_quat(rows[:, 9:13], scalar_first=True)
    acc = quat.apply(rows[:, 3:6]) - [0.0, 0.0, G]
    omega, force = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        chain = turns[k * per]
        for j in range(k * per + 1, (k + 1) * per):
            chain = chain * turns[j]
        omega[k] = chain.as_rotvec() / (per * h)
        mean = acc[k * per:(k + 1) * per].mean(axis=0) + [0.0, 0.0, G]
        force[k] = quat[(k + 1) * per - 1].inv().apply(mean)
    return omega, force


@pytest.mark.parametrize("name", list(PROFILES))
def test_the_outputs_at_common_times_do_not_depend_on_the_step(motion, name):
    coarse = STEPS[0]
    runs = {}
    for h in STEPS:
        motion.start(name)
        runs[h] = motion.run(h, int(round(DURATION / h)))
    reference = runs[coarse]
    assert np.ptp(reference[:, [0, 1, 2, 3, 4, 5, 9, 10, 11, 12]], axis=0).max() > 1e-3  # it moves
    for h in STEPS[1:]:
        per = int(round(coarse / h))
        at_common = runs[h][per - 1::per]
        assert np.abs(at_common[:, 6:13] - reference[:, 6:13]).max() < 1e-9, (name, h)  # m, q at the times
        omega, force = _composed(runs[h], h, per)
        assert np.abs(omega - reference[:, 0:3]).max() < 1e-9, (name, h, np.abs(omega - reference[:, 0:3]).max())
        assert np.abs(force - reference[:, 3:6]).max() < 1e-9, (name, h, np.abs(force - reference[:, 3:6]).max())


@pytest.mark.parametrize("name", list(PROFILES))
@pytest.mark.parametrize("tiny", [1e-9, 1.7e-13])
def test_a_tiny_step_gives_finite_outputs_those_of_its_grid_cell_for_the_human_motion(motion, name, tiny):
    """After 0.3 s at 0.01 s, a step of tiny s: finite; its rate and earth-frame acceleration those
    of the 1e-4 s step from the same time (the human motion: both in one grid cell, exactly, to 1e-9;
    the closed forms: their derivatives, to the rounding of t + tiny), its orientation a unit quaternion."""
    motion.start(name)
    motion.run(0.01, 30)
    small = motion.step(0.3, tiny)
    motion.start(name)
    motion.run(0.01, 30)
    fine = motion.step(0.3, 1e-4)
    assert np.isfinite(small).all()
    assert abs(np.linalg.norm(small[9:13]) - 1.0) < 1e-12
    earth = [Rotation.from_quat(row[9:13], scalar_first=True).apply(row[3:6]) for row in (small, fine)]
    scale = max(1.0, np.abs(fine[0:6]).max())
    tolerance = 1e-9 if name == "human" else 1e-2 * scale
    assert np.abs(small[0:3] - fine[0:3]).max() < tolerance
    assert np.abs(earth[0] - earth[1]).max() < (1e-9 * scale if name == "human" else 1e-2 * scale + 1e-3)


def test_the_two_fmi_versions_give_the_same_outputs(tmp_path):
    rows = []
    for version in VERSIONS:
        m = Motion(fmu_path(version), tmp_path / version, version)
        m.start("human")
        rows.append(m.run(0.004, 50))
        m.fmu.freeInstance()
    assert np.array_equal(rows[0], rows[1])


def test_the_fmu_equals_the_python_profile_sampled_at_its_steps(motion):
    """The human motion on its grid of 1e-3 s sampled by generate() at 500 Hz: the FMU at 0.002 s."""
    motion.start("human", {"human_delta_v": 0.7, "human_rot_rms": 1.2})
    got = motion.run(0.002, 150)
    sampled = profile("human").motion({"delta_v": 0.7, "rot_rms": 1.2}, g=G).generate(0.3, 500.0, seed=3)
    expected = np.column_stack([sampled.gyr, sampled.acc, sampled.mag, sampled.quat])
    assert np.abs(got - expected).max() < 1e-9 * max(1.0, np.abs(expected).max())


# ---- the parameters' plausible ranges

def _outside(p) -> list[float]:
    """Values just outside p's range on either side, and ones no arithmetic survives."""
    return [p.low - max(abs(p.low), 1.0) * 1e-3, p.high * (1.0 + 1e-3) + 1e-3, 1e300, -1e300, math.nan, math.inf]


def _message(name: str, p, value: float) -> str:
    unit = "" if p.unit == "1" else f" {p.unit}"
    return f"parameter {name}_{p.name} = {value!r}{unit} is outside its plausible range [{p.low:g}, {p.high:g}]{unit}"


@pytest.mark.parametrize("name", list(TABLE))
def test_a_profile_refuses_a_value_outside_a_parameters_range_in_python(name):
    for p in TABLE[name][1]:
        profile(name).motion({p.name: p.low}).generate(0.05, 100.0)  # the edges are taken
        profile(name).motion({p.name: p.high})
        for value in _outside(p):
            with pytest.raises(ValueError) as refused:
                profile(name).motion({p.name: value})
            assert str(refused.value) == _message(name, p, value)
    with pytest.raises(ValueError, match=r"parameter g = 0.0 m/s\^2 is outside its plausible range \[1, 30\]"):
        profile(name).motion(g=0.0)


@pytest.mark.parametrize("name, parameter, value", [
    ("step_rotation", "hold", 0.0), ("linear_motion", "period", 0.0), ("incline", "frequency", 0.0),
    ("human", "grid", 0.0), ("human", "delta_v", 1e300), ("lever_arm", "rate", 1e300), ("coning", "theta", math.nan),
    ("offset_rotation", "radius", -1.0),
])
def test_the_fmu_refuses_a_parameter_outside_its_range_at_initialisation(motion, name, parameter, value):
    p = next(p for p in TABLE[name][1] if p.name == parameter)
    motion.log.clear()
    with pytest.raises(FMICallException, match=REFUSED):
        motion.start(name, {f"{name}_{parameter}": value})
    assert any(_message(name, p, value) in line for line in motion.log), motion.log


def test_the_fmu_refuses_a_gravity_outside_its_range(motion):
    motion.log.clear()
    with pytest.raises(FMICallException, match=REFUSED):
        motion.start("lever_arm", {"g": -9.81})
    assert any("parameter g = -9.81 m/s^2 is outside its plausible range [1, 30] m/s^2" in line
               for line in motion.log), motion.log


# ---- steps too large for the arithmetic

@pytest.mark.parametrize("name", list(PROFILES))
def test_a_step_that_overflows_is_refused_and_the_outputs_stay(motion, name):
    """After good steps, one whose arithmetic overflows (closed forms: its end t + h is inf) or
    that needs more grid cells than a step may draw (human): fmi2Error with the reason, the outputs
    those of the last good step."""
    motion.start(name)
    last = motion.step(0.0, 0.01)
    steps = [(0.01, 1e200)] if name == "human" else [(0.01, 1e308 - 0.01), (1e308, 1e308)]  # the last: end inf
    motion.log.clear()
    with pytest.raises(FMICallException, match=REFUSED):
        for t, h in steps:
            last = motion.step(t, h)  # a step of 1e308 s overflows some closed forms' arithmetic, not all
            assert np.isfinite(last).all()
    assert np.array_equal(motion.outputs(), last)
    reason = "needs more than 4194304 cells" if name == "human" else "overflows the motion's arithmetic"
    assert any(reason in line for line in motion.log), motion.log


def test_the_human_motion_refuses_a_step_of_too_many_grid_cells_in_python():
    stream = profile("human").motion().stream(1)
    stream.step(0.01, 0.01)
    with pytest.raises(ValueError, match="needs more than 4194304 cells of the human motion's grid"):
        stream.step(1e6, 1e6 - 0.01)
    gyr, f, q = stream.step(0.02, 0.01)  # the stream as it was
    assert np.isfinite(np.concatenate([gyr, f, q])).all()


@pytest.mark.parametrize("name", [n for n in PROFILES if n != "human"])
def test_a_closed_forms_step_that_overflows_is_refused_in_python(name):
    stream = profile(name).motion().stream()
    assert np.isfinite(np.concatenate(stream.step(0.01, 0.01))).all()
    with pytest.raises(ValueError, match=r"a step of 1e\+308 s to inf s overflows the motion's arithmetic"):
        stream.step(math.inf, 1e308)


@pytest.mark.parametrize("name", ["human", "coning"])
def test_the_outputs_do_not_depend_on_the_start_time(motion, name):
    """The motions are functions of time from 0: an experiment that starts at 0.1 s gives the
    outputs at 0.102 ... 0.3 s that one from 0 does."""
    motion.start(name)
    whole = motion.run(0.002, 150)[50:]
    motion.start(name, start_time=0.1)
    late = np.array([motion.step(0.1 + k * 0.002, 0.002) for k in range(100)])
    assert np.abs(late - whole).max() < 1e-9 * max(1.0, np.abs(whole).max())
