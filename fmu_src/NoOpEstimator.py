"""NoOpEstimator.fmu: AttitudeEstimator's interface with nothing behind it.

Built only by the FMU benchmark, to measure what the FMI plumbing alone costs per step.
"""
from __future__ import annotations

from attitude_fmu.fmu_src.AttitudeEstimator import AttitudeEstimator


class NoOpEstimator(AttitudeEstimator):
    description = "AttitudeEstimator's interface; doStep does nothing (benchmark baseline)"

    def initialise(self):
        pass

    def do_step(self, current_time, step_size):
        return True
