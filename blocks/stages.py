"""Tuning parameters of the stages an estimate runs: the method (blocks.methods), the
gyro-offset estimator (blocks.gyro_offset) and the heading estimator (blocks.heading)."""
from __future__ import annotations

from collections.abc import Mapping

from . import gyro_offset, heading
from .methods import method as get_method

ESTIMATORS = {"the gyro-offset estimator": gyro_offset.PARAMS, "the heading estimator": heading.PARAMS}


def split_params(method: str, params: Mapping[str, float] | None, offset: bool, mag: bool):
    """params (name → value) split into (the method's, the gyro-offset estimator's, the
    heading estimator's); offset and mag say whether those two run. A name goes to every
    running stage that has it (delta_n, the gyro's noise density, to the method and the
    gyro-offset estimator alike); a name no running stage has is refused, naming theirs."""
    stages = ((f"the method {method}", get_method(method).params, True),
              *((name, ps, runs) for (name, ps), runs in zip(ESTIMATORS.items(), (offset, mag))))
    params = dict(params or {})
    running = [(stage, ps) for stage, ps, runs in stages if runs]
    for name in params:
        if not any(p.name == name for _, ps in running for p in ps):
            known = "; ".join(f"{stage}: {', '.join(p.name for p in ps) or 'none'}" for stage, ps in running)
            raise ValueError(f"unknown parameter {name!r} ({known})")
    return tuple({p.name: params[p.name] for p in ps if p.name in params} if runs else {} for _, ps, runs in stages)
