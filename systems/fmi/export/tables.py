"""The variables of an exported diagram's FMU and its generated C tables (diagram_tables.h, the
contract of fmu_src/diagram/diagram.h), from a flattened diagram (systems.fmi.export.flatten)."""
from __future__ import annotations

import re

import numpy as np

from attitude_fmu.systems.fmi.interface.escaping import c_double, c_string
from attitude_fmu.systems.fmi.interface.variables import IN, OUT, PAR, REAL, Table, element_names

# a signal's unit by its label's stem, as the project's blocks name their signals (FMI unit names)
UNIT_STEMS = {"gyr": "rad/s", "gyr_raw": "rad/s", "omega": "rad/s", "offset": "rad/s", "acc": "m/s2", "acc_raw": "m/s2",
              "f": "m/s2", "ghat": "m/s2", "ghatl": "m/s2", "mag": "uT", "m": "uT", "mag_offset": "uT",
              "incl_err": "rad", "q": "1", "qt": "1", "qh": "1", "ql": "1"}
KINDS = ("lti", "method", "filter", "gyro_offset", "heading", "latency", "imu", "magnetometer", "human",
         "closed_form", "error")  # DiagramKind's order (fmu_src/diagram/diagram.h)
MATRICES = ("A", "B", "C", "D")
LTI_MAX = 32  # the largest n + m of a state-space block (fmu_src/diagram/diagram.h, DIAGRAM_LTI_MAX)


def signal_unit(label: str) -> str | None:
    """The unit of a signal the project's blocks name (gyr_x: rad/s, q_w: 1, …), None for another."""
    stem = re.sub(r"_[wxyz]$", "", label)
    return UNIT_STEMS.get(stem)


def variables(diagram, fmi: str = "2.0", scalar_parameters: bool = False) -> tuple[list, dict[int, int]]:
    """(the FMU's variables: the diagram's inputs, its outputs, then each state space's matrices as
    parameters, FMI 2.0 (or scalar_parameters): one scalar each (A[0,0], …), FMI 3.0: an array each (A, its
    Dimensions);
    the value reference of each state-space block's first matrix element, by block index).
    ValueError where two variables would have the same name (FMI 3.0: time included), or a name is no
    FMI variable name (escaping.fmi_name)."""
    system, table, first = diagram.system, Table(), {}
    for label in system.input_labels:
        table.real(label, 0.0, signal_unit(label), f"input {label}", IN)
    for label in system.output_labels:
        table.real(label, 0.0, signal_unit(label), f"output {label} (at the sample the last step began; before the "
                   "first step, sample 0's)", OUT, calculated=True)
    for index, block in enumerate(diagram.blocks):
        if block.lti is None:
            continue
        if block.n_states + block.n_inputs > LTI_MAX:
            raise ValueError(f"block {block.path or system.name!r}: {block.n_states} states and {block.n_inputs} "
                             f"inputs; an exported state space takes {LTI_MAX} of them at most together")
        first[index] = sum(v.size for v in table)
        prefix = f"{block.path}." if block.path else ""
        kind = "continuous" if diagram.dt == 0 else f"discrete (dt = {diagram.dt!r} s)"
        for matrix in MATRICES:
            shape = (block.n_states if matrix in "AB" else block.n_outputs,
                     block.n_states if matrix in "AC" else block.n_inputs)
            values = np.asarray(getattr(block.lti, matrix), dtype=float)
            values = values.reshape(shape) if values.size else np.zeros(shape)
            description = f"{kind} state-space matrix {matrix} of {block.path or system.name}"
            if fmi == "3.0" and not scalar_parameters:
                if values.size:
                    table.add(f"{prefix}{matrix}", REAL, PAR, "fixed", tuple(map(float, values.ravel())),
                              f"{description}, {shape[0]}×{shape[1]}, row-major", dimensions=shape)
            else:
                for name, value in zip(element_names(f"{prefix}{matrix}", shape), values.ravel()):
                    table.add(name, REAL, PAR, "fixed", float(value), description)
    names = [v.name for v in table] + (["time"] if fmi == "3.0" else [])  # FMI 3.0's independent variable
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"the FMU's variables need distinct names: {', '.join(repeated)} named twice (rename the "
                         f"diagram's signals)")
    return list(table), first


def _array(c_type: str, name: str, items: list[str]) -> str:
    """A static C array; C99 has no empty ones: one dummy element where there are none."""
    return f"static const {c_type} {name}[{max(1, len(items))}] = {{{', '.join(items) or '0'}}};"


def _term(to: int, term, gain: float) -> str:
    source, index = term
    kind = {"u": "DIAGRAM_FROM_INPUT", "y": "DIAGRAM_FROM_SIGNAL"}[source]
    return f"{{{to}, {kind}, {index}, {c_double(gain)}}}"


def tables_header(name: str, diagram, first_parameter: dict[int, int], x0) -> str:
    """The text of diagram_tables.h for the FMU name (a C identifier): the blocks, their order, the two
    linear maps and the initial state x0 (python-control's state vector); the blocks' names as C string
    literals (escaping.c_string), no other text of the system's."""
    system, blocks = diagram.system, diagram.blocks
    extra, rows = [], []
    for index, block in enumerate(blocks):
        if block.kind not in KINDS:
            raise ValueError(f"block {block.path!r}: kind {block.kind!r} has no C step (fmu_src/diagram/diagram.h)")
        step = block.step
        numbers, names, text = (step.numbers, step.names, step.text) if step is not None else ((), (), None)
        if numbers:
            extra.append(_array("double", f"NUMBERS_{index}", [c_double(float(v)) for v in numbers]))
        if names:
            extra.append(_array("char *const", f"NAMES_{index}", [c_string(n) for n in names]))
        dt = diagram.dt if step is None else step.dt
        rows.append(
            f"    {{{c_string(block.path or system.name)}, DIAGRAM_{block.kind.upper()}, "
            f"{int(block.feedthrough)}, {int(bool(step and step.start))}, {block.input}, {block.n_inputs}, "
            f"{block.output}, {block.n_outputs}, {block.state}, {block.n_states}, {c_double(float(dt))}, "
            f"{c_string(text) if text else 'NULL'}, {f'NAMES_{index}' if names else 'NULL'}, "
            f"{f'NUMBERS_{index}' if numbers else 'NULL'}, {len(numbers)}, {first_parameter.get(index, 0)}}},")
    input_terms = [_term(to, term, gain) for to, expression in enumerate(diagram.inputs)
                   for term, gain in sorted(expression.items())]
    output_terms = [_term(to, term, gain) for to, expression in enumerate(diagram.outputs)
                    for term, gain in sorted(expression.items())]
    ltis = [b for b in blocks if b.lti is not None]
    x0 = np.zeros(diagram.n_states) if x0 is None else np.asarray(x0, dtype=float).ravel()
    return "\n".join([
        f"/* diagram_tables.h: the diagram of {name}.fmu, generated by systems/fmi/export from the python-control",
        " * system; read by models/Diagram.c (fmu_src/diagram/diagram.h). Do not edit. */",
        "#ifndef DIAGRAM_TABLES_H",
        "#define DIAGRAM_TABLES_H",
        "",
        f'#include "{name}_variables.h"',
        '#include "diagram/diagram.h"',
        "",
        f"#define DIAGRAM_DT {c_double(diagram.dt)}",
        f"#define DIAGRAM_N_BLOCKS {len(blocks)}",
        f"#define DIAGRAM_N_STATES {diagram.n_states}",
        f"#define DIAGRAM_N_SIGNALS {diagram.n_signals}",
        f"#define DIAGRAM_N_BLOCK_INPUTS {len(diagram.inputs)}",
        f"#define DIAGRAM_N_INPUTS {system.ninputs}",
        f"#define DIAGRAM_N_OUTPUTS {system.noutputs}",
        "#define DIAGRAM_INPUT0 0",
        f"#define DIAGRAM_OUTPUT0 {system.ninputs}",
        f"#define DIAGRAM_LTI_DOUBLES {sum(b.n_states * (b.n_states + b.n_inputs) for b in ltis)}",
        f"#define DIAGRAM_LTI_SIZE {max((b.n_states + b.n_inputs for b in ltis), default=0)}",
        f"#define DIAGRAM_N_INPUT_TERMS {len(input_terms)}",
        f"#define DIAGRAM_N_OUTPUT_TERMS {len(output_terms)}",
        "",
        *extra,
        "",
        f"static const DiagramBlock DIAGRAM_BLOCKS[{len(blocks)}] = {{",
        *rows,
        "};",
        _array("size_t", "DIAGRAM_ORDER", [str(i) for i in diagram.order]),
        _array("DiagramTerm", "DIAGRAM_INPUT_TERMS", input_terms),
        _array("DiagramTerm", "DIAGRAM_OUTPUT_TERMS", output_terms),
        _array("double", "DIAGRAM_X0", [c_double(float(v)) for v in x0]),
        "",
        "#endif",
        "",
    ])
