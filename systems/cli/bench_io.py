"""`attitude bench --io`: a recording's whole way through `attitude estimate` (read, checks,
estimate, write), CSV → CSV and Parquet → Parquet, against pandas read_csv +
vqf.VQF.updateBatch (9D) + pandas to_csv of the same columns in the same run; and the
peak memory of each of ours, in a process of its own, beside the recording's size."""
from __future__ import annotations

import contextlib
import io
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from attitude_fmu.systems.evaluation.bench import bench_recording
from attitude_fmu.systems.recordings.writing import CSV_DIGITS

IO_FS = 1000.0  # Hz: 1 M samples are a 17-minute recording
INPUT_COLUMNS = ("t", *(f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in "xyz"))


def io_recording(n: int, folder: Path) -> dict:
    """A 9D recording of n samples at IO_FS written into folder as in.csv and in.parquet
    (pyarrow); {format: path}, and "array_bytes": its own size as float64 columns."""
    import pyarrow as pa
    import pyarrow.csv as pc
    import pyarrow.parquet as pq

    gyr, acc, mag = bench_recording(n, mag=True, fs=IO_FS)
    columns = [np.arange(1, n + 1) / IO_FS, *gyr.T, *acc.T, *mag.T]
    table = pa.table(dict(zip(INPUT_COLUMNS, map(np.ascontiguousarray, columns))))
    pc.write_csv(table, folder / "in.csv", write_options=pc.WriteOptions(quoting_style="none"))
    pq.write_table(table, folder / "in.parquet")
    return {"csv": folder / "in.csv", "parquet": folder / "in.parquet", "array_bytes": 8 * n * len(INPUT_COLUMNS)}


def _ours(source: Path, out: Path) -> None:
    from attitude_fmu.systems.cli.commands import main

    with contextlib.redirect_stderr(io.StringIO()):
        if main(["estimate", str(source), "--out", str(out)]) != 0:
            raise RuntimeError(f"attitude estimate {source} failed")


def _peers(source: Path, out: Path) -> None:
    """pandas read_csv + vqf's 9D filter (its C++ core) + pandas to_csv of t, q and the
    up-vector g (the columns of ours) at CSV_DIGITS significant digits."""
    import pandas as pd
    import vqf

    data = pd.read_csv(source)
    part = lambda s: np.ascontiguousarray(data[[f"{s}_{a}" for a in "xyz"]].to_numpy())
    t = data["t"].to_numpy()
    quat = vqf.VQF(1.0 / IO_FS).updateBatch(part("gyr"), part("acc"), part("mag"))["quat9D"]
    w, x, y, z = quat.T
    up = np.column_stack([2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z])
    table = pd.DataFrame({"t": t, **dict(zip(("q_w", "q_x", "q_y", "q_z"), quat.T)),
                          **dict(zip(("g_x", "g_y", "g_z"), up.T))})
    table.to_csv(out, index=False, float_format=f"%.{CSV_DIGITS}g")


PEAK_SCRIPT = """
import sys
from attitude_fmu.systems.cli.commands import main
code = main(sys.argv[1:])
status = dict(line.split(":", 1) for line in open("/proc/self/status"))
print(int(status["VmHWM"].split()[0]) * 1024 if code == 0 else -1)
"""  # VmHWM: the process's own high-water mark (a child's ru_maxrss counts its parent's at the fork)


def peak_memory(source: Path, out: Path) -> int:
    """Peak resident memory (bytes) of `attitude estimate source --out out` in a process of
    its own (Linux: /proc/self/status)."""
    run = subprocess.run([sys.executable, "-c", PEAK_SCRIPT, "estimate", str(source), "--out", str(out)],
                         capture_output=True, text=True)
    peak = int(run.stdout.split()[-1]) if run.returncode == 0 and run.stdout.split() else -1
    if peak < 0:
        raise RuntimeError(f"attitude estimate {source} failed: {run.stderr.strip()[-500:]}")
    return peak


def bench_io(n: int = 1_000_000, repeat: int = 3, progress: bool = True) -> dict:
    """Best seconds of each way over `repeat` interleaved rounds, their ratios to the peers',
    and the peak memory of ours beside the recording's size (its columns as float64, its
    CSV file) and that of a process that estimates one second of it (imports and all)."""
    try:
        import pandas  # noqa: F401
        import vqf  # noqa: F401
    except ImportError as exc:
        raise RuntimeError(f"attitude bench --io compares with pandas and vqf ({exc}); "
                           "install them with: pip install 'attitude-fmu[bench]'") from None
    with tempfile.TemporaryDirectory(prefix="attitude_bench_io_") as tmp:
        folder = Path(tmp)
        if progress:
            print(f"bench: writing a {n}-sample 9D recording at {IO_FS:g} Hz", file=sys.stderr, flush=True)
        files = io_recording(n, folder)
        (folder / "small").mkdir()
        small = io_recording(int(IO_FS), folder / "small")
        ways = {
            "csv_to_csv": lambda: _ours(files["csv"], folder / "out.csv"),
            "parquet_to_parquet": lambda: _ours(files["parquet"], folder / "out.parquet"),
            "pandas_vqf_9d_pandas": lambda: _peers(files["csv"], folder / "peers.csv"),
        }
        _ours(small["csv"], folder / "small" / "out.csv")  # kernels compiled (or loaded) outside the timing
        best = dict.fromkeys(ways, np.inf)
        for round_ in range(repeat):
            for name, run in ways.items():
                if progress:
                    print(f"bench: round {round_ + 1}/{repeat}, {name}", file=sys.stderr, flush=True)
                start = time.perf_counter()
                run()
                best[name] = min(best[name], time.perf_counter() - start)
        if progress:
            print("bench: peak memory, each in a process of its own", file=sys.stderr, flush=True)
        memory = {"csv_to_csv": peak_memory(files["csv"], folder / "out.csv"),
                  "parquet_to_parquet": peak_memory(files["parquet"], folder / "out.parquet"),
                  "one_second": peak_memory(small["csv"], folder / "small" / "out.csv")}
        sizes = {"array_bytes": files["array_bytes"], "csv_bytes": files["csv"].stat().st_size,
                 "parquet_bytes": files["parquet"].stat().st_size}
    peers = best["pandas_vqf_9d_pandas"]
    return {"samples": n, "fs_hz": IO_FS, "seconds": best,
            "ratio_vs_peers": {name: t / peers for name, t in best.items()},
            "peak_memory_bytes": memory, "recording": sizes}


def print_io(result: dict) -> None:
    """bench_io's result as a table."""
    mb = lambda b: f"{b / 1e6:.0f} MB"
    rec = result["recording"]
    print(f"{result['samples']} samples at {result['fs_hz']:g} Hz with a magnetometer: "
          f"columns {mb(rec['array_bytes'])}, CSV {mb(rec['csv_bytes'])}, Parquet {mb(rec['parquet_bytes'])}; best of the rounds")
    for name, seconds in result["seconds"].items():
        memory = result["peak_memory_bytes"].get(name)
        print(f"{name:>22} {seconds:7.2f} s {result['ratio_vs_peers'][name]:6.2f}×"
              + (f"   peak memory {mb(memory)}" if memory else ""))
    print(f"{'(one second of it)':>22} {'':>17}   peak memory {mb(result['peak_memory_bytes']['one_second'])}")
