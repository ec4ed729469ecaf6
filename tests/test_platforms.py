"""The native FMUs with every platform's binaries (systems.fmi.platforms, cross-compiled by CMake with
zig's compiler): every FMU holds them; each binary's header names its format and architecture and its
export table the FMI functions; the Linux ones need glibc 2.17 at most; the Windows ones, under wine,
and the aarch64 Linux ones, under qemu-user, in a C host built by the same toolchain
(tests/fmi_runner.c), give the outputs of this machine's build under fmpy within 1e-12 on a 30 s
stream. The macOS binaries are checked for format, architecture and exports only. The same for a
python-control diagram exported with every platform's binaries (attitude_fmu.export_fmu).

One cross build per platform for the whole session (build/tests-platforms/platform-<tuple>, warnings
as errors), merged into copies of this machine's FMUs (tests/native.py's build)."""
import io
import os
import re
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from elftools.elf.elffile import ELFFile
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.fmi.native import NATIVE_NAMES
from attitude_fmu.systems.fmi.platforms import PLATFORMS, add_platforms, library_name
from tests import native as c_build

ROOT = Path(__file__).resolve().parent.parent
BUILD_ROOT = ROOT / "build" / "tests-platforms"
OPTIONS = ("AF_WERROR=ON", "AF_TESTS=ON")
RUNNER_PLATFORMS = ("x86_64-windows", "aarch64-linux")  # where the runner runs here: under wine, qemu-user
FMI2_FOLDERS = ("linux64", "win64", "darwin64")
AARCH64_SYSROOT = Path("/usr/aarch64-linux-gnu")  # Debian's libc6-arm64-cross
TOLERANCE = 1e-12
STREAM_S, STEP_S = 30.0, 0.01

pytestmark = pytest.mark.slow  # the cross builds: about a minute with zig's cache warm, five more cold (its C runtimes)


# ---- the builds, once for the session
@pytest.fixture(scope="module")
def host_fmus():
    """This machine's native FMUs (tests/native.py's build): {(name, fmi): path}."""
    built = c_build.build(["fmus"]) / "built" / "native"
    return {(n, fmi): built / ("fmi3" if fmi == 3 else "") / f"{n}.fmu" for n in NATIVE_NAMES for fmi in (2, 3)}


@pytest.fixture(scope="module")
def platform_fmus(host_fmus, tmp_path_factory):
    """Copies of host_fmus with every platform's binaries, and the runner (tests/fmi_runner.c, built for
    every platform) of RUNNER_PLATFORMS: ({(name, fmi): path}, {platform: runner})."""
    pytest.importorskip("ziglang", reason="the cross builds need zig's compiler: pip install ziglang")
    folder = tmp_path_factory.mktemp("platforms")
    fmus = {}
    for (name, fmi), path in host_fmus.items():
        (folder / f"fmi{fmi}").mkdir(exist_ok=True)
        fmus[name, fmi] = Path(shutil.copyfile(path, folder / f"fmi{fmi}" / path.name))
    builds = add_platforms(fmus.values(), list(PLATFORMS), BUILD_ROOT, OPTIONS, log=lambda m: None,
                           targets=["fmi_runner"], source=ROOT)  # the clone: its tests/ hold the runner
    runners = {p: builds[p] / "tests" / ("fmi_runner.exe" if p.endswith("windows") else "fmi_runner")
               for p in RUNNER_PLATFORMS}
    return fmus, runners


# ---- the binaries' headers, read here (no objdump)
def elf_header(data: bytes) -> tuple[str, set[str], list[str]]:
    """An ELF shared library's (architecture, exported function names, GLIBC_ versions it needs)."""
    elf = ELFFile(io.BytesIO(data))
    assert elf.elfclass == 64 and elf["e_type"] == "ET_DYN"
    arch = {"EM_X86_64": "x86_64", "EM_AARCH64": "aarch64"}[elf["e_machine"]]
    exports = {s.name for s in elf.get_section_by_name(".dynsym").iter_symbols()
               if s["st_info"]["bind"] == "STB_GLOBAL" and s["st_info"]["type"] == "STT_FUNC"
               and s["st_shndx"] != "SHN_UNDEF"}
    needed = [aux.name for _, auxes in elf.get_section_by_name(".gnu.version_r").iter_versions() for aux in auxes]
    return arch, exports, [v for v in needed if v.startswith("GLIBC_")]


def _string(data: bytes, offset: int) -> str:
    return data[offset:data.index(b"\0", offset)].decode()


def pe_header(data: bytes) -> tuple[str, set[str]]:
    """A PE32+ DLL's (architecture, names in its export directory)."""
    assert data[:2] == b"MZ"
    pe = struct.unpack_from("<I", data, 0x3C)[0]
    assert data[pe:pe + 4] == b"PE\0\0"
    machine, n_sections, _, _, _, optional_size, characteristics = struct.unpack_from("<HHIIIHH", data, pe + 4)
    optional = pe + 24
    assert struct.unpack_from("<H", data, optional)[0] == 0x20B and characteristics & 0x2000  # PE32+, a DLL
    export_rva = struct.unpack_from("<I", data, optional + 112)[0]  # data directory 0 of PE32+
    sections = [struct.unpack_from("<IIII", data, optional + optional_size + 40 * i + 8) for i in range(n_sections)]

    def offset(rva):
        return next(rva - va + raw for size, va, raw_size, raw in sections if va <= rva < va + max(size, raw_size))

    directory = offset(export_rva)
    n_names, _, names = struct.unpack_from("<III", data, directory + 24)
    exports = {_string(data, offset(struct.unpack_from("<I", data, offset(names) + 4 * i)[0])) for i in range(n_names)}
    return {0x8664: "x86_64", 0xAA64: "aarch64"}[machine], exports


def macho_header(data: bytes) -> tuple[str, set[str]]:
    """A 64-bit Mach-O dylib's (architecture, external symbols defined in a section, as C names)."""
    magic, cpu, _, filetype, n_commands = struct.unpack_from("<IiiII", data, 0)
    assert magic == 0xFEEDFACF and filetype == 6  # MH_MAGIC_64, MH_DYLIB
    at, exports = 32, set()
    for _ in range(n_commands):
        command, size = struct.unpack_from("<II", data, at)
        if command == 0x2:  # LC_SYMTAB
            symbols, n_symbols, strings, _ = struct.unpack_from("<IIII", data, at + 8)
            for k in range(n_symbols):
                name, kind = struct.unpack_from("<IB", data, symbols + 16 * k)
                if kind & 0xE0 == 0 and kind & 0x0E == 0x0E and kind & 0x01:  # no stab, N_SECT, N_EXT
                    exports.add(_string(data, strings + name).removeprefix("_"))
        at += size
    return {0x01000007: "x86_64", 0x0100000C: "aarch64"}[cpu], exports


def standard_functions(fmi: int) -> set[str]:
    """The functions an FMI co-simulation FMU exports, from the standard's header (fmpy's copy): FMI 2.0's
    common and co-simulation ones, FMI 3.0's every one."""
    import fmpy

    text = (Path(fmpy.__file__).parent / "c-code" / f"fmi{fmi}Functions.h").read_text()
    if fmi == 2:  # the model-exchange section left out
        start = text.index("Functions for FMI2 for Model Exchange")
        text = text[:start] + text[text.index("Functions for FMI2 for Co-Simulation", start):]
    return set(re.findall(rf"#define (fmi{fmi}\w+)\s+fmi{fmi}FullName", text))


def folders(fmi: int) -> list[str]:
    """The binaries folders every native FMU of FMI version fmi holds."""
    return list(FMI2_FOLDERS) if fmi == 2 else list(PLATFORMS)


def platform_of(folder: str) -> str:
    """The FMI 3.0 platform tuple of a binaries folder (FMI 2.0's or FMI 3.0's)."""
    return next(p for p, (_, fmi2) in PLATFORMS.items() if folder in (p, fmi2))


def test_every_native_fmu_holds_every_platforms_binary(platform_fmus):
    """FMI 2.0: linux64, win64, darwin64; FMI 3.0: x86_64-linux, aarch64-linux, x86_64-windows,
    x86_64-darwin, aarch64-darwin; each binary named by the model identifier with its system's suffix."""
    fmus, _ = platform_fmus
    for (name, fmi), fmu in fmus.items():
        binaries = {n for n in zipfile.ZipFile(fmu).namelist() if n.startswith("binaries/") and not n.endswith("/")}
        assert binaries == {f"binaries/{f}/{library_name(name, platform_of(f))}" for f in folders(fmi)}, fmu


def test_each_binary_is_its_platforms_format_and_architecture_and_exports_the_fmi_functions(platform_fmus):
    """ELF (Linux), PE32+ DLL (Windows), Mach-O dylib (macOS) of the folder's architecture, whose export
    table holds exactly the standard's functions (FMI 2.0 co-simulation: its common and co-simulation
    ones) among its fmi2*/fmi3* names, and nothing of the model or the C core besides."""
    fmus, _ = platform_fmus
    for (name, fmi), fmu in fmus.items():
        with zipfile.ZipFile(fmu) as zf:
            for folder in folders(fmi):
                platform = platform_of(folder)
                data = zf.read(f"binaries/{folder}/{library_name(name, platform)}")
                system = platform.split("-")[1]
                arch, exports = {"linux": elf_header, "windows": pe_header, "darwin": macho_header}[system](data)[:2]
                assert arch == platform.split("-")[0], (fmu, folder)
                assert {e for e in exports if e.startswith(("fmi2", "fmi3"))} == standard_functions(fmi), (fmu, folder)
                # nothing else but the linker's own names (reserved: a leading underscore, e.g. __dso_handle)
                assert not [e for e in exports if not e.startswith((f"fmi{fmi}", "_"))], (fmu, folder)


def test_the_linux_binaries_need_glibc_2_17_at_most(platform_fmus):
    """No GLIBC_ symbol version newer than 2.17 in .gnu.version_r of any Linux binary (x86_64 and
    aarch64)."""
    fmus, _ = platform_fmus
    for (name, fmi), fmu in fmus.items():
        with zipfile.ZipFile(fmu) as zf:
            for folder in (f for f in folders(fmi) if platform_of(f).endswith("linux")):
                needed = elf_header(zf.read(f"binaries/{folder}/{name}.so"))[2]
                assert needed, (fmu, folder)
                newest = max(tuple(int(x) for x in v.removeprefix("GLIBC_").split(".")) for v in needed)
                assert newest <= (2, 17), (fmu, folder, needed)


# ---- the binaries run: wine and qemu-user, against this machine's build under fmpy
def stream(seed: int = 20) -> dict[str, np.ndarray]:
    """STREAM_S s at STEP_S of a rotating IMU (fixed seed): the true angular rate (mean over each
    step), specific force and field in sensor coordinates, and gyro, accelerometer and magnetometer
    samples of them with noise; rad/s, m/s², µT."""
    rng = np.random.default_rng(seed)
    n = int(round(STREAM_S / STEP_S))
    t = np.arange(n + 1) * STEP_S
    rate = np.column_stack([0.8 * np.sin(2 * np.pi * f * t + p) for f, p in ((0.21, 0.0), (0.13, 1.0), (0.34, 2.0))])
    mean_rate = 0.5 * (rate[1:] + rate[:-1])
    turns = Rotation.from_rotvec(mean_rate * STEP_S)
    attitude = [Rotation.identity()]
    for turn in turns:
        attitude.append(attitude[-1] * turn)
    to_sensor = Rotation.concatenate(attitude[1:]).inv()
    force = to_sensor.apply([0.0, 0.0, 9.81]) + 0.5 * np.sin(np.outer(t[1:], [1.1, 0.7, 1.9]))
    field = to_sensor.apply([0.0, 20.0, -40.0])
    return {"omega": mean_rate, "f": force, "m": field,
            "gyr": mean_rate + 0.002 * rng.standard_normal((n, 3)), "acc": force + 0.05 * rng.standard_normal((n, 3)),
            "mag": field + 0.3 * rng.standard_normal((n, 3)), "t": t[:-1]}


INPUT_GROUPS = {"AttitudeEstimator": ("gyr", "acc", "mag"), "ImuSensor": ("omega", "f", "m"), "MotionProfile": ()}


def interface(fmu: Path) -> tuple[object, list[int], list[int], list[int]]:
    """The FMU's model description and value references of its Real inputs, Real outputs, Boolean outputs."""
    md = read_model_description(str(fmu))
    real = ("Real", "Float64")

    def refs(causality, types):
        return [v.valueReference for v in md.modelVariables if v.causality == causality and v.type in types]
    return md, refs("input", real), refs("output", real), refs("output", ("Boolean",))


def fmpy_replay(fmu: Path, rows: np.ndarray) -> np.ndarray:
    """rows (t, h, inputs) through the FMU's binary for this machine under fmpy: per step, the status
    (0), the Real outputs and the Boolean outputs (1.0, 0.0), as fmi_runner's replay writes them."""
    md, inputs, outputs, booleans = interface(fmu)
    unzipped = extract(str(fmu))
    fmi3 = md.fmiVersion == "3.0"
    slave = (FMU3Slave if fmi3 else FMU2Slave)(guid=md.instantiationToken if fmi3 else md.guid, unzipDirectory=unzipped,
                                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName="ref")
    slave.instantiate()
    if not fmi3:
        slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    set_real, get_real = (slave.setFloat64, slave.getFloat64) if fmi3 else (slave.setReal, slave.getReal)
    table = np.zeros((len(rows), 1 + len(outputs) + len(booleans)))
    for k, (t, h, *u) in enumerate(rows):
        if inputs:
            set_real(inputs, list(u))
        slave.doStep(t, h)
        table[k, 1:1 + len(outputs)] = get_real(outputs)
        table[k, 1 + len(outputs):] = [float(b) for b in slave.getBoolean(booleans)] if booleans else []
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    return table


def runner_replay(command: list[str], fmu: Path, folder: str, rows: np.ndarray, work: Path, path=str,
                  env=None) -> np.ndarray:
    """rows through the FMU's binary of the binaries folder in fmi_runner (command: the runner, behind
    an emulator, in the environment env), paths given to it through path; its replay table."""
    md, inputs, outputs, booleans = interface(fmu)
    unzipped = Path(extract(str(fmu), unzipdir=str(work / "fmu")))
    binary = unzipped / "binaries" / folder / library_name(md.coSimulation.modelIdentifier, platform_of(folder))
    data, out = work / "rows.bin", work / "out.bin"
    np.ascontiguousarray(rows, dtype=float).tofile(data)
    fmi3 = md.fmiVersion == "3.0"
    resources = path(unzipped / "resources") if fmi3 else (unzipped / "resources").as_uri()
    script = [f"load{'3' if fmi3 else ''} {path(binary)}",
              f"instantiate {md.instantiationToken if fmi3 else md.guid} {resources} 0",
              *([] if fmi3 else ["setup"]), "enter", "exit",
              " ".join(map(str, ["replay", path(data), path(out), len(inputs), *inputs, len(outputs), *outputs,
                                 len(booleans), *booleans])),
              "terminate", "free", "unload"]
    (work / "script.txt").write_text("\n".join(script) + "\n")
    proc = subprocess.run([*command, path(work / "script.txt")], capture_output=True, text=True, timeout=600, cwd=work,
                          env=env)
    assert proc.returncode == 0 and f"replay {len(rows)} 0" in proc.stdout, (proc.stdout, proc.stderr[-3000:])
    return np.fromfile(out).reshape(len(rows), -1)


def rows_for(name: str) -> np.ndarray:
    """The stream as replay rows (t, h, inputs) for the FMU name."""
    s = stream()
    return np.column_stack([s["t"], np.full(len(s["t"]), STEP_S), *(s[g] for g in INPUT_GROUPS[name])])


def assert_same(table: np.ndarray, reference: np.ndarray, what) -> None:
    """Every status OK, every Boolean equal, every Real output within TOLERANCE (relative beyond 1)."""
    assert table.shape == reference.shape and not table[:, 0].any(), what
    scale = np.maximum(1.0, np.abs(reference))
    worst = float(np.max(np.abs(table - reference) / scale))
    assert worst <= TOLERANCE, (what, worst)


CASES = [("AttitudeEstimator", 2), ("AttitudeEstimator", 3), ("ImuSensor", 2), ("ImuSensor", 3),
         ("MotionProfile", 2), ("MotionProfile", 3)]


def test_the_cross_built_x86_64_linux_binary_equals_this_machines_under_fmpy(platform_fmus, host_fmus):
    """The glibc 2.17 binary zig built (linux64, x86_64-linux in the merged FMUs) gives this machine's
    compiler's outputs within 1e-12, under fmpy."""
    fmus, _ = platform_fmus
    for name, fmi in CASES:
        rows = rows_for(name)
        assert_same(fmpy_replay(fmus[name, fmi], rows), fmpy_replay(host_fmus[name, fmi], rows), (name, fmi))


@pytest.fixture(scope="module")
def wine(tmp_path_factory):
    """wine (Debian's wine64) and its environment: a prefix of its own for the module, quiet; skips where
    there is none."""
    wine = shutil.which("wine") or shutil.which("wine64")
    if wine is None:
        pytest.skip("no wine: apt-get install wine64 (.ci/run does)")
    return wine, {**os.environ, "WINEDEBUG": "-all", "WINEPREFIX": str(tmp_path_factory.mktemp("wineprefix"))}


def windows_path(path: Path) -> str:
    """A Linux path as wine's Z: drive shows it."""
    return "Z:" + str(Path(path).resolve()).replace("/", "\\")


@pytest.mark.parametrize("name,fmi", CASES)
def test_the_windows_binary_under_wine_equals_this_machines_under_fmpy(platform_fmus, host_fmus, wine, name, fmi,
                                                                       tmp_path):
    """The DLL (win64 / x86_64-windows) in fmi_runner.exe under wine: every output of every step of the
    stream within 1e-12 of this machine's binary under fmpy, every status fmi2OK."""
    fmus, runners = platform_fmus
    command, env = [wine[0], str(runners["x86_64-windows"])], wine[1]
    folder = "win64" if fmi == 2 else "x86_64-windows"
    rows = rows_for(name)
    table = runner_replay(command, fmus[name, fmi], folder, rows, tmp_path, windows_path, env)
    assert_same(table, fmpy_replay(host_fmus[name, fmi], rows), (name, fmi))


@pytest.mark.parametrize("name", NATIVE_NAMES)
def test_the_aarch64_linux_binary_under_qemu_equals_this_machines_under_fmpy(platform_fmus, host_fmus, name, tmp_path):
    """The FMI 3.0 aarch64-linux binary in the aarch64 fmi_runner under qemu-user (with Debian's aarch64
    glibc, libc6-arm64-cross): every output within 1e-12 of this machine's binary under fmpy."""
    qemu = shutil.which("qemu-aarch64")
    if qemu is None or not (AARCH64_SYSROOT / "lib" / "ld-linux-aarch64.so.1").exists():
        pytest.skip("no qemu-aarch64 or no aarch64 glibc: apt-get install qemu-user libc6-arm64-cross (.ci/run does)")
    fmus, runners = platform_fmus
    rows = rows_for(name)
    table = runner_replay([qemu, "-L", str(AARCH64_SYSROOT), str(runners["aarch64-linux"])], fmus[name, 3],
                          "aarch64-linux", rows, tmp_path)
    assert_same(table, fmpy_replay(host_fmus[name, 3], rows), (name, 3))


# ---- a python-control diagram exported with every platform's binaries (attitude_fmu.export_fmu)
@pytest.fixture(scope="module")
def exported_fmus(platform_fmus, tmp_path_factory):
    """The gyro-offset stage and wiener as one diagram (systems.evaluation.bench.exported_estimator), FMI 2.0
    and 3.0, for this machine only and for every platform: {(fmi, "host" | "all"): path}."""
    from attitude_fmu.systems.evaluation.bench import exported_estimator

    fmus = {}
    for fmi in (2, 3):
        for which in ("host", "all"):
            folder = tmp_path_factory.mktemp(f"exported-{which}-fmi{fmi}")
            fmus[fmi, which] = exported_estimator(folder / "ExportedEstimator.fmu", f"{fmi}.0", which)
    return fmus


def exported_rows() -> np.ndarray:
    """The stream as replay rows (t, h, gyr, acc) of the exported diagram, at its own step."""
    s = stream()
    return np.column_stack([s["t"], np.full(len(s["t"]), STEP_S), s["gyr"], s["acc"]])


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_exported_diagram_holds_every_platforms_binary_and_each_runs_as_this_machines(exported_fmus,
                                                                                        platform_fmus, wine, fmi,
                                                                                        tmp_path):
    """Every binaries folder of the FMI version, each binary of its format and architecture exporting the
    standard's functions; the zig-built x86-64 Linux binary under fmpy, the Windows one under wine and (FMI
    3.0) the aarch64 Linux one under qemu-user give this machine's compiler's outputs within 1e-12."""
    fmu, name = exported_fmus[fmi, "all"], "ExportedEstimator"
    with zipfile.ZipFile(fmu) as zf:
        binaries = {n for n in zf.namelist() if n.startswith("binaries/") and not n.endswith("/")}
        assert binaries == {f"binaries/{f}/{library_name(name, platform_of(f))}" for f in folders(fmi)}
        for folder in folders(fmi):
            platform = platform_of(folder)
            header = {"linux": elf_header, "windows": pe_header, "darwin": macho_header}[platform.split("-")[1]]
            arch, exports = header(zf.read(f"binaries/{folder}/{library_name(name, platform)}"))[:2]
            assert arch == platform.split("-")[0]
            assert {e for e in exports if e.startswith(("fmi2", "fmi3"))} == standard_functions(fmi), folder
    rows = exported_rows()
    reference = fmpy_replay(exported_fmus[fmi, "host"], rows)
    assert_same(fmpy_replay(fmu, rows), reference, ("zig x86_64-linux", fmi))
    _, runners = platform_fmus
    (tmp_path / "wine").mkdir()
    table = runner_replay([wine[0], str(runners["x86_64-windows"])], fmu, "win64" if fmi == 2 else "x86_64-windows",
                          rows, tmp_path / "wine", windows_path, wine[1])
    assert_same(table, reference, ("windows", fmi))
    qemu = shutil.which("qemu-aarch64")
    if fmi == 3 and qemu and (AARCH64_SYSROOT / "lib" / "ld-linux-aarch64.so.1").exists():
        (tmp_path / "qemu").mkdir()
        table = runner_replay([qemu, "-L", str(AARCH64_SYSROOT), str(runners["aarch64-linux"])], fmu,
                              "aarch64-linux", rows, tmp_path / "qemu")
        assert_same(table, reference, ("aarch64-linux", fmi))
