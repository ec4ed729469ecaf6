"""Throughput of the batch estimator against vqf's C++ core and ahrs' Madgwick, same run."""
from __future__ import annotations

import sys
import time

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
        # the filter alone: local noise densities (the default), and stationary
        "wiener": lambda: estimate(gyr, acc, BENCH_FS, gyro_offset=False),
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


def bench_fmu(steps: int = 5000, repeat: int = 5, progress: bool = True) -> dict:
    """Per-step cost (µs) of AttitudeEstimator.fmu and of a no-op FMU with its interface,
    both driven by fmpy (set inputs, doStep, get outputs) in interleaved rounds."""
    import tempfile

    from fmpy import extract, read_model_description

    from attitude_fmu.systems.fmi.build import build_fmus
    from attitude_fmu.systems.fmi.cosim import load_slave

    gyr, acc = bench_recording(steps)
    inputs = np.hstack([gyr, acc])
    with tempfile.TemporaryDirectory(prefix="attitude_bench_") as tmp:
        if progress:
            print("bench: building AttitudeEstimator.fmu and NoOpEstimator.fmu", file=sys.stderr, flush=True)
        paths = build_fmus(tmp, ("AttitudeEstimator", "NoOpEstimator"))
        fmus = {}
        for path in paths:
            md = read_model_description(path)
            vr = {v.name: v.valueReference for v in md.modelVariables}
            fmu = load_slave(md, extract(path), path.stem)
            fmu.instantiate()  # once: pythonfmu cannot instantiate again after fmi2FreeInstance
            fmus[path.stem] = (fmu, [vr[f"{s}_{a}"] for s in ("gyr", "acc") for a in "xyz"],
                               [vr[n] for n in ("q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw")],
                               [vr["valid"]])
        best = dict.fromkeys(fmus, np.inf)
        for round_ in range(repeat):
            for name, (fmu, vin, vout, vvalid) in fmus.items():
                if progress:
                    print(f"bench: round {round_ + 1}/{repeat}, {name}, {steps} steps", file=sys.stderr, flush=True)
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
        for fmu, *_ in fmus.values():
            fmu.freeInstance()
    per_step = {name: t * 1e6 for name, t in best.items()}
    return {"steps": steps, "us_per_step": per_step,
            "ratio_vs_noop": per_step["AttitudeEstimator"] / per_step["NoOpEstimator"]}
