"""A python-control system as the blocks an exported FMU runs (fmu_src/diagram/diagram.h): the
leaves of its interconnects, nested to any depth, each a state space or one of the project's
blocks with a C step (blocks.control_system.c_step), the linear maps that feed their inputs and
the diagram's outputs, and an order of evaluation that respects direct feedthrough."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# a linear expression over the diagram's inputs ("u", j) and the blocks' outputs ("y", i): term → gain
Expression = dict


class ExportError(ValueError):
    """A system that cannot be exported as a native FMU; the message names the block and why."""


@dataclass
class Block:
    """One leaf of the diagram. path: its name within its interconnects' (a.b.c); step: its C step
    (None: a state space, lti); input, output, state: the first of its inputs, outputs and states
    among all blocks'."""

    path: str
    system: object
    step: object = None
    lti: object = None
    input: int = 0
    output: int = 0
    state: int = 0

    @property
    def kind(self) -> str:
        return "lti" if self.step is None else self.step.kind

    @property
    def n_inputs(self) -> int:
        return self.system.ninputs

    @property
    def n_outputs(self) -> int:
        return self.system.noutputs

    @property
    def n_states(self) -> int:
        return self.system.nstates

    @property
    def feedthrough(self) -> bool:
        """Whether its outputs at a sample depend on its inputs at that sample: a state space's with a
        non-zero D; every C step is taken as one (its outputs and next state come from one call)."""
        if self.lti is not None:
            return bool(np.any(np.asarray(self.lti.D) != 0))
        return True


@dataclass
class Diagram:
    """The flattened system: its blocks; inputs[i]: block input i as an Expression; outputs[k]:
    the diagram's output k; order: the blocks' indices as a step evaluates them (without
    feedthrough first); dt: the sample time (s), 0 for a continuous state space."""

    system: object
    blocks: list[Block] = field(default_factory=list)
    inputs: list[Expression] = field(default_factory=list)
    outputs: list[Expression] = field(default_factory=list)
    order: list[int] = field(default_factory=list)
    dt: float = 0.0

    @property
    def n_states(self) -> int:
        return sum(b.n_states for b in self.blocks)

    @property
    def n_signals(self) -> int:
        return sum(b.n_outputs for b in self.blocks)


def _state_space(system):
    """system as a control.StateSpace if it is linear (StateSpace, TransferFunction, an interconnect of
    them), else None."""
    import control

    if isinstance(system, control.StateSpace):
        return system
    if isinstance(system, control.TransferFunction):
        return control.ss(system)
    return None


def _substitute(expression: Expression, local: dict, rows=None) -> Expression:
    """expression with each term ("u", j) replaced by local[j] and, given rows, each ("c", r) by rows[r]
    (Expressions)."""
    out: Expression = {}
    for (source, index), gain in expression.items():
        if source == "u":
            terms = local[index]
        elif source == "c" and rows is not None:
            terms = rows[index]
        else:
            terms = {(source, index): 1.0}
        for term, g in terms.items():
            out[term] = out.get(term, 0.0) + gain * g
    return {term: g for term, g in out.items() if g != 0.0}


def _leaf(diagram: Diagram, system, path: str) -> list[Expression]:
    """system added as a block; returns its outputs as Expressions over its own inputs ("u") and the
    blocks' outputs ("y"); its inputs' Expressions ("u" of its own) are appended to diagram.inputs."""
    from attitude_fmu.blocks.control_system import c_step

    lti, step = _state_space(system), c_step(system)
    if lti is None and step is None:
        raise ExportError(f"block {path or system.name!r} ({type(system).__name__}) has no C step: its update and output are "
                          f"Python functions; export it with backend='python' (the FMU then needs a Python with "
                          f"attitude_fmu where it runs)")
    block = Block(path, lti if lti is not None else system, step, lti, len(diagram.inputs), diagram.n_signals,
                  diagram.n_states)
    diagram.blocks.append(block)
    diagram.inputs.extend({("u", j): 1.0} for j in range(block.n_inputs))
    return [{("y", block.output + i): 1.0} for i in range(block.n_outputs)]


def _expand(diagram: Diagram, system, path: str) -> list[Expression]:
    """The blocks of system added (an interconnect's recursively) with their inputs' Expressions over
    system's inputs ("u") and the blocks' outputs; returns system's outputs likewise."""
    from control.nlsys import InterconnectedSystem

    if not isinstance(system, InterconnectedSystem) or _state_space(system) is not None:
        return _leaf(diagram, system, path)
    # each child's blocks, its block inputs (a range of diagram.inputs) and outputs over its own inputs
    children = []
    for child in system.syslist:
        first = len(diagram.inputs)
        outputs = _expand(diagram, child, f"{path}.{child.name}" if path else child.name)
        children.append((first, len(diagram.inputs), child.ninputs, outputs))
    offsets = np.cumsum([0] + [child[2] for child in children]).tolist()
    # a child's own input j is row offsets[k] + j of python-control's ulist: ("c", row) until resolved
    outputs = [_substitute(o, {j: {("c", offsets[k] + j): 1.0} for j in range(count)})
               for k, (_, _, count, child_outputs) in enumerate(children) for o in child_outputs]
    ulist = [_combine(system.connect_map[row], outputs) for row in range(offsets[-1])]
    for row in range(offsets[-1]):
        ulist[row] = _add(ulist[row], {("u", j): g for j, g in enumerate(system.input_map[row]) if g != 0.0}, 1.0)
    ulist = _resolved(ulist, path)
    for k, (first, last, count, _) in enumerate(children):
        local = {j: ulist[offsets[k] + j] for j in range(count)}
        for i in range(first, last):
            diagram.inputs[i] = _substitute(diagram.inputs[i], local)
    signals = [_substitute(o, {}, ulist) for o in outputs] + ulist
    return [_combine(system.output_map[row], signals) for row in range(system.noutputs)]


def _add(expression: Expression, other: Expression, gain: float) -> Expression:
    """expression + gain · other."""
    out = dict(expression)
    for term, g in other.items():
        out[term] = out.get(term, 0.0) + gain * g
    return {term: g for term, g in out.items() if g != 0.0}


def _combine(row, signals: list[Expression]) -> Expression:
    """Σ row[c] · signals[c]."""
    out: Expression = {}
    for column, gain in enumerate(row):
        if gain != 0.0:
            out = _add(out, signals[column], gain)
    return out


def _resolved(ulist: list[Expression], path: str) -> list[Expression]:
    """ulist with every term ("c", row) (a child's output that passes that child input through) replaced
    by that row's Expression; ExportError where rows pass each other through in a ring."""
    done: dict[int, Expression] = {}

    def resolve(row: int, visiting: tuple) -> Expression:
        if row in done:
            return done[row]
        if row in visiting:
            raise ExportError(f"algebraic loop of pure connections in {path or 'the diagram'}: inputs "
                              f"{', '.join(map(str, visiting))} pass each other through")
        expression = ulist[row]
        while any(source == "c" for source, _ in expression):
            term = next(t for t in expression if t[0] == "c")
            gain = expression.pop(term)
            expression = _add(expression, resolve(term[1], visiting + (row,)), gain)
        done[row] = expression
        return expression

    return [resolve(row, ()) for row in range(len(ulist))]


def evaluation_order(diagram: Diagram) -> list[int]:
    """The blocks' indices in the order a step evaluates them: those without feedthrough first (their
    outputs come from their state), then those with, each after the blocks whose outputs it takes.
    ExportError naming the blocks of an algebraic loop (feedthrough blocks that feed each other)."""
    owner = {}
    for index, block in enumerate(diagram.blocks):
        for i in range(block.n_outputs):
            owner[block.output + i] = index
    needs: dict[int, set[int]] = {}
    for index, block in enumerate(diagram.blocks):
        if block.feedthrough:
            needs[index] = {owner[i] for b in range(block.input, block.input + block.n_inputs)
                            for (source, i) in diagram.inputs[b] if source == "y"
                            and diagram.blocks[owner[i]].feedthrough}
    order = [index for index, block in enumerate(diagram.blocks) if not block.feedthrough]
    done = set(order)
    pending = [index for index in range(len(diagram.blocks)) if index not in done]
    while pending:
        ready = [index for index in pending if needs[index] <= done]
        if not ready:
            loop = _loop(needs, pending)
            names = " → ".join(diagram.blocks[i].path for i in loop)
            raise ExportError(f"algebraic loop: {names} → {diagram.blocks[loop[0]].path}: each block's output at a "
                              f"sample depends on its input at that sample around the loop (direct feedthrough); "
                              f"break it with a block that has a state (a delay)")
        order += ready
        done.update(ready)
        pending = [index for index in pending if index not in done]
    return order


def _loop(needs: dict[int, set[int]], pending: list[int]) -> list[int]:
    """One cycle among the pending blocks (each needs another pending one), in the order of its flow."""
    pending_set, path, seen = set(pending), [], {}
    node = pending[0]
    while node not in seen:
        seen[node] = len(path)
        path.append(node)
        node = min(needs[node] & pending_set)
    cycle = path[seen[node]:]
    return cycle[::-1]


def flatten(system) -> Diagram:
    """system (a control.StateSpace, TransferFunction, one of the project's blocks or an interconnect of
    them) as its blocks; ExportError naming a block that cannot be exported and why."""
    import control

    if not isinstance(system, control.InputOutputSystem):
        raise ExportError(f"not a python-control system: {type(system).__name__}")
    dt = system.dt
    if dt is True:
        raise ExportError(f"system {system.name!r} is discrete with an unspecified sample time (dt=True): give it "
                          f"one (dt in seconds)")
    diagram = Diagram(system, dt=float(dt or 0.0))
    if dt == 0 and _state_space(system) is None:
        raise ExportError(f"system {system.name!r} is continuous and not linear: only continuous state spaces and "
                          f"transfer functions are exported (discretised exactly at the communication step)")
    diagram.outputs = _expand(diagram, system, "")
    diagram.order = evaluation_order(diagram)
    return diagram
