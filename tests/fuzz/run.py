"""The fuzz targets of the FMU states' deserialiser (tests/fuzz/fuzz_state.c, one per model) run for a
bounded time from the corpus tests/fuzz/corpus/<Model>, with the address and undefined-behaviour
sanitizers: under libFuzzer where clang has it (CMake option AF_FUZZ), else (libfuzzer=False, or no
clang) the targets' own driver built by the C compiler with AF_SANITIZE (seeded mutations: bytes
flipped, fields set to edge values, inputs cut short). Half the inputs are consistent forgeries (the
case byte's bit 6: the models' clocks made to agree with their counts); each input has 20 s at most
(libFuzzer's -timeout, the driver's CALL_LIMIT), so a hang is a finding.

    python -m tests.fuzz.run SECONDS [--driver]    SECONDS per model; exit 1 on a finding

Each run is reported as "<model>: <executions> runs in <s> s, <findings> findings"; a finding is a
libFuzzer artifact (crash, leak, timeout, out of memory) or, for the driver, a sanitizer's report or
an abort (a refused state that changed the instance)."""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from tests import native

MODELS = ("AttitudeEstimator", "ImuSensor", "MotionProfile")
CORPUS = Path(__file__).resolve().parent / "corpus"
MAX_LEN = 65536  # bytes of an input: the largest state (ImuSensor's, its delay line) and then some


@dataclass
class Run:
    model: str
    runs: int
    seconds: float
    findings: list

    def __str__(self):
        return f"{self.model}: {self.runs} runs in {self.seconds:.0f} s, {len(self.findings)} findings"


def build(libfuzzer: bool | None) -> tuple[Path, bool]:
    """The three fuzz targets built: (the folder of the executables, whether they are libFuzzer's).
    libFuzzer's with clang (cmake/clang.cmake, AF_FUZZ), where CMake finds clang with libFuzzer (None:
    the driver's otherwise; True: required); else (False, or none found) their own driver's, built
    with AF_SANITIZE by tests/native.py."""
    from attitude_fmu.build_fmu import cmake_build

    targets = [f"fuzz_state_{m}" for m in MODELS]
    if libfuzzer is not False:
        folder = native.ROOT / "build" / "fuzz"
        options = (f"CMAKE_TOOLCHAIN_FILE={native.ROOT / 'cmake' / 'clang.cmake'}", "AF_WERROR=ON", "AF_FUZZ=ON",
                   "AF_PYTHON=OFF")
        try:
            cmake_build(folder, targets, options, source=native.ROOT)
            return folder / "tests", True
        except subprocess.CalledProcessError:
            if libfuzzer:
                raise
            shutil.rmtree(folder, ignore_errors=True)  # a configuration that failed is not kept
            print("tests.fuzz.run: no clang with libFuzzer (Debian: clang libclang-rt-dev): the targets' own driver",
                  file=sys.stderr)
    return native.build(targets, sanitize=True) / "tests", False


def run_libfuzzer(binary: Path, model: str, seconds: float, work: Path) -> Run:
    fresh = work / model
    fresh.mkdir()
    command = [str(binary), f"-max_total_time={int(seconds)}", f"-max_len={MAX_LEN}", "-timeout=20",
               "-print_final_stats=1", f"-artifact_prefix={work}/{model}-", str(fresh), str(CORPUS / model)]
    start = time.monotonic()
    proc = subprocess.run(command, capture_output=True, text=True, timeout=seconds + 300)
    elapsed = time.monotonic() - start
    runs = re.search(r"stat::number_of_executed_units:\s*(\d+)", proc.stderr)
    findings = sorted(str(p) for p in work.glob(f"{model}-*"))
    if proc.returncode != 0 and not findings:
        findings = [proc.stderr[-3000:]]
    return Run(model, int(runs.group(1)) if runs else 0, elapsed, findings)


def run_driver(binary: Path, model: str, seconds: float, seed: int = 1) -> Run:
    inputs = sorted(str(p) for p in (CORPUS / model).iterdir())
    env = {**os.environ, "ASAN_OPTIONS": "detect_leaks=1", "UBSAN_OPTIONS": "print_stacktrace=1"}
    start = time.monotonic()
    proc = subprocess.run([str(binary), str(seconds), str(seed), *inputs], capture_output=True, text=True,
                          timeout=seconds + 300, env=env)
    elapsed = time.monotonic() - start
    runs = re.search(r"runs (\d+)", proc.stdout)
    reports = [r for r in ("runtime error", "Sanitizer", "fuzz_state:") if r in proc.stderr]
    hung = ["an input ran longer than the driver's CALL_LIMIT (SIGALRM)"] if proc.returncode == -signal.SIGALRM else []
    findings = hung + ([proc.stderr[-3000:]] if proc.returncode != 0 or reports else [])
    return Run(model, int(runs.group(1)) if runs else 0, elapsed, findings)


def fuzz(seconds: float, libfuzzer: bool | None = None) -> list[Run]:
    """Every model's target for seconds from its corpus: libFuzzer's where available (None: where clang
    has it), else the driver's."""
    folder, libfuzzer = build(libfuzzer)
    with tempfile.TemporaryDirectory() as work:
        return [run_libfuzzer(folder / f"fuzz_state_{m}", m, seconds, Path(work)) if libfuzzer
                else run_driver(folder / f"fuzz_state_{m}", m, seconds) for m in MODELS]


if __name__ == "__main__":
    results = fuzz(float(sys.argv[1]), False if "--driver" in sys.argv[2:] else None)
    for result in results:
        print(result)
        for finding in result.findings:
            print(finding, file=sys.stderr)
    sys.exit(1 if any(r.findings for r in results) else 0)
