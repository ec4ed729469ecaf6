"""Estimator methods by name: their documented parameters and their earth-frame filter.

Every method here is an earth-frame LTI filter carried into the sensor frame by
`sensor_frame.sensor_frame_system`; the name is the one `attitude estimate --method` takes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Mapping

import control

from . import earth_filters as ef
from .sensor_frame import DiscreteFilter


@dataclass(frozen=True)
class Param:
    """One tuning parameter: name, default (None: derived), unit and meaning."""

    name: str
    default: float | None
    unit: str
    doc: str


@dataclass(frozen=True)
class Method:
    name: str
    summary: str
    params: tuple[Param, ...]
    design: Callable[[Mapping[str, float | None]], control.TransferFunction]

    def resolve(self, overrides: Mapping[str, float] | None = None) -> dict[str, float | None]:
        """Defaults updated by overrides; unknown names and non-positive values are refused."""
        known = {p.name: p.default for p in self.params}
        for name, value in (overrides or {}).items():
            if name not in known:
                raise ValueError(
                    f"unknown parameter {name!r} for method {self.name!r}; "
                    f"known: {', '.join(known)}"
                )
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"parameter {name} must be a finite positive number, got {value!r}")
            known[name] = float(value)
        return known

    def filter(self, overrides: Mapping[str, float] | None = None) -> control.TransferFunction:
        """The earth-frame filter for these parameters."""
        return self.design(self.resolve(overrides))


NOISE_PARAMS = (
    Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density, one-sided (datasheet)"),
    Param("delta_v", 1.0, "m/s/√Hz", "slosh: density of the velocity of the motion (eq. 14)"),
    Param("g", ef.STANDARD_GRAVITY, "m/s²", "magnitude of gravity"),
)


def _omega_g(p: Mapping[str, float | None]) -> float:
    return p["omega_g"] if p["omega_g"] is not None else ef.omega_g(p["delta_n"], p["delta_v"], p["g"])


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
        "Rizun's optimal Wiener filter: eq. 34 (Butterworth), or eq. 33 when omega_c is given",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "break frequency; default sqrt(g·delta_n/delta_v), eq. 25"),
            Param("omega_c", None, "rad/s", "band limit of the motion; given, eq. 33 replaces eq. 34"),
        ),
        _design_wiener,
    ),
    "first_order": Method(
        "first_order",
        "Rizun §4.2: first-order low-pass in the gyro-estimated earth frame",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "Wiener break frequency the best cut-off derives from"),
            Param("omega_c", 10.0, "rad/s", "band limit of the motion (for the best cut-off)"),
            Param("omega_f", None, "rad/s", "cut-off; default (omega_g⁴/(2·omega_c))^(1/3), the best"),
        ),
        _design_first_order,
    ),
}


def method(name: str) -> Method:
    try:
        return METHODS[name]
    except KeyError:
        raise ValueError(f"unknown method {name!r}; available: {', '.join(METHODS)}") from None


@lru_cache(maxsize=64)
def discrete_filter(name: str, params: tuple, Ts: float) -> DiscreteFilter:
    """Method name's filter for params ((name, value) pairs) at sample time Ts (s), designed once."""
    return DiscreteFilter.from_lti(method(name).filter(dict(params)), Ts)
