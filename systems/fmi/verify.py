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

The chain co-simulated is the native one (DIR/native: MotionProfile, ImuSensor and
AttitudeEstimator in C) where it is built, else the pythonfmu one (DIR). With --python the
pythonfmu chain runs every configuration too, with the same seeds: each row then reports the
largest difference between the two estimators' outputs (native_max_diff, over every Real
output but the Euler angles, derived from q, and every step; native_valid_equal: their `valid`
agrees at every step), held within CHAIN_TOLERANCE. Each configuration runs the SSP
`attitude ssp` writes for it (write_verify_ssp), as an independent call (verify_one).
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
from attitude_fmu.blocks.methods.wiener_local import settled_filter
from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.fmi.build import ensure_built
from attitude_fmu.systems.fmi.cosim import cosimulate
from attitude_fmu.systems.fmi.platforms import parse_platforms
from attitude_fmu.systems.fmi.ssp import CHAINS, COMPONENTS, write_ssp
from attitude_fmu.systems.simulation.motion import PROFILES

RMS_MARGIN = 1.3  # statistical allowance of a 1200 s run over the analytic RMS
BOUNDED_METHODS = ("wiener", "first_order")
BIAS_BOUND_DEG = 0.05
EXACT_BOUND_DEG = 1e-6
STEP_S = 0.02  # communication step, s
KERNEL_SETTLE_S = 100.0  # start-up cut for the methods that are not LTI filters, s
JACOBI_LAG = 2  # steps by which the estimator's inputs arrive late under a Jacobi master: motion -> imu -> estimator
CHAIN_TOLERANCE = 1e-9  # the native and the pythonfmu chain's estimator outputs, with the same seeds
DERIVED_OUTPUTS = ("estimator.valid", "estimator.roll", "estimator.pitch", "estimator.yaw")  # not held to it


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
            filt = settled_filter(params, 3.0 * motion.rot_rms**2, motion.delta_v)
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


MOTION_SEED = 3  # the motion's seed in every configuration (the sensor's: the scenario's, else ImuSensor's default)


def chain_difference(out: dict, other: dict) -> tuple[float, bool]:
    """The largest difference between the estimator's Real outputs in two co-simulations' records
    (two chains of the same configuration), and whether its `valid` agrees at every step. The
    Euler angles are left out: derived from q, which is compared, they are ill-conditioned at
    pitch ±90° (step_rotation's last step), where 1e-16 of q turns roll and yaw by up to 2π and
    pitch by 1e-8."""
    names = [k for k in out if k.startswith("estimator.") and k not in DERIVED_OUTPUTS]
    diff = max(float(np.abs(out[n] - other[n]).max()) for n in names)
    return diff, bool((out["estimator.valid"] == other["estimator.valid"]).all())


def settle_steps(profile: str, method: str, step: float = STEP_S) -> int:
    """The steps cut at the start of a configuration before it is measured; ValueError where the
    scenario is too short to leave as long to measure."""
    scenario = SCENARIOS[profile]
    m = get_method(method)
    settle = scenario.settle_s
    if settle is None:
        settle = settle_time(m.filter()) if m.is_sensor_frame else KERNEL_SETTLE_S
    start = int(math.ceil(settle / step))
    if start >= int(scenario.duration / step) * 3 // 4:
        raise ValueError(f"{profile}: {scenario.duration:g} s is too short for {method} to settle "
                         f"({start * step:.0f} s) and leave as long to measure")
    return start


def write_verify_ssp(path, fmu_dir, profile: str, method: str, chain: str = "native", step: float = STEP_S) -> Path:
    """The SSP of one configuration (profile × method), with the FMUs of the chain (native or python)
    inside: what verify runs, and what `attitude ssp` writes for other tools."""
    settle_steps(profile, method, step)  # refuses a scenario too short to measure
    scenario = SCENARIOS[profile]
    return write_ssp(path, fmu_dir, {
        "motion": {"profile": profile, "seed": MOTION_SEED},
        "imu": dict(scenario.imu),
        "estimator": {"method": method, "Ts": step, "gyro_offset": "off"},
    }, scenario.duration, step, chain=chain)


def write_verify_ssps(fmu_dir, out, profiles=None, methods=None, chain: str = "native") -> list[Path]:
    """out/<profile>_<method>.ssp for every profile × method (default: all): `attitude ssp`."""
    missing = [fmu for fmu, _, _ in COMPONENTS.values() if not (Path(fmu_dir) / CHAINS[chain] / f"{fmu}.fmu").is_file()]
    if missing:
        raise RuntimeError(f"the {chain} chain's {', '.join(missing)} FMUs are not built in {Path(fmu_dir) / CHAINS[chain]}"
                           + (" (the native FMUs need a C compiler; --python takes the pythonfmu ones)"
                              if chain == "native" else ""))
    Path(out).mkdir(parents=True, exist_ok=True)
    return [write_verify_ssp(Path(out) / f"{p}_{m}.ssp", fmu_dir, p, m, chain)
            for p in profiles or SCENARIOS for m in methods or METHODS]


def row_of(out: dict, profile: str, method: str, step: float = STEP_S, lag: int = 0) -> dict:
    """The verify table's row of a co-simulation's record; lag: the steps by which the estimator's
    inputs arrive late in the master that ran it (libcosim's: 2), taken off against the truth."""
    scenario = SCENARIOS[profile]
    start = settle_steps(profile, method, step)
    n = len(out["time"]) - lag
    q_true = np.column_stack([out[f"motion.qt_{c}"] for c in "wxyz"])[start:n]
    up_true = np.column_stack([2 * (q_true[:, 1] * q_true[:, 3] - q_true[:, 0] * q_true[:, 2]),
                               2 * (q_true[:, 2] * q_true[:, 3] + q_true[:, 0] * q_true[:, 1]),
                               1 - 2 * (q_true[:, 1] ** 2 + q_true[:, 2] ** 2)])
    up_est = np.column_stack([out[f"estimator.g_{c}"] for c in "xyz"])[start + lag:]
    err = np.degrees(inclination_error(up_est, up_true))
    row = {
        "profile": profile, "method": method,
        "rms_deg": rms(err), "max_deg": float(err.max()),
        "mean_deg": math.degrees(bias_angle(up_est, q_true)),
        "metric": scenario.metric, "bound_deg": scenario.bound_deg(profile, method),
        "valid": bool(out["estimator.valid"][start + lag:].all()),
    }
    value = row["rms_deg"] if scenario.metric == "rms" else row["mean_deg"]
    row["pass"] = bool(row["valid"] and (row["bound_deg"] is None or value <= row["bound_deg"]))
    return row


def verify_one(fmu_dir, profile: str, method: str, workdir, step: float = STEP_S, progress=None,
               chain: str = "native", python: bool = False, master: str = "gauss-seidel") -> dict:
    """Co-simulate one profile with one method (an independent call: a pool can run many at once)
    on the chain; the row of the verify table. With python (and the native chain), the pythonfmu
    chain runs the same configuration too: the row then holds the largest difference between the
    two estimators' outputs (native_max_diff, native_valid_equal) and passes only where both rows
    pass and that difference is within CHAIN_TOLERANCE. master: cosimulate's ("jacobi": the estimator's
    inputs JACOBI_LAG steps late, taken off against the truth)."""
    lag = JACOBI_LAG if master == "jacobi" else 0
    ssp = write_verify_ssp(Path(workdir) / f"{profile}_{method}_{chain}.ssp", fmu_dir, profile, method, chain, step)
    out = cosimulate(ssp, SCENARIOS[profile].duration, step, progress=progress, master=master)
    row = {**row_of(out, profile, method, step, lag), "chain": chain, "master": master, "native_max_diff": None,
           "native_valid_equal": None}
    if python and chain == "native":
        ssp = write_verify_ssp(Path(workdir) / f"{profile}_{method}_python.ssp", fmu_dir, profile, method, "python", step)
        other = cosimulate(ssp, SCENARIOS[profile].duration, step, progress=progress, master=master)
        row["native_max_diff"], row["native_valid_equal"] = chain_difference(out, other)
        row["pass"] = bool(row["pass"] and row_of(other, profile, method, step, lag)["pass"]
                           and row["native_valid_equal"] and row["native_max_diff"] <= CHAIN_TOLERANCE)
    return row


def chain_of(fmu_dir) -> str:
    """The chain verify runs by default: native where fmu_dir/native has its three FMUs (a C
    compiler built them), else python."""
    native = Path(fmu_dir) / CHAINS["native"]
    return "native" if all((native / f"{fmu}.fmu").is_file() for fmu, _, _ in COMPONENTS.values()) else "python"


def verify_job(fmu_dir, profile: str, method: str, step: float = STEP_S, chain: str = "native",
               python: bool = False, master: str = "gauss-seidel") -> dict:
    """verify_one in a folder of its own; a job of verify."""
    with tempfile.TemporaryDirectory(prefix="attitude_verify_") as workdir:
        return verify_one(fmu_dir, profile, method, workdir, step, chain=chain, python=python, master=master)


def verify(fmu_dir, profiles=None, methods=None, step: float = STEP_S, progress: bool = True,
           python: bool = False, jobs: Jobs | None = None, platforms: str = "host",
           master: str = "gauss-seidel") -> list[dict]:
    """Rows for every profile × method (default: all), on the native chain where it is built
    (chain_of), with python the pythonfmu chain beside it (verify_one). Each row is a job of
    jobs (systems.cluster.jobs.Jobs; default: this process, a bar when progress), whose
    workers see fmu_dir at its absolute path; a row whose job failed (jobs reports it) is left
    out. platforms (systems.fmi.platforms.parse_platforms: host, all or a list of FMI 3.0 tuples):
    the native FMUs are first made to hold those platforms' binaries (ensure_built), and the
    chain runs this machine's among them (x86_64-linux: the glibc 2.17 one). master: the co-simulation
    master (systems.fmi.cosim.cosimulate's: gauss-seidel, or jacobi as strict masters step)."""
    wanted = parse_platforms(platforms)
    if wanted:
        ensure_built(fmu_dir, log=lambda m: print(f"attitude: {m}", file=sys.stderr), platforms=wanted)
    chain = chain_of(fmu_dir)
    runs = [(p, m) for p in list(profiles or SCENARIOS) for m in list(methods or METHODS)]
    jobs = jobs or Jobs(bar=progress)
    rows = jobs.map(verify_job, [(str(Path(fmu_dir).absolute()), p, m, step, chain, python, master) for p, m in runs],
                    [f"{p} × {m}" for p, m in runs], "co-simulations")
    return [row for row in rows if not isinstance(row, Failure)]
