"""export_fmu: any python-control diagram of state spaces, transfer functions and the project's blocks
as a native co-simulation FMU (FMI 2.0 or 3.0), or any discrete python-control system as a pythonfmu
FMU (backend="python")."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from attitude_fmu.systems.fmi.export.flatten import ExportError, flatten
from attitude_fmu.systems.fmi.interface.escaping import c_identifier, fmi_name, xml_text

BACKENDS = ("native", "python")


NAME_MAX = 200  # characters of a model identifier: its files' names (NAME_variables.h, NAME.dll) stay below 255 bytes


def _model_name(system, name: str | None) -> str:
    """The FMU's model identifier: name, or the system's name; ValueError unless a C identifier (no
    keyword) of NAME_MAX characters at most."""
    name = c_identifier(name if name is not None else system.name, "the FMU's name (model identifier; give name=)")
    if len(name) > NAME_MAX:
        raise ValueError(f"the FMU's name (model identifier) has {len(name)} characters; its files' names take "
                         f"{NAME_MAX} at most: give a shorter name=")
    return name


def export_fmu(system, path, *, x0=None, step: float | None = None, fmi_version: str = "2.0",
               platforms: str = "host", name: str | None = None, backend: str = "native",
               cmake_options=(), log=lambda message: None, scalar_parameters: bool = False) -> Path:
    """system (a python-control system) as a co-simulation FMU written to path; returns its path.

    system: a control.StateSpace or TransferFunction (SISO or MIMO; discrete ones step at their dt,
    continuous ones are held by zero-order hold over each communication step), one of the project's
    blocks (estimator_system, offset_system, heading_system, latency_system, ImuModel.system,
    HumanMotion.system, ClosedForm.system, magnetometer_system, attitude_error_system), or a
    control.interconnect of these, nested to any depth. After the doStep that ends at t[k+1], with
    the inputs of sample k held over it, the outputs are the system's outputs at sample k as
    control.input_output_response computes them. A state space's matrices are parameters, changeable
    before initialisation (FMI 3.0: an array each, A; FMI 2.0: a scalar each, A[0,1]; inside a diagram
    prefixed by the block's path, block.A).
    x0: the initial state (python-control's state vector; None: zeros, which for the project's
    blocks means at rest on the first sample); step: the DefaultExperiment's step (s; default the
    system's dt, 0.01 s for a continuous one); a discrete system runs on the grid of its sample time from
    the start time: a communication step runs the samples it reaches, its inputs held, and one that
    reaches none (a master's final shortfall of picoseconds) holds state and outputs;
    fmi_version: "2.0" or "3.0"; platforms: "host", "all" or FMI 3.0 platform tuples
    (systems.fmi.platforms; needs the `platforms` extra); name: the model identifier (default the
    system's name); backend: "native" (C, no Python at run time) or "python" (pythonfmu: any discrete
    system, Python functions included; the FMU needs a Python with attitude_fmu and control where it
    runs); cmake_options: more -D options of the native build (NAME=VALUE: AF_WERROR=ON, warnings as
    errors; AF_SANITIZE=ON, the address and undefined-behaviour sanitizers); log: progress messages;
    scalar_parameters: in FMI 3.0 too, one scalar parameter per matrix entry (A[0,1]) instead of an array per
    matrix, for importers that read every Float64 variable as a scalar (OMSimulator's result file refuses
    an array parameter: "fmi3GetFloat64: 1 values for 1 value references, which hold 9"); FMI 2.0 has
    scalars only.
    ExportError names a block that cannot be exported natively (a Python-function block, an
    algebraic loop) and why; ValueError for bad arguments and for names that cannot go into the FMU's
    files as they are (systems.fmi.interface.escaping): a signal label outside FMI's structured naming
    (a<b: rename it, or quote it, 'a<b'), a name that is no C identifier. Every other text (the
    system's and blocks' names) is escaped where it goes: C string literals, XML, Python literals."""
    from attitude_fmu.systems.fmi.platforms import parse_platforms

    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if fmi_version not in ("2.0", "3.0"):
        raise ValueError(f"fmi_version must be '2.0' or '3.0', got {fmi_version!r}")
    model = _model_name(system, name)
    xml_text(str(system.name), "the system's name")
    for label in (*getattr(system, "input_labels", ()), *getattr(system, "output_labels", ())):
        fmi_name(label)
    path = Path(path)
    if path.suffix != ".fmu":
        raise ValueError(f"the FMU's path must end in .fmu, got {str(path)!r}")
    if not path.parent.is_dir():
        raise ValueError(f"cannot write {path}: no folder {path.parent}")
    if step is not None and not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0):
        raise ValueError(f"step must be a finite positive number of seconds, got {step!r}")
    nstates = system.nstates if hasattr(system, "nstates") else 0
    if x0 is not None:
        x0 = np.asarray(x0, dtype=float).ravel()
        if x0.size != nstates or not np.isfinite(x0).all():
            raise ValueError(f"x0 must hold {nstates} finite values (the system's states), got {x0.size}")
    if backend == "python":
        from attitude_fmu.systems.fmi.export.python import write_python

        return write_python(path, model, system, x0, step, fmi_version)
    diagram = flatten(system)
    if diagram.dt and step is not None and not math.isclose(step, diagram.dt, rel_tol=1e-9):
        raise ValueError(f"{system.name} is discrete with sample time {diagram.dt!r} s: it steps at that, not at "
                         f"{step!r} s")
    from attitude_fmu.systems.fmi.export.native import write_native

    description = (f"python-control system {system.name} exported by attitude_fmu.export_fmu: {len(diagram.blocks)} "
                   f"block(s) in C ({', '.join(sorted({b.kind for b in diagram.blocks}))}), "
                   + (f"sample time {diagram.dt!r} s" if diagram.dt else "continuous, held by zero-order hold"))
    return write_native(path, model, fmi_version, diagram, x0, step or diagram.dt or 0.01, description,
                        parse_platforms(platforms), tuple(cmake_options), log, scalar_parameters)


__all__ = ["ExportError", "export_fmu"]
