"""Sample timing: the gyro's and the accelerometer's sample conventions and latency compensation.

The project's convention (docs/conventions.md): gyro sample k is the mean rate over the sample
time before t_k, (t_k−1, t_k], as a closed-form motion's `at` and the FMU's `gyr` input.
Many sources give the rate at t_k instead (a simulation's ω(t_k), a multibody model's
output, most IMU drivers): `gyr_samples` "point" turns those into interval means by the
trapezoid, (ω_k−1 + ω_k)/2. Integrated as means, point samples lead the motion by Ts/2
(on a ±10° pitch at 0.5 Hz sampled at 100 Hz, 0.12° of tilt RMS; tests/test_real_data.py).
An accelerometer sample is the specific force at t_k (`acc_samples` "point", the
convention's). One averaged over the sample time as the gyro is (a recording averaged
down to a lower rate, a sensor that averages both over each sample: `acc_samples`
"mean") sees the sensor about Ts/2 earlier; it is turned into the sensor frame at t_k by
the second half of the step's rotation, exp(−[ω]·Ts/2), the turn carry_forward gives the
up-vector. Read as point values, such means lag by |ω|·Ts/2 of tilt, which the filter
passes through its low-pass B.

Latency: an IMU's samples lag the motion (the group delay of its digital filters, a few
milliseconds), so an estimate made from them shows the orientation of that long ago.
This stage carries the estimate forward over the latency with the gyro: q ← q ⊗ exp(ω·L),
and the up-vector into the sensor frame of that moment. L (s) counts in the convention
above, after any conversion: a sensor whose point samples are taken d late has L = d.
`attitude evaluate` measures L against an optical reference
(systems.evaluation.evaluate.imu_latency). One step in the C core (blocks/core/stages/timing.c)
serves the batch path, the online step (FMU) and the python-control block.
"""
from __future__ import annotations

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, sample_system, with_c_step
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY

# the core's values: the relative difference below which two sample times are one (a master that
# keeps time in integer nanoseconds, or sums steps in floating point, hands over Ts with rounding
# noise), and same_step(Ts, reference), whether Ts is reference up to it
STEP_TOLERANCE, same_step = _core.STEP_TOLERANCE, _core.same_step
# an FMU with a sample time runs, in a communication step, grid_samples(start, Ts, t, h) samples: the
# instants start + k·Ts its step reaches, up to GRID_TOLERANCE samples (a master that sums its steps falls
# short by picoseconds), GRID_MAX_SAMPLES at most, the first beginning at grid_before(start, Ts, t)
GRID_TOLERANCE, GRID_MAX_SAMPLES, grid_samples = _core.GRID_TOLERANCE, _core.GRID_MAX_SAMPLES, _core.grid_samples
grid_before = _core.grid_before
MAX_LATENCY_S = _core.MAX_LATENCY_S  # s: the gyro's last rate is no guide to the orientation further ahead
GYR_SAMPLES, ACC_SAMPLES = _core.GYR_SAMPLES, _core.ACC_SAMPLES  # the sample conventions (above), the usual first


def check_samples(gyr_samples: str, acc_samples: str = "point") -> tuple[str, str]:
    """(gyr_samples, acc_samples), refused unless in GYR_SAMPLES and ACC_SAMPLES."""
    _core.check_samples(gyr_samples, acc_samples)
    return gyr_samples, acc_samples


def check_latency(latency: float) -> float:
    """latency (s) as a float, refused unless finite and within ±MAX_LATENCY_S."""
    return _core.check_latency(float(latency))


def interval_means(gyr, before=None) -> np.ndarray:
    """Point samples of the rate (N×3, rad/s, at t_k) as means over (t_k−1, t_k], the
    trapezoid (ω_k−1 + ω_k)/2, a new array; before (3, rad/s): the point sample before the
    first, None: the first sample, with nothing before it, stays."""
    raw = np.asarray(gyr, dtype=float)
    gyr = raw.copy()
    gyr[1:] = 0.5 * (raw[:-1] + raw[1:])
    if before is not None:
        gyr[0] = 0.5 * (np.asarray(before, dtype=float) + raw[0])
    return gyr


def carry_forward_rows(quat, gravity, gyr, latency: float) -> None:
    """Every row of quat (N×4, sensor → earth) and gravity (N×3, any length), contiguous
    float arrays, carried forward over latency (s) at the rates gyr (N×3, rad/s), in place:
    q ⊗ exp(ω·latency), and the up-vector in the sensor frame latency seconds later."""
    _core.carry_forward_rows(quat, gravity, np.ascontiguousarray(gyr, dtype=float), latency)


def interval_ends(gyr, acc, Ts: float) -> np.ndarray:
    """Accelerometer means (N×3, m/s², each over the sample time Ts s before its sample) in the
    sensor frame at each sample's time, a new array: turned as carry_forward_rows turns the
    up-vector over Ts/2 at the step's mean rate gyr (N×3, rad/s)."""
    acc = np.ascontiguousarray(acc, dtype=float)
    out = np.empty_like(acc)
    _core.interval_ends(np.ascontiguousarray(gyr, dtype=float), acc, Ts, out)
    return out


def latency_system(dt: float, latency: float, quat_inputs=("q_w", "q_x", "q_y", "q_z"), name: str = "latency"):
    """Static python-control block: inputs gyr_x..z (rad/s), the orientation (quat_inputs)
    and ghat_x..z (m/s²); outputs ql_w..z and ghatl_x..z, both carried forward over
    latency (s). Marked with its C step, "latency" (numbers [latency])."""
    latency = check_latency(latency)

    def advance(state, u):
        quat, gravity = u[3:7].reshape(1, 4).copy(), u[7:10].reshape(1, 3).copy()
        _core.carry_forward_rows(quat, gravity, u[0:3].reshape(1, 3), latency)
        return state, np.concatenate([quat[0], gravity[0]])

    system = sample_system(advance, [f"gyr_{a}" for a in "xyz"] + list(quat_inputs) + [f"ghat_{a}" for a in "xyz"],
                           [f"ql_{c}" for c in "wxyz"] + [f"ghatl_{a}" for a in "xyz"], [], dt, name)
    return with_c_step(system, CStep("latency", dt, numbers=(latency,),
                                     rest_inputs=(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, STANDARD_GRAVITY)))
