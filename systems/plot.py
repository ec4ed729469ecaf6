"""`attitude plot`: a recording's inclination error over time and its spectrum against eq. 42."""
from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.spatial.transform import Rotation

from blocks import accuracy
from blocks.methods import design_delta_v, method as get_method
from blocks.stages import split_params

from .batch import estimate
from .errors import quaternion_errors
from .recording import RecordingError, read_recording


def plot_recording(path, out, method: str = "wiener", params=None, offline: bool = False,
                   gyro_offset: bool = True) -> dict:
    """Draw the error of method on a recording with a reference into out (PNG); returns
    the inclination RMSE (deg) over the movement phase."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rec = read_recording(path)
    if rec.quat_ref is None or rec.movement is None:
        raise RecordingError(f"{rec.name}: no optical reference (opt_quat and movement); nothing to plot")
    valid = rec.movement & np.isfinite(rec.quat_ref).all(axis=1)
    if valid.sum() < 16:
        raise RecordingError(f"{rec.name}: too few valid reference samples during movement")
    est = estimate(rec.gyr, rec.acc, rec.fs, method, params, offline=offline, gyro_offset=gyro_offset)
    inclination = np.full(len(rec.gyr), np.nan)
    inclination[valid] = np.degrees(quaternion_errors(est.quat[valid], rec.quat_ref[valid])[2])
    # horizontal earth-frame components of the estimated up: small-angle tilt errors, rad
    up = est.gravity / np.linalg.norm(est.gravity, axis=1, keepdims=True)
    tilt = Rotation.from_quat(rec.quat_ref[valid], scalar_first=True).apply(up[valid])[:, :2]
    f, psd = signal.welch(tilt, fs=rec.fs, nperseg=min(len(tilt), int(60 * rec.fs)), axis=0)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 7))
    t = np.arange(1, len(rec.gyr) + 1) / rec.fs
    top.plot(t, inclination, lw=0.7)
    top.set_xlabel("time, s")
    top.set_ylabel("inclination error, °")
    rmse = math.sqrt(float(np.nanmean(inclination**2)))
    label = f"{method}{' --offline' if offline else ''}"
    top.set_title(f"{rec.name}: {label}, RMSE {rmse:.2f}° over the movement phase")
    bottom.loglog(f[1:], psd[1:].mean(axis=1), label="measured, horizontal components")
    m = get_method(method)
    if m.is_sensor_frame and method == "wiener" and not offline:
        p = m.resolve(split_params(method, params, gyro_offset, False)[0])
        g = p["g"]
        # one-sided per Hz: 2·S(2πf); divided by g² for a tilt in rad
        delta_v = design_delta_v(p)
        model = 2 * accuracy.butterworth_error_spectrum(2 * np.pi * f[1:], p["delta_n"], delta_v, g) / g**2
        bottom.loglog(f[1:], model, "--", label=f"eq. 42, stationary noise model (δv = {delta_v:g} m/s/√Hz)")
    bottom.set_xlabel("frequency, Hz")
    bottom.set_ylabel("tilt error PSD, rad²/Hz")
    bottom.legend()
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return {"inclination_rmse_deg": rmse}
