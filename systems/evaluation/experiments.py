"""Rizun (2008) reproduced in simulation: Table 1, the error spectrum (eq. 42), the
first-order comparison (§4.2), centripetal bias (§2.4) and angle filtering (§2.5)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal

from attitude_fmu.blocks.errors import bias_angle, earth_frame_error, inclination_error, rms
from attitude_fmu.blocks.filters import accuracy
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.filters.earth_filters import settle_time
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.blocks.pipeline.batch import AttitudeEstimate, estimate
from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.simulation.motion import HumanMotion, Motion, profile
from attitude_fmu.systems.simulation.sensor_model import ImuModel

PAPER_G = 9.8  # m/s²: the g that reproduces every printed digit of Table 1
TABLE1_ROWS = ((0.10, 1.0), (0.10, 2.0), (0.20, 1.0), (0.20, 2.0))  # δn in °/s/√Hz, δv in m/s/√Hz
TABLE1_SLOSH = (1.0, 0.5, 2.0)  # mismatch a = δv'/δv of the three columns


@dataclass
class HumanRun:
    """A simulated human-motion run after the filter's start-up has been cut off."""

    motion: Motion
    est: AttitudeEstimate
    start: int  # first sample kept
    g: float
    stop: int | None = None  # one past the last sample kept (None: to the end)

    @property
    def kept(self) -> slice:
        return slice(self.start, self.stop)

    @property
    def errors(self) -> np.ndarray:
        """Inclination error per kept sample, rad."""
        return inclination_error(self.est.gravity[self.kept], self.motion.up[self.kept])

    def earth_error(self) -> np.ndarray:
        """Kept gravity-estimate error in true earth coordinates, N×3, m/s²."""
        return earth_frame_error(self.est.gravity[self.kept], self.motion.quat[self.kept], self.g)


def simulate_human(delta_n: float, delta_v: float, a: float = 1.0, method: str = "wiener",
                   params: dict | None = None, duration: float = 20000.0, fs: float = 100.0,
                   seed: int = 0, omega_c: float = 10.0, g: float = PAPER_G,
                   rot_rms: float = 1.0, offline: bool = False) -> HumanRun:
    """Run an estimator designed for (delta_n, delta_v) on human motion of slosh a·delta_v.

    delta_n in rad/s/√Hz, delta_v in m/s/√Hz, durations in s, fs in Hz, rot_rms (RMS
    angular rate per axis) in rad/s; offline: the forward–backward smoother, both ends cut.
    """
    design = {"delta_n": delta_n, "delta_v": delta_v, "g": g, **(params or {})}
    motion = HumanMotion(delta_v=a * delta_v, omega_c=omega_c, rot_rms=rot_rms, g=g).generate(duration, fs, seed)
    gyr, acc = ImuModel(delta_n=delta_n).apply(motion, seed=seed + 1)
    est = estimate(gyr, acc, fs, method, design, offline=offline, gyro_offset=False)
    start = int(settle_time(get_method(method).filter(design)) * fs)
    if start >= len(acc) // 3:
        raise ValueError(f"duration {duration} s is too short for the filter to settle")
    return HumanRun(motion, est, start, g, len(acc) - start if offline else None)


def table1_simulated(dn_deg: float, dv: float, a: float, duration: float, fs: float, seed: int) -> float:
    """One simulated cell of Table 1, degrees RMS (δn in °/s/√Hz, δv in m/s/√Hz, slosh
    mismatch a, duration in s, fs in Hz); a job of table1."""
    return math.degrees(rms(simulate_human(math.radians(dn_deg), dv, a, duration=duration, fs=fs, seed=seed).errors))


def table1(duration: float = 20000.0, fs: float = 100.0, seed: int = 0, rows=TABLE1_ROWS,
           progress=True, jobs: Jobs | None = None) -> list[dict]:
    """Table 1 with analytic (eq. 50) and simulated RMS attitude errors side by side; each
    simulated cell is a job of jobs (systems.cluster.jobs.Jobs; default: this process, a bar
    when progress). A cell whose job failed (jobs reports it) has simulated_deg None."""
    jobs = jobs or Jobs(bar=progress)
    specs = [(dn_deg, dv, a, duration, fs, seed + 10 * i + j)
             for i, (dn_deg, dv) in enumerate(rows) for j, a in enumerate(TABLE1_SLOSH)]
    simulated = iter(jobs.map(table1_simulated, specs,
                              [f"δn={c[0]}°/s/√Hz, δv={c[1]} m/s/√Hz, a={c[2]}" for c in specs], "cells"))
    table = []
    for dn_deg, dv in rows:
        dn = math.radians(dn_deg)
        cells = []
        for a in TABLE1_SLOSH:
            value = next(simulated)
            cells.append({"a": a, "analytic_deg": math.degrees(accuracy.rms_attitude_error(dn, dv, a, PAPER_G)),
                          "simulated_deg": None if isinstance(value, Failure) else value})
        table.append({
            "delta_n_deg": dn_deg, "delta_v": dv,
            "inv_omega_g_s": 1.0 / ef.omega_g(dn, dv, PAPER_G), "cells": cells,
        })
    return table


def simulated_error_spectrum(run: HumanRun, segment_s: float = 2000.0):
    """Welch estimate of the horizontal earth-frame error spectrum of a run.

    Returns ω (rad/s) and the two-sided spectrum S(ω) of eq. 42 ((m/s²)²/(rad/s)),
    averaged over the x and y components (z holds no gyro error, see eq. 20).
    """
    err = run.earth_error()[:, :2]
    fs = run.motion.fs
    f, p = signal.welch(err, fs=fs, nperseg=int(segment_s * fs), axis=0, detrend=False)
    # one-sided per Hz → two-sided per rad/s with ⟨x²⟩ = (1/2π)∫S dω
    return 2 * math.pi * f, p.mean(axis=1) / 2.0


def first_order_comparison(delta_n: float = math.radians(0.1), delta_v: float = 1.0,
                           omega_c: float = 10.0, duration: float = 20000.0, fs: float = 100.0,
                           seed: int = 0, g: float = PAPER_G) -> dict:
    """§4.2: mean-square error of the best first-order filter over the optimal one.

    The paper: larger "by the reduced factor (ω_c/ω_g)^(1/3)". Minimising eq. 41 for the
    first-order filter gives the exact ratio (3·2^(5/6)/8)·(ω_c/ω_g)^(1/3) for ω_c ≫ ω_g.
    """
    wg = ef.omega_g(delta_n, delta_v, g)
    wf = ef.best_first_order_cutoff(wg, omega_c)
    runs = {
        name: simulate_human(delta_n, delta_v, method=name, params=params, duration=duration,
                             fs=fs, seed=seed, omega_c=omega_c, g=g)
        for name, params in (("wiener", {}), ("first_order", {"omega_c": omega_c, "omega_f": wf}))
    }
    # mean-square of the horizontal earth-frame components, the quantity of eq. 43
    ms = {name: float(np.mean(run.earth_error()[:, :2] ** 2)) for name, run in runs.items()}
    analytic = (accuracy.mean_square_error(ef.first_order(wf), delta_n, delta_v, omega_c, g)
                / accuracy.mean_square_error(ef.butterworth(wg), delta_n, delta_v, omega_c, g))
    return {
        "omega_g": wg, "omega_c": omega_c, "omega_f": wf,
        "paper_factor": (omega_c / wg) ** (1 / 3),
        "analytic_ratio": analytic,
        "simulated_ratio": ms["first_order"] / ms["wiener"],
        "rms_deg": {name: math.degrees(rms(run.errors)) for name, run in runs.items()},
    }


def lever_arm_bias(rate: float = 2.0, radius: float = 0.2, duration: float = 600.0, fs: float = 100.0,
                   delta_n: float = math.radians(0.1), delta_v: float = 1.0, g: float = PAPER_G) -> dict:
    """§2.4: the estimator against low-pass filtering the raw accelerometer in sensor coordinates.

    Both use the same Butterworth (eq. 34); ideal sensors. Angles in degrees.
    """
    motion = profile("lever_arm").motion({"rate": rate, "radius": radius}, g=g).generate(duration, fs)
    params = {"delta_n": delta_n, "delta_v": delta_v, "g": g}
    filt = get_method("wiener").filter(params)
    start = int(settle_time(filt) * fs)
    est = estimate(motion.gyr, motion.acc, fs, "wiener", params, gyro_offset=False)
    lowpass = _lti_filter(filt, motion.acc, fs)  # the raw accelerometer in sensor coordinates
    # eq. 19: the mean sensor-frame acceleration is the mean centripetal ω × v
    mean_acc = motion.acc[start:].mean(axis=0) - g * motion.up[start:].mean(axis=0)
    up = motion.up[start]  # constant in sensor coordinates for this motion
    predicted = inclination_error(g * up + mean_acc, up)
    return {
        "estimator_mean_deg": math.degrees(float(np.mean(inclination_error(est.gravity[start:], motion.up[start:])))),
        "estimator_bias_deg": math.degrees(bias_angle(est.gravity[start:], motion.quat[start:])),
        "lowpass_mean_deg": math.degrees(float(np.mean(inclination_error(lowpass[start:], motion.up[start:])))),
        "eq19_predicted_deg": math.degrees(float(predicted)),
        "centripetal_m_s2": float(np.linalg.norm(mean_acc)),
    }


def incline_angle_bias(duration: float = 600.0, fs: float = 100.0, frequency: float = 1.0,
                       delta_n: float = math.radians(0.1), delta_v: float = 1.0, g: float = PAPER_G) -> dict:
    """§2.5: low-pass filtering the apparent pitch angle against filtering the vector.

    Pitch is the angle of the sensor x axis above the horizontal, from the measured (or
    estimated) up-vector u as atan2(u_x, √(u_y² + u_z²)); degrees.
    """
    motion = profile("incline").motion({"frequency": frequency}, g=g).generate(duration, fs)
    params = {"delta_n": delta_n, "delta_v": delta_v, "g": g}
    filt = get_method("wiener").filter(params)
    start = int(settle_time(filt) * fs)
    true_pitch = _pitch(motion.up[start:]).mean()
    angle_filtered = _lti_filter(filt, _pitch(motion.acc), fs)[start:].mean()
    vector_filtered = _pitch(estimate(motion.gyr, motion.acc, fs, "wiener", params,
                                      gyro_offset=False).gravity[start:]).mean()
    return {
        "true_pitch_deg": math.degrees(true_pitch),
        "angle_filter_bias_deg": math.degrees(angle_filtered - true_pitch),
        "vector_filter_bias_deg": math.degrees(vector_filtered - true_pitch),
        "mean_apparent_pitch_deg": math.degrees(_pitch(motion.acc[start:]).mean()),
    }


def _pitch(vectors) -> np.ndarray:
    v = np.asarray(vectors)
    return np.arctan2(v[:, 0], np.hypot(v[:, 1], v[:, 2]))


def _lti_filter(filt, x, fs: float) -> np.ndarray:
    """The earth-frame filter (ZOH form) on the columns of x, without rotation, at rest on x[0]."""
    return DiscreteFilter.from_lti(filt, 1.0 / fs).apply(x)
