"""Building the project's FMUs (FMI 2.0 co-simulation): those of fmu_src/ with pythonfmu
into DIR/; the native ones, in C with no Python, which the package's build made
(systems.fmi.native), copied into DIR/native/, the native estimator as FMI 3.0 co-simulation
(systems.fmi.fmi3) into DIR/native/fmi3/; with platforms, the native FMUs with the binaries of other
platforms too (systems.fmi.platforms).

Each pythonfmu FMU carries in its resources the modules of attitude_fmu that its fmu_src
adapter imports (carried_files), the compiled extension attitude_fmu._core among them, so it
runs where only numpy, scipy, control and pythonfmu are installed, and carries no command
line, plots, benchmarks or build code; its packages have no __init__.py there, so that FMUs
of one build share them (carried_code.foreign_code).

On Linux (and macOS, not yet tried there) the FMU's binary is fmu_src/fmi2_guard.c as the
package's build made it (built/fmi2_guard.so); it loads pythonfmu's library from beside it and
gives the FMI status codes their meaning (a logged error ends the call in fmi2Error); in an
importer without Python it first starts the interpreter recorded by python_environment.
Where the guard is not built the FMUs keep pythonfmu's binary, and a warning says what that costs.
"""
from __future__ import annotations

import ast
import hashlib
import importlib.machinery
import json
import shutil
import site
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

import attitude_fmu
from attitude_fmu.build_fmu import project_version
from attitude_fmu.systems.fmi.interface.documentation import write_documentation
from attitude_fmu.systems.fmi.carried_code import PACKAGE, code_digest
from attitude_fmu.systems.fmi import fmi3, platforms as cross
from attitude_fmu.systems.fmi.native import NATIVE_NAMES, NotBuilt, built, copy_fmus, is_current
from attitude_fmu.systems.recordings.output import copy_file, replaced

FMU_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")
PACKAGE_DIR = Path(attitude_fmu.__file__).resolve().parent
SOURCE_DIR = PACKAGE_DIR / "fmu_src"
FINGERPRINT = "resources/attitude_fmu_sources.sha256"  # in the FMU: the sources it was built from
PYTHON_ENVIRONMENT = "resources/python_environment.txt"  # in the FMU: see python_environment
VARIABLE_TYPES = "resources/variable_types.txt"  # in the FMU: see variable_types


def _module_file(module: str) -> Path | None:
    """The file of an attitude_fmu module or package (dotted name): its source, or a compiled
    extension module's library (attitude_fmu._core); None if there is none."""
    parts = module.split(".")[1:]
    package = PACKAGE_DIR.joinpath(*parts, "__init__.py")
    if package.is_file():
        return package
    if not parts:
        return None
    stem = PACKAGE_DIR.joinpath(*parts)
    return next((path for suffix in (".py", *importlib.machinery.EXTENSION_SUFFIXES)
                 if (path := stem.with_name(stem.name + suffix)).is_file()), None)


def _imports(path: Path, module: str) -> set[str]:
    """The attitude_fmu modules the file of module imports anywhere in it (functions
    included), except under `if TYPE_CHECKING:`; `from package import name` counts the
    submodule name where there is one, else the package. An extension module imports none."""
    if path.suffix != ".py":
        return set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skipped = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING"
               for child in node.body for n in ast.walk(child)}
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == PACKAGE)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            if base.split(".")[0] != PACKAGE:
                continue
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if _module_file(f"{base}.{alias.name}") else base)
    return found


def adapter_description(name: str) -> str:
    """The description of the adapter fmu_src/<name>.py's class name (its `description = ...`, a string
    literal), read without importing it."""
    tree = ast.parse((SOURCE_DIR / f"{name}.py").read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef) and node.name == name:
            for item in node.body:
                if isinstance(item, ast.Assign) and [ast.unparse(t) for t in item.targets] == ["description"]:
                    return ast.literal_eval(item.value)
    raise ValueError(f"fmu_src/{name}.py: class {name} states no description")


def carried_files(name: str) -> list[str]:
    """Paths, relative to the package folder, of the modules the adapter fmu_src/<name>.py
    (an FMU's top-level module) imports, directly or through others, with the __init__.py
    of every package on the way."""
    adapter = SOURCE_DIR / f"{name}.py"
    todo, seen = sorted(_imports(adapter, name)), set()
    while todo:
        module = todo.pop()
        parts = module.split(".")
        for i in range(1, len(parts) + 1):  # a module's packages are imported with it
            prefix = ".".join(parts[:i])
            if prefix not in seen and _module_file(prefix) is not None:
                seen.add(prefix)
                todo.extend(_imports(_module_file(prefix), prefix))
    return sorted(_module_file(m).relative_to(PACKAGE_DIR).as_posix() for m in seen)


def source_fingerprint(name: str) -> str:
    """SHA-256 over what an FMU is built from: its adapter, the modules it carries
    (carried_files, the extension module's library included) and the guard's binary (guard_binary)."""
    digest = hashlib.sha256(code_digest(PACKAGE_DIR, [f"fmu_src/{name}.py", *carried_files(name)]).encode())
    guard = guard_binary(log=lambda message: None)
    digest.update(guard.read_bytes() if guard is not None else b"\0no guard")
    return digest.hexdigest()


def python_environment() -> str:
    """What fmi2_guard.c starts Python from in a host without it: the path of this
    interpreter's shared libpython (empty where LIBDIR has none, e.g. a statically linked
    interpreter whose distribution ships the library apart), its soname (looked up on the
    library path), and the folders of this environment's packages as a list literal (put
    first on sys.path)."""
    soname = sysconfig.get_config_var("INSTSONAME") or ""
    library = Path(sysconfig.get_config_var("LIBDIR") or "") / soname if soname else None
    folders = [p for p in dict.fromkeys(site.getsitepackages() + [site.getusersitepackages()]) if Path(p).is_dir()]
    return f"{library if library and library.is_file() else ''}\n{soname}\n{json.dumps(folders)}\n"


def variable_types(model_description: bytes) -> str:
    """What fmi2_guard.c checks value references against: one line with the type of value
    reference 0, 1, ... (R Real, I Integer or Enumeration: both set and got as fmi2Integer, B Boolean,
    S String; - none)."""
    from xml.etree import ElementTree

    letters = {"Real": "R", "Integer": "I", "Enumeration": "I", "Boolean": "B", "String": "S"}
    types = {}
    for variable in ElementTree.fromstring(model_description).iter("ScalarVariable"):
        types[int(variable.get("valueReference"))] = next(letters[c.tag] for c in variable if c.tag in letters)
    return "".join(types.get(vr, "-") for vr in range(max(types, default=-1) + 1)) + "\n"


def built_from(fmu) -> str | None:
    """The source fingerprint stored in the FMU at its build; None if it has none."""
    try:
        with zipfile.ZipFile(fmu) as zf:
            return zf.read(FINGERPRINT).decode().strip()
    except (KeyError, OSError, zipfile.BadZipFile):
        return None


def build_fmus(out, names=FMU_NAMES, native=NATIVE_NAMES, fmi3_names=fmi3.FMI3_NAMES, platforms=()) -> list[Path]:
    """Build the named pythonfmu FMUs into the directory out, and copy the named native ones
    into out/native and the named FMI 3.0 ones into out/native/fmi3 (none where the package's
    build did not make them: a warning says so), with the binaries of the platforms (FMI 3.0
    tuples, systems.fmi.platforms.add_platforms) added to those; returns their paths. Each FMU is
    made in a temporary folder and written into out whole (systems.recordings.output.replaced): an
    interrupted or failed build leaves out's files as they were."""
    from pythonfmu.builder import FmuBuilder

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    built_fmus = []
    guard = guard_binary() if names else None
    with tempfile.TemporaryDirectory(prefix="attitude_fmu_") as tmp:
        for name in names:
            # only what the adapter imports, as namespace packages (carried_code.foreign_code)
            staged = Path(tmp) / name / PACKAGE
            for relative in (f for f in carried_files(name) if not f.endswith("__init__.py")):
                (staged / relative).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(PACKAGE_DIR / relative, staged / relative)
            documentation = write_documentation(Path(tmp) / name / "documentation", name, adapter_description(name),
                                                project_version())
            path = Path(FmuBuilder.build_FMU(SOURCE_DIR / f"{name}.py", dest=Path(tmp) / "out",
                                             project_files=[staged], documentation_folder=documentation,
                                             needsExecutionTool="false", canGetAndSetFMUstate="true",
                                             canSerializeFMUstate="true"))
            guarded(path, guard)
            with zipfile.ZipFile(path, "a", zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(FINGERPRINT, source_fingerprint(path.stem) + "\n")
            built_fmus.append(copy_file(path, out / path.name))
    copied = copy_fmus(out / "native", native) + fmi3.copy_fmi3_fmus(out / "native" / "fmi3", fmi3_names)
    if platforms and copied:
        cross.add_platforms(copied, platforms, log=lambda m: print(m, file=sys.stderr))
    return built_fmus + copied


GUARD_PLATFORMS = {"linux": "linux64", "darwin": "darwin64"}  # sys.platform prefix → FMI binaries folder
PYTHONFMU_LIBRARY = "pythonfmu-export.so"  # the name fmi2_guard.c loads


def guard_platform() -> str | None:
    """The FMI binaries folder the guard is built for on this machine; None: no guard here."""
    return next((v for k, v in GUARD_PLATFORMS.items() if sys.platform.startswith(k)), None)


def guard_binary(log=lambda m: print(m, file=sys.stderr)) -> Path | None:
    """fmi2_guard.c as the package's build made it (built/fmi2_guard.so); None (with a warning)
    where there is none for this platform."""
    consequence = ("the FMUs keep pythonfmu's own binary: an invalid parameter ends in fmi2Discard "
                   "instead of fmi2Error, and log messages need debug logging on")
    if guard_platform() is None:
        log(f"warning: no FMI guard for platform {sys.platform}; {consequence}")
        return None
    try:
        return built("fmi2_guard.so")
    except NotBuilt as exc:
        log(f"warning: {exc}; {consequence}")
        return None


def install_guard(fmu: Path, guard: Path) -> None:
    """Make guard the FMU's binary for this platform, pythonfmu's library its PYTHONFMU_LIBRARY."""
    platform = guard_platform()
    suffix = ".dylib" if platform == "darwin64" else ".so"
    binary = f"binaries/{platform}/{fmu.stem}{suffix}"
    with zipfile.ZipFile(fmu) as src, replaced(fmu) as fh, zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as dst:
        if binary not in src.namelist():
            raise RuntimeError(f"{fmu} has no {binary} to guard")
        for item in src.infolist():
            name = item.filename
            if name == binary:
                name = f"binaries/{platform}/{PYTHONFMU_LIBRARY}"
                dst.write(guard, binary)
            dst.writestr(name if name != item.filename else item, src.read(item))


def guarded(fmu: Path, guard: Path | None) -> None:
    """A pythonfmu FMU made the project's: guard (guard_binary; None: pythonfmu's own binary kept) its
    binary, the interpreter it starts in a host without Python (python_environment) and its variables'
    types (variable_types) in its resources."""
    if guard is not None:
        install_guard(fmu, guard)
    with zipfile.ZipFile(fmu, "a", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(PYTHON_ENVIRONMENT, python_environment())
        zf.writestr(VARIABLE_TYPES, variable_types(zf.read("modelDescription.xml")))


def ensure_built(fmu_dir, rebuild: bool = False, log=print, platforms=()) -> Path:
    """The directory holding every FMU, building those missing or built from other sources
    than this installation's (or all with rebuild): FMUs loaded into one process share the
    first-loaded copy of the project's modules, so the ones run must match the code; a
    native FMU is current where its guid is that of the package's (systems.fmi.native.is_current)
    and it holds the binaries of the platforms (FMI 3.0 tuples: systems.fmi.platforms)."""
    fmu_dir = Path(fmu_dir)
    names = {n: fmu_dir / f"{n}.fmu" for n in FMU_NAMES}
    names.update({f"native/{n}": fmu_dir / "native" / f"{n}.fmu" for n in NATIVE_NAMES})
    names.update({f"native/fmi3/{n}": fmu_dir / "native" / "fmi3" / f"{n}.fmu" for n in fmi3.FMI3_NAMES})
    missing = [n for n, path in names.items() if rebuild or not path.is_file()]
    stale = [n for n, path in names.items() if n not in missing and not (
        fmi3.is_current(path) and cross.holds_platforms(path, platforms) if n.startswith("native/fmi3/")
        else is_current(path) and cross.holds_platforms(path, platforms) if n.startswith("native/")
        else built_from(path) == source_fingerprint(n))]
    if missing:
        log(f"building {', '.join(missing)} into {fmu_dir}")
    if stale:
        log(f"rebuilding {', '.join(stale)} in {fmu_dir}: built from other sources than these")
    todo = set(missing) | set(stale)
    if todo:
        build_fmus(fmu_dir, [n for n in FMU_NAMES if n in todo], [n for n in NATIVE_NAMES if f"native/{n}" in todo],
                   [n for n in fmi3.FMI3_NAMES if f"native/fmi3/{n}" in todo], platforms)
    return fmu_dir
