"""The causal pipeline over whole recordings (blocks.pipeline.causal as one block of rows),
and the batch-only offline additions: the smoother, the gyro offset and the heading from
passes forward and backward in time, and delays measured from the whole recording."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.methods import wiener_local
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.blocks.pipeline.causal import Pipeline, State, Step, at, configure, run
from attitude_fmu.blocks.stages import heading as heading_stage
from attitude_fmu.blocks.stages import heading_choice, lever_arm, soft_iron
from attitude_fmu.blocks.stages import scale_error
from attitude_fmu.blocks.stages.delays import mag_delay
from attitude_fmu.blocks.stages.gyro_offset import correct as correct_gyro
from attitude_fmu.blocks.stages.gyro_offset import online_pass
from attitude_fmu.blocks.stages.hard_iron import back_dated
from attitude_fmu.blocks.stages.heading import smoothed_with_magnetometer
from attitude_fmu.blocks.stages.lever_arm import LeverArm
from attitude_fmu.blocks.stages.soft_iron import SoftIron
from attitude_fmu.blocks.stages.timing import carry_forward_rows, interval_ends, interval_means


@dataclass
class AttitudeEstimate:
    """Per-sample output of an estimator.

    gravity: N×3 gravity estimate ĝ in sensor coordinates, m/s² (points up);
    quat: N×4 orientation [w, x, y, z], sensor → earth (heading from integrated gyro).
    """

    gravity: np.ndarray
    quat: np.ndarray
    offset: np.ndarray | None = None  # N×3 gyro-offset estimate, rad/s, when one was made
    mag_accepted: np.ndarray | None = None  # N, magnetometer samples the heading used
    mag_offset: np.ndarray | None = None  # N×3, µT, hard-iron offset estimate (blocks.stages.hard_iron)
    mag_delay: np.ndarray | None = None  # N, s, the magnetometer's delay behind the gyro the heading allowed for
    mag_delay_source: str | None = None  # "given", "online" (blocks.stages.mag_delay) or "measured" (whole recording)
    mag_soft_iron: SoftIron | None = None  # offline: the ellipsoid the field was turned onto a sphere by, if proven
    lever_arm: LeverArm | None = None  # offline: the sensor's place from a fixed centre of rotation, if proven
    chosen: dict | None = None  # parameters chosen from the recording: {"scale_error": value[, "tau_heading": s]}

    @property
    def up(self) -> np.ndarray:
        """N×3 unit up-vector in sensor coordinates."""
        return self.gravity / np.linalg.norm(self.gravity, axis=1, keepdims=True)


def check_imu(gyr, acc, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Validated contiguous float copies of N×3 gyro (rad/s) and accelerometer (m/s²)."""
    if not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0):
        raise ValueError(f"sample rate fs must be a finite positive number of Hz, got {fs!r}")
    arrays = []
    for name, data in (("gyr", gyr), ("acc", acc)):
        a = np.asarray(data, dtype=float)
        if a.ndim != 2 or a.shape[1] != 3 or a.shape[0] == 0:
            raise ValueError(f"{name} must have shape (N, 3) with N ≥ 1, got {a.shape}")
        bad = ~np.isfinite(a)
        if bad.any():
            row = int(np.argwhere(bad)[0][0])
            raise ValueError(f"{name} has {int(bad.sum())} non-finite values (first at sample {row})")
        arrays.append(np.ascontiguousarray(a))
    if arrays[0].shape != arrays[1].shape:
        raise ValueError(f"gyr and acc differ in length: {arrays[0].shape[0]} vs {arrays[1].shape[0]}")
    return arrays[0], arrays[1]


def check_mag(mag, n: int) -> np.ndarray:
    """A validated contiguous float copy of the magnetometer (n×3, µT; a row with a NaN is a missing sample)."""
    mag = np.ascontiguousarray(mag, dtype=float)
    if mag.shape != (n, 3):
        raise ValueError(f"mag must have the shape {(n, 3)}, got {mag.shape}")
    finite = np.isfinite(mag)
    if finite.all():  # (one pass where every sample is there)
        return mag
    infinite = int(np.isinf(mag).sum())
    if infinite:
        raise ValueError(f"mag has {infinite} infinite values (NaN marks a missing sample)")
    if not (finite[:, 0] & finite[:, 1] & finite[:, 2]).any():
        raise ValueError("mag has no sample without NaN: estimate without it (--heading gyro, or mag=None)")
    return mag


def check_options(method: str = "wiener", params: Mapping[str, float] | None = None, offline: bool = False,
                  gyro_offset: bool = True, mag: bool = False, latency: float = 0.0, gyr_samples: str = "mean",
                  acc_samples: str = "point") -> Pipeline:
    """Refuse what estimate() would refuse of its options, before any data is read: an
    unknown method, a parameter no running stage has or a value out of range, --offline
    with a method that is not an earth-frame filter, a latency, gyr_samples or acc_samples
    out of range. mag: whether a magnetometer will be given. Returns the pipeline
    (blocks.pipeline.causal.configure)."""
    pipeline = configure(method, params, gyro_offset, mag, latency, gyr_samples, acc_samples)
    if offline and not get_method(method).is_sensor_frame:
        raise ValueError(f"offline smoothing needs an earth-frame filter method "
                         f"({', '.join(n for n, m in METHODS.items() if m.is_sensor_frame)}), not {method!r}")
    return pipeline


def estimate(
    gyr, acc, fs: float, method: str = "wiener", params: Mapping[str, float] | None = None,
    initial_gravity=None, offline: bool = False, gyro_offset: bool = True, mag=None, latency: float = 0.0,
    gyr_samples: str = "mean", acc_samples: str = "point", threads: int | None = None,
) -> AttitudeEstimate:
    """Estimate attitude over a recording: gyr N×3 rad/s, acc N×3 m/s², fs in Hz.

    The causal pipeline (blocks.pipeline.causal) over every sample: params are the
    documented parameters of the method (blocks.methods.registry), of the gyro-offset
    estimator when it runs and of the heading estimator when mag is given
    (blocks.pipeline.causal.split_params), defaults otherwise. The filter starts at rest
    on initial_gravity (m/s², sensor coordinates, before the first sample), by default the
    first accelerometer sample turned back by the first gyro sample
    (blocks.filters.sensor_frame.start_gravity); rows whose accelerometer is all zero
    before the first that is not are waited over as OnlineEstimator waits, and hold the
    estimate the stages start with there (held_before). gyro_offset (default on, as `attitude
    estimate` and the FMU): estimate the gyro offset at rest and while moving and remove it
    (blocks.stages.gyro_offset; the estimate is returned as `offset`). mag (N×3, µT; rows
    with a NaN are missing samples): heading from the magnetometer with a guard against
    disturbances (blocks.stages.heading); without it the heading is the gyro's (6D). The
    magnetometer's delay behind the gyro, unless given as the parameter mag_delay, is
    estimated online (blocks.stages.mag_delay); `mag_delay` holds it per sample. latency
    (s): the IMU's delay behind the motion; the estimate is carried forward over it with
    the (offset-free) gyro (blocks.stages.timing). gyr_samples: "mean" (the project's
    convention: sample k is the mean rate over the sample time before it) or "point" (the
    rate at t_k, turned into means first). acc_samples: "point" (the convention: the
    specific force at t_k) or "mean" (over the sample time before it, turned into the
    sensor frame at t_k first; blocks.stages.timing).

    threads: at most this many threads for the causal pipeline (blocks.pipeline.causal.run;
    the offline path runs on one): with two, its stages are pipelined over them (up to the
    gyro offset, or with heading up to the method, on one; the rest on the other), the
    outputs bit for bit those of one thread; None (automatic): two for 20 000 rows or more
    where the process may run on two CPUs or more and the gyro offset or the heading runs.
    scale_error's choice (below) is made on the second of two threads while the first runs the
    timing and gyro-offset stages ahead; where the pipeline runs on one, its windows run on up to
    this many threads at once (None: one per CPU the process may run on). Pass 1 where processes
    already use every CPU (one estimate per worker).

    scale_error (wiener with its local densities): unless given, chosen from the recording
    (blocks.stages.scale_error: of its candidates, the one whose estimate predicts the
    accelerometer best 0.5 s ahead through the gyro), online and offline alike; the value is
    returned in `chosen`. With mag, unless tau_heading is given, the heading's time constant
    then follows the gyro the choice found (blocks.stages.heading_choice), returned in
    `chosen` too.

    offline: the batch-only additions (smoothed). The method's earth-frame filter runs
    forward, then backward over the forward estimate (for `wiener` the non-causal Wiener
    smoother, see blocks.filters.accuracy.smoother_mean_square_gravity_error); the gyro
    offset comes from passes forward and backward in time; where the sensor turns about a
    fixed centre (a robot's wrist, a pendulum) the accelerometer is freed of that rotation's
    accelerations before the filter runs (blocks.stages.lever_arm; `lever_arm`, None where
    not proven); the magnetometer's delay is
    measured from the whole recording (blocks.stages.delays.mag_delay; 0 where it cannot
    be or comes out negative) and each hard-iron offset the heading stage took or dropped
    holds from where the field changed (blocks.stages.hard_iron.back_dated); the heading
    stage runs forward and backward in time, each row's correction the passes' weighted
    mean (blocks.stages.heading.smoothed_with_magnetometer), mag_accepted where either used
    the field.
    """
    pipeline = check_options(method, params, offline, gyro_offset, mag is not None, latency, gyr_samples,
                             acc_samples)
    gyr, acc = check_imu(gyr, acc, fs)
    mag = None if mag is None else check_mag(mag, len(gyr))
    step = at(pipeline, 1.0 / fs)
    # as OnlineEstimator, the stages wait for an accelerometer sample
    start = 0 if acc[0].any() else int(np.argmax(acc.any(axis=1)))
    if not acc[start].any():
        raise ValueError("acc is zero throughout: no gravity to start on")
    if start:
        gyr, acc, mag = gyr[start:], acc[start:], None if mag is None else mag[start:]
    chosen = {}

    def chosen_pipeline(workers: int) -> Pipeline | None:
        """The pipeline with the parameters chosen from the recording (into chosen), None where none is."""
        found = _chosen_scale_error(pipeline, step, gyr, acc, initial_gravity, workers)
        if found is None:
            return None
        chosen["scale_error"] = found[0]
        if pipeline.heading_params is not None and "tau_heading" not in pipeline.heading_params:
            chosen["tau_heading"] = _chosen_tau_heading(pipeline, *found)
        return check_options(method, {**(params or {}), **chosen}, offline, gyro_offset, mag is not None, latency,
                             gyr_samples, acc_samples)

    def choose(workers: int) -> Step | None:
        made = chosen_pipeline(workers)
        return None if made is None else at(made, 1.0 / fs)

    choosing = scale_error.applies(method, dict(pipeline.params))
    if offline:
        made = chosen_pipeline(_core.cpus() if threads is None else threads) if choosing else None
        if made is not None:
            pipeline, step = made, at(made, 1.0 / fs)
        est = smoothed(pipeline, step, gyr, acc, mag, initial_gravity)
    else:  # the choice made while the stages before the method run (blocks.pipeline.causal.run)
        rows = run(pipeline, step, State(), gyr, acc, mag, initial_gravity=initial_gravity, threads=threads,
                   choose=choose if choosing else None)
        est = AttitudeEstimate(rows.gravity, rows.quat, rows.offset, rows.mag_accepted, rows.mag_offset,
                               rows.mag_delay, _mag_delay_source(pipeline, offline=False))
    est.chosen = chosen or None
    return held_before(est, start)


def _chosen_scale_error(pipeline: Pipeline, step: Step, gyr, acc, initial_gravity,
                        threads: int | None) -> tuple[float, float, float] | None:
    """blocks.stages.scale_error's choice for the pipeline's method, with the gyro's mean square
    rate ⟨|ω|²⟩ (rad²/s²) and the mean variance of the offset removed from it ((rad/s)², 0 with
    no offset stage) over the rows it scored (None: the recording is too short): the method
    alone, on the samples as the pipeline turns them (its sample conventions, the gyro freed of
    its offset and the accelerometer of the online lever arm by a forward pass), over the
    windows of scale_error.subset, one after another
    (each from the start at rest on its first rows, its warm-up with the method's default
    scale_error, each candidate on from there), or over every row from initial_gravity where
    that is None; the windows on up to threads threads at once (None: a thread for each CPU the
    process may run on)."""
    fs = 1.0 / step.Ts
    gyr = interval_means(gyr) if pipeline.point_gyr else gyr
    acc = interval_ends(gyr, acc, step.Ts) if pipeline.mean_acc else acc
    found = scale_error.subset(len(gyr), fs)
    windows = None
    if found is not None:  # the windows' rows, a slice of the recording each
        rows, windows = found
        parts = [slice(rows[first], rows[first] + end - first) for first, _, end in windows]
        gyr, acc = np.concatenate([gyr[part] for part in parts]), np.concatenate([acc[part] for part in parts])
    variance = np.zeros_like(gyr)
    if pipeline.offset_params is not None:
        offset, variance, acc = online_pass(gyr, acc, fs, pipeline.offset_params)
        gyr = gyr - offset
    own = dict(pipeline.params)

    def alone(params) -> _core.Step:
        return at(configure(pipeline.method, params, gyro_offset=False), step.Ts).core

    per_block = scale_error.block_errors(alone(own), [alone({**own, "scale_error": c}) for c in scale_error.SCALE_ERRORS],
                                         gyr, acc, fs, windows, initial_gravity,
                                         _core.cpus() if threads is None else threads)
    found = None if per_block is None else scale_error.choose(dict(zip(scale_error.SCALE_ERRORS, per_block)))
    if found is None:
        return None
    scored = [slice(first, end) for _, first, end in windows or [(0, 0, len(gyr))]]
    rates = np.concatenate([gyr[part] for part in scored])
    return (found[0], float(np.mean(np.einsum("ij,ij->i", rates, rates))),
            float(np.mean(np.concatenate([variance[part] for part in scored]))))


def _chosen_tau_heading(pipeline: Pipeline, value: float, rate_ms: float, offset_variance: float) -> float:
    """blocks.stages.heading_choice.time_constant for the scale_error value chosen on a gyro of
    mean square rate rate_ms (rad²/s²) and offset variance offset_variance ((rad/s)², as
    _chosen_scale_error returns them), with the pipeline's own parameters."""
    method = get_method(pipeline.method)
    own = method.resolve(dict(pipeline.params))

    def density(scale: float) -> float:
        return wiener_local.gyro_density({**own, "scale_error": scale}, rate_ms)

    return heading_choice.time_constant(heading_stage.resolve(pipeline.heading_params)["tau_heading"],
                                        density(method.resolve()["scale_error"]), density(value), offset_variance)


def held_before(est: AttitudeEstimate, start: int) -> AttitudeEstimate:
    """est preceded by start rows that hold its first (the rows the stages waited over)."""
    if start:
        for name, values in vars(est).items():
            if isinstance(values, np.ndarray):
                setattr(est, name, np.concatenate([np.repeat(values[:1], start, axis=0), values]))
    return est


def _mag_delay_source(pipeline: Pipeline, offline: bool) -> str | None:
    if pipeline.heading_params is None:
        return None
    return "given" if pipeline.heading_params.get("mag_delay") is not None else "measured" if offline else "online"


def smoothed(pipeline: Pipeline, step: Step, gyr, acc, mag, initial_gravity=None) -> AttitudeEstimate:
    """The offline estimate (see estimate): the pipeline's stages in their order, the
    gyro offset, the method and the heading each replaced by its offline form."""
    fs = 1.0 / step.Ts
    if pipeline.point_gyr:
        gyr = interval_means(gyr)
    if pipeline.mean_acc:
        acc = interval_ends(gyr, acc, step.Ts)
    offset = None
    if pipeline.offset_params is not None:
        gyr, offset = correct_gyro(gyr, acc, fs, pipeline.offset_params, offline=True)
    lever = lever_arm.fit(gyr, acc, fs)  # a fixed centre of rotation's accelerations, where proven
    if lever is not None:
        acc = lever.corrected(gyr, acc, fs)
    # the method forward, then backward over its estimate (blocks/core/pipeline/offline.h); wiener's
    # local densities: both passes at the lower of the break frequencies estimated forward and backward
    est = AttitudeEstimate(np.empty((len(gyr), 3)), np.empty((len(gyr), 4)), offset, lever_arm=lever)
    _core.smooth(step.core, gyr, acc, None if initial_gravity is None else np.asarray(initial_gravity, dtype=float),
                 est.gravity, est.quat)
    if mag is not None:
        _offline_heading(est, pipeline, mag, gyr, fs)
    if pipeline.latency:
        carry_forward_rows(est.quat, est.gravity, gyr, pipeline.latency)
    return est


def _offline_heading(est: AttitudeEstimate, pipeline: Pipeline, mag, gyr, fs: float) -> None:
    """The heading stage smoothed over the whole recording, in place: the magnetometer's
    delay measured unless given, then once more with each hard-iron offset from where the
    field changed, on the field freed of it; then, where the field the heading used proves an
    ellipsoid (blocks.stages.soft_iron), once more on the field turned onto a sphere."""
    params = dict(pipeline.heading_params)
    resolved = heading_stage.resolve(params)  # mag_cal_tol and mag_cal_spread (the delay is set below)
    est.mag_delay_source = _mag_delay_source(pipeline, offline=True)
    if est.mag_delay_source == "measured":
        params["mag_delay"] = max(mag_delay(gyr, mag, fs) or 0.0, 0.0)
    quat = est.quat
    est.quat, est.mag_accepted, est.mag_offset, est.mag_delay = smoothed_with_magnetometer(quat, mag, fs, params)
    if est.mag_offset.any():  # again, with each hard-iron offset from where the field changed
        est.mag_offset = back_dated(mag, est.mag_offset, fs, resolved)
        freed = mag - est.mag_offset
        if est.mag_delay_source == "measured":  # the offset no longer hides the delay
            params["mag_delay"] = max(mag_delay(gyr, freed, fs) or 0.0, 0.0)
        est.quat, est.mag_accepted, _, est.mag_delay = smoothed_with_magnetometer(quat, freed, fs,
                                                                                  {**params, "mag_cal_time": 0.0})
        mag = freed
    est.mag_soft_iron = soft_iron.fit(mag[est.mag_accepted], resolved["mag_cal_spread"])
    if est.mag_soft_iron is not None:
        est.quat, est.mag_accepted, _, est.mag_delay = smoothed_with_magnetometer(
            quat, est.mag_soft_iron.corrected(mag), fs, {**params, "mag_cal_time": 0.0})
