"""`attitude verify`: every profile co-simulated with every estimator as FMUs, against bounds.

Bounds hold where the theory gives them, for Rizun's filters (`wiener`, and the
first-order filter of §4.2): on `human` the RMS inclination error may exceed the
analytic value of the method's filter (eq. 41 over the profile's spectrum; for `wiener`
eq. 34 at the break frequency its local densities settle on for the profile,
blocks.methods.wiener_local.settled_filter) by at most RMS_MARGIN; on `lever_arm` (Rizun §2.4), `incline` (§2.5),
`offset_rotation` (Tseng 5) and `linear_motion` (Tseng 4) the mean error (tilt of the
time-averaged estimate) stays below 0.05°; on the pure rotations `coning`, `sine_rotation`
and `step_rotation` with ideal sensors the RMS error stays below EXACT_BOUND_DEG, since
the discrete step is exact for an earth-fixed input. The other estimators' rows are
reported (bound_deg null). The estimator FMU runs with gyro_offset off: the simulated
gyros have no offset, and the bounds are the filters' own.
"""
from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from attitude_fmu.blocks.errors import bias_angle, inclination_error, rms
from attitude_fmu.blocks.filters import accuracy
from attitude_fmu.blocks.filters.earth_filters import settle_time
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.fmi.cosim import cosimulate
from attitude_fmu.systems.fmi.ssp import write_ssp
from attitude_fmu.systems.simulation.motion import PROFILES

RMS_MARGIN = 1.3  # statistical allowance of a 1200 s run over the analytic RMS
BOUNDED_METHODS = ("wiener", "first_order")
BIAS_BOUND_DEG = 0.05
EXACT_BOUND_DEG = 1e-6
STEP_S = 0.02  # communication step, s
KERNEL_SETTLE_S = 100.0  # start-up cut for the methods that are not LTI filters, s


@dataclass(frozen=True)
class Scenario:
    """How a profile is verified: duration (s), sensor parameters and the bounded metric."""

    duration: float
    metric: str  # "rms" or "mean"
    imu: dict = field(default_factory=dict)
    exact: bool = False  # a pure rotation with ideal sensors: bound EXACT_BOUND_DEG
    settle_s: float | None = None  # start-up cut, s; None: from the method (see verify_one)

    def bound_deg(self, profile: str, method: str) -> float | None:
        if method not in BOUNDED_METHODS:
            return None
        if self.exact:
            return EXACT_BOUND_DEG
        if self.metric == "mean":
            return BIAS_BOUND_DEG
        motion = PROFILES[profile].motion()
        m = get_method(method)
        params = m.resolve()
        if m.runs_kernel(params):  # wiener's local densities: eq. 34 where they settle
            filt = m.kernel.settled_filter(params, 3.0 * motion.rot_rms**2, motion.delta_v)
        else:
            filt = m.design(params)
        ms = accuracy.mean_square_error(filt, params["delta_n"], motion.delta_v, motion.omega_c, motion.g)
        return RMS_MARGIN * math.degrees(math.sqrt(2.0 * ms) / motion.g)


SCENARIOS = {
    # the sensor matches the estimators' default noise model (δn = 0.1 °/s/√Hz, δv = 1 m/s/√Hz)
    "human": Scenario(1200.0, "rms", {"delta_n": math.radians(0.1), "seed": 7}),
    # ideal sensors: the claims are about the bias that acceleration causes
    "lever_arm": Scenario(600.0, "mean"),
    "incline": Scenario(600.0, "mean"),
    "offset_rotation": Scenario(600.0, "mean"),
    "linear_motion": Scenario(600.0, "mean"),
    # these start at rest with no acceleration, so no start-up transient to cut
    "coning": Scenario(120.0, "rms", exact=True, settle_s=1.0),
    "sine_rotation": Scenario(120.0, "rms", exact=True, settle_s=1.0),
    "step_rotation": Scenario(120.0, "rms", exact=True, settle_s=1.0),
}


def verify_one(fmu_dir, profile: str, method: str, workdir, step: float = STEP_S) -> dict:
    """Co-simulate one profile with one method; the row of the verify table."""
    scenario = SCENARIOS[profile]
    m = get_method(method)
    settle = scenario.settle_s
    if settle is None:
        settle = settle_time(m.filter()) if m.is_sensor_frame else KERNEL_SETTLE_S
    start = int(math.ceil(settle / step))
    if start >= int(scenario.duration / step) * 3 // 4:
        raise ValueError(f"{profile}: {scenario.duration:g} s is too short for {method} to settle "
                         f"({start * step:.0f} s) and leave as long to measure")
    ssp = write_ssp(Path(workdir) / f"{profile}_{method}.ssp", fmu_dir, {
        "motion": {"profile": profile, "seed": 3},
        "imu": dict(scenario.imu),
        "estimator": {"method": method, "Ts": step, "gyro_offset": "off"},
    }, scenario.duration, step)
    out = cosimulate(ssp, scenario.duration, step)
    q_true = np.column_stack([out[f"motion.qt_{c}"] for c in "wxyz"])[start:]
    up_true = np.column_stack([2 * (q_true[:, 1] * q_true[:, 3] - q_true[:, 0] * q_true[:, 2]),
                               2 * (q_true[:, 2] * q_true[:, 3] + q_true[:, 0] * q_true[:, 1]),
                               1 - 2 * (q_true[:, 1] ** 2 + q_true[:, 2] ** 2)])
    up_est = np.column_stack([out[f"estimator.g_{c}"] for c in "xyz"])[start:]
    err = np.degrees(inclination_error(up_est, up_true))
    row = {
        "profile": profile, "method": method,
        "rms_deg": rms(err), "max_deg": float(err.max()),
        "mean_deg": math.degrees(bias_angle(up_est, q_true)),
        "metric": scenario.metric, "bound_deg": scenario.bound_deg(profile, method),
        "valid": bool(out["estimator.valid"][start:].all()),
    }
    value = row["rms_deg"] if scenario.metric == "rms" else row["mean_deg"]
    row["pass"] = bool(row["valid"] and (row["bound_deg"] is None or value <= row["bound_deg"]))
    return row


def verify_job(fmu_dir, profile: str, method: str, step: float = STEP_S) -> dict:
    """verify_one in a folder of its own; a job of verify."""
    with tempfile.TemporaryDirectory(prefix="attitude_verify_") as workdir:
        return verify_one(fmu_dir, profile, method, workdir, step)


def verify(fmu_dir, profiles=None, methods=None, step: float = STEP_S, progress: bool = True,
           jobs: Jobs | None = None) -> list[dict]:
    """Rows for every profile × method (default: all); each row is a job of jobs
    (systems.cluster.jobs.Jobs; default: this process, a bar when progress), whose workers
    see fmu_dir at its absolute path. A row whose job failed (jobs reports it) is left out."""
    runs = [(p, m) for p in list(profiles or SCENARIOS) for m in list(methods or METHODS)]
    jobs = jobs or Jobs(bar=progress)
    rows = jobs.map(verify_job, [(str(Path(fmu_dir).absolute()), p, m, step) for p, m in runs],
                    [f"{p} × {m}" for p, m in runs], "co-simulations")
    return [row for row in rows if not isinstance(row, Failure)]
