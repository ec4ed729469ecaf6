"""Motions with exact truth: orientation, ideal gyro and ideal specific force.

Sampling follows docs/conventions.md: gyr[k] is the (constant) angular rate over (t[k−1], t[k]],
so integrating it reproduces quat exactly; acc[k] is the specific force g·up + a at t[k]
in sensor coordinates, with a the mean acceleration over the sample interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.control_system import sample_system
from attitude_fmu.blocks.filters.earth_filters import STANDARD_GRAVITY
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.params import Param
from attitude_fmu.blocks.quaternion import quat_multiply, quat_normalized, quat_rotate, rotvec_quat
from attitude_fmu.systems.simulation.noise import MOTION, NoiseStream, normals

AXES = ("x", "y", "z")
EARTH_FIELD_UT = (0.0, 20.0, -45.0)  # magnetic field in ENU, µT: northwards and down
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

    @property
    def mag(self) -> np.ndarray:
        """N×3 ideal magnetic field in sensor coordinates, µT (EARTH_FIELD_UT in the earth frame)."""
        return Rotation.from_quat(self.quat, scalar_first=True).inv().apply(EARTH_FIELD_UT)


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
        """Sample duration (s) at fs (Hz) from a fixed seed (the noise stream MOTION of
        systems.simulation.noise); starts level, at rest."""
        n = int(round(duration * fs))
        if n < 1:
            raise ValueError(f"duration·fs must give at least one sample, got {duration!r}·{fs!r}")
        noise = normals(seed, MOTION, n)
        state = np.zeros(10)
        state[6] = 1.0
        out = np.empty((n, 10))
        _human_run(state, noise, self.coefficients(fs), out)
        return Motion(fs, out[:, 6:10], out[:, 0:3], out[:, 3:6])

    def system(self, fs: float, name: str = "motion"):
        """Discrete python-control system: inputs eps_v_x..z, eps_w_x..z (unit normal
        noise per sample); states v (m/s), omega (rad/s), q; outputs TRUTH_OUTPUTS."""
        coef = self.coefficients(fs)

        def advance(state, u):
            out = np.empty((1, 10))
            _human_run(state, u.reshape(1, 6), coef, out)
            return state, out[0]

        return sample_system(
            advance, [f"eps_{s}_{a}" for s in "vw" for a in AXES], TRUTH_OUTPUTS,
            [f"v_{a}" for a in AXES] + [f"w_{a}" for a in AXES] + ["qm_w", "qm_x", "qm_y", "qm_z"], coef[4], name)

    @staticmethod
    def initial_state() -> np.ndarray:
        """At rest, level: v = 0, ω = 0, q = identity."""
        return np.array([0, 0, 0, 0, 0, 0, 1.0, 0, 0, 0])

    def stream(self, seed: int = 0) -> "HumanStream":
        """Sample-by-sample generator equal to generate() with the same seed."""
        return HumanStream(self, seed)


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


class HumanStream:
    """HumanMotion sample by sample (for the motion FMU): the same compiled step and the
    same noise stream as HumanMotion.generate with the same seed."""

    def __init__(self, motion: HumanMotion, seed: int = 0):
        self.motion = motion
        self.noise = NoiseStream(seed, MOTION)
        self.state = motion.initial_state()
        self._out = np.empty((1, 10))
        self._h = None

    def step(self, t: float, h: float):
        """Ideal (gyr, specific force, quat) for the interval (t − h, t]."""
        if h != self._h:
            self._coef, self._h = self.motion.coefficients(1.0 / h), h
        _human_run(self.state, self.noise.next().reshape(1, 6), self._coef, self._out)
        return self._out[0, 0:3], self._out[0, 3:6], self._out[0, 6:10]


@dataclass(frozen=True)
class ClosedFormMotion:
    """A motion given by closed forms of orientation R(t) (sensor → earth) and earth-frame
    velocity v(t) (m/s). Sampled over (t − h, t]: gyr is the rotation vector of
    R(t−h)ᵀR(t) over h (so integrating it reproduces R exactly) and the specific force is
    R(t)ᵀ·((v(t) − v(t−h))/h + g·ẑ)."""

    name: str
    orientation: Callable[[np.ndarray], Rotation]
    velocity: Callable[[np.ndarray], np.ndarray]
    g: float = STANDARD_GRAVITY

    def at(self, t, h: float):
        """(gyr N×3, specific force N×3, quat N×4) for the intervals ending at times t."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        now, before = self.orientation(t), self.orientation(t - h)
        gyr = (before.inv() * now).as_rotvec() / h
        acc = (self.velocity(t) - self.velocity(t - h)) / h + [0.0, 0.0, self.g]
        return gyr, now.inv().apply(acc), now.as_quat(scalar_first=True)

    def generate(self, duration: float, fs: float, seed: int = 0) -> Motion:
        """Sample duration (s) at fs (Hz); seed is unused (the motion is deterministic)."""
        t = np.arange(1, int(round(duration * fs)) + 1) / fs
        gyr, acc, quat = self.at(t, 1.0 / fs)
        return Motion(fs, quat, gyr, acc)

    def stream(self, seed: int = 0) -> "ClosedFormMotion":
        """Sample by sample: step(t, h) gives the interval (t − h, t], as generate() does."""
        return self

    def step(self, t: float, h: float):
        gyr, acc, quat = self.at(t, h)
        return gyr[0], acc[0], quat[0]


def steady_lever_arm(rate: float = 2.0, radius: float = 0.2, mount_deg=(20.0, -10.0),
                     g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Rizun §2.4: sensor turning at rate (rad/s) about the vertical on an arm of radius (m).

    The sensor is mounted with roll and pitch mount_deg (degrees) relative to the arm, so
    its mean centripetal acceleration in sensor coordinates, rate²·radius towards the
    axis, is constant and non-zero. R(t) = Rz(rate·t)·R_mount.
    """
    mount = Rotation.from_euler("xy", mount_deg, degrees=True)
    return ClosedFormMotion(
        "lever_arm",
        lambda t: Rotation.from_rotvec(np.outer(rate * t, [0.0, 0.0, 1.0])) * mount,
        lambda t: rate * radius * np.column_stack([-np.sin(rate * t), np.cos(rate * t), np.zeros_like(t)]),
        g,
    )


def incline_oscillation(incline_deg: float = 45.0, peak_acc_g: float = math.sqrt(2.0), frequency: float = 1.0,
                        g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Rizun §2.5 (Fig. 3): harmonic motion along an incline, sensor x up the slope, no rotation.

    Acceleration peak_acc_g·g·sin(2π·frequency·t) along the incline.
    """
    orient = Rotation.from_euler("y", -incline_deg, degrees=True)  # sensor x up the slope
    along = orient.apply([1.0, 0.0, 0.0])
    w = 2 * math.pi * frequency
    amplitude = peak_acc_g * g / w  # of the velocity, m/s
    return ClosedFormMotion(
        "incline",
        lambda t: Rotation.from_quat(np.tile(orient.as_quat(), (len(t), 1))),
        lambda t: np.outer(-amplitude * np.cos(w * t), along),
        g,
    )


def _rot(axis: str, angle) -> Rotation:
    """Rotation about a coordinate axis by angle (rad, scalar or array)."""
    angle = np.atleast_1d(np.asarray(angle, dtype=float))
    vectors = np.zeros((len(angle), 3))
    vectors[:, "xyz".index(axis)] = angle
    return Rotation.from_rotvec(vectors)


def _at_rest(t):
    return np.zeros((len(np.atleast_1d(t)), 3))


def coning(theta: float = 1.0, rate: float = 1.0, g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Luinge's coning motion with half-angle theta (rad) at rate (rad/s), fixed in position:
    R(t) = Rz(rate·t)·Rx(theta)·Rz(−rate·t) (Luinge's formula for ω has a typo: its second component should carry sin Ωt)."""
    return ClosedFormMotion(
        "coning", lambda t: _rot("z", rate * t) * _rot("x", np.full(len(np.atleast_1d(t)), theta)) * _rot("z", -rate * t),
        _at_rest, g)


def sine_rotation(amplitude_deg: float = 10.0, frequency: float = 0.5, inclination_deg: float = 0.0,
                  g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Tseng experiments 1–2: ±amplitude_deg pitch (about the platform's y axis) at
    frequency (Hz); the IMU inclined by inclination_deg about the platform's x axis."""
    amp, w, incl = math.radians(amplitude_deg), 2 * math.pi * frequency, math.radians(inclination_deg)
    return ClosedFormMotion(
        "sine_rotation", lambda t: _rot("y", amp * np.sin(w * t)) * _rot("x", np.full(len(np.atleast_1d(t)), incl)),
        _at_rest, g)


STEP_SIZES_DEG = (5.0, 10.0, 20.0, 45.0, 90.0)


def step_rotation(hold: float = 10.0, ramp: float = 0.2, g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Tseng experiment 3: pitch steps of STEP_SIZES_DEG, each held hold (s) and back to 0
    for hold (s); each step a raised-cosine ramp of ramp (s). Repeats after the last."""
    levels = np.array([x for size in STEP_SIZES_DEG for x in (size, 0.0)])
    radians = np.radians(levels)

    def pitch(t):
        t = np.asarray(t, dtype=float)
        i = np.floor(t / hold).astype(int)
        into = t - i * hold
        now, before = radians[i % len(levels)], radians[(i - 1) % len(levels)]
        blend = np.where(into < ramp, 0.5 - 0.5 * np.cos(np.pi * np.clip(into / ramp, 0, 1)), 1.0)
        return np.where(t < hold, now * blend, before + (now - before) * blend)

    return ClosedFormMotion("step_rotation", lambda t: _rot("y", pitch(np.atleast_1d(t))), _at_rest, g)


def linear_motion(amplitude: float = 0.5, period: float = 4.0, mount_x_deg: float = 0.0, mount_y_deg: float = 0.0,
                  mount_z_deg: float = 0.0, g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Tseng experiment 4: back and forth along the earth x axis, x(t) = amplitude·(1 −
    cos 2πt/period)/2 (m), the IMU mounted rotated by mount_x/y/z_deg about X, Y, Z."""
    mount = Rotation.from_euler("XYZ", [mount_x_deg, mount_y_deg, mount_z_deg], degrees=True)
    w = 2 * math.pi / period
    return ClosedFormMotion(
        "linear_motion", lambda t: Rotation.from_quat(np.tile(mount.as_quat(), (len(np.atleast_1d(t)), 1))),
        lambda t: np.outer(amplitude * w / 2 * np.sin(w * np.atleast_1d(t)), [1.0, 0.0, 0.0]), g)


def offset_rotation(frequency: float = 0.4, amplitude_deg: float = 45.0, radius: float = 0.2,
                    inclination_deg: float = 0.0, pitch_deg: float = 0.0, g: float = STANDARD_GRAVITY) -> ClosedFormMotion:
    """Tseng experiment 5: yaw ψ = amplitude_deg·sin(2π·frequency·t) on an arm of radius (m),
    so centripetal and tangential acceleration; the IMU mounted with inclination_deg about
    x and pitch_deg about y. R(t) = Rz(ψ)·R_mount, position radius·(cos ψ, sin ψ, 0)."""
    amp, w = math.radians(amplitude_deg), 2 * math.pi * frequency
    mount = Rotation.from_euler("xy", [inclination_deg, pitch_deg], degrees=True)

    def velocity(t):
        t = np.atleast_1d(t)
        psi, psi_dot = amp * np.sin(w * t), amp * w * np.cos(w * t)
        return radius * np.column_stack([-np.sin(psi) * psi_dot, np.cos(psi) * psi_dot, np.zeros_like(t)])

    return ClosedFormMotion("offset_rotation", lambda t: _rot("z", amp * np.sin(w * np.atleast_1d(t))) * mount,
                            velocity, g)


@dataclass(frozen=True)
class Profile:
    """A named motion with documented parameters (blocks.methods.registry.Param)."""

    name: str
    summary: str
    factory: Callable
    params: tuple

    def motion(self, overrides: dict | None = None, g: float = STANDARD_GRAVITY):
        """The motion for these parameter overrides (unknown names are refused)."""
        known = {p.name: p.default for p in self.params}
        for name, value in (overrides or {}).items():
            if name not in known:
                raise ValueError(f"unknown parameter {name!r} for profile {self.name!r}; known: {', '.join(known)}")
            if not math.isfinite(value):
                raise ValueError(f"parameter {name} must be finite, got {value!r}")
            known[name] = float(value)
        return self.factory(**known, g=g)


def _profiles() -> dict:
    return {p.name: p for p in (
        Profile("human", "band-limited human motion (Rizun eq. 14) with random rotation", HumanMotion, (
            Param("delta_v", 1.0, "m/s/√Hz", "slosh: density of the velocity"),
            Param("omega_c", 10.0, "rad/s", "band limit of the velocity"),
            Param("rot_rms", 1.0, "rad/s", "RMS angular rate per axis"),
            Param("rot_cutoff", 5.0, "rad/s", "band limit of the angular rate"),
        )),
        Profile("lever_arm", "steady rotation about the vertical on a lever arm (Rizun §2.4)", steady_lever_arm, (
            Param("rate", 2.0, "rad/s", "turn rate"),
            Param("radius", 0.2, "m", "arm length"),
        )),
        Profile("incline", "harmonic motion along a 45° incline, peak √2·g (Rizun §2.5)", incline_oscillation, (
            Param("incline_deg", 45.0, "deg", "slope of the incline"),
            Param("peak_acc_g", math.sqrt(2.0), "1", "peak acceleration in units of g"),
            Param("frequency", 1.0, "Hz", "frequency of the oscillation"),
        )),
        Profile("coning", "Luinge's coning motion, theta = rate = 1", coning, (
            Param("theta", 1.0, "rad", "half-angle of the cone"),
            Param("rate", 1.0, "rad/s", "coning rate"),
        )),
        Profile("sine_rotation", "Tseng 1-2: ±10° sinusoidal pitch, optionally inclined", sine_rotation, (
            Param("amplitude_deg", 10.0, "deg", "pitch amplitude"),
            Param("frequency", 0.5, "Hz", "pitch frequency"),
            Param("inclination_deg", 0.0, "deg", "IMU inclination about x (Tseng 2: 20)", True),
        )),
        Profile("step_rotation", "Tseng 3: pitch steps of 5, 10, 20, 45, 90°", step_rotation, (
            Param("hold", 10.0, "s", "time each level is held"),
            Param("ramp", 0.2, "s", "duration of each raised-cosine step"),
        )),
        Profile("linear_motion", "Tseng 4: back and forth along a line, IMU mounted at an angle", linear_motion, (
            Param("amplitude", 0.5, "m", "travel"),
            Param("period", 4.0, "s", "period of the back-and-forth"),
            Param("mount_x_deg", 0.0, "deg", "mounting rotation about X", True),
            Param("mount_y_deg", 0.0, "deg", "mounting rotation about Y", True),
            Param("mount_z_deg", 0.0, "deg", "mounting rotation about Z", True),
        )),
        Profile("offset_rotation", "Tseng 5: 0.4 Hz yaw oscillation on a 20 cm arm", offset_rotation, (
            Param("frequency", 0.4, "Hz", "yaw frequency"),
            Param("amplitude_deg", 45.0, "deg", "yaw amplitude"),
            Param("radius", 0.2, "m", "arm length"),
            Param("inclination_deg", 0.0, "deg", "IMU inclination about x", True),
            Param("pitch_deg", 0.0, "deg", "IMU pitch about y", True),
        )),
    )}


PROFILES = _profiles()


def profile(name: str) -> Profile:
    """The motion profile of that name (PROFILES: human, lever_arm, incline, coning, …);
    its .motion(overrides) is the motion with exact truth, its .params the parameters."""
    try:
        return PROFILES[name]
    except KeyError:
        raise ValueError(f"unknown profile {name!r}; available: {', '.join(PROFILES)}") from None
