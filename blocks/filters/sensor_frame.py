"""The sensor-frame transformation (Rizun eq. 35) of any earth-frame LTI filter.

An earth-frame filter ẋ = A·x + B·u, y = C·x + D·u (one scalar axis, n states) acts on
each component of the accelerometer signal in the gyro-estimated earth frame. Carried
into the sensor frame with d/dt|sensor = d/dt|earth − ω̂×, each of its n states becomes a
3-vector (the rows of X, n×3) that also turns with −ω̂×:

    dX/dt = A·X + B·y_aᵀ − (ω̂ × each row of X),      ĝ = C·X + D·y_aᵀ.

Discrete time (sample time Ts): the rotation over a sample is applied exactly (constant
ω̂ over (t[k−1], t[k]], docs/conventions.md), the LTI part by its zero-order-hold form (Ad, Bd).
Rotation and LTI part act on different indices of X and so commute; the step is exact
for an earth-frame-constant input. The same compiled step serves the python-control
block, the batch path and the FMU.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from attitude_fmu.blocks.control_system import sample_system
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.quaternion import level_quat, quat_multiply, quat_normalized, quat_rotate, rotvec_quat

AXES = ("x", "y", "z")
INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in AXES]  # of every estimator block: rad/s, m/s²
OUTPUTS = [f"ghat_{a}" for a in AXES] + ["q_w", "q_x", "q_y", "q_z"]  # m/s²; sensor → earth
GRAVITY_OUTPUTS = OUTPUTS[:3]
QUAT_NAMES = OUTPUTS[3:]


@dataclass(frozen=True)
class DiscreteFilter:
    """Zero-order-hold form of a SISO earth-frame filter at sample time Ts (s)."""

    Ad: np.ndarray  # n×n
    Bd: np.ndarray  # n
    C: np.ndarray  # n
    D: float
    Ts: float

    @classmethod
    def from_lti(cls, earth_filter, Ts: float) -> "DiscreteFilter":
        import control
        if not (math.isfinite(Ts) and Ts > 0):
            raise ValueError(f"sample time Ts must be a finite positive number of seconds, got {Ts!r}")
        ss = _siso_state_space(earth_filter)
        disc = control.c2d(ss, Ts, method="zoh")
        return cls(
            Ad=np.ascontiguousarray(disc.A, dtype=float),
            Bd=np.ascontiguousarray(np.ravel(disc.B), dtype=float),
            C=np.ascontiguousarray(np.ravel(disc.C), dtype=float),
            D=float(np.ravel(disc.D)[0]),
            Ts=float(Ts),
        )

    @property
    def order(self) -> int:
        return self.Ad.shape[0]

    def rest_state(self, acc0) -> np.ndarray:
        """State X (n×3) the filter holds after resting with constant input acc0 (m/s²)."""
        unit = np.linalg.solve(np.eye(self.order) - self.Ad, self.Bd)
        return np.outer(unit, np.asarray(acc0, dtype=float))

    def apply(self, x) -> np.ndarray:
        """The filter on each column of x (N, or N×3), output k after input k, at rest on x[0].

        This is the sensor-frame step with the gyro at zero: no rotation, plain LTI.
        """
        x = np.asarray(x, dtype=float)
        columns = np.zeros((len(x), 3))
        columns[:, : 1 if x.ndim == 1 else x.shape[1]] = x.reshape(len(x), -1)
        out = np.empty_like(columns)
        sensor_frame_run(np.zeros_like(columns), columns, self.Ad, self.Bd, self.C, self.D, self.Ts,
                         self.rest_state(columns[0]), np.array([1.0, 0.0, 0.0, 0.0]), out, np.empty((len(x), 4)))
        return out[:, 0] if x.ndim == 1 else out[:, : x.shape[1]]


@kernel(inline=True)
def turn_rows(X, Xr, gyr, k, Ts):
    """Rows of X (earth-fixed vectors in sensor coordinates) turned into sample k's sensor
    frame, written to Xr: the exact rotation by −ω̂·Ts for gyr[k] (rad/s) held over
    (t[k−1], t[k]]. Returns that sample's rotation quaternion."""
    dq = rotvec_quat(gyr[k, 0] * Ts, gyr[k, 1] * Ts, gyr[k, 2] * Ts)
    # a vector fixed in the earth frame turns by the inverse rotation in sensor coordinates
    dq_inv = (dq[0], -dq[1], -dq[2], -dq[3])
    for j in range(X.shape[0]):
        Xr[j, 0], Xr[j, 1], Xr[j, 2] = quat_rotate(dq_inv, (X[j, 0], X[j, 1], X[j, 2]))
    return dq


@kernel(inline=True)
def filter_rows(X, Xr, acc, k, Ad, Bd, C, D, g_out):
    """The discrete LTI filter per axis: X = Ad·Xr + Bd·acc[k]ᵀ, g_out[k] = C·X + D·acc[k]."""
    n = Ad.shape[0]
    a0, a1, a2 = acc[k, 0], acc[k, 1], acc[k, 2]
    g0, g1, g2 = D * a0, D * a1, D * a2
    for j in range(n):
        s0, s1, s2 = Bd[j] * a0, Bd[j] * a1, Bd[j] * a2
        for m in range(n):
            s0 += Ad[j, m] * Xr[m, 0]
            s1 += Ad[j, m] * Xr[m, 1]
            s2 += Ad[j, m] * Xr[m, 2]
        X[j, 0], X[j, 1], X[j, 2] = s0, s1, s2
        g0 += C[j] * s0
        g1 += C[j] * s1
        g2 += C[j] * s2
    g_out[k, 0], g_out[k, 1], g_out[k, 2] = g0, g1, g2


@kernel(inline=True)
def level_onto_gravity(q, dq, g_out, k):
    """Orientation q (sensor → earth, in place): integrate the sample's rotation dq, then
    level it so that q turns ĝ = g_out[k] onto earth up (heading stays integrated gyro)."""
    g0, g1, g2 = g_out[k, 0], g_out[k, 1], g_out[k, 2]
    qt = quat_multiply((q[0], q[1], q[2], q[3]), dq)
    norm = math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)
    if norm > 0.0:
        qt = quat_multiply(level_quat(quat_rotate(qt, (g0, g1, g2)), norm), qt)
    q[0], q[1], q[2], q[3] = quat_normalized(qt)


@kernel(inline=True)
def sensor_frame_step(X, q, gyr, acc, k, Ad, Bd, C, D, Ts, Xr, g_out):
    """Sample k: rotate the state rows by −ω̂·Ts, apply the ZOH filter, output ĝ.

    X (n×3) and q (4, sensor → earth) are updated in place; g_out[k] receives ĝ (m/s²).
    q integrates the gyro and is levelled each sample so that q rotates ĝ onto earth up
    (its heading is integrated gyro). gyr[k] in rad/s is the mean rate over
    (t[k−1], t[k]], acc[k] in m/s² is taken at t[k]. Xr (n×3) is scratch space.
    """
    dq = turn_rows(X, Xr, gyr, k, Ts)
    filter_rows(X, Xr, acc, k, Ad, Bd, C, D, g_out)
    level_onto_gravity(q, dq, g_out, k)


@kernel()
def sensor_frame_run(gyr, acc, Ad, Bd, C, D, Ts, X, q, g_out, q_out):
    """Run sensor_frame_step over N samples; X and q hold the final state afterwards."""
    Xr = np.empty_like(X)
    for k in range(gyr.shape[0]):
        sensor_frame_step(X, q, gyr, acc, k, Ad, Bd, C, D, Ts, Xr, g_out)
        q_out[k, 0], q_out[k, 1], q_out[k, 2], q_out[k, 3] = q[0], q[1], q[2], q[3]


def state_names(order: int) -> list[str]:
    """Names of the 3·n sensor-frame filter states, row by row of X."""
    return [f"x{j}_{a}" for j in range(order) for a in AXES]


class SensorFrameStepper:
    """The discrete sensor-frame filter as a stepper: state = [X row by row (3·n), q (4)]."""

    def __init__(self, disc: DiscreteFilter):
        self.disc = disc
        self.state_names = state_names(disc.order) + QUAT_NAMES

    def initial_state(self, acc0) -> np.ndarray:
        """At rest on acc0 (m/s²), q = identity."""
        return np.concatenate([self.disc.rest_state(acc0).ravel(), [1.0, 0.0, 0.0, 0.0]])

    def run(self, state, gyr, acc, gravity, quat) -> None:
        """Step over gyr, acc (N×3); state updated in place; gravity N×3, quat N×4 written."""
        d, n = self.disc, self.disc.order
        sensor_frame_run(gyr, acc, d.Ad, d.Bd, d.C, d.D, d.Ts, state[: 3 * n].reshape(n, 3), state[3 * n:],
                         gravity, quat)


def stepper_system(stepper, dt: float, name: str = "estimator"):
    """Inputs gyr_x..z (rad/s), acc_x..z (m/s²); outputs ghat_x..z (m/s²) and q_w..q_z,
    equal to the batch path's estimate at k. x0: stepper.initial_state(gravity), or
    python-control's default zero state, with which the block starts at rest on its first
    sample as the batch path does (blocks.filters.sensor_frame.start_gravity)."""
    def advance(state, u):
        gravity, quat = np.empty((1, 3)), np.empty((1, 4))
        stepper.run(state, u[0:3].reshape(1, 3).copy(), u[3:6].reshape(1, 3).copy(), gravity, quat)
        return state, np.concatenate([gravity[0], quat[0]])

    return sample_system(advance, INPUTS, OUTPUTS, stepper.state_names, dt, name,
                         start=lambda u: stepper.initial_state(start_gravity(u[0:3], u[3:6], dt)))


def sensor_frame_system(earth_filter, dt: float | None = None, name: str = "estimator"):
    """python-control nonlinear I/O system of an earth-frame SISO filter in the sensor frame.

    Inputs gyr_x..z (rad/s) and acc_x..z (m/s²); outputs ghat_x..z (m/s²).
    dt None: continuous time, states X (row by row). dt > 0: discrete time with the
    compiled step above; states X then q_w..q_z, outputs also q_w..q_z. A discrete
    system's output at k is taken after the update with the inputs at k, so it equals
    the batch path's estimate at k; x0 should come from `initial_state`.
    """
    if dt is None:
        return _continuous_system(_siso_state_space(earth_filter), name)
    return stepper_system(SensorFrameStepper(DiscreteFilter.from_lti(earth_filter, dt)), dt, name)


def time_reversed(gyr) -> np.ndarray:
    """Gyro (N×3, rad/s) for a pass backward in time: the step from sample k+1 to k turns
    the frame back by gyr[k+1] (row 0, before the first step, is 0)."""
    return np.vstack([np.zeros((1, 3)), -np.asarray(gyr)[:0:-1]])


def start_gravity(gyr0, acc0, Ts: float) -> np.ndarray:
    """The gravity to start at rest on, before the first sample: acc0 (m/s², measured at the
    end of the first interval) turned back by that interval's rotation gyr0·Ts (rad), so
    that the first step, which turns the state by gyr0·Ts, meets acc0 without the
    one-sample slip of docs/conventions.md."""
    dq = rotvec_quat(gyr0[0] * Ts, gyr0[1] * Ts, gyr0[2] * Ts)
    return np.array(quat_rotate(dq, (acc0[0], acc0[1], acc0[2])))


def initial_state(earth_filter, Ts: float, acc0) -> np.ndarray:
    """Initial state vector of the discrete system: at rest on acc0, q = identity."""
    return SensorFrameStepper(DiscreteFilter.from_lti(earth_filter, Ts)).initial_state(acc0)


def _continuous_system(ss, name):
    import control
    A = np.asarray(ss.A, dtype=float)
    B = np.ravel(ss.B).astype(float)
    C = np.ravel(ss.C).astype(float)
    D = float(np.ravel(ss.D)[0])
    n = A.shape[0]

    def update(t, x, u, params):
        X = np.reshape(x, (n, 3))
        dX = A @ X + np.outer(B, u[3:6]) - np.cross(u[:3], X)
        return dX.ravel()

    def output(t, x, u, params):
        return C @ np.reshape(x, (n, 3)) + D * np.asarray(u[3:6])

    return control.nlsys(
        update, output, inputs=INPUTS, outputs=GRAVITY_OUTPUTS,
        states=state_names(n), name=name,
    )


def _siso_state_space(earth_filter) -> control.StateSpace:
    import control
    ss = control.ss(earth_filter)
    if ss.ninputs != 1 or ss.noutputs != 1:
        raise ValueError("the earth-frame filter must be single-input single-output (one axis)")
    if not ss.isctime():
        raise ValueError("the earth-frame filter must be a continuous-time system")
    return ss
