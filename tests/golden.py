"""Golden outputs: what the estimator and the simulation gave on fixed streams before the C core
became their only implementation (frozen from the numba-compiled Python at commit f877a67,
which the tests of that time held equal to the C core step by step). tests/test_golden.py holds
every path to them.

    python -m tests.golden            # freeze again: only after a deliberate change of results
    python -m tests.golden DIR        # the native FMUs' outputs, of the FMUs built into DIR

Each case is a function of no arguments that returns a dict of arrays; the streams it runs on
are made here from numpy's generator and scipy's Rotation alone (not the project's simulation),
so a case's input does not depend on the code under test. Long outputs are kept every
DECIMATE-th row (and the last), which keeps the file small.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

GOLDEN = Path(__file__).with_name("golden.npz")
FROZEN_SCALE_ERROR = {"scale_error": 0.005}  # the estimate cases' value (frozen before the batch path chose it)
# the heading's low-pass off (1 - exp(-Ts/1 ns) is 1): each field sample judged alone, as when the cases were frozen
FROZEN_MAG_GUARD = {"tau_mag_guard": 1e-9}


def as_online(method: str = "wiener", params=None) -> dict:
    """params with which estimate() runs the step an online estimator or an FMU runs with params:
    wiener's scale_error held at its online default, which the batch path would choose from the
    recording (blocks.stages.scale_error)."""
    return {**FROZEN_SCALE_ERROR, **(params or {})} if method == "wiener" else dict(params or {})
DECIMATE = 25  # rows kept of the streams of a few thousand samples; 2·DECIMATE of the longer ones
BROAD = Path(__file__).resolve().parents[1].parent / "shared" / "broad"
BROAD_RECORDING = BROAD / "32_disturbed_attached_magnet_1cm.mat"  # rest, fast turns, a magnet attached
EARTH_FIELD = np.array([0.0, 20.0, -45.0])  # µT, ENU


def rows(a, every: int = DECIMATE) -> np.ndarray:
    """Every every-th row of a, and the last."""
    a = np.asarray(a)
    keep = np.unique(np.r_[np.arange(0, len(a), every), len(a) - 1])
    return a[keep]


def turning(n, fs, seed, rates=(0.2, 0.3, 0.5), amplitude=(1.5, 0.5, 0.4), accel=0.0, rest=None):
    """A sensor turning about every axis (Z-Y-X angles amplitude·sin(rate·t)), still between
    rest[0] and rest[1] s where given, with a horizontal acceleration of accel m/s² (sines):
    (quat N×4 at t_k, gyr N×3 the exact mean rate over (t_k−1, t_k], acc N×3 at t_k, no noise)."""
    t = np.arange(1, n + 1) / fs

    def angles(t):
        if rest is not None:
            t = np.where(t < rest[0], t, np.maximum(t - (rest[1] - rest[0]), rest[0]))
        return np.column_stack([a * np.sin(r * t + 0.3 * i) for i, (a, r) in enumerate(zip(amplitude, rates))])

    now, before = Rotation.from_euler("ZYX", angles(t)), Rotation.from_euler("ZYX", angles(t - 1.0 / fs))
    gyr = (before.inv() * now).as_rotvec() * fs
    linear = accel * np.column_stack([np.sin(1.3 * t), np.cos(0.7 * t), 0.3 * np.sin(2.1 * t)])
    acc = now.inv().apply(linear + [0.0, 0.0, 9.81])
    return now.as_quat(scalar_first=True), gyr, acc


def imu(quat, gyr, acc, fs, seed, offset=(0.01, -0.02, 0.005), hard_iron=(12.0, -4.0, 7.0), mag_every=1,
        mag_late=0, noise=(math.radians(0.05), 0.01, 0.3)):
    """Measured (gyr, acc, mag): white noise of the densities noise (gyro rad/s/√Hz, acc
    m/s²/√Hz, mag µT/√Hz), a gyro offset (rad/s), hard iron (µT), a magnetometer mag_late
    samples late that samples every mag_every-th step (NaN between)."""
    rng = np.random.default_rng(seed)
    scale = math.sqrt(fs / 2.0)
    field = Rotation.from_quat(quat, scalar_first=True).inv().apply(EARTH_FIELD)
    if mag_late:
        field = np.vstack([np.repeat(field[:1], mag_late, axis=0), field[:-mag_late]])
    gyr = gyr + noise[0] * scale * rng.standard_normal(gyr.shape) + offset
    acc = acc + noise[1] * scale * rng.standard_normal(acc.shape)
    mag = field + hard_iron + noise[2] * scale * rng.standard_normal(field.shape)
    mag[np.arange(len(mag)) % mag_every != 0] = np.nan
    return gyr, acc, mag


def human_stream():
    """1450 samples: 3 with the accelerometer all 0, 2.5 s still, then fast turns and shaking;
    Ts 10 ms, 8 ms from sample 800; a magnetometer two samples late at a third of the rate;
    NaN, ±inf and beyond-range samples here and there: (gyr, acc, mag, Ts)."""
    fs = 100.0
    quat, gyr, acc = turning(1450, fs, 5, rates=(1.1, 0.9, 1.7), amplitude=(1.2, 0.6, 0.7), accel=3.0,
                             rest=(0.0, 2.5))
    gyr, acc, mag = imu(quat, gyr, acc, fs, 5, mag_every=3, mag_late=2)
    Ts = np.where(np.arange(1450) < 800, 0.01, 0.008)
    acc[:3] = 0.0
    gyr[600, 1], acc[601, 0], gyr[602, 2], acc[900, 2] = np.nan, np.inf, -np.inf, np.nan
    gyr[603, 0], acc[604, 1] = math.radians(4001.0), 401.0 * 9.80665  # beyond every IMU's range
    mag[606, 2], mag[609] = np.inf, 0.0  # no field sample
    return gyr, acc, mag, Ts


def hard_motion():
    """3000 samples of fast tumbling (up to about 12 rad/s, upside down on the way; linear
    accelerations of ±6 m/s²; 3 samples with no accelerometer), Ts changed twice: (Ts, gyr, acc)."""
    rng = np.random.default_rng(7)
    Ts = np.concatenate([np.full(1200, 0.01), np.full(900, 0.0037), np.full(900, 0.025)])
    t = np.cumsum(Ts)
    freq, phase = rng.uniform(0.2, 2.5, (3, 4)), rng.uniform(0, 2 * np.pi, (3, 4))
    amplitude = np.array([4.0, 3.0, 2.0, 1.5])
    gyr = np.stack([(amplitude * np.sin(freq[i] * t[:, None] + phase[i])).sum(axis=1) for i in range(3)], axis=1)
    gyr[t > 20.0] *= 0.1
    steps = Rotation.from_rotvec(gyr * Ts[:, None])
    q = [Rotation.identity()]
    for step in steps:
        q.append(q[-1] * step)
    up = Rotation.concatenate(q[1:]).inv().apply([0.0, 0.0, 1.0])
    acc = 9.81 * up + 6.0 * np.sin(np.outer(t, [0.7, 1.3, 2.1]) + 1.0) * (np.sin(0.4 * t)[:, None] > 0.3)
    acc[[1300, 1301, 2500]] = 0.0
    return Ts, gyr + 0.01 * rng.standard_normal(gyr.shape), acc


def recording_9d(n=6000, fs=100.0, seed=11):
    """A minute of turning and shaking at 100 Hz, still for the first 8 s and from 30 to 36 s,
    with gyro offset, hard iron and a magnetometer 3 samples late: (gyr, acc, mag, fs)."""
    quat, gyr, acc = turning(n, fs, seed, rates=(0.6, 0.8, 1.1), amplitude=(1.5, 0.6, 0.5), accel=2.0,
                             rest=(8.0, 14.0))
    gyr, acc, mag = imu(quat, gyr, acc, fs, seed, mag_late=3)
    return gyr, acc, mag, fs


METHOD_CASES = (("wiener", {}), ("wiener", {"scale_error": 0.02, "tau_noise": 0.3}), ("wiener", {"stationary": 1.0}),
                ("wiener", {"omega_c": 5.0}), ("first_order", {}), ("first_order", {"omega_f": 0.3}), ("tseng", {}),
                ("tseng_adaptive", {}), ("tseng_adaptive", {"tol": 2.0, "k_I": 0.0}), ("luinge", {}),
                ("luinge", {"tilt_sd": 0.01}), ("mahony", {}), ("mahony", {"k_P": 4.0, "k_I": 1.0}))
ONLINE_OUTPUTS = ("quat", "up", "euler", "offset", "mag_offset", "mag_delay")


def _stage_params(heading, gyro_offset):
    params = {"delta_n": math.radians(0.05), "rest_time": 1.0, "tau_acc": 1.0} if gyro_offset else {}
    heading_params = {"tau_heading": 2.0, "mag_new_time": 4.0, "mag_cal_time": 8.0, **FROZEN_MAG_GUARD}
    return {**params, **heading_params} if heading else params


def online_configs():
    """(name, OnlineEstimator keyword arguments) of the online cases."""
    configs = []
    for method in ("wiener", "first_order", "tseng", "tseng_adaptive", "luinge", "mahony"):
        for heading in (True, False):
            for gyro_offset in (True, False):
                configs.append(dict(method=method, heading=heading, gyro_offset=gyro_offset))
    for timing in (dict(gyr_samples="point"), dict(acc_samples="mean"), dict(latency=0.003),
                   dict(gyr_samples="point", acc_samples="mean", latency=0.003)):
        for method in ("wiener", "tseng_adaptive"):
            configs.append(dict(method=method, heading=True, gyro_offset=True, **timing))
    return [("online " + " ".join(f"{k}={v}" for k, v in c.items()), {**c, "params": _stage_params(c["heading"],
                                                                                                  c["gyro_offset"])})
            for c in configs]


def run_online(config, gyr, acc, mag, Ts, columns=17):
    """OnlineEstimator over a stream: taken (N) and its outputs after each sample (rows of N×17:
    quat, up, euler, offset, mag_offset, mag_delay; columns: the first `columns`)."""
    from attitude_fmu import OnlineEstimator

    est = OnlineEstimator(**config)
    taken, out = np.empty(len(gyr), dtype=bool), np.empty((len(gyr), 17))
    for k in range(len(gyr)):
        taken[k] = est.step(gyr[k], acc[k], Ts[k], mag[k])
        out[k] = np.concatenate([est.quat, est.up, est.euler, est.offset, est.mag_offset, [est.mag_delay]])
    return {"taken": taken, "out": rows(out[:, :columns])}


def run_methods(name, given):
    """One method alone (no gyro offset) through the online estimator over hard_motion, whose Ts changes."""
    Ts, gyr, acc = hard_motion()
    return run_online(dict(method=name, params=given, gyro_offset=False), gyr, acc, np.full_like(gyr, np.nan), Ts, 7)


def estimate_case(**options):
    """estimate() over recording_9d: quat, gravity and, where made, offset, mag_accepted, mag_offset, mag_delay;
    scale_error held at FROZEN_SCALE_ERROR (tests/test_scale_error.py holds the choice of it), the
    heading's low-pass off (FROZEN_MAG_GUARD)."""
    from attitude_fmu import estimate

    gyr, acc, mag, fs = recording_9d()
    with_mag = options.pop("with_mag", True)
    mag = mag if with_mag else None
    options["params"] = as_online(options.get("method", "wiener"), {**(FROZEN_MAG_GUARD if with_mag else {}),
                                                                    **options.get("params", {})})
    est = estimate(gyr, acc, fs, mag=mag, **options)
    out = {"quat": rows(est.quat, 2 * DECIMATE), "gravity": rows(est.gravity, 2 * DECIMATE)}
    for name in ("offset", "mag_accepted", "mag_offset", "mag_delay"):
        if getattr(est, name) is not None:
            out[name] = rows(getattr(est, name), 2 * DECIMATE)
    return out


ESTIMATE_CASES = {
    "estimate default 9D": dict(),
    "estimate 6D no offset": dict(with_mag=False, gyro_offset=False),
    "estimate offline 9D": dict(offline=True),
    "estimate offline 6D": dict(offline=True, with_mag=False),
    "estimate offline stationary": dict(offline=True, with_mag=False, params={"stationary": 1.0}),
    "estimate offline first_order": dict(offline=True, method="first_order", gyro_offset=False),
    "estimate offline tseng": dict(offline=True, method="tseng"),
    "estimate luinge latency": dict(method="luinge", latency=0.004, gyr_samples="point", acc_samples="mean"),
    "estimate mag_delay given": dict(params={"mag_delay": 0.02}),
}


def broad_case(offline):
    """estimate() with the defaults (scale_error held at FROZEN_SCALE_ERROR, the heading's low-pass off)
    over the first 30 s of a BROAD recording (9D)."""
    from attitude_fmu import estimate, read_recording

    rec = read_recording(BROAD_RECORDING)
    n = int(30.0 * rec.fs)
    est = estimate(rec.gyr[:n], rec.acc[:n], rec.fs, mag=rec.mag[:n], offline=offline,
                   params={**FROZEN_SCALE_ERROR, **FROZEN_MAG_GUARD})
    return {"quat": rows(est.quat, 2 * DECIMATE), "gravity": rows(est.gravity, 2 * DECIMATE), "offset": rows(est.offset, 2 * DECIMATE)}


# the profiles of the numba-compiled Python frozen here; those added since (phone_flat, running, robot_arm) are held
# to their scipy definitions instead (tests/test_simulation.py)
FROZEN_PROFILES = ("human", "lever_arm", "incline", "coning", "sine_rotation", "step_rotation", "linear_motion",
                   "offset_rotation")


def simulation_case():
    """The simulation: the noise streams, HumanMotion, every profile frozen, the sensor model."""
    from attitude_fmu import HumanMotion, ImuModel, profile
    from attitude_fmu.systems.simulation.noise import MAGNETOMETER, MOTION, SENSOR, normals

    out = {f"normals {s}": normals(123456789, s, 50) for s in (MOTION, SENSOR, MAGNETOMETER)}
    out["normals first"] = normals(2**64 - 1, SENSOR, 5, first=10**12)
    human = HumanMotion(delta_v=0.7, rot_rms=1.2).generate(3.0, 100.0, seed=3)
    out.update({"human quat": human.quat, "human gyr": human.gyr, "human acc": human.acc})
    for name in FROZEN_PROFILES:  # the human motion on a grid of one cell per sample: the process frozen here
        motion = profile(name).motion({"grid": 1 / 50.0} if name == "human" else None).generate(3.0, 50.0)
        out.update({f"profile {name} quat": motion.quat, f"profile {name} gyr": motion.gyr,
                    f"profile {name} acc": motion.acc})
    model = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.01, 0.0, -0.02),
                     gyr_scale=((0.01, 0.002, 0.0), (0.0, -0.01, 0.003), (0.001, 0.0, 0.02)), acc_noise=0.02,
                     acc_offset=(0.1, -0.05, 0.0), latency=0.025, mag_noise=0.2, mag_offset=(5.0, -3.0, 1.0))
    gyr, acc = model.apply(human, seed=4)
    out.update({"imu gyr": gyr, "imu acc": acc, "imu mag": model.apply_mag(human, seed=4)})
    return out


def stages_case():
    """The stages alone: the gyro-offset estimator (forward, offline), heading with hard iron,
    and the magnetometer's delay measured from a recording."""
    from attitude_fmu.blocks.stages import gyro_offset, heading
    from attitude_fmu.blocks.stages.delays import mag_delay

    gyr, acc, mag, fs = recording_9d()
    out = {}
    for offline in (False, True):
        _, offset = gyro_offset.correct(gyr, acc, fs, {"tau_acc": 1.0}, offline=offline)
        out[f"offset offline={offline}"] = rows(offset, 2 * DECIMATE)
    quat = Rotation.from_rotvec(np.cumsum(gyr, axis=0) / fs).as_quat(scalar_first=True)  # any orientation stream
    for params in ({}, {"mag_delay": 0.03, "mag_cal_time": 20.0}, {"mag_new_time": 5.0}):
        q, accepted, offset, delay = heading.with_magnetometer(quat, mag, fs, {**params, **FROZEN_MAG_GUARD})
        key = " ".join(f"{k}={v}" for k, v in params.items())
        out.update({f"heading quat {key}": rows(q, 2 * DECIMATE), f"heading accepted {key}": accepted,
                    f"heading offset {key}": rows(offset, 2 * DECIMATE), f"heading delay {key}": rows(delay, 2 * DECIMATE)})
    out["mag_delay"] = np.array([mag_delay(gyr, mag, fs) or np.nan])
    return out


def cases():
    """name → function of no arguments that returns the case's arrays."""
    found = {name: (lambda c=config: run_online(c, *human_stream())) for name, config in online_configs()}
    found.update({f"method {n} {' '.join(f'{k}={v}' for k, v in g.items())}": (lambda n=n, g=g: run_methods(n, g))
                  for n, g in METHOD_CASES})
    found.update({name: (lambda o=options: estimate_case(**dict(o))) for name, options in ESTIMATE_CASES.items()})
    found.update({"simulation": simulation_case, "stages": stages_case})
    if BROAD_RECORDING.exists():
        found.update({"broad online": lambda: broad_case(False), "broad offline": lambda: broad_case(True)})
    return found


def load() -> dict[str, dict[str, np.ndarray]]:
    """The frozen outputs: case → array name → array."""
    with np.load(GOLDEN) as data:
        golden: dict[str, dict[str, np.ndarray]] = {}
        for key in data.files:
            case, _, name = key.partition("::")
            golden.setdefault(case, {})[name] = data[key]
    return golden


def freeze() -> None:
    arrays = {f"{case}::{name}": value for case, make in cases().items() for name, value in make().items()}
    np.savez_compressed(GOLDEN, **arrays)
    print(f"{GOLDEN}: {len(arrays)} arrays, {GOLDEN.stat().st_size / 1e3:.0f} kB", file=sys.stderr)




GOLDEN_FMUS = Path(__file__).with_name("golden_fmus.npz")
FMU_STEP = 0.01  # s


def _simulate(fmu, start_values, inputs=None, n=600, outputs=None):
    """fmpy's simulation of the FMU over n steps of FMU_STEP: input column k drives the step
    that ends at (k+1)·FMU_STEP; the outputs after each step (row 0: before the first, left out)."""
    from fmpy import read_model_description, simulate_fmu

    from attitude_fmu.systems.fmi.cosim import start_values as fmu_start_values

    signals = None
    if inputs is not None:
        signals = np.zeros(n, dtype=[("time", float)] + [(name, float) for name in inputs])
        signals["time"] = np.arange(n) * FMU_STEP
        for name, column in inputs.items():
            signals[name] = column
    result = simulate_fmu(str(fmu), start_values=fmu_start_values(read_model_description(str(fmu)), start_values),
                          input=signals, step_size=FMU_STEP,
                          output_interval=FMU_STEP, stop_time=n * FMU_STEP, output=outputs)
    return np.column_stack([result[name] for name in outputs])[1:]


def fmu_cases(folder) -> dict[str, dict[str, np.ndarray]]:
    """The native FMUs of folder (folder/native/*.fmu, folder/native/fmi3/*.fmu) over fixed
    streams: their outputs after each step."""
    folder = Path(folder)
    gyr, acc, mag, _ = recording_9d(600, 1.0 / FMU_STEP)
    inputs = {f"{s}_{a}": column for s, data in (("gyr", gyr), ("acc", acc), ("mag", mag))
              for a, column in zip("xyz", data.T)}
    estimated = ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "gyr_offset_x", "gyr_offset_y", "gyr_offset_z",
                 "mag_offset_x", "mag_offset_y", "mag_offset_z", "mag_delay_used"]
    out = {}
    for method in ("wiener", "luinge", "tseng_adaptive"):
        for version, path in (("2.0", folder / "native" / "AttitudeEstimator.fmu"),
                              ("3.0", folder / "native" / "fmi3" / "AttitudeEstimator.fmu")):
            start = {"method": method, "Ts": FMU_STEP, "tau_heading": 2.0, **FROZEN_MAG_GUARD}
            out[f"AttitudeEstimator {version} {method}"] = {"out": _simulate(path, start, inputs, outputs=estimated)}
    truth = ["omega_x", "omega_y", "omega_z", "f_x", "f_y", "f_z", "m_x", "m_y", "m_z", "qt_w", "qt_x", "qt_y",
             "qt_z"]
    motion = folder / "native" / "MotionProfile.fmu"
    for name in ("human", "lever_arm", "incline", "coning", "sine_rotation", "step_rotation", "linear_motion",
                 "offset_rotation"):
        grid = {"human_grid": FMU_STEP} if name == "human" else {}  # one cell a step: the process frozen here
        out[f"MotionProfile {name}"] = {"out": _simulate(motion, {"profile": name, "seed": 3, **grid}, n=300,
                                                         outputs=truth)}
    human = out["MotionProfile human"]["out"]
    sensor_inputs = {name: human[:, i] for i, name in enumerate(truth[:9])}
    out["ImuSensor"] = {"out": _simulate(
        folder / "native" / "ImuSensor.fmu",
        {"delta_n": 0.002, "gyr_offset_x": 0.01, "gyr_scale_y_x": 0.01, "acc_noise": 0.02, "acc_offset_z": 0.1,
         "latency": 0.025, "mag_noise": 0.2, "mag_offset_y": 4.0, "seed": 9},
        sensor_inputs, n=300, outputs=[f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in "xyz"])}
    return out


def load_fmus() -> dict[str, np.ndarray]:
    """The native FMUs' frozen outputs: case → outputs after each step."""
    with np.load(GOLDEN_FMUS) as data:
        return {key: data[key] for key in data.files}


def freeze_fmus(folder) -> None:
    arrays = {case: rows(values["out"], 5) for case, values in fmu_cases(folder).items()}
    np.savez_compressed(GOLDEN_FMUS, **arrays)
    print(f"{GOLDEN_FMUS}: {len(arrays)} arrays, {GOLDEN_FMUS.stat().st_size / 1e3:.0f} kB", file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) > 1:  # python -m tests.golden FMU_DIR: the native FMUs built into FMU_DIR (build_fmu.py --out)
        freeze_fmus(sys.argv[1])
    else:
        freeze()
