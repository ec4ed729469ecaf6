"""The causal pipeline: the stages of an estimate in their order, and what each hands the next.

    gyr, acc ─▶ 1 sample timing ─▶ 2 gyro offset ─▶ 3 method ─▶ 4 heading ─▶ 5 latency ─▶ q, ĝ
                                                                   ▲ mag

1. sample timing (blocks.stages.timing): gyro point samples become means over the sample
   time, accelerometer means the specific force at the sample's time;
2. gyro offset (blocks.stages.gyro_offset, optional): estimated at rest and while moving,
   and removed from the gyro;
3. method (blocks.methods.registry): the gravity estimate ĝ and the orientation q, whose
   heading is the integrated gyro's;
4. heading (blocks.stages.heading, with a magnetometer): q turned about earth up to the
   magnetometer's heading, freed of hard iron and of the magnetometer's delay;
5. latency (blocks.stages.timing): q and ĝ carried forward over the IMU's delay with the
   offset-free gyro.

Every stage is causal and feeds only the next, so running each over a block of samples
before the next begins equals running the samples one at a time through all of them:
`run` takes any number of rows. Its two drivers are blocks.pipeline.batch (a whole
recording as one block; the offline smoother is a batch-only addition there) and
blocks.pipeline.online (one sample per call, an FMU's doStep).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from attitude_fmu.blocks.filters.sensor_frame import start_gravity
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.blocks.methods.registry import stepper
from attitude_fmu.blocks.stages import gyro_offset as offset_stage
from attitude_fmu.blocks.stages import heading as heading_stage
from attitude_fmu.blocks.stages.timing import (
    carry_forward_rows,
    check_latency,
    check_samples,
    interval_ends,
    interval_means,
)

ESTIMATORS = {"the gyro-offset estimator": offset_stage.PARAMS, "the heading estimator": heading_stage.PARAMS}
# beyond these no IMU measures: a sample beyond them is not taken (the widest MEMS ranges,
# ±4000 °/s and ±400 g per axis)
MAX_GYR_RAD_S = math.radians(4000.0)
MAX_ACC_M_S2 = 400.0 * 9.80665


def valid_sample(gyr, acc) -> bool:
    """Whether a gyro (rad/s) and an accelerometer sample (m/s², 3 values each) are finite
    and within every IMU's range, MAX_GYR_RAD_S and MAX_ACC_M_S2 per axis."""
    return all(math.isfinite(v) and abs(v) <= MAX_GYR_RAD_S for v in gyr) and \
        all(math.isfinite(v) and abs(v) <= MAX_ACC_M_S2 for v in acc)


def split_params(method: str, params: Mapping[str, float] | None, offset: bool, mag: bool):
    """params (name → value) split into (the method's, the gyro-offset estimator's, the
    heading estimator's); offset and mag say whether those two run. A name goes to every
    running stage that has it (delta_n, the gyro's noise density, to the method and the
    gyro-offset estimator alike); a name no running stage has is refused, naming theirs."""
    stages = ((f"the method {method}", get_method(method).params, True),
              *((name, ps, runs) for (name, ps), runs in zip(ESTIMATORS.items(), (offset, mag))))
    params = dict(params or {})
    running = [(stage, ps) for stage, ps, runs in stages if runs]
    for name in params:
        if not any(p.name == name for _, ps in running for p in ps):
            known = "; ".join(f"{stage}: {', '.join(p.name for p in ps) or 'none'}" for stage, ps in running)
            raise ValueError(f"unknown parameter {name!r} ({known})")
    return tuple({p.name: params[p.name] for p in ps if p.name in params} if runs else {} for _, ps, runs in stages)


@dataclass(frozen=True, eq=False)
class Pipeline:
    """A configuration of the stages, validated by `configure`: the method and its
    parameters ((name, value) pairs), the gyro-offset and heading estimators' parameters
    (None: the stage does not run), the latency (s) and the sample conventions."""

    method: str
    params: tuple[tuple[str, float], ...]
    offset_params: dict | None
    heading_params: dict | None
    latency: float
    point_gyr: bool
    mean_acc: bool


def configure(method: str = "wiener", params: Mapping[str, float] | None = None, gyro_offset: bool = True,
              heading: bool = False, latency: float = 0.0, gyr_samples: str = "mean",
              acc_samples: str = "point") -> Pipeline:
    """The pipeline of `attitude estimate`: method and params as there (a name goes to
    every running stage that has it, split_params); gyro_offset and heading say whether
    those stages run; latency (s) and the sample conventions as blocks.stages.timing.
    Every value is checked here, before any sample is taken."""
    m = get_method(method)
    own, offset_params, heading_params = split_params(method, params, gyro_offset, heading)
    m.runs_kernel(m.resolve(own))  # refuses values out of range (blocks.params.resolve_params)
    for stage, runs, overrides in ((offset_stage, gyro_offset, offset_params), (heading_stage, heading, heading_params)):
        if runs:
            stage.resolve(overrides)
    gyr_samples, acc_samples = check_samples(gyr_samples, acc_samples)
    return Pipeline(method, tuple(sorted(own.items())), offset_params if gyro_offset else None,
                    heading_params if heading else None, check_latency(latency), gyr_samples == "point",
                    acc_samples == "mean")


@dataclass(frozen=True, eq=False)
class Step:
    """The pipeline's coefficients at one sample time Ts (s): the method's stepper and the
    coefficients of the gyro-offset and heading stages that run."""

    Ts: float
    stepper: object
    offset_coef: np.ndarray | None
    heading_coef: np.ndarray | None


def at(pipeline: Pipeline, Ts: float) -> Step:
    """The pipeline discretised for the sample time Ts (s)."""
    if not (isinstance(Ts, (int, float)) and math.isfinite(Ts) and Ts > 0):
        raise ValueError(f"sample time must be a finite positive number of seconds, got {Ts!r}")
    offset, mag = pipeline.offset_params, pipeline.heading_params
    return Step(float(Ts), stepper(pipeline.method, pipeline.params, Ts),
                None if offset is None else offset_stage.coefficients(offset_stage.resolve(offset), Ts),
                None if mag is None else heading_stage.coefficients(heading_stage.resolve(mag), Ts))


@dataclass
class State:
    """What the stages carry from one block of samples to the next: the last gyro point
    sample (rad/s, point samples), the gyro-offset, method and heading states; the method's
    is None until the first sample."""

    last_gyr: np.ndarray | None = None
    offset: np.ndarray | None = None
    method: np.ndarray | None = None
    heading: np.ndarray = field(default_factory=heading_stage.initial_state)


@dataclass
class Rows:
    """The pipeline's outputs for N samples: ĝ (N×3, m/s², sensor coordinates) and q
    (N×4, sensor → earth), after latency; the gyro-offset estimate and its variance per
    axis (N×3, rad/s and (rad/s)²) where that stage runs; where the heading stage runs,
    whether each field sample was used (N), the hard-iron offset (N×3, the field's unit)
    and the magnetometer's delay allowed for (N, s)."""

    gravity: np.ndarray
    quat: np.ndarray
    offset: np.ndarray | None = None
    offset_variance: np.ndarray | None = None
    mag_accepted: np.ndarray | None = None
    mag_offset: np.ndarray | None = None
    mag_delay: np.ndarray | None = None

    @classmethod
    def empty(cls, pipeline: Pipeline, n: int) -> "Rows":
        offset, mag = pipeline.offset_params is not None, pipeline.heading_params is not None
        return cls(np.empty((n, 3)), np.empty((n, 4)), *((np.empty((n, 3)), np.empty((n, 3))) if offset else (None, None)),
                   *((np.empty(n, dtype=np.bool_), np.empty((n, 3)), np.empty(n)) if mag else (None, None, None)))


def sample_timing(pipeline: Pipeline, step: Step, state: State, gyr, acc):
    """Stage 1 over rows gyr, acc (N×3): both in the project's convention (new arrays where
    converted); state.last_gyr carries a point sample over to the next block."""
    if pipeline.point_gyr:
        raw = gyr
        gyr = interval_means(raw, state.last_gyr)
        state.last_gyr = np.array(raw[-1], dtype=float)
    if pipeline.mean_acc:
        acc = interval_ends(gyr, acc, step.Ts)
    return gyr, acc


def run(pipeline: Pipeline, step: Step, state: State, gyr, acc, mag=None, out: Rows | None = None,
        initial_gravity=None) -> Rows:
    """The rows gyr (N×3, rad/s), acc (N×3, m/s²) and, where the heading stage runs, mag
    (N×3, µT; a row with a NaN, or all 0, has no field sample) through stages 1–5, state
    carried on; the outputs into out (Rows.empty(pipeline, N) if None). Contiguous float
    arrays, finite gyr and acc. The first block starts the stages at rest on its first
    row; the method's at initial_gravity (m/s², sensor coordinates, before the first
    sample) when given, else the first accelerometer sample turned back by the first
    gyro sample (blocks.filters.sensor_frame.start_gravity)."""
    gyr, acc = sample_timing(pipeline, step, state, gyr, acc)
    out = Rows.empty(pipeline, len(gyr)) if out is None else out
    starting = state.method is None
    if pipeline.offset_params is not None:
        if starting:
            state.offset = offset_stage.initial_state(step.offset_coef, gyr[0], acc[0])
        offset_stage.run(state.offset, step.offset_coef, gyr, acc, out.offset, out.offset_variance)
        gyr = gyr - out.offset
    if starting:
        state.method = step.stepper.initial_state(start_gravity(gyr[0], acc[0], step.Ts) if initial_gravity is None
                                                  else initial_gravity)
    step.stepper.run(state.method, gyr, acc, out.gravity, out.quat)
    if pipeline.heading_params is not None:  # in place: each row is read before it is written
        heading_stage.run(state.heading, step.heading_coef, out.quat, mag, out.quat, out.mag_accepted, out.mag_offset,
                    out.mag_delay)
    if pipeline.latency:
        carry_forward_rows(out.quat, out.gravity, gyr, pipeline.latency)
    return out
