"""The system `attitude export FILE.py:NAME` names: NAME in the Python file FILE, a python-control
system or a function of no arguments returning one (or a pair (system, x0))."""
from __future__ import annotations

import runpy
from pathlib import Path


def load_system(spec: str):
    """(system, x0 or None) of spec "FILE.py:NAME"; ValueError saying what is wrong with it."""
    import control

    file, colon, name = spec.rpartition(":")
    if not colon or not file or not name:
        raise ValueError(f"give the system as FILE.py:NAME (a python-control system, or a function of no arguments "
                         f"returning one, in FILE.py), got {spec!r}")
    path = Path(file)
    if not path.is_file():
        raise ValueError(f"{file}: no such file")
    namespace = runpy.run_path(str(path), run_name="__attitude_export__")
    if name not in namespace:
        found = sorted(k for k, v in namespace.items() if isinstance(v, control.InputOutputSystem) or
                       (callable(v) and getattr(v, "__module__", None) == "__attitude_export__"))
        raise ValueError(f"{file} defines no {name!r}" + (f"; it defines {', '.join(found)}" if found else ""))
    value = namespace[name]
    if callable(value) and not isinstance(value, control.InputOutputSystem):
        value = value()
    system, x0 = value if isinstance(value, tuple) and len(value) == 2 else (value, None)
    if not isinstance(system, control.InputOutputSystem):
        raise ValueError(f"{spec} is a {type(system).__name__}, not a python-control system (or a function of no "
                         f"arguments returning one, or (system, x0))")
    return system, x0
