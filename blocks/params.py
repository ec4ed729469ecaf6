"""Tuning parameters: one documented field each (name, default, unit, meaning), and their
validation. Every method (blocks.methods.registry) and stage (blocks.stages) lists its own."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    """One tuning parameter: name, default (None: derived), unit and meaning."""

    name: str
    default: float | None
    unit: str
    doc: str
    allow_zero: bool = False


def resolve_params(params: tuple[Param, ...], overrides: Mapping[str, float] | None, owner: str) -> dict:
    """The defaults of params updated by overrides; unknown names, non-finite values and
    non-positive ones (negative ones where allow_zero) are refused, naming owner."""
    known = {p.name: p for p in params}
    values = {p.name: p.default for p in params}
    for name, value in (overrides or {}).items():
        if name not in known:
            raise ValueError(f"unknown parameter {name!r} for {owner}; known: {', '.join(known)}")
        low_ok = value >= 0 if known[name].allow_zero else value > 0
        if not (isinstance(value, (int, float)) and math.isfinite(value) and low_ok):
            kind = "non-negative" if known[name].allow_zero else "positive"
            raise ValueError(f"parameter {name} must be a finite {kind} number, got {value!r}")
        values[name] = float(value)
    return values
