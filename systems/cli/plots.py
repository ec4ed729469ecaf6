"""`attitude plot`: a recording's inclination error over time and its spectrum against eq. 42;
without a reference, the estimate's angles over time."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy import signal
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import quaternion_errors
from attitude_fmu.blocks.filters import accuracy
from attitude_fmu.blocks.methods.registry import design_delta_v
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.blocks.pipeline.batch import check_options, estimate
from attitude_fmu.blocks.pipeline.causal import split_params
from attitude_fmu.systems.evaluation.alignment import align as align_reference
from attitude_fmu.systems.evaluation.alignment import heading_offset, without_heading_offset
from attitude_fmu.systems.recordings.output import save_figure
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import RecordingError, print_notes
from attitude_fmu.systems.recordings.writing import euler_degrees


def plot_recording(path, out, method: str = "wiener", params=None, offline: bool = False,
                   gyro_offset: bool = True, heading: bool = True, read_options=None, latency: float = 0.0,
                   gyr_samples: str = "mean", acc_samples: str = "point", align: bool = False,
                   reference_north: str = "other") -> dict:
    """Draw the error of method on a recording with a reference into out (PNG): the
    inclination error over time, with heading (and a magnetometer in the recording) the
    heading error with the samples the disturbance guard refused shaded and the times a
    hard-iron offset was taken or dropped marked, and the tilt error's spectrum beside eq. 42.
    Returns the inclination and (with the magnetometer) heading RMSE (deg) over the
    movement phase (Recording.evaluated). A recording without a reference gets the
    estimate's roll, pitch and yaw over time instead (and the gyro offset estimate), and
    an empty dict. read_options: keyword arguments of read_recording (its notes go to
    standard error); latency (s), gyr_samples and acc_samples: as blocks.pipeline.batch.estimate's;
    align and reference_north as systems.evaluation.evaluate.evaluate's (with align, the
    alignment found is returned under "alignment")."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    check_options(method, params, offline, gyro_offset, heading, latency, gyr_samples, acc_samples)
    rec = read_recording(path, **(read_options or {}))
    print_notes(rec.notes)
    valid = None if rec.quat_ref is None else rec.evaluated()
    if valid is not None and valid.sum() < 16:
        raise RecordingError(f"{rec.name}: too few valid reference samples to plot")
    mag = rec.mag if heading else None
    est = estimate(rec.gyr, rec.acc, rec.fs, method, params, offline=offline, gyro_offset=gyro_offset, mag=mag,
                   latency=latency, gyr_samples=gyr_samples, acc_samples=acc_samples)
    label = f"{method}{' --offline' if offline else ''}{f' --latency {latency:g}' if latency else ''}"
    t = np.arange(1, len(rec.gyr) + 1) / rec.fs
    if valid is None:
        _plot_angles(plt, rec.name, label, t, est, out)
        return {}
    found = None
    if align:
        found, quat_ref = align_reference(rec, est.quat)
        rec = replace(rec, quat_ref=quat_ref)
        valid = rec.evaluated()
    if reference_north != "magnetic":  # the reference's own north: the estimate's constant heading offset removed
        quat_ref = rec.quat_ref.copy()
        quat_ref[valid] = without_heading_offset(quat_ref[valid], heading_offset(est.quat[valid], quat_ref[valid]))
        rec = replace(rec, quat_ref=quat_ref)
    inclination, heading_error = np.full(len(rec.gyr), np.nan), np.full(len(rec.gyr), np.nan)
    _, heading_error[valid], inclination[valid] = np.degrees(quaternion_errors(est.quat[valid], rec.quat_ref[valid]))
    # horizontal earth-frame components of the estimated up: small-angle tilt errors, rad
    up = est.gravity / np.linalg.norm(est.gravity, axis=1, keepdims=True)
    tilt = Rotation.from_quat(rec.quat_ref[valid], scalar_first=True).apply(up[valid])[:, :2]
    f, psd = signal.welch(tilt, fs=rec.fs, nperseg=min(len(tilt), int(60 * rec.fs)), axis=0)
    fig, axes = plt.subplots(2 if mag is None else 3, 1, figsize=(8, 7 if mag is None else 10))
    top, bottom = axes[0], axes[-1]
    top.plot(t, inclination, lw=0.7)
    top.set_xlabel("time, s")
    top.set_ylabel("inclination error, °")
    rmse = {"inclination_rmse_deg": math.sqrt(float(np.nanmean(inclination**2)))}
    top.set_title(f"{rec.name}: {label}\nRMSE {rmse['inclination_rmse_deg']:.2f}° over the movement phase")
    if mag is not None:
        rmse["heading_rmse_deg"] = math.sqrt(float(np.nanmean(heading_error**2)))
        _heading_panel(axes[1], t, heading_error, est, rmse["heading_rmse_deg"])
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
    save_figure(fig, out, dpi=110)
    plt.close(fig)
    return rmse if found is None else {**rmse, "alignment": found.to_json()}


def _plot_angles(plt, name, label, t, est, out) -> None:
    """The estimate's roll and pitch, its yaw (shaded where the magnetometer's field was
    refused) and, when estimated, the gyro offset, over time, into out (PNG)."""
    panels = 2 + (est.offset is not None)
    fig, axes = plt.subplots(panels, 1, figsize=(8, 3.2 * panels), sharex=True)
    angles = euler_degrees(est.quat)
    angles[1:][np.abs(np.diff(angles, axis=0)) > 180.0] = np.nan  # no line across a wrap at ±180°
    for i, name_i in enumerate(("roll", "pitch")):
        axes[0].plot(t, angles[:, i], lw=0.7, label=name_i)
    axes[0].set_ylabel("°")
    axes[0].set_title(f"{name}: {label} (no reference: the estimate)")
    axes[1].plot(t, angles[:, 2], lw=0.7, color="C2", label="yaw")
    axes[1].set_ylabel("°")
    if est.mag_accepted is not None:
        _shade_refused(axes[1], t, est)
        axes[1].set_title(f"yaw, from the magnetometer ({_delay_text(est)})")
    else:
        axes[1].set_title("yaw, from the gyro (6D)")
    if est.offset is not None:
        for i, axis in enumerate("xyz"):
            axes[2].plot(t, np.degrees(est.offset[:, i]), lw=0.9, label=axis)
        axes[2].set_ylabel("°/s")
        axes[2].set_title("gyro offset estimate")
    axes[-1].set_xlabel("time, s")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right")
    fig.tight_layout()
    save_figure(fig, out, dpi=110)
    plt.close(fig)


def _delay_text(est) -> str:
    """The magnetometer's delay the heading allowed for at the end, and where it came from."""
    return f"its delay {1e3 * est.mag_delay[-1]:.1f} ms at the end, {est.mag_delay_source}"


def _shade_refused(ax, t, est) -> None:
    """Shade the samples whose field the disturbance guard refused."""
    refused = ~est.mag_accepted
    ax.fill_between(t, 0, 1, where=refused, transform=ax.get_xaxis_transform(), color="0.85", step="mid",
                    label=f"field refused ({100 * refused.mean():.0f} % of samples)")


def _heading_panel(ax, t, heading_error, est, rmse) -> None:
    """Heading error over time; shaded where the guard refused the field, lines where the
    hard-iron offset changed."""
    ax.plot(t, heading_error, lw=0.7, color="C1")
    _shade_refused(ax, t, est)
    used = np.any(est.mag_offset != 0, axis=1)
    for i, k in enumerate(np.flatnonzero(used[1:] != used[:-1])):
        ax.axvline(t[k + 1], color="C3", lw=1.0, label=None if i else "hard-iron offset taken or dropped")
    ax.set_xlabel("time, s")
    ax.set_ylabel("heading error, °")
    ax.set_title(f"heading from the magnetometer ({_delay_text(est)}), RMSE {rmse:.2f}°")
    ax.legend(loc="upper right")
