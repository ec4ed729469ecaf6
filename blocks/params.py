"""Tuning parameters: one documented field each (name, default, unit, meaning, plausible
range). blocks.tuning lists every method's and stage's; the C core validates values
against them (blocks/core/params.h, through attitude_fmu._core.resolve_params)."""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One tuning parameter: name, default (None: derived), unit and meaning, and the
    plausible range of its values, low ≤ value ≤ high in the same unit; 0 only where
    allow_zero (low is then 0), every other value strictly positive. A value outside is
    refused before any sample is taken (attitude_fmu._core.resolve_params); rules that
    depend on the sample time are checked where the coefficients are made for one
    (Mahony's gains, blocks/core/methods/mahony.h). choices, where given, are the only values
    taken (a switch such as 0 or 1)."""

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
