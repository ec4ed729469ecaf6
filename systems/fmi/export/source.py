"""The system `attitude export FILE.py:NAME` names: NAME in the Python file FILE, a python-control
system or a function of no arguments returning one (or a pair (system, x0))."""
from __future__ import annotations

import runpy
from pathlib import Path

from attitude_fmu.systems.fmi.cosim import one_line


def load_system(spec: str):
    """(system, x0 or None) of spec "FILE.py:NAME"; ValueError saying in one line what is wrong with it:
    no such file, a file that fails to run (its exception named) or ends the program (sys.exit), no NAME in
    it, a function NAME that needs arguments or raises, a value that is no python-control system."""
    import control

    file, colon, name = spec.rpartition(":")
    if not colon or not file or not name:
        raise ValueError(f"give the system as FILE.py:NAME (a python-control system, or a function of no arguments "
                         f"returning one, in FILE.py), got {spec!r}")
    path = Path(file)
    if not path.is_file():
        raise ValueError(f"{file}: no such file")
    namespace = _ran(lambda: runpy.run_path(str(path), run_name="__attitude_export__"), f"{file} failed to run")
    if name not in namespace:
        found = sorted(k for k, v in namespace.items() if isinstance(v, control.InputOutputSystem) or
                       (callable(v) and getattr(v, "__module__", None) == "__attitude_export__"))
        raise ValueError(f"{file} defines no {name!r}" + (f"; it defines {', '.join(found)}" if found else ""))
    value = namespace[name]
    if callable(value) and not isinstance(value, control.InputOutputSystem):
        value = _ran(value, f"{name}() in {file} failed")
    system, x0 = value if isinstance(value, tuple) and len(value) == 2 else (value, None)
    if not isinstance(system, control.InputOutputSystem):
        raise ValueError(f"{spec} is a {type(system).__name__}, not a python-control system (or a function of no "
                         f"arguments returning one, or (system, x0))")
    return system, x0


def _ran(call, failed: str):
    """call() of the user's code; its exception, or its attempt to end the program (SystemExit), as a
    ValueError of one line starting with failed."""
    try:
        return call()
    except SystemExit as exc:
        raise ValueError(f"{failed}: it called sys.exit({exc.code!r}); a file given to export defines the "
                         "system without ending the program") from None
    except Exception as exc:
        raise ValueError(f"{failed}: {one_line(exc)}") from None
