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

Where the native estimator FMU is built (DIR/native/AttitudeEstimator.fmu), it runs in the
same co-simulation beside the pythonfmu one, on the same sensor signals and parameters;
each row reports the largest difference between their outputs (native_max_diff, over
every Real output and step; native_valid_equal: their `valid` agrees at every step).
"""
from __future__ import annotations

import math
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from attitude_fmu.blocks.errors import bias_angle, inclination_error, rms
from attitude_fmu.blocks.filters import accuracy
from attitude_fmu.blocks.filters.earth_filters import settle_time
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.methods.registry import method as get_method
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


def native_difference(out: dict) -> tuple[float, bool]:
    """The largest difference between the pythonfmu and the native estimator's Real outputs
    in a co-simulation's record, and whether their `valid` agrees at every step."""
    names = [k.removeprefix("estimator.") for k in out if k.startswith("estimator.") and k != "estimator.valid"]
    diff = max(float(np.abs(out[f"estimator.{n}"] - out[f"native.{n}"]).max()) for n in names)
    return diff, bool((out["estimator.valid"] == out["native.valid"]).all())


def verify_one(fmu_dir, profile: str, method: str, workdir, step: float = STEP_S, progress=None) -> dict:
    """Co-simulate one profile with one method; the row of the verify table (with the
    native estimator beside the pythonfmu one where fmu_dir/native has it)."""
    scenario = SCENARIOS[profile]
    native = (Path(fmu_dir) / "native" / "AttitudeEstimator.fmu").is_file()
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
    }, scenario.duration, step, native=native)
    out = cosimulate(ssp, scenario.duration, step, progress=progress)
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
    row["native_max_diff"], row["native_valid_equal"] = native_difference(out) if native else (None, None)
    value = row["rms_deg"] if scenario.metric == "rms" else row["mean_deg"]
    row["pass"] = bool(row["valid"] and (row["bound_deg"] is None or value <= row["bound_deg"]))
    return row


def verify(fmu_dir, profiles=None, methods=None, step: float = STEP_S, progress: bool = True) -> list[dict]:
    """Rows for every profile × method (default: all)."""
    profiles = list(profiles or SCENARIOS)
    methods = list(methods or METHODS)
    rows = []
    with tempfile.TemporaryDirectory(prefix="attitude_verify_") as workdir:
        for i, (profile, method) in enumerate((p, m) for p in profiles for m in methods):
            label = f"verify: {i + 1}/{len(profiles) * len(methods)} {profile} × {method}"
            tty = sys.stderr.isatty()
            report = (lambda f, label=label: print(f"\r{label} {f:4.0%}", end="", file=sys.stderr, flush=True)) \
                if progress and tty else None
            if progress and not tty:
                print(f"{label} …", file=sys.stderr, flush=True)
            rows.append(verify_one(fmu_dir, profile, method, workdir, step, report))
            if progress:
                print(f"\r{label} done", file=sys.stderr, flush=True)
    return rows
