"""The native FMUs' binaries for other platforms than this one, cross-compiled by CMake with zig's C
compiler (the `ziglang` package; cmake/zig.cmake) and put into the FMUs built for this one.

    add_platforms(fmus, parse_platforms("all"))    → every FMU of fmus holds the binaries of every platform

PLATFORMS names each platform by its FMI 3.0 platform tuple, with zig's target and the FMI 2.0 binaries
folder. FMI 2.0 names no folder for aarch64 (fmpy, on an aarch64 machine, looks in linux64 and darwin64),
so the FMI 2.0 FMUs carry x86_64 binaries only, and the FMI 3.0 ones every platform's. The Linux
binaries link against glibc 2.17, so they load on every Linux distribution of the last ten years.

Each platform is one CMake build folder, build_root/platform-<tuple> (configured once, with the
toolchain file cmake/zig.cmake and no Python extension), which builds the FMUs' libraries only;
its binaries folders (fmus/fmi<N>/<Name>/binaries/<folder>/) are copied into the FMU of the same
name and FMI version, a binary of the same path replaced (this platform's, where it is one of them).
The FMU's modelDescription.xml and sources are this platform's build's: every build generates the
same from the same sources, and an FMU's binary refuses another guid.
"""
from __future__ import annotations

import os
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from attitude_fmu.systems.fmi.native import NATIVE_NAMES

# FMI 3.0 platform tuple → (zig's target, the FMI 2.0 binaries folder or None: no FMI 2.0 binary)
PLATFORMS = {
    "x86_64-linux": ("x86_64-linux-gnu.2.17", "linux64"),
    "aarch64-linux": ("aarch64-linux-gnu.2.17", None),
    "x86_64-windows": ("x86_64-windows-gnu", "win64"),
    "x86_64-darwin": ("x86_64-macos", "darwin64"),
    "aarch64-darwin": ("aarch64-macos", None),
}
LIBRARY_SUFFIXES = {"linux": ".so", "windows": ".dll", "darwin": ".dylib"}  # by the tuple's system
TOOLCHAIN = "cmake/zig.cmake"


def parse_platforms(text: str) -> list[str]:
    """The platforms named by text: "host" (none besides this one: []), "all" (every one of PLATFORMS),
    or a comma-separated list of FMI 3.0 platform tuples; ValueError for an unknown one."""
    if text == "host":
        return []
    if text == "all":
        return list(PLATFORMS)
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in PLATFORMS]
    if unknown or not names:
        raise ValueError(f"unknown platform {', '.join(unknown) or repr(text)}: give host, all or a comma-separated "
                         f"list of {', '.join(PLATFORMS)}")
    return list(dict.fromkeys(names))


def library_name(name: str, platform: str) -> str:
    """The file name of the FMU name's binary for the platform (an FMI 3.0 platform tuple)."""
    return name + LIBRARY_SUFFIXES[platform.split("-")[1]]


def default_build_root(source: Path) -> Path:
    """Where the platforms' build folders go: the clone's build/ (source a clone), else a folder in the
    user's cache (an installed package's folder may not be writable)."""
    if (source / "pyproject.toml").is_file():
        return source / "build"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "attitude_fmu" / "build"


def cross_build(platform: str, build_root=None, options=(), targets=(), source=None) -> Path:
    """The FMUs' libraries for one platform (and the targets, e.g. tests/fmi_runner of a clone), built
    by CMake with zig's compiler from source (default: the package's folder, or the clone it is) in
    build_root/platform-<platform>; returns that folder. Raises subprocess.CalledProcessError where
    CMake or the compiler fails."""
    from attitude_fmu.build_fmu import ROOT, cmake_build, project_version

    source = Path(source or ROOT)
    zig_target, fmi2 = PLATFORMS[platform]
    folder = Path(build_root or default_build_root(source)) / f"platform-{platform}"
    libraries = [f"{name}_fmi3" for name in NATIVE_NAMES] + ([f"{name}_fmi2" for name in NATIVE_NAMES] if fmi2 else [])
    configure = (f"CMAKE_TOOLCHAIN_FILE={source / TOOLCHAIN}", f"AF_ZIG_TARGET={zig_target}", "AF_PYTHON=OFF",
                 f"AF_VERSION={project_version()}", *options)
    return cmake_build(folder, [*libraries, *targets], configure, source=source)


def binaries(folder: Path, fmi: int, name: str) -> dict[str, Path]:
    """The binaries a build folder made for the FMU name of FMI version fmi (2 or 3): path in the FMU → file."""
    stage = Path(folder) / "fmus" / f"fmi{fmi}" / name
    return {path.relative_to(stage).as_posix(): path for path in sorted(stage.glob("binaries/*/*"))
            if path.name.startswith(name + ".") and path.suffix in LIBRARY_SUFFIXES.values()}


def add_binaries(fmu: Path, files: dict[str, Path]) -> None:
    """The files (path in the FMU → file) written into the FMU at fmu, any entry of the same path replaced;
    the FMU is rewritten whole and replaces the old one at once."""
    from attitude_fmu.systems.recordings.output import replaced

    with zipfile.ZipFile(fmu) as src, replaced(fmu) as fh, zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            if item.filename not in files:
                dst.writestr(item, src.read(item))
        for path in sorted(files):
            info = zipfile.ZipInfo(path, date_time=(1980, 1, 2, 0, 0, 0))
            info.compress_type, info.external_attr = zipfile.ZIP_DEFLATED, 0o755 << 16
            dst.writestr(info, files[path].read_bytes())


def fmi_version(fmu: Path) -> int:
    """The FMU's FMI major version (2 or 3), from its modelDescription.xml."""
    from xml.etree import ElementTree

    with zipfile.ZipFile(fmu) as zf:
        return int(ElementTree.fromstring(zf.read("modelDescription.xml")).get("fmiVersion").split(".")[0])


def add_platforms(fmus, platforms, build_root=None, options=(), log=print, targets=(), source=None) -> dict[str, Path]:
    """The binaries of the platforms (FMI 3.0 tuples, parse_platforms) cross-built (cross_build, with
    the targets, from source; as many platforms at once as there are processors) and put into each
    native FMU of fmus (paths; named by their model identifier); returns each platform's build folder."""
    fmus = [Path(fmu) for fmu in fmus]
    log(f"building the native FMUs' binaries for {', '.join(platforms)}")
    with ThreadPoolExecutor(max_workers=max(1, min(len(platforms), os.cpu_count() or 1))) as pool:
        folders = dict(zip(platforms, pool.map(lambda p: cross_build(p, build_root, options, targets, source),
                                               platforms)))
    for folder in folders.values():
        for fmu in fmus:
            add_binaries(fmu, binaries(folder, fmi_version(fmu), fmu.stem))
    return folders


def platforms_of(fmu: Path) -> set[str]:
    """The binaries folders the FMU at fmu holds a binary of its model identifier in."""
    with zipfile.ZipFile(fmu) as zf:
        parts = [name.split("/") for name in zf.namelist()]
    return {p[1] for p in parts if len(p) == 3 and p[0] == "binaries" and p[2].startswith(Path(fmu).stem + ".")}


def holds_platforms(fmu: Path, platforms) -> bool:
    """Whether the FMU at fmu holds a binary for each of the platforms (FMI 2.0: those it has a folder for)."""
    folders = [platform if fmi_version(fmu) == 3 else PLATFORMS[platform][1] for platform in platforms]
    return {folder for folder in folders if folder} <= platforms_of(fmu)
