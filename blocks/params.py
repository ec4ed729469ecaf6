"""Tuning parameters: one documented field each (name, default, unit, meaning, plausible
range), and their validation. Every method (blocks.methods.registry) and stage
(blocks.stages) lists its own."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One tuning parameter: name, default (None: derived), unit and meaning, and the
    plausible range of its values, low ≤ value ≤ high in the same unit; 0 only where
    allow_zero (low is then 0), every other value strictly positive. A value outside is
    refused before any sample is taken (resolve_params); rules that depend on the sample
    time are checked where the coefficients are made for one (blocks.methods.mahony). choices,
where given, are the only values taken (a switch such as 0 or 1)."""

    name: str
    default: float | None
    unit: str
    doc: str
    allow_zero: bool = False
    low: float = 0.0
    high: float = math.inf
    choices: tuple[float, ...] | None = None  # where only these values have a meaning (a switch)

    def range_text(self) -> str:
        """The plausible range as messages and the help say it: "[1e-07, 1] rad/s/√Hz", "(0, 100] s"."""
        low = "0" if self.allow_zero or self.low == 0 else f"{self.low:g}"
        bracket = "[" if self.allow_zero or self.low > 0 else "("
        return f"{bracket}{low}, {self.high:g}]{_unit(self)}"


def resolve_params(params: tuple[Param, ...], overrides: Mapping[str, float] | None, owner: str) -> dict:
    """The defaults of params updated by overrides; unknown names, values that are not
    finite numbers, non-positive ones (negative ones where allow_zero) and ones outside a
    parameter's plausible range (Param.low, Param.high) are refused, naming owner."""
    known = {p.name: p for p in params}
    values = {p.name: p.default for p in params}
    for name, value in (overrides or {}).items():
        if name not in known:
            raise ValueError(f"unknown parameter {name!r} for {owner}; known: {', '.join(known)}")
        p = known[name]
        number = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
        if not (number and (value >= 0 if p.allow_zero else value > 0)):
            kind = "non-negative" if p.allow_zero else "positive"
            raise ValueError(f"parameter {name} must be a finite {kind} number ({p.range_text()}), got {value!r}")
        if p.choices is not None and value not in p.choices:
            raise ValueError(f"parameter {name} must be {' or '.join(f'{c:g}' for c in p.choices)}, got {value!r} "
                             f"({p.doc})")
        if not p.low <= value <= p.high:
            raise ValueError(f"parameter {name} = {value:g}{_unit(p)} is outside its plausible range "
                             f"{p.range_text()} ({p.doc})")
        values[name] = float(value)
    return values


def _unit(p: Param) -> str:
    return "" if p.unit == "1" else f" {p.unit}"


# plausible ranges shared by the parameters of one kind (Param's low and high, keyword arguments)
TIME_S = {"low": 1e-9, "high": 1e12}  # s: time constants and durations; 1 ns: at once, 1e12 s: never
GRAVITY_M_S2 = {"low": 1.0, "high": 30.0}  # m/s²: gravity anywhere a body is measured (the moon's 1.6, Jupiter's 25)
GYRO_NOISE = {"low": 1e-12, "high": 1.0}  # rad/s/√Hz: a simulation's noise-free gyro to 57 °/s/√Hz
SLOSH = {"low": 1e-5, "high": 100.0}  # m/s/√Hz: the density of a motion's velocity, rest to violent shaking
FREQUENCY_RAD_S = {"low": 1e-4, "high": 1e5}  # rad/s: break frequencies and band limits
ANGLE_RAD = {"low": 1e-6, "high": math.pi}  # rad: tolerances and clips of angles
RATE_RAD_S = {"low": 1e-6, "high": math.radians(4000.0)}  # rad/s: within the widest gyro range
FRACTION = {"low": 1e-6, "high": 1.0}  # 1: relative tolerances
