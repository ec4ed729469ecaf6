"""Any per-sample step as a discrete-time python-control nonlinear I/O system, what a block of
the project tells the FMU exporter (systems.fmi.export) about its C step, and the state it holds
at rest (rest_state, rest_point: where control.linearize and control.find_operating_point start)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

REMEMBERED = 16  # steps (state, input) remembered: an interconnect asks a block for several inputs per step
REST_TIME = 100.0  # s: how long a block rests on its inputs for rest_state, past every start-up at default parameters
REST_ROWS = 4096  # samples of a rest stepped at once


@dataclass(frozen=True)
class CStep:
    """A project block's C step, as an exported FMU runs it (fmu_src/diagram/diagram.h, DiagramKind):
    kind: "method", "filter", "gyro_offset", "heading", "latency", "imu", "magnetometer", "human",
    "closed_form" or "error"; dt: its sample time (s); text: the method's or profile's name; names
    and numbers: the kind's numbers (diagram.h), the given parameters' names beside their values;
    start: whether it starts at rest from an all-zero state (sample_system's start);
    rest: inputs at rest → the state the block holds there (None: the zero state is its rest);
    rest_inputs: the inputs of its natural rest (rest_state's default; None: all 0)."""

    kind: str
    dt: float
    text: str | None = None
    names: tuple[str, ...] = ()
    numbers: tuple[float, ...] = ()
    start: bool = False
    rest: Callable[[np.ndarray], np.ndarray] | None = None
    rest_inputs: tuple[float, ...] | None = None


def given(params) -> dict:
    """CStep's names and numbers for the parameters given (a mapping name → value, or None), as given."""
    params = dict(params or {})
    return {"names": tuple(params), "numbers": tuple(float(v) for v in params.values())}


def with_c_step(system, step: CStep):
    """system, marked as running step (read by c_step); returned for chaining."""
    system.c_step = step
    return system


def c_step(system) -> CStep | None:
    """The C step of one of the project's blocks (with_c_step), None for any other system."""
    step = getattr(system, "c_step", None)
    return step if isinstance(step, CStep) else None


def sample_system(advance, inputs, outputs, states, dt: float, name: str, start=None):
    """A discrete python-control system from advance(x, u) → (next state, output at k):
    the output at k is taken after the update with the inputs at k, as a batch path that
    writes each sample's estimate after taking it. python-control asks the update and the
    output function separately for one step: advance runs once per (x, u) and serves both.
    start(u) → the state to begin with at a first input u, used where x is all zeros
    (python-control's default initial state, no state a step can be in): the block then
    starts at rest on its first sample, as the batch path and the FMU do."""
    import control
    remembered: dict[tuple[bytes, bytes], tuple[np.ndarray, np.ndarray]] = {}

    def step(x, u):
        x, u = np.array(x, dtype=float), np.asarray(u, dtype=float)
        key = (x.tobytes(), u.tobytes())
        if key not in remembered:
            if start is not None and x.size and not x.any():
                x = np.array(start(u), dtype=float)
            state, output = advance(x, u)
            if len(remembered) >= REMEMBERED:
                remembered.pop(next(iter(remembered)))
            remembered[key] = (np.array(state, dtype=float), np.array(output, dtype=float))
        return remembered[key]

    return control.nlsys(lambda t, x, u, params: step(x, u)[0], lambda t, x, u, params: step(x, u)[1],
                         inputs=list(inputs), outputs=list(outputs), states=list(states), dt=dt, name=name)


def resting(run, state, u, dt: float) -> np.ndarray:
    """state after the inputs u held REST_TIME s at the sample time dt (s), in place and returned:
    run(state, rows) takes the block's step over rows of inputs (m × len(u)), state in place."""
    n = math.ceil(REST_TIME / dt)
    rows = np.tile(np.asarray(u, dtype=float), (min(n, REST_ROWS), 1))
    while n > 0:
        m = min(n, len(rows))
        run(state, rows[:m])
        n -= m
    return state


def rest_state(system, u=None, states=None) -> np.ndarray:
    """The state system holds at rest on its inputs u held constant, in python-control's order.

    A block of the project's (c_step): started at rest on u (where it has a start), then
    REST_TIME s of u; u defaults to its natural rest (CStep.rest_inputs): gyro 0 rad/s,
    accelerometer g·ẑ m/s² (g = blocks.tuning.STANDARD_GRAVITY), orientation the identity, a
    field pointing north (µT), noise 0. Clocks keep counting (wiener's t and the stages' step
    counts; the steps no longer depend on them at rest): control.find_operating_point finds
    this point with those states held (ix) and their updates left free (idx).
    An interconnect: each block at rest on the inputs the others give it at rest, the
    diagram's inputs u (default 0); a diagram whose blocks feed back on each other at rest gets
    the last of as many passes as it has blocks (a first guess for find_operating_point).
    Any other system: the zero state.
    states: {block name: state} for blocks whose state at rest is given (e.g. a controller's)."""
    return _rest(system, u, states or {})[0]


def rest_point(system, u=None, states=None):
    """control.OperatingPoint of system at rest (rest_state, the same u and states): its states,
    its inputs there and its outputs; control.linearize(system, rest_point(system)) linearises there."""
    import control
    x, u = _rest(system, u, states or {})
    return control.OperatingPoint(x, u, np.atleast_1d(np.asarray(system.output(0.0, x, u), dtype=float)))


def _rest(system, u, given) -> tuple[np.ndarray, np.ndarray]:
    """(state, inputs) of system at rest on u (rest_state)."""
    import control
    step = c_step(system)
    if u is None:
        u = step.rest_inputs if step is not None and step.rest_inputs is not None else np.zeros(system.ninputs)
    u = np.asarray(u, dtype=float)
    if u.shape != (system.ninputs,):
        raise ValueError(f"the inputs at rest of {system.name!r} must be {system.ninputs} numbers, got shape {u.shape}")
    if system.name in given:
        x = np.asarray(given[system.name], dtype=float)
        if x.shape != (system.nstates,):
            raise ValueError(f"the state of {system.name!r} must be {system.nstates} numbers, got shape {x.shape}")
        return x, u
    if isinstance(system, control.InterconnectedSystem):
        return _diagram_rest(system, u, given), u
    if step is not None and step.rest is not None:
        return np.asarray(step.rest(u), dtype=float), u
    return np.zeros(system.nstates), u


def _diagram_rest(diagram, u, given) -> np.ndarray:
    """The blocks' states at rest in diagram on its inputs u, pass after pass: each block at rest
    on the inputs of the previous pass (first: its own rest's), until they hold."""
    blocks = diagram.syslist
    rests = [_rest(block, None, given) for block in blocks]
    split = np.cumsum([block.ninputs for block in blocks])[:-1]
    for _ in blocks:
        outputs = [np.atleast_1d(block.output(0.0, x, ub)) for block, (x, ub) in zip(blocks, rests)]
        feed = diagram.connect_map @ np.concatenate(outputs) + diagram.input_map @ u
        inputs = np.split(feed, split)
        if all(np.array_equal(new, ub) for new, (_, ub) in zip(inputs, rests)):
            break
        rests = [rest if np.array_equal(new, rest[1]) else _rest(block, new, given)
                 for block, new, rest in zip(blocks, inputs, rests)]
    return np.concatenate([x for x, _ in rests])
