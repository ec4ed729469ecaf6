"""The sensor-frame transformation (Rizun eq. 35) of any earth-frame LTI filter.

An earth-frame filter ẋ = A·x + B·u, y = C·x + D·u (one scalar axis, n states) acts on
each component of the accelerometer signal in the gyro-estimated earth frame. Carried
into the sensor frame with d/dt|sensor = d/dt|earth − ω̂×, each of its n states becomes a
3-vector (the rows of X, n×3) that also turns with −ω̂×:

    dX/dt = A·X + B·y_aᵀ − (ω̂ × each row of X),      ĝ = C·X + D·y_aᵀ.

Discrete time (sample time Ts): the rotation over a sample is applied exactly (constant
ω̂ over (t[k−1], t[k]], docs/conventions.md), the LTI part by its zero-order-hold form (Ad, Bd:
DiscreteFilter, python-control's c2d). Rotation and LTI part act on different indices of X
and so commute; the step is exact for an earth-frame-constant input. The step is the C
core's (blocks/core/filters/sensor_frame.h, attitude_fmu._core.Stepper), which the
python-control block, the batch path and the FMU share.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, resting, sample_system, with_c_step
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY

AXES = ("x", "y", "z")
INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in AXES]  # of every estimator block: rad/s, m/s²
OUTPUTS = [f"ghat_{a}" for a in AXES] + ["q_w", "q_x", "q_y", "q_z"]  # m/s²; sensor → earth
GRAVITY_OUTPUTS = OUTPUTS[:3]
QUAT_NAMES = OUTPUTS[3:]
REST_INPUTS = (0.0, 0.0, 0.0, 0.0, 0.0, STANDARD_GRAVITY)  # an estimator's natural rest: gyro 0, acc g·ẑ


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
        disc = control.c2d(_siso_state_space(earth_filter), Ts, method="zoh")
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
        return _core.rest_state(self.Ad, self.Bd, np.asarray(acc0, dtype=float))

    def stepper(self) -> _core.Stepper:
        """Its sensor-frame step (state: X row by row, then q)."""
        return _core.Stepper.of_filter(self.Ad, self.Bd, self.C, self.D, self.Ts)

    def apply(self, x) -> np.ndarray:
        """The filter on each column of x (N, or N×3), output k after input k, at rest on x[0].

        This is the sensor-frame step with the gyro at zero: no rotation, plain LTI.
        """
        x = np.asarray(x, dtype=float)
        columns = np.zeros((len(x), 3))
        columns[:, : 1 if x.ndim == 1 else x.shape[1]] = x.reshape(len(x), -1)
        out = np.empty_like(columns)
        step = self.stepper()
        step.run(step.initial_state(columns[0]), np.zeros_like(columns), columns, out, np.empty((len(x), 4)))
        return out[:, 0] if x.ndim == 1 else out[:, : x.shape[1]]


def state_names(order: int) -> list[str]:
    """Names of the 3·n sensor-frame filter states, row by row of X."""
    return [f"x{j}_{a}" for j in range(order) for a in AXES]


def stepper_system(stepper: _core.Stepper, dt: float, name: str = "estimator", step: CStep | None = None):
    """Inputs gyr_x..z (rad/s), acc_x..z (m/s²); outputs ghat_x..z (m/s²) and q_w..q_z,
    equal to the batch path's estimate at k. x0: stepper.initial_state(gravity), or
    python-control's default zero state, with which the block starts at rest on its first
    sample as the batch path does (start_gravity). step: the C step it is marked with
    (with_c_step; its start, rest and natural rest filled in here), None: unmarked."""
    def advance(state, u):
        gravity, quat = np.empty((1, 3)), np.empty((1, 4))
        stepper.run(state, u[0:3].reshape(1, 3), u[3:6].reshape(1, 3), gravity, quat)
        return state, np.concatenate([gravity[0], quat[0]])

    def start(u):
        return stepper.initial_state(start_gravity(u[0:3], u[3:6], dt))

    def run(state, rows):
        n = len(rows)
        stepper.run(state, np.ascontiguousarray(rows[:, 0:3]), np.ascontiguousarray(rows[:, 3:6]), np.empty((n, 3)),
                    np.empty((n, 4)))

    system = sample_system(advance, INPUTS, OUTPUTS, stepper.state_names, dt, name, start=start)
    if step is None:
        return system
    return with_c_step(system, replace(step, start=True, rest=lambda u: resting(run, start(u), u, dt),
                                       rest_inputs=REST_INPUTS))


def sensor_frame_system(earth_filter, dt: float | None = None, name: str = "estimator"):
    """python-control nonlinear I/O system of an earth-frame SISO filter in the sensor frame.

    Inputs gyr_x..z (rad/s) and acc_x..z (m/s²); outputs ghat_x..z (m/s²).
    dt None: continuous time, states X (row by row). dt > 0: discrete time with the
    C core's step; states X then q_w..q_z, outputs also q_w..q_z. A discrete system's
    output at k is taken after the update with the inputs at k, so it equals the batch
    path's estimate at k; x0 should come from `initial_state`. The discrete system is marked
    with its C step, "filter" (numbers [n, Ad, Bd, C, D]).
    """
    if dt is None:
        return _continuous_system(_siso_state_space(earth_filter), name)
    disc = DiscreteFilter.from_lti(earth_filter, dt)
    numbers = (disc.order, *disc.Ad.ravel(), *disc.Bd, *disc.C, disc.D)
    return stepper_system(disc.stepper(), dt, name, CStep("filter", dt, numbers=tuple(map(float, numbers))))


def time_reversed(gyr) -> np.ndarray:
    """Gyro (N×3, rad/s) for a pass backward in time: the step from sample k+1 to k turns
    the frame back by gyr[k+1] (row 0, before the first step, is 0)."""
    return np.vstack([np.zeros((1, 3)), -np.asarray(gyr)[:0:-1]])


def start_gravity(gyr0, acc0, Ts: float) -> np.ndarray:
    """The gravity to start at rest on, before the first sample: acc0 (m/s², measured at the
    end of the first interval) turned back by that interval's rotation gyr0·Ts (rad), so
    that the first step, which turns the state by gyr0·Ts, meets acc0 without the
    one-sample slip of docs/conventions.md."""
    return _core.start_gravity(gyr0, acc0, Ts)


def initial_state(earth_filter, Ts: float, acc0) -> np.ndarray:
    """Initial state vector of the discrete system: at rest on acc0, q = identity."""
    return DiscreteFilter.from_lti(earth_filter, Ts).stepper().initial_state(acc0)


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
