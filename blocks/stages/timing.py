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
(systems.evaluation.evaluate.imu_latency). One kernel serves the batch path, the online step (FMU)
and the python-control block.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.control_system import sample_system
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.quaternion import quat_multiply, quat_rotate, rotvec_quat

# relative difference below which two sample times are one: a master that keeps time in
# integer nanoseconds, or sums steps in floating point, hands over Ts with rounding noise
STEP_TOLERANCE = 1e-9
MAX_LATENCY_S = 0.5  # the gyro's last rate is no guide to the orientation further ahead
GYR_SAMPLES = ("mean", "point")  # the gyro's sample convention (module docstring)
ACC_SAMPLES = ("point", "mean")  # the accelerometer's


def check_samples(gyr_samples: str, acc_samples: str = "point") -> tuple[str, str]:
    """(gyr_samples, acc_samples), refused unless in GYR_SAMPLES and ACC_SAMPLES."""
    for name, value, allowed in (("gyr_samples", gyr_samples, GYR_SAMPLES), ("acc_samples", acc_samples, ACC_SAMPLES)):
        if value not in allowed:
            raise ValueError(f"{name} must be {' or '.join(map(repr, allowed))}, got {value!r}")
    return gyr_samples, acc_samples


def same_step(Ts: float, reference: float) -> bool:
    """Whether the sample time Ts (s) is reference (s) up to STEP_TOLERANCE."""
    return abs(Ts - reference) <= STEP_TOLERANCE * reference


def interval_mean(before, now):
    """The mean rate over the sample time between two point samples of it (rad/s): the
    trapezoid (ω_k−1 + ω_k)/2."""
    return 0.5 * (before + now)


def interval_means(gyr, before=None) -> np.ndarray:
    """Point samples of the rate (N×3, rad/s, at t_k) as means over (t_k−1, t_k]
    (interval_mean), a new array; before (3, rad/s): the point sample before the first,
    None: the first sample, with nothing before it, stays."""
    raw = np.asarray(gyr, dtype=float)
    gyr = raw.copy()
    gyr[1:] = interval_mean(raw[:-1], raw[1:])
    if before is not None:
        gyr[0] = interval_mean(np.asarray(before, dtype=float), raw[0])
    return gyr


def check_latency(latency: float) -> float:
    """latency (s) as a float, refused unless finite and within ±MAX_LATENCY_S."""
    latency = float(latency)
    if not (math.isfinite(latency) and abs(latency) <= MAX_LATENCY_S):
        raise ValueError(f"latency must be a finite number of seconds within ±{MAX_LATENCY_S:g}, got {latency!r}")
    return latency


@kernel(inline=True)
def carry_forward(q, up, gyr, latency):
    """(q ⊗ exp(gyr·latency), up in the sensor frame latency seconds later): q sensor →
    earth (4-tuple), up (3-tuple, any length), gyr (rad/s, 3-tuple), latency (s)."""
    dq = rotvec_quat(gyr[0] * latency, gyr[1] * latency, gyr[2] * latency)
    return quat_multiply(q, dq), quat_rotate((dq[0], -dq[1], -dq[2], -dq[3]), up)


@kernel()
def carry_forward_rows(quat, gravity, gyr, latency):
    """carry_forward on every row of quat (N×4) and gravity (N×3), in place; gyr N×3 (rad/s)."""
    for k in range(quat.shape[0]):
        q, up = carry_forward((quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3]),
                              (gravity[k, 0], gravity[k, 1], gravity[k, 2]),
                              (gyr[k, 0], gyr[k, 1], gyr[k, 2]), latency)
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q
        gravity[k, 0], gravity[k, 1], gravity[k, 2] = up


@kernel(inline=True)
def interval_end(gyr, acc, Ts):
    """acc (3-tuple, m/s²), a mean over the sample time (t_k−1, t_k], in the sensor frame
    at t_k: turned as carry_forward turns the up-vector over Ts/2 (s) at the step's mean
    rate gyr (3-tuple, rad/s)."""
    return carry_forward((1.0, 0.0, 0.0, 0.0), acc, gyr, 0.5 * Ts)[1]


@kernel()
def interval_ends(gyr, acc, Ts):
    """interval_end on every row: accelerometer means (N×3, m/s²) in the sensor frame at
    each sample's time, a new array; gyr N×3 (rad/s, the means over the same sample times)."""
    out = np.empty_like(acc)
    for k in range(acc.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = interval_end((gyr[k, 0], gyr[k, 1], gyr[k, 2]),
                                                      (acc[k, 0], acc[k, 1], acc[k, 2]), Ts)
    return out


def latency_system(dt: float, latency: float, quat_inputs=("q_w", "q_x", "q_y", "q_z"), name: str = "latency"):
    """Static python-control block: inputs gyr_x..z (rad/s), the orientation (quat_inputs)
    and ghat_x..z (m/s²); outputs ql_w..z and ghatl_x..z, both carried forward over
    latency (s)."""
    latency = check_latency(latency)

    def advance(state, u):
        quat, gravity = u[3:7].reshape(1, 4).copy(), u[7:10].reshape(1, 3).copy()
        carry_forward_rows(quat, gravity, u[0:3].reshape(1, 3).copy(), latency)
        return state, np.concatenate([quat[0], gravity[0]])

    return sample_system(advance, [f"gyr_{a}" for a in "xyz"] + list(quat_inputs) + [f"ghat_{a}" for a in "xyz"],
                         [f"ql_{c}" for c in "wxyz"] + [f"ghatl_{a}" for a in "xyz"], [], dt, name)
