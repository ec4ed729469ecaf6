"""The native FMUs' states as a validated format, and the calls an importer may get wrong: an FMU
state's bytes with any single field out of its range (its header's checksum and configuration made
to agree, as anyone can make them), of another configuration or of another FMU are refused with
fmi2Error and leave the instance as it was (its serialised state the same bytes, its steps the
same outputs as a twin's); a freed or foreign state is refused without being read; huge counts
and steps the arithmetic cannot take are refused; FMI 3.0's `time` comes back with a state.

Where the fields of a model's state lie in the serialised bytes comes from the fuzz target built
for that model (tests/fuzz/fuzz_state.c --fields), which reads the model's own struct. The FMUs
are fmpy's to load; in the sanitized run (tests/test_sanitized.py) they are the sanitized build's."""
import ctypes
import io
import math
import re
import struct
import subprocess
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2FMUstate
from fmpy.fmi3 import FMU3Slave

from tests import native

STEP = 0.01
WARM_UP = 30
HEADER_CHECK = -8  # the checksum: the header's last 8 bytes (fmu_state.h)
HEADER_TIME = -16
PHASE, ERROR_PHASE = 52, 4  # the header's phase and the state machine's error state (fmi2/instance.h)
FNV_BASIS, FNV_PRIME, MASK = 14695981039346656037, 1099511628211, (1 << 64) - 1
HUGE_COUNTS = (2**62, 2**64 - 1, 2**30)

# the configurations the field cases start from: the model's parameters
CONFIGS = {
    "AttitudeEstimator": {"method": "tseng", "heading": "mag", "gyro_offset": "on"},
    "AttitudeEstimator mahony": {"method": "mahony", "gyr_samples": "point"},
    "ImuSensor": {"latency": 0.013, "seed": 5},
    "MotionProfile human": {"profile": "human", "seed": 2},
    "MotionProfile coning": {"profile": "coning"},
}

NAN, INF = math.nan, math.inf
# (configuration, field, element, value): each a state with that one value out of its range
FIELD_CASES = [
    ("AttitudeEstimator", "discretised", 0, 2),
    ("AttitudeEstimator", "discretised", 0, 0),
    ("AttitudeEstimator", "pipeline.method.method", 0, 99),
    ("AttitudeEstimator", "pipeline.method.method", 0, -1),
    ("AttitudeEstimator", "pipeline.method.kernel", 0, 5),
    ("AttitudeEstimator", "pipeline.method.kernel", 0, -7),
    ("AttitudeEstimator", "pipeline.method.filter.n", 0, 6),
    ("AttitudeEstimator", "pipeline.method.filter.n", 0, -1),
    ("AttitudeEstimator", "pipeline.offset_runs", 0, 2),
    ("AttitudeEstimator", "pipeline.heading_runs", 0, 0),
    ("AttitudeEstimator", "pipeline.point_gyr", 0, 1),
    ("AttitudeEstimator", "pipeline.latency", 0, 0.5),
    ("AttitudeEstimator", "step.Ts", 0, NAN),
    ("AttitudeEstimator", "step.Ts", 0, -0.01),
    ("AttitudeEstimator", "step.Ts", 0, 0.0),
    ("AttitudeEstimator", "step.stepper.kernel", 0, 5),
    ("AttitudeEstimator", "step.stepper.kernel", 0, -1),
    ("AttitudeEstimator", "step.stepper.state_size", 0, 1000),
    ("AttitudeEstimator", "step.stepper.state_size", 0, -3),
    ("AttitudeEstimator", "step.stepper.coef.sensor_frame.n", 0, 99),
    ("AttitudeEstimator", "step.stepper.coef.sensor_frame.n", 0, -2),
    ("AttitudeEstimator", "step.stepper.coef.sensor_frame.Ad", 3, 1e300),
    ("AttitudeEstimator", "state.has_last_gyr", 0, 2),
    ("AttitudeEstimator", "state.started", 0, 3),
    ("AttitudeEstimator", "state.started", 0, -1),
    ("AttitudeEstimator", "state.last_gyr", 1, NAN),
    ("AttitudeEstimator", "state.offset.t", 0, INF),
    ("AttitudeEstimator", "state.method", 0, NAN),
    ("AttitudeEstimator", "state.method", 15, 2.0),  # tseng's 5 rows, then q: q_w, no unit quaternion
    ("AttitudeEstimator", "state.heading.steps", 0, NAN),
    ("AttitudeEstimator", "state.heading.hard_iron.fit_steps", 0, -INF),
    ("AttitudeEstimator", "quat", 0, NAN),
    ("AttitudeEstimator", "mag_delay", 0, INF),
    ("AttitudeEstimator mahony", "pipeline.method.kernel", 0, 0),
    ("AttitudeEstimator mahony", "step.stepper.kernel", 0, 2),
    ("AttitudeEstimator mahony", "state.has_last_gyr", 0, 7),
    ("AttitudeEstimator mahony", "state.method", 0, 0.0),  # mahony's q_w: no unit quaternion
    ("ImuSensor", "params.latency", 0, 0.02),
    ("ImuSensor", "params.delta_n", 0, 1.0),
    ("ImuSensor", "seed", 0, 6),
    ("ImuSensor", "step_size", 0, NAN),
    ("ImuSensor", "step_size", 0, -0.01),
    ("ImuSensor", "step_size", 0, 0.02),
    ("ImuSensor", "delay.latency", 0, 0.5),
    ("ImuSensor", "delay.fs", 0, 0.0),
    ("ImuSensor", "delay.rows", 0, 0),
    ("ImuSensor", "delay.rows", 0, -1),
    ("ImuSensor", "delay.rows", 0, 1024),
    ("ImuSensor", "delay.rows", 0, 5000),
    ("ImuSensor", "delay.head", 0, -1),
    ("ImuSensor", "delay.head", 0, 3),
    ("ImuSensor", "delay.head", 0, 100000),
    ("ImuSensor", "delay.x", 2, NAN),
    ("MotionProfile human", "human", 0, 2),
    ("MotionProfile human", "human", 0, 0),
    ("MotionProfile human", "stream.params.delta_v", 0, 2.0),
    ("MotionProfile human", "stream.seed", 0, 3),
    ("MotionProfile human", "stream.k", 0, 2**62),
    ("MotionProfile human", "stream.k", 0, 0),
    ("MotionProfile human", "stream.grid", 0, 0.0),
    ("MotionProfile human", "stream.coef", 1, NAN),
    ("MotionProfile human", "stream.state", 0, INF),
    ("MotionProfile human", "stream.state", 6, 2.0),
    ("MotionProfile human", "stream.q0", 0, 5.0),
    ("MotionProfile human", "stream.t", 0, -1.0),
    ("MotionProfile human", "stream.t", 0, NAN),
    ("MotionProfile human", "stream.t", 0, 1e300),
    ("MotionProfile human", "closed.profile", 0, 3),
    ("MotionProfile coning", "human", 0, 1),
    ("MotionProfile coning", "human", 0, -5),
    ("MotionProfile coning", "closed.profile", 0, 99),
    ("MotionProfile coning", "closed.profile", 0, -1),
    ("MotionProfile coning", "closed.profile", 0, 0),
    ("MotionProfile coning", "closed.p", 0, 1e300),
    ("MotionProfile coning", "closed.g", 0, NAN),
    ("MotionProfile coning", "stream.k", 0, 5),
]
# (configuration, variable, value): a variable's value that its type cannot hold
VALUE_CASES = [
    ("AttitudeEstimator", "method", 0),
    ("AttitudeEstimator", "method", 99),
    ("AttitudeEstimator", "heading", -1),
    ("AttitudeEstimator", "valid", 2),
    ("MotionProfile coning", "profile", 99),
    ("MotionProfile human", "omega_x", NAN),  # outputs: a step leaves them as they were rather than not finite
    ("MotionProfile coning", "omega_y", -INF),
    ("AttitudeEstimator", "q_w", NAN),
    ("ImuSensor", "acc_z", INF),
]
# (configuration, header field, offset, format, value): the header's own fields
HEADER_CASES = [
    ("AttitudeEstimator", "tag", 0, "B", ord("x")),
    ("AttitudeEstimator", "version", 48, "I", 1),
    ("AttitudeEstimator", "phase", 52, "i", 9),
    ("AttitudeEstimator", "phase", 52, "i", -1),
    ("AttitudeEstimator", "phase", 52, "i", 0),  # instantiated, with an initialised model's state
    ("AttitudeEstimator", "guid", 57, "B", None),  # None: a hex digit other than the guid's own
    ("AttitudeEstimator", "size", 120, "Q", 1 << 40),
    ("AttitudeEstimator", "configuration", 128, "Q", 12345),
    ("AttitudeEstimator", "time", 136, "d", NAN),
    ("MotionProfile human", "time", 136, "d", INF),
    ("ImuSensor", "time", 136, "d", -INF),
]


def model_of(config: str) -> str:
    return config.split()[0]


@pytest.fixture(scope="module")
def folder(request):
    sanitized = native.sanitized_build()
    return sanitized / "built" if sanitized else request.getfixturevalue("fmu_dir")


@pytest.fixture(scope="module")
def layout():
    """Per model: the header's size, the state's size, every field's and value's (offset, type)."""
    sanitized = native.sanitized_build() is not None
    targets = [f"fuzz_state_{m}" for m in ("AttitudeEstimator", "ImuSensor", "MotionProfile")]
    tests = native.build(targets, sanitize=sanitized) / "tests"
    out = {}
    for target in targets:
        lines = subprocess.run([str(tests / target), "--fields"], capture_output=True, text=True, check=True).stdout
        info = {"fields": {}, "values": {}}
        for line in lines.splitlines():
            words = line.split()
            if words[0] in ("header", "size"):
                info[words[0]] = int(words[1])
            else:
                info[words[0] + "s"][words[1]] = (int(words[2]), words[3])
        out[target.removeprefix("fuzz_state_")] = info
    return out


class Instance:
    """An instance of a native FMU (FMI 2.0 or 3.0) through fmpy, its parameters set, initialised and
    stepped WARM_UP times; its log kept."""

    def __init__(self, folder, config: str, fmi: int = 2, params=None, warm_up: int = WARM_UP):
        model = model_of(config)
        path = folder / "native" / ("fmi3" if fmi == 3 else "") / f"{model}.fmu"
        self.md = read_model_description(str(path))
        self.fmi, self.log, self.t = fmi, [], 0.0
        self.vars = {v.name: v for v in self.md.modelVariables}
        unzipped = extract(str(path))

        def logger(*args):
            self.log.append(args[-1].decode() if isinstance(args[-1], bytes) else str(args[-1]))

        if fmi == 3:
            self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier=model,
                                 instanceName="state")
            self.fmu.instantiate(logMessage=lambda env, status, category, message: logger(message))
        else:
            from fmpy import calloc, free
            from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                                   fmi2CallbackLoggerTYPE, fmi2StepFinishedTYPE)

            self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier=model,
                                 instanceName="state")
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: logger(message))
            callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            callbacks.stepFinished = fmi2StepFinishedTYPE()
            self._callbacks = callbacks  # kept alive with the instance
            self.fmu.instantiate(callbacks=callbacks)
        for name, value in {**CONFIGS[config], **(params or {})}.items():
            self.set(name, value)
        if fmi == 3:
            self.fmu.enterInitializationMode()
        else:
            self.fmu.setupExperiment()
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.steps(warm_up)

    def set(self, name, value):
        v = self.vars[name]
        if v.type == "Enumeration":
            items = [item.name for item in v.declaredType.items]
            value = items.index(value) + 1
            (self.fmu.setInt64 if self.fmi == 3 else self.fmu.setInteger)([v.valueReference], [value])
        elif v.type in ("Integer", "Int32"):
            (self.fmu.setInt32 if self.fmi == 3 else self.fmu.setInteger)([v.valueReference], [int(value)])
        else:
            (self.fmu.setFloat64 if self.fmi == 3 else self.fmu.setReal)([v.valueReference], [float(value)])

    def inputs(self, k):
        """the inputs of step k: smooth and plausible"""
        names = [v for v in self.md.modelVariables if v.causality == "input"]
        return [v.valueReference for v in names], [0.3 * math.sin(0.05 * k + i) + (9.0 if i % 3 == 2 else 0.5)
                                                   for i, v in enumerate(names)]

    def outputs(self):
        vrs = [v.valueReference for v in self.md.modelVariables
               if v.causality == "output" and v.type in ("Real", "Float64")]
        return np.array((self.fmu.getFloat64 if self.fmi == 3 else self.fmu.getReal)(vrs))

    def step(self, k, h=STEP):
        vrs, values = self.inputs(k)
        if vrs:
            (self.fmu.setFloat64 if self.fmi == 3 else self.fmu.setReal)(vrs, values)
        self.fmu.doStep(self.t, h)
        self.t += h

    def steps(self, n, first=0):
        out = []
        for k in range(first, first + n):
            self.step(k)
            out.append(self.outputs())
        return np.array(out)

    def serialised(self) -> bytes:
        state = self.fmu.getFMUState()
        data = bytes(self.fmu.serializeFMUState(state))
        self.fmu.freeFMUState(state)
        return data

    def free(self):
        self.fmu.freeInstance()


def fnv(data: bytes) -> int:
    h = FNV_BASIS
    for byte in data:
        h = ((h ^ byte) * FNV_PRIME) & MASK
    return h


def forged(data: bytes, header: int, offset: int, fmt: str, value) -> bytes:
    """data with value (struct format fmt) at offset, the checksum made to agree as anyone can"""
    out = bytearray(data)
    struct.pack_into("<" + fmt, out, offset, value)
    struct.pack_into("<Q", out, header + HEADER_CHECK, fnv(bytes(out[header:])))
    return bytes(out)


FORMATS = {"int32": "i", "float64": "d", "uint64": "Q", "bool": "i", "enumeration": "i"}


def assert_refused_and_unchanged(folder, config, bad: bytes, fmi: int = 2, reason: str = ""):
    """bad refused by fmi2DeSerializeFMUstate (FMI 3.0: fmi3DeserializeFMUState) with fmi2Error and a
    message; the instance's serialised state the same bytes after, and its steps a twin's"""
    target, twin = Instance(folder, config, fmi), Instance(folder, config, fmi)
    try:
        before = target.serialised()
        assert before == twin.serialised()
        target.log.clear()
        with pytest.raises(FMICallException, match="DeserializeFMUState|DeSerializeFMUstate") as refused:
            target.fmu.deserializeFMUState(bad) if fmi == 3 else target.fmu.deSerializeFMUstate(bad)
        assert refused.value.status == 3  # fmi2Error
        messages = [m for m in target.log if "eserializeFMUState" in m or "eSerializeFMUstate" in m]
        assert messages and "no state made" in messages[-1] and reason in messages[-1], target.log
        assert target.serialised() == before
        assert np.array_equal(target.steps(10, WARM_UP), twin.steps(10, WARM_UP))
    finally:
        target.free()
        twin.free()


@pytest.mark.parametrize("config, field, element, value", FIELD_CASES,
                         ids=[f"{c}-{f}[{e}]={v}" for c, f, e, v in FIELD_CASES])
def test_a_state_with_a_field_out_of_its_range_is_refused_and_the_instance_steps_as_before(
        folder, layout, config, field, element, value):
    info = layout[model_of(config)]
    offset, kind = info["fields"][field]
    fmt = FORMATS[kind]
    donor = Instance(folder, config)
    valid = donor.serialised()
    donor.free()
    at = offset + element * struct.calcsize(fmt)
    assert struct.unpack_from("<" + fmt, valid, at)[0] != value or math.isnan(value)  # a change
    assert_refused_and_unchanged(folder, config, forged(valid, info["header"], at, fmt, value))


@pytest.mark.parametrize("config, name, value", VALUE_CASES, ids=[f"{c}-{n}={v}" for c, n, v in VALUE_CASES])
def test_a_state_with_a_value_its_variable_cannot_hold_is_refused(folder, layout, config, name, value):
    info = layout[model_of(config)]
    offset, kind = info["values"][name]
    donor = Instance(folder, config)
    valid = donor.serialised()
    donor.free()
    assert_refused_and_unchanged(folder, config, forged(valid, info["header"], offset, FORMATS[kind], value),
                                 reason="value")


@pytest.mark.parametrize("config, field, offset, fmt, value", HEADER_CASES,
                         ids=[f"{f}={v}" for _, f, _, _, v in HEADER_CASES])
def test_a_state_with_a_header_field_out_of_its_range_is_refused(folder, layout, config, field, offset, fmt, value):
    info = layout[model_of(config)]
    donor = Instance(folder, config)
    valid = donor.serialised()
    donor.free()
    if value is None:
        value = ord("0") if valid[offset] != ord("0") else ord("1")
    assert_refused_and_unchanged(folder, config, forged(valid, info["header"], offset, fmt, value))


@pytest.mark.parametrize("cells", [2**64 - 2, 2**63, 2**53 + 2])
def test_a_human_motion_state_with_cells_beyond_its_grid_is_refused_though_its_times_agree(folder, layout, cells):
    """Issue 50: a consistent forgery, the cells drawn near 2^64 (the count would wrap in the next step's
    loop and never end) with the stream's time and the header's time those cells reach, is refused; a
    stream draws 2^53 cells at most (human_motion.h, HUMAN_MAX_GRID)."""
    info = layout["MotionProfile"]
    donor = Instance(folder, "MotionProfile human")
    valid = donor.serialised()
    donor.free()
    grid = struct.unpack_from("<d", valid, info["fields"]["stream.grid"][0])[0]
    bad = valid
    for field, fmt, value in (("stream.k", "Q", cells), ("stream.t", "d", cells * grid)):
        bad = forged(bad, info["header"], info["fields"][field][0], fmt, value)
    bad = forged(bad, info["header"], info["header"] + HEADER_TIME, "d", cells * grid)
    assert_refused_and_unchanged(folder, "MotionProfile human", bad, reason="grid cells drawn")


def test_a_state_cut_short_or_of_another_fmu_is_refused(folder, layout):
    imu = Instance(folder, "ImuSensor")
    foreign = imu.serialised()
    imu.free()
    donor = Instance(folder, "AttitudeEstimator")
    valid = donor.serialised()
    donor.free()
    assert_refused_and_unchanged(folder, "AttitudeEstimator", foreign, reason="another size")
    assert_refused_and_unchanged(folder, "AttitudeEstimator", valid[:-1], reason="another size")
    assert_refused_and_unchanged(folder, "AttitudeEstimator", valid[:100], reason="another size")


def test_the_fmi3_estimator_refuses_a_forged_state_as_fmi2_does(folder, layout):
    info = layout["AttitudeEstimator"]
    donor = Instance(folder, "AttitudeEstimator", fmi=3)
    valid = donor.serialised()
    donor.free()
    offset, _ = info["fields"]["pipeline.method.kernel"]
    assert_refused_and_unchanged(folder, "AttitudeEstimator", forged(valid, info["header"], offset, "i", 77), fmi=3,
                                 reason="configuration")


@pytest.mark.parametrize("config, other", [("AttitudeEstimator", {"method": "luinge"}),
                                           ("AttitudeEstimator", {"tau_heading": 3.0}),
                                           ("MotionProfile coning", {"profile": "incline"}),
                                           ("ImuSensor", {"seed": 6})])
def test_a_state_of_another_configuration_is_refused_by_an_initialised_instance(folder, config, other):
    """It is made (its bytes are valid), but an instance of another configuration does not take it;
    one not yet initialised does, with the configuration."""
    source = Instance(folder, config, params=other)
    data, t = source.serialised(), source.t
    expected = source.steps(5, WARM_UP)
    source.free()
    target, twin = Instance(folder, config), Instance(folder, config)
    try:
        state = target.fmu.deSerializeFMUstate(data)
        target.log.clear()
        with pytest.raises(FMICallException, match="fmi2SetFMUstate"):
            target.fmu.setFMUstate(state)
        assert any("another configuration" in m for m in target.log), target.log
        assert target.serialised() == twin.serialised()
        assert np.array_equal(target.steps(10, WARM_UP), twin.steps(10, WARM_UP))
        target.fmu.reset()
        target.fmu.setFMUstate(state)  # instantiated: the state brings its configuration
        target.t = t
        assert np.array_equal(target.steps(5, WARM_UP), expected)
    finally:
        target.free()
        twin.free()


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_freed_or_foreign_state_is_refused_without_being_read(folder, fmi):
    """fmi2FreeFMUstate, fmi2SetFMUstate and fmi2SerializedFMUstateSize (FMI 3.0: fmi3...FMUState) of a state
    freed already, or of another instance's: fmi2Error, the instance as it was (the sanitized run would report
    a read of freed memory); states not freed go with their instance (and LeakSanitizer would tell)."""
    one, other = Instance(folder, "AttitudeEstimator", fmi), Instance(folder, "AttitudeEstimator", fmi)
    prefix, kind = ("fmi3", "FMUState") if fmi == 3 else ("fmi2", "FMUstate")
    raw = {name: getattr(one.fmu, f"{prefix}{name}{kind}" + ("Size" if name == "Serialized" else ""))
           for name in ("Free", "Set", "Serialized")}
    try:
        state = one.fmu.getFMUState()
        copy = fmi2FMUstate(state.value)
        one.fmu.freeFMUState(state)
        assert state.value is None
        before = one.serialised()
        for call in (lambda: raw["Free"](one.fmu.component, ctypes.byref(copy)),
                     lambda: raw["Set"](one.fmu.component, copy),
                     lambda: raw["Serialized"](one.fmu.component, copy, ctypes.byref(ctypes.c_size_t()))):
            one.log.clear()
            with pytest.raises(FMICallException):
                call()
            assert any("freed already, or another's" in m for m in one.log), one.log
        foreign = other.fmu.getFMUState()
        one.log.clear()
        with pytest.raises(FMICallException, match=f"{prefix}Set{kind}"):
            one.fmu.setFMUState(foreign)
        assert any("not an FMU state of this instance" in m for m in one.log)
        assert one.serialised() == before
        for _ in range(3):
            one.fmu.getFMUState()  # left for fmi2FreeInstance
        assert np.array_equal(one.steps(5, WARM_UP), other.steps(5, WARM_UP))
    finally:
        one.free()
        other.free()


@pytest.mark.parametrize("call", ["fmi3SetInt32", "fmi3SetBoolean", "fmi3GetInt32", "fmi3GetFloat64",
                                  "fmi3SetInt64", "fmi3GetBoolean"])
@pytest.mark.parametrize("count", HUGE_COUNTS)
def test_a_huge_count_is_refused_before_anything_is_sized_by_it(folder, call, count):
    fmu = Instance(folder, "AttitudeEstimator", fmi=3, warm_up=1)
    try:
        c_type = {"Int32": ctypes.c_int32, "Boolean": ctypes.c_bool, "Float64": ctypes.c_double,
                  "Int64": ctypes.c_int64}[call[7:]]
        vr, values = (ctypes.c_uint32 * 1)(0), (c_type * 1)()
        fmu.log.clear()
        with pytest.raises(FMICallException, match=call):
            getattr(fmu.fmu, call)(fmu.fmu.component, vr, count, values, count)
        assert any("value references: more than" in m for m in fmu.log), fmu.log
        with pytest.raises(FMICallException, match=call):  # counts that differ
            getattr(fmu.fmu, call)(fmu.fmu.component, vr, 1, values, count)
    finally:
        fmu.free()


STEPS = [(0.3, NAN), (0.3, INF), (0.3, -0.01), (0.3, 0.0), (NAN, 0.01), (INF, 0.01), (0.3, 1e200), (0.3, 1e300),
         (1e308, 1e308)]


@pytest.mark.parametrize("config, fmi", [("AttitudeEstimator", 2), ("AttitudeEstimator", 3), ("ImuSensor", 2),
                                         ("AttitudeEstimator mahony", 2), ("MotionProfile coning", 3)])
@pytest.mark.parametrize("t, h", STEPS, ids=[f"t={t}-h={h}" for t, h in STEPS])
def test_a_step_that_is_not_finite_positive_or_overflows_is_refused_and_the_state_kept(folder, config, fmi, t, h):
    """fmi2Error (FMI 3.0: fmi3Error), the outputs and the model's state those of the last good step: the
    instance's serialised data the same, and from it (restored past the error) the same steps as a twin."""
    fmu, twin = Instance(folder, config, fmi), Instance(folder, config, fmi)
    try:
        saved = fmu.fmu.getFMUState()
        vrs, values = fmu.inputs(WARM_UP)
        if vrs:
            (fmu.fmu.setFloat64 if fmi == 3 else fmu.fmu.setReal)(vrs, values)
        last, data = fmu.outputs(), fmu.serialised()
        fmu.log.clear()
        with pytest.raises(FMICallException, match="DoStep") as refused:
            fmu.fmu.doStep(t, h)
        assert refused.value.status == 3 and fmu.log, fmu.log
        assert np.array_equal(fmu.outputs(), last)
        after = fmu.serialised()  # but for the phase (the error state), the same bytes
        assert struct.unpack_from("<i", after, PHASE)[0] == ERROR_PHASE
        assert after[:PHASE] + after[PHASE + 4:] == data[:PHASE] + data[PHASE + 4:]
        fmu.fmu.setFMUState(saved)
        assert np.array_equal(fmu.steps(10, WARM_UP), twin.steps(10, WARM_UP))
    finally:
        fmu.free()
        twin.free()


def test_fmi3_time_comes_back_with_a_state(folder):
    fmu = Instance(folder, "AttitudeEstimator", fmi=3)
    time_vr = next(v.valueReference for v in fmu.md.modelVariables if v.name == "time")
    try:
        state = fmu.fmu.getFMUState()
        data = bytes(fmu.fmu.serializeFMUState(state))
        assert fmu.fmu.getFloat64([time_vr]) == [pytest.approx(WARM_UP * STEP, abs=1e-12)]
        assert struct.unpack_from("<d", data, 152 + HEADER_TIME)[0] == fmu.fmu.getFloat64([time_vr])[0]
        fmu.steps(20, WARM_UP)
        assert fmu.fmu.getFloat64([time_vr])[0] > (WARM_UP + 19) * STEP
        fmu.fmu.setFMUState(state)
        assert fmu.fmu.getFloat64([time_vr]) == [pytest.approx(WARM_UP * STEP, abs=1e-12)]
        fmu.steps(7, WARM_UP)
        fmu.fmu.setFMUState(fmu.fmu.deserializeFMUState(data))
        assert fmu.fmu.getFloat64([time_vr]) == [pytest.approx(WARM_UP * STEP, abs=1e-12)]
        fmu.fmu.reset()  # time 0 (not gettable before initialisation) until the state brings it back
        fmu.fmu.setFMUState(state)
        assert fmu.fmu.getFloat64([time_vr]) == [pytest.approx(WARM_UP * STEP, abs=1e-12)]
    finally:
        fmu.free()


@pytest.mark.slow
def test_the_fuzz_targets_driver_finds_nothing():
    """tests/fuzz/fuzz_state.c's own driver (seeded mutations of the corpus) under ASan, UBSan and
    LeakSanitizer, a few seconds a model: runs, refusals and taken states, no report."""
    from tests.fuzz import run

    for result in run.fuzz(6.0, libfuzzer=False):
        assert result.runs > 100 and not result.findings, result.findings


def _rewritten_ssp(ssp: Path, out: Path, change) -> Path:
    """ssp with change(name, bytes) -> bytes applied to each of its files, as out"""
    with zipfile.ZipFile(ssp) as source, zipfile.ZipFile(out, "w") as target:
        for item in source.infolist():
            target.writestr(item, change(item.filename, source.read(item.filename)))
    return out


def _nested(name: str, data: bytes, fmu: str, change) -> bytes:
    """data of the SSP's file name, with change applied to the files of the FMU fmu within it"""
    if not name.endswith(f"/{fmu}.fmu"):
        return data
    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as source, zipfile.ZipFile(buffer, "w") as target:
        for item in source.infolist():
            target.writestr(item, change(item.filename, source.read(item.filename)))
    return buffer.getvalue()


@pytest.fixture(scope="module")
def chain_ssp(folder, tmp_path_factory):
    from attitude_fmu.systems.fmi.ssp import write_ssp

    return write_ssp(tmp_path_factory.mktemp("ssp") / "chain.ssp", folder, {"motion": {"profile": "coning"}}, 0.05,
                     STEP, chain="native")


@pytest.mark.parametrize("old, new, message", [
    (b'endConnector="gyr_x"', b'endConnector="gyr_q"', "component estimator has no input variable 'gyr_q'"),
    (b'startConnector="omega_x"', b'startConnector="omega_q"', "component motion has no output variable 'omega_q'"),
    (b'startConnector="omega_x"', b'startConnector="seed"', "component motion has no output variable 'seed'"),
    (b'endElement="estimator"', b'endElement="estimater"', "names a component the SSD does not have: 'estimater'"),
    (b'name="profile"', b'name="profil"', "component motion has no variable 'profil' (a parameter binding"),
])
def test_cosimulate_names_a_missing_variable_connector_or_component(chain_ssp, tmp_path, monkeypatch, old, new,
                                                                    message):
    from attitude_fmu.systems.fmi.cosim import cosimulate

    def change(name, data):
        assert name != "SystemStructure.ssd" or old in data, (old, data[:2000])
        return data.replace(old, new, 1) if name == "SystemStructure.ssd" else data

    bad = _rewritten_ssp(chain_ssp, tmp_path / "bad.ssp", change)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "extracted"))
    (tmp_path / "extracted").mkdir()
    with pytest.raises(ValueError, match=re.escape(message)):
        cosimulate(bad, 0.05, STEP)
    assert list((tmp_path / "extracted").iterdir()) == []  # every extraction folder removed


def test_cosimulate_removes_the_extraction_folders_when_a_binary_fails_to_load(chain_ssp, tmp_path, monkeypatch):
    from attitude_fmu.systems.fmi.cosim import cosimulate

    def broken(name, data):  # the sensor's binary: not a shared library
        return _nested(name, data, "ImuSensor", lambda inner, d: b"not a library" if inner.startswith("binaries/")
                       else d)

    bad = _rewritten_ssp(chain_ssp, tmp_path / "broken.ssp", broken)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "extracted"))
    (tmp_path / "extracted").mkdir()
    with pytest.raises(RuntimeError, match="component imu: its binary .* failed to load"):
        cosimulate(bad, 0.05, STEP)
    assert list((tmp_path / "extracted").iterdir()) == []
    assert cosimulate(chain_ssp, 0.05, STEP)["time"].size == 5  # the good one runs
