"""The attitude_fmu code a pythonfmu FMU carries in its resources: the digest the build takes of it
(systems.fmi.build) and the check, when the FMU is instantiated (fmu_src/fmu_support.py), that the code
its process runs is the FMU's own. Only the standard library is imported."""
from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import sys
from pathlib import Path

PACKAGE = "attitude_fmu"  # the modules of it an FMU imports are in its resources, under this name
_file_digests: dict[Path, str] = {}  # source file → SHA-256 of its contents, taken the first time it is read


def code_digest(root, files) -> str:
    """SHA-256 over the files (paths relative to the folder root): their paths and contents;
    a file root does not have counts as empty."""
    root = Path(root)
    digest = hashlib.sha256()
    for relative in sorted(files):
        digest.update(f"{relative}\0".encode())
        path = root / relative
        digest.update(path.read_bytes() if path.is_file() else b"\0missing")
    return digest.hexdigest()


def _file_digest(path: Path) -> str | None:
    """The digest of a source file's contents, remembered: an importer may delete an FMU's
    folder when it is done with it while its modules stay loaded. None: gone unread."""
    if path not in _file_digests:
        if not path.is_file():
            return None
        _file_digests[path] = hashlib.sha256(path.read_bytes()).hexdigest()
    return _file_digests[path]


def _origin(module: str) -> Path | None:
    """The file this process runs a module from: the loaded one, else the one an import would load."""
    loaded = sys.modules.get(module)
    if loaded is not None:
        return Path(loaded.__file__).resolve() if getattr(loaded, "__file__", None) else None
    try:
        spec = importlib.util.find_spec(module)
    except ImportError:
        return None
    return Path(spec.origin).resolve() if spec is not None and spec.origin else None


def foreign_code(resources) -> str | None:
    """Why an FMU whose resources folder is resources cannot run in this process, or None.

    An FMU carries the modules of attitude_fmu it imports (sources, and the extension
    module's library), as packages without an __init__.py (namespace packages), so that
    FMUs of one build loaded into one process (each carrying its own part) share one
    package. Python keeps one copy of a module per process: if a module was imported from
    other sources (an FMU of another build, an installed attitude_fmu of another version),
    this FMU would run that code; it is refused instead."""
    if resources is None:
        return None
    own_root = Path(resources) / PACKAGE
    for path in sorted(own_root.rglob("*")):
        suffix = next((s for s in (".py", *importlib.machinery.EXTENSION_SUFFIXES) if path.name.endswith(s)), None)
        if suffix is None:
            continue
        module = ".".join((PACKAGE, *path.relative_to(own_root).parent.parts, path.name[: -len(suffix)]))
        origin = _origin(module)
        if origin is None or origin == path.resolve():
            continue
        theirs = _file_digest(origin)
        if theirs is not None and theirs != _file_digest(path.resolve()):
            return (f"this FMU's code differs from the attitude-fmu code this process imported before it ({module} "
                    f"from {origin}); "
                    "a process holds one copy of it: run FMUs of one build together, or each in a process of its own")
    return None
