"""Estimator methods by name: their documented parameters (blocks.tuning), their earth-frame
filter designs, and their per-sample step.

A method is either an earth-frame LTI filter carried into the sensor frame
(blocks.filters.sensor_frame), or a kernel of its own in the C core (wiener's local noise
densities, blocks.methods.wiener_local; Luinge's tilt Kalman filter; Mahony's filter;
Tseng's adaptive filter, which switches between Mahony's and the `tseng` filter). The C core
decides which runs and validates every parameter (attitude_fmu._core); the designs stay
here as python-control transfer functions, and their zero-order holds (python-control's
c2d, discrete_filter) are what the C core's step takes. Names are those of `attitude
estimate --method`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Mapping

from attitude_fmu import _core
from attitude_fmu.blocks import tuning
from attitude_fmu.blocks.control_system import CStep, given
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter, stepper_system
from attitude_fmu.blocks.params import Param

NOMINAL_DELTA_V = tuning.NOMINAL_DELTA_V


@dataclass(frozen=True)
class Method:
    """design gives the earth-frame filter of a sensor-frame method (resolved params →
    transfer function); mode_filter the earth-frame filter a kernel switches to where it
    has one (tseng_adaptive's complementary mode)."""

    name: str
    summary: str
    params: tuple[Param, ...]
    design: Callable[[Mapping[str, float | None]], object] | None = None
    mode_filter: Callable[[], object] | None = None

    def resolve(self, overrides: Mapping[str, float] | None = None) -> dict[str, float | None]:
        """Defaults updated by overrides; unknown names and values out of range are refused (the C core's)."""
        return _core.resolve_params(self.name, overrides)

    def runs_kernel(self, p: Mapping[str, float | None]) -> bool:
        """Whether resolved parameters p select the method's own step over its filter."""
        return _core.method_kernel(self.name, {k: v for k, v in p.items() if v is not None}) != "sensor_frame"

    @property
    def is_sensor_frame(self) -> bool:
        return self.design is not None

    def filter(self, overrides: Mapping[str, float] | None = None):
        """The earth-frame filter for these parameters (sensor-frame methods only)."""
        if self.design is None:
            raise ValueError(f"method {self.name!r} is not an earth-frame LTI filter")
        return self.design(self.resolve(overrides))


def design_delta_v(p: Mapping[str, float | None]) -> float:
    """The slosh density (m/s/√Hz) the stationary filter is designed for."""
    return p["delta_v"] if p["delta_v"] is not None else NOMINAL_DELTA_V


def _omega_g(p: Mapping[str, float | None]) -> float:
    return p["omega_g"] if p["omega_g"] is not None else ef.omega_g(p["delta_n"], design_delta_v(p), p["g"])


def _design_wiener(p):
    wg = _omega_g(p)
    return ef.butterworth(wg) if p["omega_c"] is None else ef.wiener_band_limited(wg, p["omega_c"])


def _design_first_order(p):
    if p["omega_f"] is not None:
        return ef.first_order(p["omega_f"])
    return ef.first_order(ef.best_first_order_cutoff(_omega_g(p), p["omega_c"]))


DESIGNS = {"wiener": _design_wiener, "tseng": lambda p: tseng.earth_filter(), "first_order": _design_first_order}
MODE_FILTERS = {"tseng_adaptive": tseng.earth_filter}

METHODS: dict[str, Method] = {
    name: Method(name, summary, params, DESIGNS.get(name), MODE_FILTERS.get(name))
    for name, (summary, params) in tuning.METHODS.items()
}


def method(name: str) -> Method:
    """The Method of that name (METHODS), or a ValueError naming the ones there are."""
    if name not in METHODS:
        _core.method_index(name)  # raises, naming them
    return METHODS[name]


@lru_cache(maxsize=64)
def discrete_filter(name: str, params: tuple, Ts: float) -> DiscreteFilter:
    """The earth-frame filter method name's C step runs for params ((name, value) pairs) held
    over Ts (s): its design (a sensor-frame method) or the filter it switches to
    (tseng_adaptive's), designed once."""
    m = method(name)
    return DiscreteFilter.from_lti(m.filter(dict(params)) if m.design is not None else m.mode_filter(), Ts)


@dataclass(frozen=True)
class Holds:
    """The source of a method's discrete filters for the C core (the zoh of
    _core.Pipeline.at, _core.Stepper.of_method and _core.Online.step): called with a sample
    time Ts (s), it gives discrete_filter(method, params, Ts)."""

    method: str
    params: tuple  # (name, value) pairs

    def __call__(self, Ts: float) -> DiscreteFilter:
        return discrete_filter(self.method, self.params, Ts)


def stepper(name: str, params: tuple, Ts: float) -> _core.Stepper:
    """The C core's step of method name for params ((name, value) pairs) at sample time Ts (s):
    state = stepper.initial_state(gravity), then stepper.run(state, gyr, acc, gravity, quat)
    over rows; stepper.state_names name the state's values."""
    return _core.Stepper.of_method(name, dict(params), Ts, Holds(name, params))


def estimator_system(method: str = "wiener", params: Mapping[str, float] | None = None, dt: float = 0.01,
                     name: str = "estimator"):
    """The method (a name of METHODS) with its params as a discrete python-control system of
    sample time dt (s), named name: inputs gyr_x..z (rad/s), acc_x..z (m/s²), outputs
    ghat_x..z (m/s²) and q_w..q_z, the batch path's estimate at each sample
    (blocks.filters.sensor_frame.stepper_system; its state is the C step's state array; from
    the zero initial state it starts at rest on its first sample). Marked with its C step,
    "method" (the params given, as given)."""
    return stepper_system(stepper(method, tuple(sorted((params or {}).items())), dt), dt, name,
                          CStep("method", dt, method, **given(params)))
