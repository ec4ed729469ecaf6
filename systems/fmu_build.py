"""Building the project's FMUs (FMI 2.0 co-simulation) from fmu_src/ with pythonfmu.

Each FMU carries fmu_src/fmu_support.py and the packages blocks/ and systems/ in its
resources, so it runs where only numpy, scipy, control and pythonfmu are installed.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

import blocks
import fmu_src
import systems

FMU_NAMES = ("AttitudeEstimator", "ImuSensor", "MotionProfile")
SOURCE_DIR = Path(fmu_src.__file__).resolve().parent


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
                                                       needsExecutionTool="false")))
        finally:
            sys.path.remove(str(SOURCE_DIR))
    return built


def ensure_built(fmu_dir, rebuild: bool = False, log=print) -> Path:
    """The directory holding every FMU, building those missing (or all with rebuild)."""
    fmu_dir = Path(fmu_dir)
    missing = [n for n in FMU_NAMES if rebuild or not (fmu_dir / f"{n}.fmu").is_file()]
    if missing:
        log(f"building {', '.join(missing)} into {fmu_dir}")
        build(fmu_dir, missing)
    return fmu_dir
