"""Motions with exact truth: orientation, ideal gyro and ideal specific force.

Sampling follows NOTES §1: gyr[k] is the (constant) angular rate over (t[k−1], t[k]],
so integrating it reproduces quat exactly; acc[k] is the specific force g·up + a at t[k]
in sensor coordinates, with a the mean acceleration over the sample interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np
from scipy.spatial.transform import Rotation

from blocks.earth_filters import STANDARD_GRAVITY
from blocks.jit import kernel
from blocks.quaternion import quat_multiply, quat_normalized, quat_rotate, rotvec_quat

AXES = ("x", "y", "z")
TRUTH_OUTPUTS = [f"omega_{a}" for a in AXES] + [f"f_{a}" for a in AXES] + [
    "qt_w", "qt_x", "qt_y", "qt_z"
]


@dataclass
class Motion:
    """A sampled motion: fs (Hz), quat N×4 (sensor → earth), gyr N×3 (rad/s), acc N×3 (m/s²)."""

    fs: float
    quat: np.ndarray
    gyr: np.ndarray
    acc: np.ndarray

    @property
    def t(self) -> np.ndarray:
        return np.arange(1, len(self.gyr) + 1) / self.fs

    @property
    def up(self) -> np.ndarray:
        """N×3 true unit up-vector in sensor coordinates."""
        return Rotation.from_quat(self.quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class HumanMotion:
    """Band-limited human motion (Rizun eq. 14) with a band-limited random rotation.

    delta_v: slosh, density of the earth-frame velocity, m/s/√Hz (one-sided);
    omega_c: band limit of the velocity, rad/s; rot_rms: RMS angular rate per axis,
    rad/s; rot_cutoff: band limit of the angular rate, rad/s; g: gravity, m/s².
    Velocity and angular rate are first-order low-passed white noise (exact
    Ornstein–Uhlenbeck steps), so velocity has the spectrum of eq. 14.
    """

    delta_v: float = 1.0
    omega_c: float = 10.0
    rot_rms: float = 1.0
    rot_cutoff: float = 5.0
    g: float = STANDARD_GRAVITY

    def __post_init__(self):
        for name in ("delta_v", "omega_c", "rot_cutoff", "g"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite positive number, got {value!r}")
        if not (math.isfinite(self.rot_rms) and self.rot_rms >= 0):
            raise ValueError(f"rot_rms must be finite and non-negative, got {self.rot_rms!r}")

    def coefficients(self, fs: float) -> np.ndarray:
        """[phi_v, sig_v, phi_w, sig_w, Ts, g] of the exact OU steps at sample rate fs."""
        Ts = 1.0 / fs
        phi_v = math.exp(-self.omega_c * Ts)
        var_v = self.delta_v**2 * self.omega_c / 4.0  # (1/2π)∫ S_v dω of eq. 14
        phi_w = math.exp(-self.rot_cutoff * Ts)
        return np.array([
            phi_v, math.sqrt(var_v * (1 - phi_v**2)),
            phi_w, math.sqrt(self.rot_rms**2 * (1 - phi_w**2)), Ts, self.g,
        ])

    def generate(self, duration: float, fs: float, seed: int = 0) -> Motion:
        """Sample duration (s) at fs (Hz) from a fixed seed; starts level, at rest."""
        n = int(round(duration * fs))
        if n < 1:
            raise ValueError(f"duration·fs must give at least one sample, got {duration!r}·{fs!r}")
        noise = np.random.default_rng(seed).standard_normal((n, 6))
        state = np.zeros(10)
        state[6] = 1.0
        out = np.empty((n, 10))
        _human_run(state, noise, self.coefficients(fs), out)
        return Motion(fs, out[:, 6:10], out[:, 0:3], out[:, 3:6])

    def system(self, fs: float, name: str = "motion"):
        """Discrete python-control system: inputs eps_v_x..z, eps_w_x..z (unit normal
        noise per sample); states v (m/s), omega (rad/s), q; outputs TRUTH_OUTPUTS."""
        coef = self.coefficients(fs)

        def advance(x, u):
            state = np.array(x, dtype=float)
            out = np.empty((1, 10))
            _human_run(state, np.asarray(u, dtype=float).reshape(1, 6), coef, out)
            return state, out[0]

        return control.nlsys(
            lambda t, x, u, p: advance(x, u)[0],
            lambda t, x, u, p: advance(x, u)[1],
            inputs=[f"eps_{s}_{a}" for s in "vw" for a in AXES], outputs=TRUTH_OUTPUTS,
            states=[f"v_{a}" for a in AXES] + [f"w_{a}" for a in AXES] + ["qm_w", "qm_x", "qm_y", "qm_z"],
            dt=coef[4], name=name,
        )

    @staticmethod
    def initial_state() -> np.ndarray:
        """At rest, level: v = 0, ω = 0, q = identity."""
        return np.array([0, 0, 0, 0, 0, 0, 1.0, 0, 0, 0])


@kernel(inline=True)
def _human_step(state, noise, k, c, out):
    phi_v, sig_v, phi_w, sig_w, Ts, g = c[0], c[1], c[2], c[3], c[4], c[5]
    v0 = phi_v * state[0] + sig_v * noise[k, 0]
    v1 = phi_v * state[1] + sig_v * noise[k, 1]
    v2 = phi_v * state[2] + sig_v * noise[k, 2]
    specific = ((v0 - state[0]) / Ts, (v1 - state[1]) / Ts, (v2 - state[2]) / Ts + g)
    state[0], state[1], state[2] = v0, v1, v2
    for i in range(3, 6):
        state[i] = phi_w * state[i] + sig_w * noise[k, i]
    dq = rotvec_quat(state[3] * Ts, state[4] * Ts, state[5] * Ts)
    q = quat_normalized(quat_multiply((state[6], state[7], state[8], state[9]), dq))
    f = quat_rotate((q[0], -q[1], -q[2], -q[3]), specific)
    out[k, 0], out[k, 1], out[k, 2] = state[3], state[4], state[5]
    out[k, 3], out[k, 4], out[k, 5] = f
    out[k, 6], out[k, 7], out[k, 8], out[k, 9] = q
    state[6], state[7], state[8], state[9] = q


@kernel()
def _human_run(state, noise, coef, out):
    for k in range(noise.shape[0]):
        _human_step(state, noise, k, coef, out)


def steady_lever_arm(rate: float, radius: float, mount_deg=(20.0, -10.0), duration=600.0, fs=100.0,
                     g: float = STANDARD_GRAVITY) -> Motion:
    """Rizun §2.4: sensor turning at rate (rad/s) about the vertical on an arm of radius (m).

    The sensor is mounted with roll and pitch mount_deg (degrees) relative to the arm,
    so its mean centripetal acceleration in sensor coordinates, −rate²·radius along the
    arm, is constant and non-zero. Closed form: R(t) = Rz(rate·t)·R_mount.
    """
    t = np.arange(1, int(round(duration * fs)) + 1) / fs
    mount = Rotation.from_euler("xy", mount_deg, degrees=True)
    orient = Rotation.from_rotvec(np.outer(rate * t, [0.0, 0.0, 1.0])) * mount
    position = radius * np.column_stack([np.cos(rate * t), np.sin(rate * t), np.zeros_like(t)])
    specific_force = -rate**2 * position + [0.0, 0.0, g]
    gyr = np.tile(mount.inv().apply([0.0, 0.0, rate]), (len(t), 1))
    return Motion(fs, orient.as_quat(scalar_first=True), gyr, orient.inv().apply(specific_force))


def incline_oscillation(incline_deg=45.0, peak_acc_g=math.sqrt(2.0), frequency=1.0, duration=600.0,
                        fs=100.0, g: float = STANDARD_GRAVITY) -> Motion:
    """Rizun §2.5: harmonic motion along an incline, sensor x along the incline, no rotation.

    Acceleration peak_acc_g·g·sin(2π·frequency·t) along the incline (Fig. 3).
    """
    t = np.arange(1, int(round(duration * fs)) + 1) / fs
    orient = Rotation.from_euler("y", -incline_deg, degrees=True)  # sensor x up the slope
    along = orient.apply([1.0, 0.0, 0.0])
    w = 2 * math.pi * frequency
    # mean acceleration over each sample interval, as for every motion here
    mean_acc = peak_acc_g * g * (np.cos(w * (t - 1 / fs)) - np.cos(w * t)) * fs / w
    specific_force = np.outer(mean_acc, along) + [0.0, 0.0, g]
    quat = np.tile(orient.as_quat(scalar_first=True), (len(t), 1))
    return Motion(fs, quat, np.zeros((len(t), 3)), orient.inv().apply(specific_force))
