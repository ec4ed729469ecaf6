"""export_fmu's backend "python": a discrete python-control system as a pythonfmu FMU (fmu_src/PythonSystem.py),
with the project's guard as its binary as the project's own pythonfmu FMUs (systems.fmi.build.guarded)."""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from attitude_fmu.systems.fmi.interface.escaping import python_identifier, python_literal

SYSTEM_FILE = "system.pickle"  # in the FMU's resources: (system, x0, dt), which fmu_src/PythonSystem.py loads


def script_text(name: str, title: str) -> str:
    """The pythonfmu script of the model name (a Python identifier, no keyword): class name, a PythonSystem,
    whose docstring names the system title (any text: a Python string literal, escaping.python_literal)."""
    return (f"from attitude_fmu.fmu_src.PythonSystem import PythonSystem\n\n\n"
            f"class {python_identifier(name, 'the model identifier')}(PythonSystem):\n"
            f"    {python_literal(f'python-control system {title}, exported by attitude_fmu.')}\n")


def write_python(path: Path, name: str, system, x0, step, fmi_version: str) -> Path:
    """The pythonfmu FMU name of the discrete system (initial state x0, None: zeros) written to path."""
    import cloudpickle
    from pythonfmu.builder import FmuBuilder

    from attitude_fmu.systems.fmi.build import guard_binary, guarded
    from attitude_fmu.systems.recordings.output import copy_file

    if fmi_version != "2.0":
        raise ValueError("backend='python' builds FMI 2.0 FMUs only (pythonfmu)")
    dt = system.dt
    if dt is True or not dt:
        raise ValueError(f"backend='python' exports discrete systems with a sample time; {system.name} has dt={dt!r}")
    if step is not None and not np.isclose(step, dt, rtol=1e-9, atol=0):
        raise ValueError(f"{system.name} is discrete with sample time {dt!r} s: it steps at that, not at {step!r} s")
    x0 = np.zeros(system.nstates) if x0 is None else np.asarray(x0, dtype=float)
    with tempfile.TemporaryDirectory(prefix="attitude_fmu_export_") as tmp:
        script = Path(tmp) / f"{name}.py"
        script.write_text(script_text(name, system.name), encoding="utf-8")
        (Path(tmp) / SYSTEM_FILE).write_bytes(cloudpickle.dumps((system, x0, float(dt))))
        built = FmuBuilder.build_FMU(script, dest=Path(tmp) / "out", project_files=[Path(tmp) / SYSTEM_FILE],
                                     needsExecutionTool="false", canGetAndSetFMUstate="true",
                                     canSerializeFMUstate="true")
        guarded(Path(built), guard_binary())
        return copy_file(built, path)
