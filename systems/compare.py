"""`attitude compare`: every estimator and the peers vqf and ahrs' Madgwick on every
motion profile, on the same samples with realistic sensor noise."""
from __future__ import annotations

import math
import sys

import numpy as np
from scipy.spatial.transform import Rotation

from blocks.methods import METHODS

from .batch import estimate
from .errors import bias_angle, inclination_error, rms
from .motion import PROFILES
from .sensor_model import ImuModel

FS = 100.0  # Hz
# a MEMS IMU: gyro 0.02 °/s/√Hz, accelerometer 200 µg/√Hz, no offsets
IMU = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002)
DURATION_S = {"human": 600.0}  # others: DEFAULT_DURATION_S
DEFAULT_DURATION_S = 300.0
SKIP_S = 100.0  # start-up excluded from the statistics (ten time constants of the default Wiener filter)
PEERS = ("vqf", "madgwick")


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
    if name == "madgwick":
        return Madgwick(gyr=gyr, acc=acc, frequency=fs).Q
    raise ValueError(f"unknown peer {name!r}")


def compare_profile(name: str, methods=None, peers=PEERS, seed: int = 0) -> dict:
    """{method: {"rms_deg", "max_deg", "mean_deg"}} for one profile."""
    duration = DURATION_S.get(name, DEFAULT_DURATION_S)
    motion = PROFILES[name].motion().generate(duration, FS, seed)
    gyr, acc = IMU.apply(motion, seed + 1)
    start = int(SKIP_S * FS)
    ups = {m: estimate(gyr, acc, FS, m).up for m in (methods or METHODS)}
    for peer in peers:
        q = peer_quaternions(peer, gyr, acc, FS)
        ups[peer] = Rotation.from_quat(q, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    table = {}
    for method, up in ups.items():
        err = np.degrees(inclination_error(up[start:], motion.up[start:]))
        table[method] = {"rms_deg": rms(err), "max_deg": float(err.max()),
                         "mean_deg": math.degrees(bias_angle(up[start:], motion.quat[start:]))}
    return table


def compare(profiles=None, methods=None, peers=PEERS, progress: bool = True) -> dict:
    """{"profiles": {profile: {method: {...}}}} over the profiles (default: all)."""
    result = {}
    names = list(profiles or PROFILES)
    for i, name in enumerate(names):
        if progress:
            print(f"compare: {i + 1}/{len(names)} {name}", file=sys.stderr, flush=True)
        result[name] = compare_profile(name, methods, peers)
    return {"profiles": result}
