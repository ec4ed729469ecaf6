"""Motions with exact truth: orientation, ideal gyro and ideal specific force, sampled by the
simulation's C core (systems/simulation/core: human_motion.c, closed_form.c).

Sampling follows docs/conventions.md: gyr[k] is the (constant) angular rate over (t[k−1], t[k]],
so integrating it reproduces quat exactly; acc[k] is the specific force g·up + a at t[k]
in sensor coordinates, with a the mean acceleration over the sample interval.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, sample_system, with_c_step
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.simulation import profile_table
from attitude_fmu.systems.simulation.noise import MOTION, normals
from attitude_fmu.systems.simulation.profile_table import EARTH_FIELD_UT  # noqa: F401 (the earth's field, µT)

HUMAN_GRID = next(p.default for p in profile_table.PROFILES["human"][1] if p.name == "grid")  # s

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

    @property
    def mag(self) -> np.ndarray:
        """N×3 ideal magnetic field in sensor coordinates, µT (earth_field)."""
        return earth_field(self.quat)


def earth_field(quat) -> np.ndarray:
    """The field (…×3, µT) sensors at the orientations quat (…×4, sensor → earth) see of the
    earth's, EARTH_FIELD_UT in ENU (systems/simulation/core/earth_field.c)."""
    quat = np.asarray(quat, dtype=float)
    out = np.empty((quat.size // 4, 3))
    _core.earth_field(np.ascontiguousarray(quat).reshape(-1, 4), out)
    return out.reshape(quat.shape[:-1] + (3,))


@dataclass(frozen=True)
class HumanMotion:
    """Band-limited human motion (Rizun eq. 14) with a band-limited random rotation, on a time grid.

    delta_v: slosh, density of the earth-frame velocity, m/s/√Hz (one-sided);
    omega_c: band limit of the velocity, rad/s; rot_rms: RMS angular rate per axis,
    rad/s; rot_cutoff: band limit of the angular rate, rad/s; g: gravity, m/s²;
    grid: the time grid, s (None: the sample interval of generate()); lever_x, lever_y, lever_z:
    the lever arm, the sensor's position from the motion's point in the body frame, m (its
    specific force adds the mean of d/dt R·(ω×r) over each sample: ω×(ω×r) + α×r, the rate's
    steps between cells included). Velocity and angular
    rate are first-order low-passed white noise, exact Ornstein–Uhlenbeck steps from one grid
    point to the next with a draw of the noise stream MOTION per cell (so velocity has the
    spectrum of eq. 14 at the grid points); within a cell the rate and the acceleration are
    constant, so orientation and velocity are exact at every time and a sample over any
    interval depends on that interval alone (systems/simulation/core/human_motion.c).
    Parameters outside their plausible ranges (profile_table.py) are refused with ValueError.
    """

    delta_v: float = 1.0
    omega_c: float = 10.0
    rot_rms: float = 1.0
    rot_cutoff: float = 5.0
    g: float = STANDARD_GRAVITY
    grid: float | None = None
    lever_x: float = 0.0
    lever_y: float = 0.0
    lever_z: float = 0.0

    def __post_init__(self):
        grid = HUMAN_GRID if self.grid is None else self.grid
        _core.profile_check("human", np.array([*self._params()[:4], grid, *self.lever], dtype=float), self.g)

    def _params(self) -> tuple:
        return self.delta_v, self.omega_c, self.rot_rms, self.rot_cutoff, self.g

    @property
    def lever(self) -> np.ndarray:
        """The lever arm r (3, m, body frame)."""
        return np.array([self.lever_x, self.lever_y, self.lever_z], dtype=float)

    def coefficients(self, fs: float) -> np.ndarray:
        """[phi_v, sig_v, phi_w, sig_w, Ts, g, lever (3)] of the exact OU steps of a grid cell of 1/fs s."""
        return _core.human_coefficients(*self._params(), self.lever, fs)

    def generate(self, duration: float, fs: float, seed: int = 0) -> Motion:
        """Sample duration (s) at fs (Hz) from a fixed seed (the noise stream MOTION of
        systems.simulation.noise); starts level, at rest. With grid None the grid is the sample
        interval (a cell per sample); else the motion on its grid, sampled over (t[k−1], t[k]]."""
        n = int(round(duration * fs))
        if n < 1:
            raise ValueError(f"duration·fs must give at least one sample, got {duration!r}·{fs!r}")
        out = np.empty((n, _core.HUMAN_N_OUT))
        if self.grid is None:
            _core.human_run(self.initial_state(), normals(seed, MOTION, n), self.coefficients(fs), out)
        else:
            self.stream(seed).run(np.arange(1, n + 1) / fs, out)
        return Motion(fs, out[:, 6:10], out[:, 0:3], out[:, 3:6])

    def system(self, fs: float, name: str = "motion"):
        """Discrete python-control system: inputs eps_v_x..z, eps_w_x..z (unit normal
        noise per sample); states v (m/s), omega (rad/s), q; outputs TRUTH_OUTPUTS. A cell
        per sample: grid None (or 1/fs). Marked with its C step, "human" (numbers:
        coefficients(fs)); at rest (no noise): initial_state()."""
        if self.grid is not None and self.grid != 1.0 / fs:
            raise ValueError(f"the system takes a grid cell per sample: grid {self.grid!r} s at fs {fs!r} Hz")
        coef = self.coefficients(fs)

        def advance(state, u):
            out = np.empty((1, _core.HUMAN_N_OUT))
            _core.human_run(state, np.ascontiguousarray(u, dtype=float).reshape(1, 6), coef, out)
            return state, out[0]

        system = sample_system(
            advance, [f"eps_{s}_{a}" for s in "vw" for a in AXES], TRUTH_OUTPUTS,
            [f"v_{a}" for a in AXES] + [f"w_{a}" for a in AXES] + ["qm_w", "qm_x", "qm_y", "qm_z"], coef[4], name)
        return with_c_step(system, CStep("human", coef[4], numbers=tuple(map(float, coef)),
                                         rest=lambda u: self.initial_state()))

    @staticmethod
    def initial_state() -> np.ndarray:
        """At rest, level: v = 0, ω = 0, q = identity."""
        return np.array([0, 0, 0, 0, 0, 0, 1.0, 0, 0, 0])

    def start_quat(self) -> np.ndarray:
        """The orientation at time 0 (4, sensor → earth): level."""
        return self.initial_state()[6:10]

    def stream(self, seed: int = 0) -> _core.HumanStream:
        """The motion on its grid (None: profile_table.py's default) over any intervals from time 0
        (for the motion FMU): step(t, h) gives (gyr, specific force, quat) for the interval (t − h, t]
        as generate() samples it."""
        return _core.HumanStream(*self._params()[:4], HUMAN_GRID if self.grid is None else self.grid, self.lever,
                                 self.g, seed)


@dataclass(frozen=True)
class ClosedForm:
    """A motion given by closed forms of orientation R(t) (sensor → earth) and earth-frame
    velocity v(t): the C core's profile name (lever_arm, incline, coning, sine_rotation,
    step_rotation, linear_motion, offset_rotation, phone_flat, running, robot_arm; their formulas in
    systems/simulation/core/closed_form.h) with its parameters in profile_table.py's order.
    Sampled over (t − h, t]: gyr is the rotation vector of R(t−h)ᵀR(t) over h (so
    integrating it reproduces R exactly) and the specific force is R(t)ᵀ·((v(t) − v(t−h))/h + g·ẑ)."""

    name: str
    params: tuple
    g: float = STANDARD_GRAVITY

    def __post_init__(self):
        _core.profile_check(self.name, np.array(self.params, dtype=float), self.g)

    def at(self, t, h: float):
        """(gyr N×3, specific force N×3, quat N×4) for the intervals ending at times t."""
        t = np.ascontiguousarray(np.atleast_1d(t), dtype=float)
        gyr, acc, quat = np.empty((len(t), 3)), np.empty((len(t), 3)), np.empty((len(t), 4))
        _core.closed_form_run(self.name, np.array(self.params, dtype=float), self.g, t, h, gyr, acc, quat)
        return gyr, acc, quat

    def start_quat(self) -> np.ndarray:
        """The orientation at time 0 (4, sensor → earth): R(0)."""
        return self.at(0.0, 1.0)[2][0]

    def generate(self, duration: float, fs: float, seed: int = 0) -> Motion:
        """Sample duration (s) at fs (Hz); seed is unused (the motion is deterministic)."""
        t = np.arange(1, int(round(duration * fs)) + 1) / fs
        gyr, acc, quat = self.at(t, 1.0 / fs)
        return Motion(fs, quat, gyr, acc)

    def system(self, fs: float, name: str = "motion"):
        """Discrete python-control system of sample rate fs (Hz), no inputs: outputs
        TRUTH_OUTPUTS at sample k those of the interval ending at (k + 1)/fs, as generate()
        samples them; state k, the samples taken (x0: 0). Marked with its C step,
        "closed_form" (the profile's name; numbers its params, then g)."""
        h = 1.0 / fs

        def advance(state, u):
            gyr, acc, quat = self.at((state[0] + 1.0) * h, h)
            return state + 1.0, np.concatenate([gyr[0], acc[0], quat[0]])

        system = sample_system(advance, [], TRUTH_OUTPUTS, ["k"], h, name)
        return with_c_step(system, CStep("closed_form", h, self.name,
                                         numbers=tuple(float(p) for p in (*self.params, self.g))))

    def stream(self, seed: int = 0) -> "ClosedForm":
        """Sample by sample: step(t, h) gives the interval (t − h, t], as generate() does."""
        return self

    def step(self, t: float, h: float):
        """(gyr, specific force, quat) of the interval (t − h, t]; ValueError where the step's
        arithmetic overflows (outputs not finite), as MotionProfile.fmu refuses it."""
        gyr, acc, quat = self.at(t, h)
        if not (np.isfinite(gyr).all() and np.isfinite(acc).all() and np.isfinite(quat).all()):
            raise ValueError(f"a step of {h!r} s to {t!r} s overflows the motion's arithmetic")
        return gyr[0], acc[0], quat[0]


@dataclass(frozen=True)
class Profile:
    """A named motion with documented parameters (blocks.params.Param), from
    systems/simulation/profile_table.py."""

    name: str
    summary: str
    params: tuple

    def motion(self, overrides: dict | None = None, g: float = STANDARD_GRAVITY):
        """The motion for these parameter overrides (unknown names and values outside the plausible
        ranges of profile_table.py are refused with ValueError)."""
        known = {p.name: p.default for p in self.params}
        for name, value in (overrides or {}).items():
            if name not in known:
                raise ValueError(f"unknown parameter {name!r} for profile {self.name!r}; known: {', '.join(known)}")
            known[name] = float(value)
        if self.name == "human":
            return HumanMotion(**known, g=g)
        return ClosedForm(self.name, tuple(known.values()), g)


PROFILES = {name: Profile(name, summary, params) for name, (summary, params) in profile_table.PROFILES.items()}


def profile(name: str) -> Profile:
    """The motion profile of that name (PROFILES: human, lever_arm, incline, coning, …);
    its .motion(overrides) is the motion with exact truth, its .params the parameters."""
    try:
        return PROFILES[name]
    except KeyError:
        raise ValueError(f"unknown profile {name!r}; available: {', '.join(PROFILES)}") from None
