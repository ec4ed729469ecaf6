"""Estimator methods by name: their documented parameters and their per-sample step.

A method is either an earth-frame LTI filter carried into the sensor frame
(`sensor_frame`), or a compiled kernel of its own (`kernel`: a module with STATE_SIZE,
coefficients, initial_state and run). Both are driven through a Stepper, which the batch
path, the python-control block and the FMU share. Names are those of `attitude estimate
--method`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Mapping

import numpy as np

from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter, SensorFrameStepper, stepper_system
from attitude_fmu.blocks.methods import luinge, mahony, tseng_adaptive, wiener_local
from attitude_fmu.blocks.params import (
    ANGLE_RAD,
    FREQUENCY_RAD_S,
    GRAVITY_M_S2,
    GYRO_NOISE,
    SLOSH,
    TIME_S,
    Param,
    resolve_params,
)


@dataclass(frozen=True)
class Method:
    """design gives the earth-frame filter of a sensor-frame method; kernel is the module
    of a method with a step of its own. A method with both runs its kernel where
    kernel_when(resolved params) is true (runs_kernel), its earth-frame filter otherwise."""

    name: str
    summary: str
    params: tuple[Param, ...]
    design: Callable[[Mapping[str, float | None]], control.TransferFunction] | None = None
    kernel: object = None
    kernel_when: Callable[[Mapping[str, float | None]], bool] = lambda p: True

    def resolve(self, overrides: Mapping[str, float] | None = None) -> dict[str, float | None]:
        """Defaults updated by overrides; unknown names and non-positive values are refused."""
        return resolve_params(self.params, overrides, f"method {self.name!r}")

    def runs_kernel(self, p: Mapping[str, float | None]) -> bool:
        """Whether resolved parameters p select the method's own step over its filter."""
        return self.kernel is not None and self.kernel_when(p)

    @property
    def is_sensor_frame(self) -> bool:
        return self.design is not None

    def filter(self, overrides: Mapping[str, float] | None = None) -> control.TransferFunction:
        """The earth-frame filter for these parameters (sensor-frame methods only)."""
        if self.design is None:
            raise ValueError(f"method {self.name!r} is not an earth-frame LTI filter")
        return self.design(self.resolve(overrides))


NOMINAL_DELTA_V = 1.0  # m/s/√Hz: vigorous human motion (Rizun's Table 1), when delta_v is unset
NOISE_PARAMS = (
    Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density, one-sided (datasheet)", **GYRO_NOISE),
    Param("delta_v", None, "m/s/√Hz",
          f"slosh: density of the velocity of the motion (eq. 14); unset: {NOMINAL_DELTA_V:g} for the stationary filter",
          **SLOSH),
    Param("g", ef.STANDARD_GRAVITY, "m/s²", "magnitude of gravity", **GRAVITY_M_S2),
)
MAHONY_GAINS = (  # Mahony's filter, alone and in Tseng's adaptive switch
    Param("k_P", 1.0, "1/s", "Mahony: proportional gain on the gravity-direction error", low=1e-6, high=1e4),
    Param("k_I", 0.3, "1/s²", "Mahony: integral gain of the gyro-bias estimate; 0: no bias estimate", True, high=1e4),
)
LOCAL_NOISE_PARAMS = (
    Param("stationary", 0.0, "1", "0: omega_g from noise densities measured over the last tau_noise s "
          "(blocks.methods.wiener_local); 1, or omega_g, omega_c or delta_v given: the stationary filter",
          True, high=1.0, choices=(0.0, 1.0)),
    Param("scale_error", 0.005, "1", "rms of each element of the gyro's scale-factor and misalignment "
          "error (datasheet)", True, high=1.0),
    Param("omega_m", 10.0, "rad/s", "band limit of the motion (velocity and rate) in the local densities",
          **FREQUENCY_RAD_S),
    Param("tau_noise", 1.0, "s", "averaging time of the local densities", **TIME_S),
    Param("tau_v", 1.0, "s", "time constant of the band-pass that turns the accelerometer into the "
          "slosh velocity", **TIME_S),
    Param("delta_v_min", 0.01, "m/s/√Hz", "floor of the local slosh density (rest)", **SLOSH),
)


def design_delta_v(p: Mapping[str, float | None]) -> float:
    """The slosh density (m/s/√Hz) the stationary filter is designed for."""
    return p["delta_v"] if p["delta_v"] is not None else NOMINAL_DELTA_V


def _omega_g(p: Mapping[str, float | None]) -> float:
    return p["omega_g"] if p["omega_g"] is not None else ef.omega_g(p["delta_n"], design_delta_v(p), p["g"])


def _wiener_is_local(p: Mapping[str, float | None]) -> bool:
    return p["stationary"] == 0.0 and p["omega_g"] is None and p["omega_c"] is None and p["delta_v"] is None


def _design_wiener(p):
    wg = _omega_g(p)
    return ef.butterworth(wg) if p["omega_c"] is None else ef.wiener_band_limited(wg, p["omega_c"])


def _design_first_order(p):
    if p["omega_f"] is not None:
        return ef.first_order(p["omega_f"])
    return ef.first_order(ef.best_first_order_cutoff(_omega_g(p), p["omega_c"]))


METHODS: dict[str, Method] = {
    "wiener": Method(
        "wiener",
        "Rizun's optimal Wiener filter: eq. 34 (Butterworth) with omega_g from local noise densities; "
        "with stationary=1 eq. 34 at fixed densities, or eq. 33 when omega_c is given",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "break frequency; default sqrt(g·delta_n/delta_v), eq. 25",
                  **FREQUENCY_RAD_S),
            Param("omega_c", None, "rad/s", "band limit of the motion; given, eq. 33 replaces eq. 34",
                  **FREQUENCY_RAD_S),
        ) + LOCAL_NOISE_PARAMS,
        _design_wiener,
        kernel=wiener_local,
        kernel_when=_wiener_is_local,
    ),
    "tseng": Method(
        "tseng",
        "Tseng's complementary filter (eqs. 6-11 with compensation), in the gyro-estimated earth frame",
        (),
        lambda p: tseng.earth_filter(),
    ),
    "tseng_adaptive": Method(
        "tseng_adaptive",
        "Tseng's adaptive filter: complementary filter, Mahony's filter while |acc| leaves g by > tol",
        (
            Param("tol", 0.5, "m/s²", "accelerometer norm's distance from g that switches to Mahony's filter",
                  low=1e-4, high=400.0 * 9.80665),
            *MAHONY_GAINS,
            Param("g", ef.STANDARD_GRAVITY, "m/s²", "magnitude of gravity", **GRAVITY_M_S2),
        ),
        kernel=tseng_adaptive,
    ),
    "luinge": Method(
        "luinge",
        "Luinge's tilt Kalman filter: gyro orientation, 2-state KF on the tilt difference",
        (
            Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density (process noise of the tilt)",
                  **GYRO_NOISE),
            Param("tilt_sd", 0.05, "rad", "s.d. of the accelerometer's tilt (acceleration as noise)", **ANGLE_RAD),
            Param("g", ef.STANDARD_GRAVITY, "m/s²", "magnitude of gravity (scales the gravity output)",
                  **GRAVITY_M_S2),
        ),
        kernel=luinge,
    ),
    "mahony": Method(
        "mahony",
        "Mahony's complementary filter on SO(3) with gyro-bias estimation (IEEE TAC 53, 2008)",
        MAHONY_GAINS + (
            Param("g", ef.STANDARD_GRAVITY, "m/s²", "magnitude of gravity (scales the gravity output)",
                  **GRAVITY_M_S2),
        ),
        kernel=mahony,
    ),
    "first_order": Method(
        "first_order",
        "Rizun §4.2: first-order low-pass in the gyro-estimated earth frame",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "Wiener break frequency the best cut-off derives from", **FREQUENCY_RAD_S),
            Param("omega_c", 10.0, "rad/s", "band limit of the motion (for the best cut-off)", **FREQUENCY_RAD_S),
            Param("omega_f", None, "rad/s", "cut-off; default (omega_g⁴/(2·omega_c))^(1/3), the best",
                  **FREQUENCY_RAD_S),
        ),
        _design_first_order,
    ),
}


def method(name: str) -> Method:
    """The Method of that name (METHODS), or a ValueError naming the ones there are."""
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown method {name!r}; available: {', '.join(METHODS)}") from None


@lru_cache(maxsize=64)
def discrete_filter(name: str, params: tuple, Ts: float) -> DiscreteFilter:
    """Method name's filter for params ((name, value) pairs) at sample time Ts (s), designed once."""
    return DiscreteFilter.from_lti(method(name).filter(dict(params)), Ts)


class KernelStepper:
    """A method with a compiled kernel of its own: state and coefficients are 1-D arrays."""

    def __init__(self, module, coef: np.ndarray):
        self.module, self.coef = module, coef
        self.state_names = list(module.STATE_NAMES)

    def initial_state(self, acc0) -> np.ndarray:
        return self.module.initial_state(self.coef, np.asarray(acc0, dtype=float))

    def run(self, state, gyr, acc, gravity, quat) -> None:
        self.module.run(state, self.coef, gyr, acc, gravity, quat)


@lru_cache(maxsize=64)
def stepper(name: str, params: tuple, Ts: float):
    """The stepper of method name for params ((name, value) pairs) at sample time Ts (s)."""
    m = method(name)
    resolved = m.resolve(dict(params))
    if not m.runs_kernel(resolved):
        return SensorFrameStepper(discrete_filter(name, params, Ts))
    if not (math.isfinite(Ts) and Ts > 0):
        raise ValueError(f"sample time Ts must be a finite positive number of seconds, got {Ts!r}")
    return KernelStepper(m.kernel, m.kernel.coefficients(resolved, Ts))


def estimator_system(method: str = "wiener", params: Mapping[str, float] | None = None, dt: float = 0.01,
                     name: str = "estimator"):
    """The method (a name of METHODS) with its params as a discrete python-control system of
    sample time dt (s), named name: inputs gyr_x..z (rad/s), acc_x..z (m/s²), outputs
    ghat_x..z (m/s²) and q_w..q_z, the batch path's estimate at each sample
    (blocks.filters.sensor_frame.stepper_system; from the zero initial state it starts at
    rest on its first sample)."""
    return stepper_system(stepper(method, tuple(sorted((params or {}).items())), dt), dt, name)
