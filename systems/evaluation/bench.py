"""Throughput of the batch estimator against vqf's C++ core and ahrs' Madgwick, same run;
of an FMU step against a no-op FMU; and the wall time of evaluate and table1 on a local
Dask cluster against the same in this process (bench_workers)."""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fmpy
import numpy as np

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

BENCH_FS = 100.0  # Hz


def bench_recording(n: int = 100_000, seed: int = 0, mag: bool = False, fs: float = BENCH_FS):
    """A human-motion recording of n samples at fs (Hz; about 3.5 m/s² RMS acceleration per
    axis) with a MEMS-grade gyro: (gyr, acc), and with mag a magnetometer (µT, 0.1 µT/√Hz)
    as well: (gyr, acc, mag)."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(n / fs, fs, seed)
    imu = ImuModel(delta_n=np.radians(0.01), mag_noise=0.1)
    gyr, acc = imu.apply(motion, seed + 1)
    return (gyr, acc, imu.apply_mag(motion, seed + 1)) if mag else (gyr, acc)


def _runners(gyr, acc, mag):
    try:
        import vqf
        from ahrs.filters import Madgwick
    except ImportError as exc:
        raise RuntimeError(f"attitude bench needs the peers vqf and ahrs ({exc}); "
                           "install them with: pip install 'attitude-fmu[peers]'") from None
    Ts = 1.0 / BENCH_FS
    return {
        # the filter alone: local noise densities (the default: scale_error chosen from the recording, the
        # candidates on 140 s of it; held, as online and in the FMU), and stationary
        "wiener": lambda: estimate(gyr, acc, BENCH_FS, gyro_offset=False),
        "wiener_held": lambda: estimate(gyr, acc, BENCH_FS, "wiener", {"scale_error": 0.005}, gyro_offset=False),
        "wiener_stationary": lambda: estimate(gyr, acc, BENCH_FS, "wiener", {"stationary": 1}, gyro_offset=False),
        # what `attitude estimate` runs on a recording: the gyro-offset estimator, and heading
        "wiener_offset": lambda: estimate(gyr, acc, BENCH_FS),
        "wiener_9d": lambda: estimate(gyr, acc, BENCH_FS, mag=mag),
        "vqf": lambda: vqf.VQF(Ts).updateBatch(gyr, acc),  # with its gyro-bias estimation
        "vqf_9d": lambda: vqf.VQF(Ts).updateBatch(gyr, acc, mag),
        "madgwick": lambda: Madgwick(gyr=gyr, acc=acc, frequency=BENCH_FS),
    }


def bench(n: int = 100_000, repeat: int = 5, budget_s: float = 3.0, progress: bool = True) -> dict:
    """Best samples per second of each method over up to `repeat` interleaved rounds, and
    their ratios to vqf's 6D and 9D filters.

    Rounds alternate the methods so that the machine's load changes hit all alike; a
    method leaves the rounds once its runs have taken budget_s (it always runs once).
    """
    gyr, acc, mag = map(np.ascontiguousarray, bench_recording(n, mag=True))
    runners = _runners(gyr, acc, mag)
    for params in (None, {"stationary": 1}):  # compile (or load) the kernels outside the timing
        estimate(gyr[:10], acc[:10], BENCH_FS, "wiener", params, mag=mag[:10])
    best = dict.fromkeys(runners, np.inf)
    spent = dict.fromkeys(runners, 0.0)
    for round_ in range(repeat):
        for name, run in runners.items():
            if round_ > 0 and spent[name] >= budget_s:
                continue
            if progress:
                print(f"bench: round {round_ + 1}/{repeat}, {name} on {n} samples", file=sys.stderr, flush=True)
            start = time.perf_counter()
            run()
            elapsed = time.perf_counter() - start
            best[name], spent[name] = min(best[name], elapsed), spent[name] + elapsed
    rates = {name: n / t for name, t in best.items()}
    return {
        "samples": n,
        "samples_per_s": rates,
        "ratio_vs_vqf": {name: rate / rates["vqf"] for name, rate in rates.items()},
        "ratio_vs_vqf_9d": {name: rate / rates["vqf_9d"] for name, rate in rates.items()},
    }


def _fmpy_rounds(fmus: dict, inputs, steps: int, repeat: int, progress: bool) -> dict:
    """Best µs per step of each extracted FMU (name → (md, folder)) in fmpy's FMU2Slave loop
    (set inputs, doStep, get outputs), over interleaved rounds."""
    from attitude_fmu.systems.fmi.cosim import load_slave

    loaded = {}
    for name, (md, folder) in fmus.items():
        vr = {v.name: v.valueReference for v in md.modelVariables}
        fmu = load_slave(md, folder, name.replace("/", "_"))
        fmu.instantiate()  # once: pythonfmu cannot instantiate again after fmi2FreeInstance
        loaded[name] = (fmu, [vr[n] for n in FMU_INPUTS], [vr[n] for n in FMU_OUTPUTS], [vr["valid"]])
    best = dict.fromkeys(loaded, np.inf)
    for round_ in range(repeat):
        for name, (fmu, vin, vout, vvalid) in loaded.items():
            if progress:
                print(f"bench: round {round_ + 1}/{repeat}, {name} under fmpy, {steps} steps", file=sys.stderr, flush=True)
            fmu.reset()
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            start = time.perf_counter()
            for k in range(steps):
                fmu.setReal(vin, inputs[k].tolist())
                fmu.doStep(currentCommunicationPoint=k / BENCH_FS, communicationStepSize=1.0 / BENCH_FS)
                fmu.getReal(vout)
                fmu.getBoolean(vvalid)
            best[name] = min(best[name], (time.perf_counter() - start) / steps)
            fmu.terminate()
    for fmu, *_ in loaded.values():
        fmu.freeInstance()
    return {name: t * 1e6 for name, t in best.items()}


def _c_host_rounds(fmus: dict, inputs, repeat: int, tmp: Path, progress: bool) -> dict:
    """Best µs per step of each extracted FMU (name → (md, folder)) in a C host with no
    Python in its process (systems/evaluation/fmi_bench.c, as the package's build made it),
    each in a process of its own."""
    from attitude_fmu.systems.fmi.native import built

    host, data = built("fmi_bench"), tmp / "inputs.bin"
    np.ascontiguousarray(inputs, dtype=float).tofile(data)
    result = {}
    for name, (md, folder) in fmus.items():
        if progress:
            print(f"bench: {name} in a C host, best of {repeat} rounds of {len(inputs)} steps", file=sys.stderr,
                  flush=True)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        identifier = md.coSimulation.modelIdentifier
        binary = Path(folder) / "binaries" / fmpy.platform / f"{identifier}{fmpy.sharedLibraryExtension}"
        outputs = [n for n in md.modelVariables if n.causality == "output" and n.type == "Real"]
        proc = subprocess.run([str(host), str(binary), md.guid, (Path(folder) / "resources").as_uri(), str(data),
                               repr(1.0 / BENCH_FS), str(repeat), ",".join(str(vr[n]) for n in FMU_INPUTS),
                               ",".join(str(v.valueReference) for v in outputs),
                               str(vr["valid"]) if "valid" in vr else "-"],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"the C host failed on {name} ({proc.returncode}): {proc.stderr[-2000:]}")
        result[name] = float(proc.stdout.split()[-1]) / 1e3
    return result


FMU_INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]
FMU_OUTPUTS = ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw"]


def bench_fmu(steps: int = 5000, repeat: int = 5, progress: bool = True) -> dict:
    """Per-step cost (µs) of the estimator FMUs against no-op FMUs of their interface.

    Under fmpy (set inputs, doStep, get outputs, in interleaved rounds): the pythonfmu
    AttitudeEstimator.fmu and NoOpEstimator.fmu, and the native ones (native/…; in C).
    In a C host with no Python in its process: the native AttitudeEstimator.fmu against the
    pythonfmu one (c_host; native_speedup = pythonfmu's cost / native's), and against the same
    estimator (its defaults: the gyro-offset stage, then wiener) assembled from python-control blocks
    and exported by export_fmu (exported_ratio = its cost / the native FMU's). Each gets every Real
    output after each step. All in one run."""
    from fmpy import extract, read_model_description

    from attitude_fmu.systems.fmi.build import build_fmus

    gyr, acc = bench_recording(steps)
    inputs = np.hstack([gyr, acc])
    names = ("AttitudeEstimator", "NoOpEstimator")
    with tempfile.TemporaryDirectory(prefix="attitude_bench_") as tmp:
        if progress:
            print("bench: building AttitudeEstimator.fmu and NoOpEstimator.fmu, pythonfmu and native",
                  file=sys.stderr, flush=True)
        paths = build_fmus(tmp, names, names, fmi3_names=())
        fmus = {}
        for path in paths:
            name = path.stem if path.parent == Path(tmp) else f"native/{path.stem}"
            fmus[name] = (read_model_description(path), extract(path))
        if set(fmus) != {*names, *(f"native/{n}" for n in names)}:
            raise RuntimeError("attitude bench --fmu needs the native FMUs, which the package's build makes "
                               "(see the warning above)")
        exported = exported_estimator(Path(tmp) / "ExportedEstimator.fmu")
        fmus["exported/ExportedEstimator"] = (read_model_description(exported), extract(exported))
        per_step = _fmpy_rounds({n: fmus[n] for n in fmus if not n.startswith("exported/")}, inputs, steps, repeat,
                                progress)
        c_host = _c_host_rounds({n: fmus[n] for n in ("native/AttitudeEstimator", "AttitudeEstimator",
                                                      "exported/ExportedEstimator")}, inputs, repeat, Path(tmp),
                                progress)
    return {"steps": steps, "us_per_step": per_step,
            "ratio_vs_noop": per_step["AttitudeEstimator"] / per_step["NoOpEstimator"],
            "native_ratio_vs_noop": per_step["native/AttitudeEstimator"] / per_step["native/NoOpEstimator"],
            "c_host_us_per_step": c_host,
            "native_speedup_c_host": c_host["AttitudeEstimator"] / c_host["native/AttitudeEstimator"],
            "exported_ratio_c_host": c_host["exported/ExportedEstimator"] / c_host["native/AttitudeEstimator"]}


def exported_estimator(path: Path, fmi_version: str = "2.0", platforms: str = "host") -> Path:
    """The native AttitudeEstimator's default pipeline (gyro-offset stage, then wiener, at BENCH_FS) as a
    python-control diagram, exported by export_fmu to path (its FMI version and platforms)."""
    import control

    from attitude_fmu.blocks.methods.registry import estimator_system
    from attitude_fmu.blocks.stages.gyro_offset import offset_system
    from attitude_fmu.systems.fmi.export.api import export_fmu

    dt = 1.0 / BENCH_FS
    names = [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]
    diagram = control.interconnect(
        [offset_system(dt), estimator_system("wiener", dt=dt)], name="ExportedEstimator", inputs=names,
        inplist=[f"gyro_offset.{s}_raw_{a}" for s in ("gyr", "acc") for a in "xyz"],
        outlist=[f"estimator.{n}" for n in ("ghat_x", "ghat_y", "ghat_z", "q_w", "q_x", "q_y", "q_z")],
        connections=[[f"estimator.{s}_{a}", f"gyro_offset.{s}_{a}"] for s in ("gyr", "acc") for a in "xyz"])
    return export_fmu(diagram, path, fmi_version=fmi_version, platforms=platforms)


def bench_workers(files=(), workers: int = 2, duration: float = 20000.0) -> dict:
    """Wall time (s) of `attitude evaluate --json FILE...` (when files are given) and of
    `attitude table1 --json --duration S`, each a fresh process as a user runs it, with
    --workers 1 (in that process) and --workers N (a local cluster, its start-up included);
    the ratio of the two, and whether both printed the same results, byte for byte."""
    commands = {"table1": ["table1", "--duration", repr(duration)]}
    if files:
        commands = {"evaluate": ["evaluate", *map(str, files)], **commands}
    out = {"workers": workers}
    for name, command in commands.items():
        seconds, printed = {}, {}
        for n in (1, workers):
            start = time.perf_counter()
            run = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", *command, "--json",
                                  "--workers", str(n)], capture_output=True, text=True)
            seconds[n] = time.perf_counter() - start
            if run.returncode != 0:
                raise RuntimeError(f"attitude {' '.join(command)} --workers {n} failed: {run.stderr[-2000:]}")
            printed[n] = run.stdout
        jobs = len(files) if name == "evaluate" else sum(len(row["cells"]) for row in json.loads(printed[1]))
        out[name] = {"jobs": jobs,
                     "serial_s": seconds[1], "distributed_s": seconds[workers],
                     "ratio": seconds[1] / seconds[workers], "identical": printed[1] == printed[workers]}
    return out
