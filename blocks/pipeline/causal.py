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

Every stage is causal and feeds only the next; the C core runs them sample by sample
(blocks/core/pipeline/causal.h), over any number of rows per call: `run`. Its two drivers
are blocks.pipeline.batch (a whole recording in one call; the offline smoother is a
batch-only addition there) and blocks.pipeline.online (one sample per call, an FMU's doStep).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from attitude_fmu import _core
from attitude_fmu._core import MAX_ACC_M_S2, MAX_GYR_RAD_S  # noqa: F401 (beyond these no IMU measures, per axis)
from attitude_fmu.blocks.methods.registry import Holds
from attitude_fmu.blocks.tuning import ESTIMATORS  # noqa: F401 (the stages around the method: label → parameters)

State = _core.State  # what the stages carry from one block of samples to the next; State(): nothing seen yet


def valid_sample(gyr, acc) -> bool:
    """Whether a gyro (rad/s) and an accelerometer sample (m/s², 3 values each) are finite
    and within every IMU's range, MAX_GYR_RAD_S and MAX_ACC_M_S2 per axis (the widest MEMS
    ranges, ±4000 °/s and ±400 g)."""
    return _core.valid_sample(gyr, acc)


def split_params(method: str, params: Mapping[str, float] | None, offset: bool, mag: bool):
    """params (name → value) split into (the method's, the gyro-offset estimator's, the
    heading estimator's); offset and mag say whether those two run. A name goes to every
    running stage that has it (delta_n, the gyro's noise density, to the method and the
    gyro-offset estimator alike); a name no running stage has is refused, naming theirs."""
    return _core.split_params(method, params, offset, mag)


@dataclass(frozen=True, eq=False)
class Pipeline:
    """A configuration of the stages, validated by `configure`: the method and its
    parameters ((name, value) pairs), the gyro-offset and heading estimators' parameters
    (None: the stage does not run), the latency (s), the sample conventions, and the C
    core's configuration (core)."""

    method: str
    params: tuple[tuple[str, float], ...]
    offset_params: dict | None
    heading_params: dict | None
    latency: float
    point_gyr: bool
    mean_acc: bool
    core: _core.Pipeline

    @cached_property
    def holds(self) -> Holds:
        """The source of the method's discrete filters (python-control's c2d of its design)."""
        return Holds(self.method, self.params)


def configure(method: str = "wiener", params: Mapping[str, float] | None = None, gyro_offset: bool = True,
              heading: bool = False, latency: float = 0.0, gyr_samples: str = "mean",
              acc_samples: str = "point") -> Pipeline:
    """The pipeline of `attitude estimate`: method and params as there (a name goes to
    every running stage that has it, split_params); gyro_offset and heading say whether
    those stages run; latency (s) and the sample conventions as blocks.stages.timing.
    Every value is checked here, before any sample is taken (by the C core)."""
    core = _core.Pipeline(method, params, gyro_offset, heading, latency, gyr_samples, acc_samples)
    own, offset_params, heading_params = split_params(method, params, gyro_offset, heading)
    return Pipeline(method, tuple(sorted(own.items())), offset_params if gyro_offset else None,
                    heading_params if heading else None, core.latency, core.point_gyr, core.mean_acc, core)


@dataclass(frozen=True, eq=False)
class Step:
    """The pipeline's coefficients at one sample time Ts (s) (the C core's, core)."""

    Ts: float
    core: _core.Step


def at(pipeline: Pipeline, Ts: float) -> Step:
    """The pipeline discretised for the sample time Ts (s)."""
    core = pipeline.core.at(Ts, pipeline.holds)
    return Step(core.Ts, core)


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


def run(pipeline: Pipeline, step: Step, state: State, gyr, acc, mag=None, out: Rows | None = None,
        initial_gravity=None, threads: int | None = None, choose=None) -> Rows:
    """The rows gyr (N×3, rad/s), acc (N×3, m/s²) and, where the heading stage runs, mag
    (N×3, µT; a row with a NaN, or all 0, has no field sample) through stages 1–5, state
    carried on; the outputs into out (Rows.empty(pipeline, N) if None). Finite gyr and acc.
    The first block starts the stages at rest on its first row; the method's at
    initial_gravity (m/s², sensor coordinates, before the first sample) when given, else the
    first accelerometer sample turned back by the first gyro sample
    (blocks.filters.sensor_frame.start_gravity). threads: at most this many threads, the
    stages split over two (a chunk of rows through the first stages on one while the rest
    take the chunks before it, the outputs bit for bit those of one thread); None: two from
    20 000 rows on where the process may run on two CPUs or more and the gyro-offset or heading
    stage runs. choose: None, or choose(threads) → a Step (or None: step) of the same
    configuration but for the method's and the heading's parameters, called once before the
    method's first row with the threads it may use (1 where the stages run on beside it: on
    two threads the timing and gyro-offset stages run ahead while it chooses); the method and
    the heading then run with that step."""
    out = Rows.empty(pipeline, len(gyr)) if out is None else out
    _core.run(pipeline.core, step.core, state, gyr, acc, mag, None if initial_gravity is None else
              np.asarray(initial_gravity, dtype=float), out.gravity, out.quat, out.offset, out.offset_variance,
              out.mag_accepted, out.mag_offset, out.mag_delay, threads,
              None if choose is None else lambda workers: _core_step(choose(workers)))
    return out


def _core_step(step: Step | None) -> _core.Step | None:
    return None if step is None else step.core
