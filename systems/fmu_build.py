"""Building the project's FMUs (FMI 2.0 co-simulation) from fmu_src/ with pythonfmu.

Each FMU carries fmu_src/fmu_support.py and the packages blocks/ and systems/ in its
resources, so it runs where only numpy, scipy, control and pythonfmu are installed.

On Linux (and macOS, not yet tried there) the FMU's binary is fmu_src/fmi2_guard.c,
compiled here with the C compiler ($CC, else Python's, else cc); it loads pythonfmu's library from beside it and
gives the FMI status codes their meaning (a logged error ends the call in fmi2Error); in an
importer without Python it first starts the interpreter recorded by python_environment.
Without a compiler the FMUs keep pythonfmu's binary, and a warning says what that costs.
"""
from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import site
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

import blocks
import fmu_src
import systems
from fmu_src.fmu_support import code_digest

FMU_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")
SOURCE_DIR = Path(fmu_src.__file__).resolve().parent
FINGERPRINT = "resources/attitude_fmu_sources.sha256"  # in the FMU: the sources it was built from
PYTHON_ENVIRONMENT = "resources/python_environment.txt"  # in the FMU: see python_environment


def source_fingerprint(name: str) -> str:
    """SHA-256 over the sources an FMU is built from: its fmu_src module, fmu_support.py,
    fmi2_guard.c and the packages blocks/ and systems/ (fmu_support.code_digest)."""
    digest = hashlib.sha256()
    for path in (SOURCE_DIR / f"{name}.py", SOURCE_DIR / "fmu_support.py", SOURCE_DIR / "fmi2_guard.c"):
        digest.update(f"{path.name}\0".encode())
        digest.update(path.read_bytes())
    digest.update(code_digest(Path(blocks.__file__).resolve().parent.parent).encode())
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


def built_from(fmu) -> str | None:
    """The source fingerprint stored in the FMU at its build; None if it has none."""
    try:
        with zipfile.ZipFile(fmu) as zf:
            return zf.read(FINGERPRINT).decode().strip()
    except (KeyError, OSError, zipfile.BadZipFile):
        return None


def build(out, names=FMU_NAMES) -> list[Path]:
    """Build the named FMUs into the directory out; returns their paths."""
    from pythonfmu.builder import FmuBuilder

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    built = []
    with tempfile.TemporaryDirectory(prefix="attitude_fmu_") as tmp:
        staged = [Path(shutil.copy2(SOURCE_DIR / "fmu_support.py", tmp))]
        for package in (blocks, systems):  # without caches: no compiled files travel
            source = Path(package.__file__).resolve().parent
            staged.append(Path(shutil.copytree(source, Path(tmp) / source.name,
                                               ignore=shutil.ignore_patterns("__pycache__", "*.py[cod]"))))
        sys.path.insert(0, str(SOURCE_DIR))
        try:
            for name in names:
                built.append(Path(FmuBuilder.build_FMU(SOURCE_DIR / f"{name}.py", dest=out, project_files=staged,
                                                       needsExecutionTool="false", canGetAndSetFMUstate="true",
                                                       canSerializeFMUstate="true")))
        finally:
            sys.path.remove(str(SOURCE_DIR))
        guard = compile_guard(Path(tmp) / "fmi2_guard.so")
        for path in built:
            if guard is not None:
                install_guard(path, guard)
            with zipfile.ZipFile(path, "a", zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(FINGERPRINT, source_fingerprint(path.stem) + "\n")
                zf.writestr(PYTHON_ENVIRONMENT, python_environment())
    return built


GUARD_PLATFORMS = {"linux": "linux64", "darwin": "darwin64"}  # sys.platform prefix → FMI binaries folder
PYTHONFMU_LIBRARY = "pythonfmu-export.so"  # the name fmi2_guard.c loads


def guard_platform() -> str | None:
    """The FMI binaries folder the guard is built for on this machine; None: no guard here."""
    return next((v for k, v in GUARD_PLATFORMS.items() if sys.platform.startswith(k)), None)


def compile_guard(out: Path, log=lambda m: print(m, file=sys.stderr)) -> Path | None:
    """Compile fmi2_guard.c into the shared library out; None (with a warning) where it cannot be."""
    platform = guard_platform()
    cc = shlex.split(os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc")
    command = [*cc, "-shared", "-fPIC", "-O2", "-fvisibility=hidden", "-o", str(out),
               str(SOURCE_DIR / "fmi2_guard.c"), "-ldl", "-lpthread"]
    consequence = ("the FMUs keep pythonfmu's own binary: an invalid parameter ends in fmi2Discard "
                   "instead of fmi2Error, and log messages need debug logging on")
    if platform is None:
        log(f"warning: no FMI guard for platform {sys.platform}; {consequence}")
        return None
    try:
        subprocess.run(command, check=True, capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError) as exc:
        detail = getattr(exc, "stderr", None) or exc
        log(f"warning: cannot compile fmi2_guard.c ({shlex.join(command)}: {detail}); {consequence}")
        return None
    return out


def install_guard(fmu: Path, guard: Path) -> None:
    """Make guard the FMU's binary for this platform, pythonfmu's library its PYTHONFMU_LIBRARY."""
    platform = guard_platform()
    suffix = ".dylib" if platform == "darwin64" else ".so"
    binary = f"binaries/{platform}/{fmu.stem}{suffix}"
    staged = fmu.with_suffix(".guarded")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(staged, "w", zipfile.ZIP_DEFLATED) as dst:
        if binary not in src.namelist():
            raise RuntimeError(f"{fmu} has no {binary} to guard")
        for item in src.infolist():
            name = item.filename
            if name == binary:
                name = f"binaries/{platform}/{PYTHONFMU_LIBRARY}"
                dst.write(guard, binary)
            dst.writestr(name if name != item.filename else item, src.read(item))
    staged.replace(fmu)


def ensure_built(fmu_dir, rebuild: bool = False, log=print) -> Path:
    """The directory holding every FMU, building those missing or built from other sources
    than this installation's (or all with rebuild): FMUs loaded into one process share the
    first-loaded copy of the project's modules, so the ones run must match the code."""
    fmu_dir = Path(fmu_dir)
    missing = [n for n in FMU_NAMES if rebuild or not (fmu_dir / f"{n}.fmu").is_file()]
    stale = [n for n in FMU_NAMES if n not in missing and built_from(fmu_dir / f"{n}.fmu") != source_fingerprint(n)]
    if missing:
        log(f"building {', '.join(missing)} into {fmu_dir}")
    if stale:
        log(f"rebuilding {', '.join(stale)} in {fmu_dir}: built from other sources than these")
    if missing or stale:
        build(fmu_dir, [n for n in FMU_NAMES if n in missing or n in stale])
    return fmu_dir
