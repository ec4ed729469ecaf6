"""AttitudeEstimator.fmu: the project's attitude estimators as an FMI 2.0 co-simulation FMU.

Each doStep(t, h) takes gyr (mean rate over (t, t+h], or with gyr_samples "point" the
rate at t+h) and acc, mag at t+h, and steps the
same pipeline as `attitude estimate` (blocks.pipeline.online.OnlineEstimator). The tuning
parameters are those of every method and of the gyro-offset and heading estimators
(blocks.pipeline.causal). Each starts at its default, so an importer shows the values the
FMU runs with; one whose default is derived from others, or differs between the methods
that share its name, starts at NaN, "unset" (its description says what that means).
Parameters of a method or estimator that does not run must stay at their start values.
"""
from __future__ import annotations

import math

from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.causal import ESTIMATORS, valid_sample
from attitude_fmu.blocks.pipeline.online import OnlineEstimator, same_step
from attitude_fmu.fmu_src.fmu_support import IN, OUT, PAR, Fmi2Status, ProjectSlave, fmi_unit


def tuning_parameters():
    """Every method's tuning parameters and those of the gyro-offset and heading
    estimators, once each: name → (FMI unit, description, start value). The start value is
    the default where every stage with the name has that one default, else NaN: unset."""
    found = {}
    for owner, stage in (*((f"method {m.name}", m.params) for m in METHODS.values()), *ESTIMATORS.items()):
        for p in stage:
            found.setdefault(p.name, []).append((owner, p))
    params = {}
    for name, uses in found.items():
        first = uses[0][1]
        defaults = {p.default for _, p in uses}
        if len(defaults) == 1 and first.default is not None:
            params[name] = (fmi_unit(first.unit), f"{first.doc}; default {first.default:g}", first.default)
            continue
        if defaults == {None}:
            doc = f"{first.doc}; NaN (the start value): unset"
        else:
            each = "; ".join(f"{owner}: {'unset' if p.default is None else format(p.default, 'g')}" for owner, p in uses)
            doc = f"{first.doc}; NaN (the start value): the default of the stage that runs ({each})"
        params[name] = (fmi_unit(first.unit), doc, math.nan)
    return params


def overrides(values) -> dict:
    """The tuning parameters (name → value) that differ from their start values: those the
    estimator is given (NaN, unset, is never given)."""
    return {name: values[name] for name, (_, _, start) in tuning_parameters().items()
            if not math.isnan(values[name]) and values[name] != start}


class AttitudeEstimator(ProjectSlave):
    author = "attitude-fmu"
    description = "IMU attitude estimator (Rizun's optimal Wiener filter and peers); gravity up, ENU, q sensor->earth"
    internal_state = ("estimator", "_warned_step")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.vector("gyr", (0.0, 0.0, 0.0), "rad/s", "gyro {c}, mean rate over the step (gyr_samples mean) "
                    "or the rate at its end (point)", IN)
        self.vector("acc", (0.0, 0.0, 9.81), "m/s2", "specific force {c} at the end of the step (acc_samples point) "
                    "or its mean over the step (mean)", IN)
        self.vector("mag", (0.0, 0.0, 0.0), "uT", "magnetic field {c}; all 0: no magnetometer (heading from the gyro); NaN: no sample this step", IN)
        self.vector("q", (1.0, 0.0, 0.0, 0.0), "1", "orientation quaternion {c}, sensor -> earth (ENU)", OUT, "wxyz")
        self.vector("g", (0.0, 0.0, 1.0), "1", "estimated unit up-vector {c}, sensor coordinates", OUT)
        for name in ("roll", "pitch", "yaw"):
            self.real(name, 0.0, "rad", f"{name} (Z-Y-X Euler angles of q; derived output)", OUT)
        self.vector("gyr_offset", (0.0, 0.0, 0.0), "rad/s", "estimated gyro offset {c} (gyro_offset on; else 0)", OUT)
        self.vector("mag_offset", (0.0, 0.0, 0.0), "uT", "estimated hard-iron offset {c} of the magnetometer "
                    "(heading mag; 0 until one is proven)", OUT)
        self.real("mag_delay_used", 0.0, "s", "the magnetometer's delay behind the gyro the heading allows for "
                  "(the parameter mag_delay, or its online estimate: 0 until one is taken)", OUT)
        self.boolean_output("valid", False, "an estimate is available and the last inputs were finite")
        self.parameter("method", "wiener", f"estimator: {', '.join(METHODS)}")
        self.parameter("heading", "mag", "heading source: mag (magnetometer, hard iron fitted, guarded against disturbances) or gyro")
        self.parameter("gyro_offset", "on", "on (default, as attitude estimate): estimate and remove the gyro offset "
                       "(at rest and while moving); off: for a gyro without offset")
        self.real("Ts", 0.01, "s", "sample time the estimator expects (other step sizes are re-discretised)", PAR)
        self.parameter("gyr_samples", "mean", "mean: gyr is the mean rate over the step (the FMI convention of "
                       "MotionProfile and ImuSensor); point: the rate at the step's end (most models' outputs), "
                       "averaged with the last one")
        self.parameter("acc_samples", "point", "point: acc is the specific force at the step's end (the FMI "
                       "convention of MotionProfile and ImuSensor); mean: its mean over the step (a sensor that "
                       "averages it as the gyro), turned to the step's end by half the step's rotation")
        self.real("latency", 0.0, "s", "the IMU's delay behind the motion (its filters' group delay, gyr taken as the "
                  "mean rate over the step); q and g are carried forward over it with the gyro", PAR)
        for name, (unit, doc, start) in tuning_parameters().items():
            self.real(name, start, unit, doc, PAR)
        self.estimator = None
        self._warned_step = False

    def initialise(self):
        if not (math.isfinite(self.Ts) and self.Ts > 0):
            self.fail(f"invalid parameter: Ts must be a finite positive number of seconds, got {self.Ts!r}")
            return
        if self.heading not in ("mag", "gyro"):
            self.fail(f"invalid parameter: heading must be 'mag' or 'gyro', got {self.heading!r}")
            return
        if self.gyro_offset not in ("on", "off"):
            self.fail(f"invalid parameter: gyro_offset must be 'on' or 'off', got {self.gyro_offset!r}")
            return
        params = overrides({name: getattr(self, name) for name in tuning_parameters()})
        try:
            self.estimator = OnlineEstimator(self.method, params, heading=self.heading == "mag",
                                             gyro_offset=self.gyro_offset == "on", latency=self.latency,
                                             gyr_samples=self.gyr_samples, acc_samples=self.acc_samples)
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        if self.estimator is None:
            return self.fail("doStep before initialisation")
        if not self._warned_step and not same_step(step_size, self.Ts):
            self._warned_step = True  # a master with variable steps would log every one
            self.log(f"communication step {step_size:g} s differs from Ts = {self.Ts:g} s: filter re-discretised "
                     "for it (and, without further warnings, for every other step size)", Fmi2Status.warning)
        gyr = (self.gyr_x, self.gyr_y, self.gyr_z)
        acc = (self.acc_x, self.acc_y, self.acc_z)
        try:
            self.valid = self.estimator.step(gyr, acc, step_size, (self.mag_x, self.mag_y, self.mag_z))
        except ValueError as exc:
            return self.fail(str(exc))
        if self.valid:
            est = self.estimator
            self.q_w, self.q_x, self.q_y, self.q_z = est.quat.tolist()
            self.g_x, self.g_y, self.g_z = est.up.tolist()
            self.roll, self.pitch, self.yaw = est.euler.tolist()
            self.gyr_offset_x, self.gyr_offset_y, self.gyr_offset_z = est.offset.tolist()
            self.mag_offset_x, self.mag_offset_y, self.mag_offset_z = est.mag_offset.tolist()
            self.mag_delay_used = est.mag_delay
        elif not valid_sample(gyr, acc):
            what = "input beyond every IMU's range" if all(map(math.isfinite, gyr + acc)) else "non-finite input"
            self.log(f"t={current_time:g}: {what}; estimate held", Fmi2Status.warning)
        return True
