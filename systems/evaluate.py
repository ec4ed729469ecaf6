"""`attitude evaluate`: recordings with an optical reference (BROAD), errors as the
dataset defines them, for a project method and, on the same samples, vqf online and
offline and ahrs' Madgwick."""
from __future__ import annotations

import math
import sys

import numpy as np

from .batch import estimate
from .compare import peer_quaternions
from .errors import quaternion_errors
from .recording import Recording, read_recording

METRICS = ("total_rmse_deg", "heading_rmse_deg", "inclination_rmse_deg")


def errors_on_movement(quat, rec: Recording) -> dict:
    """RMSE (deg) of total, heading and inclination error over Recording.evaluated (the
    movement phase where the reference is finite; BROAD's definitions, see
    systems.errors.quaternion_errors)."""
    ok = rec.evaluated()
    errors = quaternion_errors(quat[ok], rec.quat_ref[ok])
    return {name: math.degrees(float(np.sqrt(np.mean(e**2)))) for name, e in zip(METRICS, errors)}


def evaluate_recording(rec: Recording, method: str = "wiener", params=None, offline: bool = False,
                       gyro_offset: bool = True, use_mag: bool = True) -> dict:
    """{method label: {metric: value}} for one recording; with a magnetometer (and use_mag)
    the method's heading comes from it, and vqf's 9D estimate is added as "vqf_9d"."""
    rec.evaluated()  # refuses a recording without a usable reference before any work
    import vqf as vqf_module  # peers: the test extra (or [peers])

    label = f"{method}_offline" if offline else method
    mag = rec.mag if use_mag else None
    est = estimate(rec.gyr, rec.acc, rec.fs, method, params, offline=offline, gyro_offset=gyro_offset, mag=mag)
    gyr, acc = np.ascontiguousarray(rec.gyr), np.ascontiguousarray(rec.acc)
    table = {
        label: errors_on_movement(est.quat, rec),
        "vqf": errors_on_movement(peer_quaternions("vqf", gyr, acc, rec.fs), rec),
        "vqf_offline": errors_on_movement(vqf_module.offlineVQF(gyr, acc, None, 1.0 / rec.fs)["quat6D"], rec),
        "madgwick": errors_on_movement(peer_quaternions("madgwick", gyr, acc, rec.fs), rec),
    }
    if mag is not None:  # vqf's "no sample" is a zero row, where ours is NaN
        mag = np.ascontiguousarray(np.where(np.isnan(mag).any(axis=1, keepdims=True), 0.0, mag))
        nine_d = vqf_module.VQF(1.0 / rec.fs).updateBatch(gyr, acc, mag)["quat9D"]
        table["vqf_9d"] = errors_on_movement(nine_d, rec)
    return table


def evaluate(paths, method: str = "wiener", params=None, offline: bool = False, gyro_offset: bool = True,
             use_mag: bool = True, progress: bool = True, start_in_movement: float | None = None,
             read_options=None) -> dict:
    """{"recordings": {name: {label: metrics}}, "mean": {label: metrics}} over the files;
    start_in_movement (s): cut each recording to begin that long into its movement phase;
    read_options: keyword arguments of read_recording (units, fs, max_gap). Every file is
    read and checked first. A recording's name is its file's stem, or its path where
    stems repeat. progress also prints how each file was read where it matters (time
    stamps, no movement flag)."""
    read = []  # every file read and checked before any estimate: a bad last file costs nothing
    for path in paths:
        rec = read_recording(path, **(read_options or {}))
        if start_in_movement is not None:
            rec = rec.into_movement(start_in_movement)
        rec.evaluated()
        if progress:
            for note in rec.notes + ([f"{rec.name}: no movement flag; errors over every sample with a reference"]
                                     if rec.movement is None else []):
                print(f"attitude: note: {note}", file=sys.stderr)
        read.append((path, rec))
    names = [rec.name for _, rec in read]
    if len(set(names)) < len(names):  # files of one name from several folders: keyed by path
        names = [str(path) for path, _ in read]
    recordings = {}
    for i, (name, (path, rec)) in enumerate(zip(names, read)):
        if progress:
            done = int(20 * i / len(paths))
            print(f"\revaluate [{'#' * done}{'.' * (20 - done)}] {i + 1}/{len(paths)} {path}",
                  end="" if sys.stderr.isatty() else "\n", file=sys.stderr, flush=True)
        recordings[name] = evaluate_recording(rec, method, params, offline, gyro_offset, use_mag)
    if progress and sys.stderr.isatty():
        print(file=sys.stderr)
    labels = set.intersection(*(set(r) for r in recordings.values()))  # vqf_9d needs every file's mag
    mean = {label: {m: float(np.mean([r[label][m] for r in recordings.values()])) for m in METRICS}
            for label in next(iter(recordings.values())) if label in labels}
    return {"recordings": recordings, "mean": mean}
