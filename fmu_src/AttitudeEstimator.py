"""AttitudeEstimator.fmu: the project's attitude estimators as an FMI 2.0 co-simulation FMU.

Each doStep(t, h) takes gyr (mean rate over (t, t+h], or with gyr_samples "point" the
rate at t+h) and acc, mag at t+h, and steps the
same pipeline as `attitude estimate` (blocks.pipeline.online.OnlineEstimator) on the grid of its
sample time Ts from the start time (blocks.stages.timing.grid_samples): the samples the step reaches,
its inputs held; none (half a sample, a master's final shortfall of picoseconds) holds the estimate. The tuning
parameters are those of every method and of the gyro-offset and heading estimators
(blocks.pipeline.causal). Each starts at its default, so an importer shows the values the
FMU runs with; one whose default is derived from others, or differs between the methods
that share its name, starts at a value that means "unset" (systems.fmi.interface.variables.tuning_parameters;
its description says what that means). Parameters of a method or estimator that does not run
must stay at their start values. The choices (method, heading, gyro_offset, gyr_samples,
acc_samples) are Enumerations, whose items the command line's choices spell.
"""
from __future__ import annotations

import math

from attitude_fmu.blocks.pipeline.causal import valid_sample
from attitude_fmu.blocks.pipeline.online import OnlineEstimator
from attitude_fmu.blocks.stages.timing import GRID_MAX_SAMPLES, grid_before, grid_samples
from attitude_fmu.fmu_src.fmu_support import Fmi2Status, ProjectSlave
from attitude_fmu.systems.fmi.interface.variables import attitude_estimator, tuning_parameters


def overrides(values) -> dict:
    """The tuning parameters (name → value) that differ from their start values: those the
    estimator is given (NaN and the start value mean unset: never given)."""
    return {name: values[name] for name, (_, _, start) in tuning_parameters().items()
            if not math.isnan(values[name]) and values[name] != start}


class AttitudeEstimator(ProjectSlave):
    author = "attitude-fmu"
    description = "IMU attitude estimator (Rizun's optimal Wiener filter and peers); gravity up, ENU, q sensor->earth"
    internal_state = ("estimator",)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.register_table(attitude_estimator())
        self.estimator = None

    def initialise(self):
        if not (math.isfinite(self.Ts) and self.Ts > 0):
            self.fail(f"invalid parameter: Ts must be a finite positive number of seconds, got {self.Ts!r}")
            return
        params = overrides({name: getattr(self, name) for name in tuning_parameters()})
        try:
            self.estimator = OnlineEstimator(self.item("method"), params, heading=self.item("heading") == "mag",
                                             gyro_offset=self.item("gyro_offset") == "on", latency=self.latency,
                                             gyr_samples=self.item("gyr_samples"),
                                             acc_samples=self.item("acc_samples"))
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        if self.estimator is None:
            return self.fail("doStep before initialisation")
        Ts, start = self.Ts, self.start_time
        n = grid_samples(start, Ts, current_time, step_size)
        if n > GRID_MAX_SAMPLES:
            return self.fail(f"a step of {step_size!r} s reaches {n:.0f} samples of Ts = {Ts!r} s; one step runs "
                             f"{GRID_MAX_SAMPLES:.0f} at most: the estimate held")
        first = grid_before(start, Ts, current_time)
        return all(self._sample(first + k * Ts) for k in range(int(n)))

    def _sample(self, t: float) -> bool:
        """One sample of Ts at t (s) on the inputs as they are; False where it failed (fmi2Error)."""
        gyr = (self.gyr_x, self.gyr_y, self.gyr_z)
        acc = (self.acc_x, self.acc_y, self.acc_z)
        try:
            self.valid = self.estimator.step(gyr, acc, self.Ts, (self.mag_x, self.mag_y, self.mag_z))
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
            self.log(f"t={t:g}: {what}; estimate held", Fmi2Status.warning)
        return True
