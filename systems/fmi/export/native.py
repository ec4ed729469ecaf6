"""A flattened python-control diagram as a native FMU: its C sources staged (the core's, the
simulation's, the FMI plumbing's, the diagram runtime of fmu_src/diagram and models/Diagram.c, and
the generated tables), its binary built by the project's CMake (CMakeLists.txt, AF_EXPORT) for this
platform and any other (cmake/zig.cmake), the folder zipped."""
from __future__ import annotations

import subprocess
import tempfile
import zipfile
from pathlib import Path

from attitude_fmu.systems.fmi.export.flatten import ExportError


def _package_root() -> Path:
    from attitude_fmu.build_fmu import ROOT

    return Path(ROOT)


def source_files(fmi: str) -> dict[str, bytes]:
    """The C sources every exported FMU of that FMI version carries, by their path under sources/:
    the estimator's core (blocks/core), the simulation's (systems/simulation/core), the generated
    parameter tables, the FMI plumbing (FMI 3.0: its entry points on FMI 2.0's, whose own are left
    out), the diagram runtime and its model file."""
    from attitude_fmu.blocks.core import generate_tables

    root, files = _package_root(), {}
    for folder in ("blocks/core", "systems/simulation/core"):
        for path in sorted((root / folder).rglob("*")):
            if path.suffix in (".c", ".h") and "bindings" not in path.relative_to(root / folder).parts:
                files[path.relative_to(root / folder).as_posix()] = path.read_bytes()
    for pattern in ("fmi2/*", "fmi3/*", "diagram/*") if fmi == "3.0" else ("fmi2/*", "diagram/*"):
        for path in sorted((root / "fmu_src").glob(pattern)):
            if path.suffix in (".c", ".h"):
                files[path.relative_to(root / "fmu_src").as_posix()] = path.read_bytes()
    if fmi == "3.0":
        del files["fmi2/functions.c"]
    files["models/Diagram.c"] = (root / "fmu_src" / "models" / "Diagram.c").read_bytes()
    files[generate_tables.HEADER] = generate_tables.header_text().encode("ascii")
    files[generate_tables.PROFILES_HEADER] = generate_tables.profiles_text().encode("ascii")
    return files


def stage_files(name: str, fmi: str, diagram, x0, step: float | None, description: str,
                scalar_parameters: bool = False) -> dict[str, bytes]:
    """The FMU's files but its binaries, by their path in it (systems/fmi/interface/generate.py's generated_files over
    the diagram's variables, scalar ones with scalar_parameters, and tables)."""
    from attitude_fmu.build_fmu import project_version
    from attitude_fmu.systems.fmi.interface.documentation import EXPORTED
    from attitude_fmu.systems.fmi.interface.generate import NativeModel, generated_files
    from attitude_fmu.systems.fmi.export.tables import tables_header, variables

    table, first = variables(diagram, fmi, scalar_parameters)
    sources = source_files(fmi)
    sources["diagram_tables.h"] = tables_header(name, diagram, first, x0).encode("ascii")
    return generated_files(name, fmi, project_version(), sources, NativeModel(lambda: table, description, EXPORTED),
                           step)


def build_binary(stage: Path, name: str, fmi: str, platform: str | None, build_dir: Path, options=()) -> None:
    """The binary of the staged FMU built into stage/binaries/ by CMake in build_dir (with the -D options):
    for this platform (platform None) or another (an FMI 3.0 tuple of systems.fmi.platforms.PLATFORMS,
    with zig's compiler)."""
    from attitude_fmu.build_fmu import cmake_build, project_version
    from attitude_fmu.systems.fmi.platforms import PLATFORMS, TOOLCHAIN

    root = _package_root()
    options = [f"AF_EXPORT={stage}", f"AF_EXPORT_NAME={name}", f"AF_EXPORT_FMI={fmi}", "AF_PYTHON=OFF",
               "AF_FMUS=OFF", f"AF_VERSION={project_version()}", *options]
    if platform is not None:
        options += [f"CMAKE_TOOLCHAIN_FILE={root / TOOLCHAIN}", f"AF_ZIG_TARGET={PLATFORMS[platform][0]}"]
    cmake_build(build_dir, ["af_export"], options, source=root, quiet=True)


def zip_folder(folder: Path, path: Path) -> None:
    """folder's files zipped into path (entries sorted, dated 1980-01-02 as the project's FMUs are) by the
    project's one writer (systems.recordings.output.replaced: complete or not at all)."""
    from attitude_fmu.systems.recordings.output import replaced

    with replaced(path) as fh, zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as zf:
        for file in sorted(p for p in folder.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(file.relative_to(folder).as_posix(), date_time=(1980, 1, 2, 0, 0, 0))
            info.compress_type, info.external_attr = zipfile.ZIP_DEFLATED, 0o644 << 16
            zf.writestr(info, file.read_bytes())


def write_native(path: Path, name: str, fmi: str, diagram, x0, step, description: str, platforms, options=(),
                 log=lambda message: None, scalar_parameters: bool = False) -> Path:
    """The native FMU of the diagram written to path, with the binaries of this platform and the platforms
    (FMI 3.0 tuples; FMI 2.0: those with an FMI 2.0 folder), each built with the -D options; its matrices
    scalar parameters in FMI 3.0 too with scalar_parameters."""
    from attitude_fmu.systems.fmi.interface.generate import write_stage
    from attitude_fmu.systems.fmi.platforms import LIBRARY_SUFFIXES, PLATFORMS

    with tempfile.TemporaryDirectory(prefix="attitude_fmu_export_") as tmp:
        stage = Path(tmp) / "stage"
        write_stage(stage, stage_files(name, fmi, diagram, x0, step, description, scalar_parameters))
        targets = [None] + [p for p in platforms if fmi == "3.0" or PLATFORMS[p][1] is not None]
        for platform in targets:
            log(f"{Path(path).name} (model {name}): building its binary for {platform or 'this platform'}")
            try:
                build_binary(stage, name, fmi, platform, Path(tmp) / f"build-{platform or 'host'}", options)
            except subprocess.CalledProcessError as exc:
                raise ExportError(f"building {name}.fmu for {platform or 'this platform'} failed:\n"
                                  f"{(exc.stdout or '')[-3000:]}{(exc.stderr or '')[-3000:]}") from exc
        for file in (stage / "binaries").rglob("*"):  # the binaries alone, not what a linker left beside them
            if file.is_file() and file.name not in {f"{name}{suffix}" for suffix in LIBRARY_SUFFIXES.values()}:
                file.unlink()
        zip_folder(stage, path)
    return path
