"""`attitude compare`: every estimator and the peers vqf and ahrs' Madgwick on every
motion profile, on the same samples with realistic sensor noise (or an IMU of the
caller's figures, see imu_model)."""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import bias_angle, inclination_error, rms
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.simulation.motion import PROFILES
from attitude_fmu.systems.simulation.recording import Sensor
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0  # Hz
DURATION_S = {"human": 600.0}  # others: DEFAULT_DURATION_S
DEFAULT_DURATION_S = 300.0
SKIP_S = 100.0  # start-up excluded from the statistics (ten time constants of the default Wiener filter)
PEERS = ("vqf", "madgwick")


def imu_model(gyro_noise_dps: float = 0.02, acc_noise: float = 0.002, gyro_scale_error: float = 0.0,
              seed: int = 0) -> ImuModel:
    """The compared IMU: gyro white noise gyro_noise_dps (°/s/√Hz), accelerometer white
    noise acc_noise (m/s²/√Hz) and a scale-factor and misalignment matrix whose elements are
    drawn normal with rms gyro_scale_error (1 = 100 %) from seed; no offsets
    (systems.simulation.recording.Sensor)."""
    return Sensor(gyro_noise_dps, acc_noise, gyro_scale_error, mag_noise=0.0).model(seed)


IMU = imu_model()  # a MEMS IMU: gyro 0.02 °/s/√Hz, accelerometer 200 µg/√Hz, ideal scale, no offsets


def peer_quaternions(name: str, gyr, acc, fs: float) -> np.ndarray:
    """Orientation (N×4, sensor → earth) of a peer on the same samples."""
    try:
        import vqf
        from ahrs.filters import Madgwick
    except ImportError as exc:
        raise RuntimeError(f"comparing with peers needs vqf and ahrs ({exc}); "
                           "install them with: pip install 'attitude-fmu[peers]'") from None
    if name == "vqf":
        return vqf.VQF(1.0 / fs).updateBatch(np.ascontiguousarray(gyr), np.ascontiguousarray(acc))["quat6D"]
    if name == "vqf_offline":
        return vqf.offlineVQF(np.ascontiguousarray(gyr), np.ascontiguousarray(acc), None, 1.0 / fs)["quat6D"]
    if name == "madgwick":
        return Madgwick(gyr=gyr, acc=acc, frequency=fs).Q
    raise ValueError(f"unknown peer {name!r}")


def compare_profile(name: str, methods=None, peers=PEERS, seed: int = 0, imu: ImuModel = IMU,
                    offline: bool = False) -> dict:
    """{method: {"rms_deg", "max_deg", "mean_deg"}} for one profile; offline adds the
    smoothers ("METHOD_offline" for the earth-frame methods, "vqf_offline")."""
    duration = DURATION_S.get(name, DEFAULT_DURATION_S)
    motion = PROFILES[name].motion().generate(duration, FS, seed)
    gyr, acc = imu.apply(motion, seed + 1)
    start = int(SKIP_S * FS)
    methods = methods or METHODS
    ups = {m: estimate(gyr, acc, FS, m, gyro_offset=False).up for m in methods}
    if offline:
        ups |= {f"{m}_offline": estimate(gyr, acc, FS, m, offline=True, gyro_offset=False).up
                for m in methods if METHODS[m].is_sensor_frame}
    for peer in peers + (("vqf_offline",) if offline and "vqf" in peers else ()):
        q = peer_quaternions(peer, gyr, acc, FS)
        ups[peer] = Rotation.from_quat(q, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    table = {}
    for method, up in ups.items():
        err = np.degrees(inclination_error(up[start:], motion.up[start:]))
        table[method] = {"rms_deg": rms(err), "max_deg": float(err.max()),
                         "mean_deg": math.degrees(bias_angle(up[start:], motion.quat[start:]))}
    return table


def compare(profiles=None, methods=None, peers=PEERS, progress: bool = True, imu: ImuModel = IMU,
            offline: bool = False, jobs: Jobs | None = None) -> dict:
    """{"profiles": {profile: {method: {...}}}} over the profiles (default: all); each
    profile is a job of jobs (systems.cluster.jobs.Jobs; default: this process, a bar when
    progress). A profile whose job failed (jobs reports it) is left out."""
    names = list(profiles or PROFILES)
    jobs = jobs or Jobs(bar=progress)
    tables = jobs.map(compare_profile, [(name, methods, tuple(peers), 0, imu, offline) for name in names], names,
                      "profiles")
    return {"profiles": {name: table for name, table in zip(names, tables) if not isinstance(table, Failure)}}
