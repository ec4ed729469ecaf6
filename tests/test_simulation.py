"""The simulation (systems/simulation/core through the public API) against independent truth:
the noise streams are Box–Muller of numpy's Philox4x64-10 blocks; the closed-form profiles
are their formulas, evaluated here with scipy's Rotation; the human motion is the exact
Ornstein–Uhlenbeck recursion of its docstring driven by the stream MOTION, a step per cell of its
grid, sampled by composing the cells' turns and velocity changes; the sensor is
Rizun's eqs. 1–2 with the streams SENSOR and MAGNETOMETER and a linear-interpolating delay
line; the noise densities measured over a long run are the parameters; refusals keep their
words."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.signal import welch
from scipy.spatial.transform import Rotation

from attitude_fmu import HumanMotion, ImuModel, _core, profile
from attitude_fmu.systems.simulation.motion import PROFILES
from attitude_fmu.systems.simulation.noise import MAGNETOMETER, MOTION, SENSOR, normals
from tests.motions import ClosedFormMotion, still

FS = 100.0
G = 9.79  # m/s², not the default: the profiles take it


# ---- the noise streams

def _philox_normals(seed, stream, n, width, first=0):
    """Normal i of sample k: lane i mod 4 of the Philox4x64-10 block of counter (k, ⌊i/4⌋, 0, 0)
    under the key (seed, stream), numpy's Philox; lanes (0, 1) and (2, 3) Box–Muller pairs of
    the uniforms ((word >> 12) + ½)·2⁻⁵²."""
    key = seed + (stream << 64)
    blocks = (width + 3) // 4
    # numpy counts its counter up before each block it draws: counter − 1
    words = np.array([[np.random.Philox(counter=(k + (j << 64) - 1) % 2**256, key=key).random_raw(4)
                       for j in range(blocks)] for k in range(first, first + n)]).reshape(n, 4 * blocks)
    u = ((words >> np.uint64(12)).astype(float) + 0.5) * 2.0**-52
    r, angle = np.sqrt(-2.0 * np.log(u[:, 0::2])), 2.0 * math.pi * u[:, 1::2]
    return np.stack([r * np.cos(angle), r * np.sin(angle)], axis=2).reshape(n, 4 * blocks)[:, :width]


@pytest.mark.parametrize("seed, stream, width, first", [(0, MOTION, 6, 0), (2**40 + 3, SENSOR, 6, 0),
                                                        (2**64 - 1, MAGNETOMETER, 3, 0), (7, SENSOR, 6, 10**12),
                                                        (123456789, MOTION, 9, 2**63)])
def test_the_normals_are_box_muller_of_numpys_philox(seed, stream, width, first):
    got = normals(seed, stream, 300, width, first=first)
    assert np.abs(got - _philox_normals(seed, stream, 300, width, first)).max() < 1e-13


def test_a_stream_read_from_a_later_sample_continues_it():
    whole = normals(5, SENSOR, 400)
    assert np.array_equal(normals(5, SENSOR, 150, first=250), whole[250:])
    assert not np.array_equal(normals(6, SENSOR, 400), whole) and not np.array_equal(normals(5, MOTION, 400), whole)


def test_the_streams_are_unit_normal_and_independent():
    z = np.hstack([normals(3, s, 100_000) for s in (MOTION, SENSOR, MAGNETOMETER)])
    assert np.abs(z.mean(axis=0)).max() < 5 / math.sqrt(len(z))
    assert np.abs(z.std(axis=0) - 1.0).max() < 0.01
    assert np.abs(np.corrcoef(z.T) - np.eye(z.shape[1])).max() < 5 / math.sqrt(len(z))
    assert np.abs(np.corrcoef(z[1:, 0], z[:-1, 0])[0, 1]) < 5 / math.sqrt(len(z))  # from one sample to the next
    assert np.mean(np.abs(z) > 4.0) == pytest.approx(6.334e-5, rel=0.25)  # the tails: P(|z| > 4)


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, True])
def test_a_seed_outside_0_to_2_64_is_refused(seed):
    with pytest.raises(ValueError) as refused:
        normals(seed, MOTION, 1)
    assert str(refused.value) == f"seed must be a whole number in [0, 2**64), got {seed!r}"


# ---- the closed-form profiles, their formulas in scipy

def _about(axis, angle):
    """Rotations about a coordinate axis by angle (rad, N)."""
    angle = np.atleast_1d(np.asarray(angle, dtype=float))
    vectors = np.zeros((len(angle), 3))
    vectors[:, "xyz".index(axis)] = angle
    return Rotation.from_rotvec(vectors)


def _fixed(rotation, t):
    """rotation at every time of t."""
    return Rotation.from_quat(np.tile(rotation.as_quat(), (len(t), 1)))


def _step_pitch(hold, ramp):
    """Tseng's experiment 3: pitch (rad) of t, steps of 5, 10, 20, 45 and 90° each held hold s
    and back to 0 for hold s, each a raised-cosine ramp of ramp s, repeating."""
    levels = np.radians([x for size in (5.0, 10.0, 20.0, 45.0, 90.0) for x in (size, 0.0)])

    def pitch(t):
        i = np.floor(t / hold).astype(int)
        into = t - i * hold
        now, before = levels[i % len(levels)], levels[(i - 1) % len(levels)]
        blend = np.where(into < ramp, 0.5 - 0.5 * np.cos(np.pi * np.clip(into / ramp, 0, 1)), 1.0)
        return np.where(t < hold, now * blend, before + (now - before) * blend)
    return pitch


def _yaw_arm(frequency, amplitude_deg, radius, inclination_deg, pitch_deg):
    """Tseng's experiment 5: yaw ψ = amplitude·sin(2π·f·t) on an arm of radius (m), the sensor
    mounted inclined about x and pitched about y."""
    amp, w = math.radians(amplitude_deg), 2 * math.pi * frequency
    mount = Rotation.from_euler("xy", [inclination_deg, pitch_deg], degrees=True)

    def velocity(t):
        psi, psi_dot = amp * np.sin(w * t), amp * w * np.cos(w * t)
        return radius * np.column_stack([-np.sin(psi) * psi_dot, np.cos(psi) * psi_dot, np.zeros_like(t)])
    return (lambda t: _about("z", amp * np.sin(w * t)) * mount), velocity


def _incline(incline_deg, peak_acc_g, frequency, g):
    """Rizun §2.5: harmonic motion along an incline, peak acceleration peak_acc_g·g, no rotation."""
    orient = Rotation.from_euler("y", -incline_deg, degrees=True)  # sensor x up the slope
    w = 2 * math.pi * frequency
    return (lambda t: _fixed(orient, t)), lambda t: np.outer(-peak_acc_g * g / w * np.cos(w * t),
                                                             orient.apply([1.0, 0.0, 0.0]))


def _yaw_pitch_roll(yaw, pitch, roll):
    """Rz(yaw)·Ry(pitch)·Rx(roll), angles in rad (N each)."""
    return Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll]))


def _running(p, g):
    """Running: phase θ = 2π·f·t; vertical acceleration impact_g·g·Σ_{n=1..4} cos(nθ)/4, forward
    forward_g·g·cos θ, sideways sway_g·g·cos(θ/2); pitch sin θ, roll and yaw sin(θ/2)."""
    w = 2 * math.pi * p["step_frequency"]

    def velocity(t):
        up = sum(np.sin(n * w * t) / n for n in range(1, 5)) / (4 * w)
        return g * np.column_stack([p["forward_g"] * np.sin(w * t) / w, 2 * p["sway_g"] * np.sin(w * t / 2) / w,
                                    p["impact_g"] * up])
    return (lambda t: _yaw_pitch_roll(*(math.radians(p[k]) * f(a * w * t) for k, f, a in (
        ("yaw_deg", np.sin, 0.5), ("pitch_deg", np.sin, 1.0), ("roll_deg", np.sin, 0.5))))), velocity


ROBOT_MOVES = ((2, 1.0), (0, 0.5), (1, -0.5), (1, 0.5), (0, -0.5), (2, -1.0))  # body axis, share of the angle


def _robot_arm(p):
    """The wrist turns about body axes by shares of angle_deg (ROBOT_MOVES, back to the start), each move
    of minimum jerk s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ over move s, then dwell s at rest; the sensor at the lever arm r
    moves with v = R·(ω×r)."""
    angle, period = math.radians(p["angle_deg"]), p["move"] + p["dwell"]
    lever = np.array([p["lever_x"], p["lever_y"], p["lever_z"]])

    def pose(t):
        i = np.floor(t / period)
        j = (i % len(ROBOT_MOVES)).astype(int)
        tau = np.clip((t - i * period) / p["move"], 0.0, 1.0)
        s, ds = tau**3 * (10 - 15 * tau + 6 * tau**2), 30 * tau**2 * (1 - tau) ** 2 / p["move"]
        axes = np.eye(3)[[ROBOT_MOVES[k][0] for k in j]] * np.array([ROBOT_MOVES[k][1] for k in j])[:, None] * angle
        before = [Rotation.identity()]
        for axis, share in ROBOT_MOVES[:-1]:
            before.append(before[-1] * Rotation.from_rotvec(np.eye(3)[axis] * share * angle))
        start = Rotation.concatenate([before[k] for k in j])
        return start * Rotation.from_rotvec(axes * s[:, None]), axes * ds[:, None]

    return (lambda t: pose(t)[0]), lambda t: pose(t)[0].apply(np.cross(pose(t)[1], lever))


# name → (parameters, g) → (orientation R(t), earth-frame velocity v(t)): the profiles' definitions
CLOSED_FORMS = {
    "lever_arm": lambda p, g: (
        lambda t: _about("z", p["rate"] * t) * Rotation.from_euler("xy", (20.0, -10.0), degrees=True),
        lambda t: p["rate"] * p["radius"] * np.column_stack([-np.sin(p["rate"] * t), np.cos(p["rate"] * t),
                                                             np.zeros_like(t)])),
    "incline": lambda p, g: _incline(p["incline_deg"], p["peak_acc_g"], p["frequency"], g),
    "coning": lambda p, g: (
        lambda t: _about("z", p["rate"] * t) * _about("x", np.full(len(t), p["theta"])) * _about("z", -p["rate"] * t),
        still),
    "sine_rotation": lambda p, g: (
        lambda t: _about("y", math.radians(p["amplitude_deg"]) * np.sin(2 * math.pi * p["frequency"] * t))
        * _about("x", np.full(len(t), math.radians(p["inclination_deg"]))), still),
    "step_rotation": lambda p, g: ((lambda t: _about("y", _step_pitch(p["hold"], p["ramp"])(t))), still),
    "linear_motion": lambda p, g: (
        lambda t: _fixed(Rotation.from_euler("XYZ", [p["mount_x_deg"], p["mount_y_deg"], p["mount_z_deg"]],
                                             degrees=True), t),
        lambda t: np.outer(p["amplitude"] * math.pi / p["period"] * np.sin(2 * math.pi / p["period"] * t),
                           [1.0, 0.0, 0.0])),
    "offset_rotation": lambda p, g: _yaw_arm(p["frequency"], p["amplitude_deg"], p["radius"], p["inclination_deg"],
                                             p["pitch_deg"]),
    "phone_flat": lambda p, g: (
        lambda t: _yaw_pitch_roll(*(math.radians(p[k]) * f(a * 2 * math.pi * p["frequency"] * t) for k, f, a in (
            ("yaw_deg", np.sin, 0.5), ("tilt_deg", np.sin, 0.7), ("tilt_deg", np.sin, 1.0)))),
        lambda t: p["travel"] * 2 * math.pi * p["frequency"] * np.column_stack([
            np.sin(2 * math.pi * p["frequency"] * t), 0.7 * np.sin(1.4 * math.pi * p["frequency"] * t),
            np.zeros_like(t)])),
    "running": _running,
    "robot_arm": lambda p, g: _robot_arm(p),
}


def _same_rotations(q, p):
    """Largest distance of unit quaternions q from p, either sign."""
    return np.minimum(np.abs(q - p).max(axis=1), np.abs(q + p).max(axis=1)).max()


def test_every_profile_but_human_has_its_closed_form_here():
    assert set(CLOSED_FORMS) == set(PROFILES) - {"human"}


@pytest.mark.parametrize("name", sorted(CLOSED_FORMS))
@pytest.mark.parametrize("changed", [False, True])
def test_a_closed_form_profile_samples_its_formula(name, changed):
    """Over (t − h, t]: quat is R(t); gyr the rotation vector of R(t−h)ᵀ·R(t) over h (so
    integrating it gives R exactly); acc R(t)ᵀ·((v(t) − v(t−h))/h + g·ẑ) (tests/motions.py);
    60 s (many turns), at its defaults and with every parameter changed, within 1e-12 of each
    quantity's scale."""
    params = {p.name: (1.3 * p.default + 0.7 if changed else p.default) for p in PROFILES[name].params}
    motion = profile(name).motion(params if changed else {}, g=G).generate(60.0, FS)
    truth = ClosedFormMotion(*CLOSED_FORMS[name](params, G), g=G).generate(60.0, FS)
    assert len(motion.gyr) == 6000 and np.ptp(motion.gyr, axis=0).max() + np.ptp(motion.acc, axis=0).max() > 0
    assert _same_rotations(motion.quat, truth.quat) < 1e-12
    assert np.abs(motion.gyr - truth.gyr).max() < 1e-12 * max(1.0, np.abs(truth.gyr).max())
    assert np.abs(motion.acc - truth.acc).max() < 1e-12 * max(1.0, np.abs(truth.acc).max())


# ---- the human motion: Ornstein–Uhlenbeck steps of the stream MOTION

@pytest.mark.parametrize("motion, seed", [(HumanMotion(), 0), (HumanMotion(0.4, 6.0, 2.5, 9.0, G), 2**33 + 5)])
def test_the_human_motion_is_the_ou_recursion_of_its_noise_stream(motion, seed):
    """v_k = φ_v·v_{k−1} + σ_v·z_k[0:3], ω_k = φ_w·ω_{k−1} + σ_w·z_k[3:6] with z the stream MOTION,
    φ = exp(−ω·Ts), σ_v² = δ_v²·ω_c/4·(1 − φ_v²) (eq. 14's variance), σ_w² = rot_rms²·(1 − φ_w²);
    the motion starts level and at rest; gyr[k] is ω_k, the rotation of each interval; the
    velocity is the earth-frame specific force less g, integrated."""
    n, Ts = 3000, 1.0 / FS
    run = motion.generate(n / FS, FS, seed)
    z = normals(seed, MOTION, n)
    rot = Rotation.from_quat(run.quat, scalar_first=True)
    steps = Rotation.concatenate([Rotation.identity(), rot[:-1]]).inv() * rot  # from level at rest
    assert np.abs(steps.as_rotvec() - run.gyr * Ts).max() < 1e-14
    velocity = np.cumsum(rot.apply(run.acc) - [0.0, 0.0, motion.g], axis=0) * Ts
    phi_v, phi_w = math.exp(-motion.omega_c * Ts), math.exp(-motion.rot_cutoff * Ts)
    sigma_v = math.sqrt(motion.delta_v**2 * motion.omega_c / 4.0 * (1.0 - phi_v**2))
    sigma_w = math.sqrt(motion.rot_rms**2 * (1.0 - phi_w**2))
    before = np.vstack([np.zeros((1, 3)), velocity[:-1]])
    assert np.abs((velocity - phi_v * before) / sigma_v - z[:, 0:3]).max() < 1e-9
    omega_before = np.vstack([np.zeros((1, 3)), run.gyr[:-1]])
    assert np.abs((run.gyr - phi_w * omega_before) / sigma_w - z[:, 3:6]).max() < 1e-9


@pytest.mark.parametrize("values, message", [
    ({"delta_v": -1.0}, "parameter human_delta_v = -1.0 m/s/√Hz is outside its plausible range [0, 100] m/s/√Hz"),
    ({"omega_c": math.nan}, "parameter human_omega_c = nan rad/s is outside its plausible range [0.0001, 100000] rad/s"),
    ({"rot_cutoff": -1.0}, "parameter human_rot_cutoff = -1.0 rad/s is outside its plausible range [0.0001, 100000] "
                           "rad/s"),
    ({"g": math.inf}, "parameter g = inf m/s^2 is outside its plausible range [1, 30] m/s^2"),
    ({"rot_rms": -0.5}, "parameter human_rot_rms = -0.5 rad/s is outside its plausible range [0, 69.8132] rad/s"),
    ({"grid": 0.0}, "parameter human_grid = 0.0 s is outside its plausible range [1e-06, 1] s"),
])
def test_the_human_motion_refuses_bad_parameters_in_its_words(values, message):
    with pytest.raises(ValueError) as refused:
        HumanMotion(**{"delta_v": 1.0, "omega_c": 10.0, "rot_rms": 1.0, "rot_cutoff": 5.0, "g": 9.81, **values})
    assert str(refused.value) == message


@pytest.mark.parametrize("cells", [1, 5])
def test_the_human_motion_on_its_grid_is_the_ou_recursion_per_cell_sampled(cells):
    """On a grid of G = Ts/cells: v_j = φ_v·v_{j−1} + σ_v·z_j[0:3], ω_j = φ_w·ω_{j−1} + σ_w·z_j[3:6] per
    cell j (z the stream MOTION, φ and σ for G), the orientation turned by ω_j·G over cell j; the samples
    over (t[k−1], t[k]]: quat the orientation at t[k], gyr the rotation vector of the turn over the
    interval over Ts, the earth-frame specific force less g the velocity's change over Ts."""
    motion, seed, n = HumanMotion(0.4, 6.0, 2.5, 9.0, G, grid=1.0 / (FS * cells)), 7, 400
    run = motion.generate(n / FS, FS, seed)
    grid, z = motion.grid, normals(seed, MOTION, n * cells)
    phi_v, phi_w = math.exp(-motion.omega_c * grid), math.exp(-motion.rot_cutoff * grid)
    sigma_v = math.sqrt(motion.delta_v**2 * motion.omega_c / 4.0 * (1.0 - phi_v**2))
    sigma_w = math.sqrt(motion.rot_rms**2 * (1.0 - phi_w**2))
    v, w = np.zeros((n * cells + 1, 3)), np.zeros((n * cells + 1, 3))
    for j in range(n * cells):
        v[j + 1] = phi_v * v[j] + sigma_v * z[j, 0:3]
        w[j + 1] = phi_w * w[j] + sigma_w * z[j, 3:6]
    turns = Rotation.from_rotvec(w[1:] * grid)
    orientation = [Rotation.identity()]
    for turn in turns:
        orientation.append(orientation[-1] * turn)
    truth = Rotation.concatenate(orientation[cells::cells])
    assert _same_rotations(run.quat, truth.as_quat(scalar_first=True)) < 1e-12
    before = Rotation.concatenate([Rotation.identity(), truth[:-1]])
    assert np.abs(run.gyr - (before.inv() * truth).as_rotvec() * FS).max() < 1e-10
    acc = Rotation.from_quat(run.quat, scalar_first=True).apply(run.acc) - [0.0, 0.0, G]
    assert np.abs(acc - np.diff(v[::cells], axis=0) * FS).max() < 1e-9


def test_the_human_motion_with_a_cell_per_sample_is_the_same_on_a_grid_of_the_sample_time():
    """grid None (a cell per sample, the batch's) and grid 1/fs: one process (to the rounding of the
    sample times k/fs against the cells' ends k·grid)."""
    motion = HumanMotion(0.4, 6.0, 2.5, 9.0, G)
    a, b = motion.generate(30.0, FS, 5), HumanMotion(0.4, 6.0, 2.5, 9.0, G, grid=1.0 / FS).generate(30.0, FS, 5)
    assert _same_rotations(a.quat, b.quat) < 1e-13
    assert np.abs(a.gyr - b.gyr).max() < 1e-10 and np.abs(a.acc - b.acc).max() < 1e-10 * np.abs(a.acc).max()


# ---- a lever arm: the sensor at r from the motion's point feels ω×(ω×r) + α×r

LEVER = np.array([0.3, -0.1, 0.2])  # m, body frame
DELTA = 1e-6  # s: the finite differences' step


def _lever_share(motion, earlier, later, span):
    """The lever arm's share of the specific force of each sample of a motion that starts at rest (N×3,
    body frame): the mean acceleration of the point R·LEVER over (t − h, t], (v(t) − v(t − h))/h, turned into
    the body at t, its velocity v at each sample time the difference of the orientations earlier and later
    (N×4 each) span s apart."""
    v = (Rotation.from_quat(later, scalar_first=True).apply(LEVER)
         - Rotation.from_quat(earlier, scalar_first=True).apply(LEVER)) / span
    before = np.vstack([np.zeros((1, 3)), v[:-1]])
    return Rotation.from_quat(motion.quat, scalar_first=True).inv().apply((v - before) * motion.fs)


def test_a_lever_arm_on_the_human_motion_adds_its_points_acceleration():
    """The human motion on a grid of 1 ms at 100 Hz, the sensor at LEVER: its specific force is the one
    at the motion's point (the same seed, no lever) plus the mean acceleration of the point R·r, whose
    velocity just before each sample time comes from the orientations DELTA apart (the rate is constant
    within a cell and steps between cells, the steps' α×r included), within 1e-4 of its scale; the rate and
    the orientation do not change. A cell per sample gives the same."""
    motion = HumanMotion(0.4, 6.0, 2.5, 9.0, G, grid=1e-3, lever_x=LEVER[0], lever_y=LEVER[1], lever_z=LEVER[2])
    moved, still_point = motion.generate(5.0, FS, seed=6), replace(motion, lever_x=0.0, lever_y=0.0,
                                                                    lever_z=0.0).generate(5.0, FS, seed=6)
    assert np.array_equal(moved.quat, still_point.quat) and np.array_equal(moved.gyr, still_point.gyr)
    out = np.empty((2 * len(moved.t), _core.HUMAN_N_OUT))
    motion.stream(6).run(np.column_stack([moved.t - DELTA, moved.t]).ravel(), out)
    share = _lever_share(moved, out[0::2, 6:10], out[1::2, 6:10], DELTA)
    assert np.abs(moved.acc - still_point.acc - share).max() < 1e-4 * np.abs(share).max()
    per_sample = HumanMotion(0.4, 6.0, 2.5, 9.0, G, lever_x=LEVER[0], lever_y=LEVER[1], lever_z=LEVER[2])
    a, b = per_sample.generate(5.0, FS, 2), replace(per_sample, grid=1.0 / FS).generate(5.0, FS, 2)
    assert np.abs(a.acc - b.acc).max() < 1e-10 * np.abs(a.acc).max()


def test_a_lever_arm_on_the_robot_arm_adds_its_points_acceleration():
    """The robot arm (a smooth rate) with the sensor at LEVER: the specific force less the wrist's (no
    lever) is the mean acceleration of the point R·r over each sample, its velocity by central differences
    of the orientation, within 1e-5 of its scale; and it is ω×(ω×r) + α×r to first order in h."""
    arm = profile("robot_arm")
    moved = arm.motion(dict(zip(("lever_x", "lever_y", "lever_z"), LEVER)), g=G).generate(12.0, FS)
    wrist_motion = arm.motion(g=G)
    wrist = wrist_motion.generate(12.0, FS)
    share = _lever_share(moved, *(wrist_motion.at(moved.t + d, 1.0 / FS)[2] for d in (-DELTA, DELTA)), 2 * DELTA)
    assert np.abs(moved.acc - wrist.acc - share).max() < 1e-5 * np.abs(share).max()
    w = moved.gyr  # the mean rate over each sample: ω(t − h/2) to second order
    alpha = np.gradient(w, 1.0 / FS, axis=0)
    first_order = np.cross(w, np.cross(w, LEVER)) + np.cross(alpha, LEVER)
    assert np.abs(moved.acc - wrist.acc - first_order).max() < 0.05 * np.abs(first_order).max()


# ---- the phone, running and robot-arm motions: their rates are their orientations' derivatives

def _euler_rate(angles, rates):
    """The body rate (N×3, rad/s) of Rz(ψ)·Ry(θ)·Rx(φ) from the angles (ψ, θ, φ) and their time derivatives
    (each N): Rx(φ)ᵀ·Ry(θ)ᵀ·ψ̇ẑ + Rx(φ)ᵀ·θ̇ŷ + φ̇x̂."""
    (psi, theta, phi), (psi_dot, theta_dot, phi_dot) = angles, rates
    roll, pitch = Rotation.from_euler("x", phi[:, None]), Rotation.from_euler("y", theta[:, None])
    z, y = np.column_stack([0 * psi, 0 * psi, psi_dot]), np.column_stack([0 * psi, theta_dot, 0 * psi])
    return roll.inv().apply(pitch.inv().apply(z)) + roll.inv().apply(y) + np.column_stack([phi_dot, 0 * psi, 0 * psi])


def _analytic_rate(name, p, t):
    """The body rate (N×3, rad/s) at the times t, by differentiating each profile's angles by hand."""
    if name == "phone_flat":
        w, a, b = 2 * math.pi * p["frequency"], math.radians(p["yaw_deg"]), math.radians(p["tilt_deg"])
        parts = ((a, 0.5 * w), (b, 0.7 * w), (b, w))
    else:
        w = 2 * math.pi * p["step_frequency"]
        parts = ((math.radians(p["yaw_deg"]), 0.5 * w), (math.radians(p["pitch_deg"]), w),
                 (math.radians(p["roll_deg"]), 0.5 * w))
    return _euler_rate([k * np.sin(c * t) for k, c in parts], [k * c * np.cos(c * t) for k, c in parts])


@pytest.mark.parametrize("name", ["phone_flat", "running"])
def test_the_phone_and_running_rates_are_their_euler_angles_derivatives(name):
    """Over samples of 1e-4 s, gyr (the mean rate over each) is the body rate of the hand-differentiated
    Euler angles at the sample's middle, within 1e-6 of its scale (the midpoint rule's error, h²·ω̈/24)."""
    p = {q.name: q.default for q in PROFILES[name].params}
    h = 1e-4
    t = np.arange(1, 20001) * h
    gyr = profile(name).motion(g=G).at(t, h)[0]
    expected = _analytic_rate(name, p, t - h / 2)
    assert np.abs(gyr - expected).max() < 1e-6 * np.abs(expected).max()


def test_the_robot_arms_rate_is_its_minimum_jerk_law():
    """Over samples of 1e-4 s, gyr is the move's axis times angle·ds/dt at the sample's middle, ds/dt =
    30τ²(1 − τ)²/move, within 1e-6 of its peak 1.875·angle/move; 0 while it dwells."""
    p = {q.name: q.default for q in PROFILES["robot_arm"].params}
    h, angle = 1e-4, math.radians(p["angle_deg"])
    t = np.arange(1, 6 * 17001) * h
    gyr = profile("robot_arm").motion(g=G).at(t, h)[0]
    period, mid = p["move"] + p["dwell"], t - h / 2
    i = np.floor(mid / period)
    tau = np.clip((mid - i * period) / p["move"], 0.0, 1.0)
    axes = np.array([np.eye(3)[ROBOT_MOVES[int(k) % 6][0]] * ROBOT_MOVES[int(k) % 6][1] for k in i])
    expected = axes * (angle * 30 * tau**2 * (1 - tau) ** 2 / p["move"])[:, None]
    peak = 1.875 * angle / p["move"]
    assert np.abs(gyr - expected).max() < 1e-6 * peak
    assert np.abs(expected).max() == pytest.approx(peak, rel=1e-6)


# ---- the phone, running and robot-arm motions: what they stand for

def _earth_acceleration(motion):
    """The earth-frame acceleration (N×3, m/s²): the specific force turned by the orientation, less g up."""
    return Rotation.from_quat(motion.quat, scalar_first=True).apply(motion.acc) - [0.0, 0.0, G]


def test_the_phone_lies_mostly_flat_and_slides_a_little():
    """phone_flat at its defaults: tilted at most tilt_deg·√2 (roll and pitch), yawing ±yaw_deg; its
    acceleration at most travel·w²·√(1 + 0.7⁴)."""
    motion = profile("phone_flat").motion(g=G).generate(60.0, FS)
    tilt = np.degrees(np.arccos(np.clip(motion.up[:, 2], -1, 1)))
    assert 2.5 < tilt.max() <= 3.0 * math.sqrt(2) + 1e-9
    yaw = Rotation.from_quat(motion.quat, scalar_first=True).as_euler("ZYX", degrees=True)[:, 0]
    assert 19.0 < np.abs(yaw).max() <= 20.0 + 1e-9
    w = 2 * math.pi * 0.2
    assert np.linalg.norm(_earth_acceleration(motion), axis=1).max() <= 0.05 * w**2 * math.sqrt(1 + 0.7**4) * 1.01


def test_running_has_impacts_at_its_step_frequency_and_no_mean_acceleration():
    """running at its defaults, 1 kHz: the vertical acceleration peaks at impact_g·g at every step (2.7 Hz:
    its spectrum's strongest line), falls to −0.38·impact_g·g between (the specific force near 0: flight);
    over whole strides (two steps) the acceleration averages to 0."""
    fs = 1000.0
    motion = profile("running").motion(g=G).generate(20.0 / 1.35, fs)  # 20 strides
    a = _earth_acceleration(motion)
    assert a[:, 2].max() == pytest.approx(2.5 * G, rel=1e-3)
    assert a[:, 2].min() == pytest.approx(-0.37989 * 2.5 * G, rel=1e-3)
    assert np.abs(a.mean(axis=0)).max() < 1e-3
    spectrum = np.abs(np.fft.rfft(a[:, 2]))
    assert np.fft.rfftfreq(len(a), 1.0 / fs)[np.argmax(spectrum)] == pytest.approx(2.7, abs=0.1)


def test_the_robot_arm_turns_fast_with_little_linear_acceleration():
    """robot_arm at its defaults with a 0.3 m lever arm: peak rate 1.875·angle/move (minimum jerk), and
    the sensor's acceleration stays below a fifth of g (rms below a tenth); back to the start after its
    six moves."""
    motion = profile("robot_arm").motion({"lever_x": 0.3}, g=G).generate(6 * 1.7, FS)
    assert np.linalg.norm(motion.gyr, axis=1).max() == pytest.approx(1.875 * math.pi / 2 / 1.2, rel=1e-3)
    a = np.linalg.norm(_earth_acceleration(motion), axis=1)
    assert a.max() < 0.2 * G and np.sqrt(np.mean(a**2)) < 0.1 * G
    assert _same_rotations(motion.quat[-1:], np.array([[1.0, 0.0, 0.0, 0.0]])) < 1e-12


@pytest.mark.parametrize("name", sorted(PROFILES))
@pytest.mark.parametrize("edge", ["low", "high"])
def test_every_profile_at_the_edges_of_its_ranges_gives_finite_samples_for_a_long_time(name, edge):
    """Every parameter at the low (high) end of its plausible range at once, g too; samples up to
    10⁶ s (the step levels of step_rotation, the turns of the rotations): finite, unit quaternions."""
    params = {p.name: getattr(p, edge) for p in PROFILES[name].params}
    motion = profile(name).motion(params, g=1.0 if edge == "low" else 30.0)
    if name == "human":
        stream = motion.stream(2)
        rows = [np.concatenate(stream.step(t, 1e-3)) for t in (1e-3, 0.5, 2.0, 2.5)]
    else:
        rows = [np.concatenate(sample, axis=1) for sample in [motion.at([0.01, 1.0, 1e3, 1e6], 1e-3)]][0]
    rows = np.array(rows)
    assert np.isfinite(rows).all(), rows
    assert np.abs(np.linalg.norm(rows[:, 6:10], axis=1) - 1.0).max() < 1e-9


# ---- the sensor: Rizun's eqs. 1–2, the noise streams, a delay line

SENSOR_ERRORS = dict(delta_n=math.radians(0.1), gyr_offset=(0.01, -0.02, 0.03),
                     gyr_scale=((0.01, -0.002, 0.0), (0.003, 0.0, 0.005), (0.0, 0.004, -0.02)), acc_noise=0.01,
                     acc_offset=(0.1, -0.2, 0.3), mag_noise=0.5, mag_offset=(8.0, -3.0, 12.0),
                     mag_soft_iron=((0.05, 0.02, -0.01), (0.02, -0.06, 0.03), (-0.01, 0.03, 0.04)))


def _late(x, samples):
    """x (N×…) samples·Ts late, linearly between whole samples (x constant within each
    interval), the first sample before the start."""
    whole, phase = divmod(samples, 1.0)
    whole = int(whole)
    padded = np.vstack([np.repeat(x[:1], whole + 1, axis=0), x])
    now = padded[1:len(x) + 1]  # x[k − whole]
    earlier = padded[:len(x)]  # x[k − whole − 1]
    return (1.0 - phase) * now + phase * earlier


@pytest.mark.parametrize("latency", [0.0, 0.02, 0.0234, 0.05])
def test_the_sensor_measures_eqs_1_2_with_its_noise_streams_through_its_delay_line(latency):
    """gyr = (I + S)·ω + δ_n·√(fs/2)·z[0:3] + b, acc = f + σ_a·√(fs/2)·z[3:6] + b_a with z the
    stream SENSOR, ω and f latency late (between samples: linear between the two it falls
    between); mag = (I + S_m)·m + σ_m·√(fs/2)·z_m + b_m with z_m the stream MAGNETOMETER (no delay)."""
    imu = ImuModel(**SENSOR_ERRORS, latency=latency)
    motion = HumanMotion().generate(20.0, FS, seed=3)
    gyr, acc = imu.apply(motion, seed=4)
    mag = imu.apply_mag(motion, seed=4)
    z, z_mag, scale = normals(4, SENSOR, len(gyr)), normals(4, MAGNETOMETER, len(gyr)), math.sqrt(FS / 2.0)
    omega, f = _late(motion.gyr, latency * FS), _late(motion.acc, latency * FS)
    S = np.array(SENSOR_ERRORS["gyr_scale"])
    expected_gyr = omega + omega @ S.T + SENSOR_ERRORS["delta_n"] * scale * z[:, 0:3] + SENSOR_ERRORS["gyr_offset"]
    expected_acc = f + SENSOR_ERRORS["acc_noise"] * scale * z[:, 3:6] + SENSOR_ERRORS["acc_offset"]
    soft = np.array(SENSOR_ERRORS["mag_soft_iron"])
    expected_mag = (motion.mag + motion.mag @ soft.T + SENSOR_ERRORS["mag_noise"] * scale * z_mag
                    + SENSOR_ERRORS["mag_offset"])
    assert np.abs(gyr - expected_gyr).max() < 1e-12 * np.abs(expected_gyr).max()
    assert np.abs(acc - expected_acc).max() < 1e-12 * np.abs(expected_acc).max()
    assert np.abs(mag - expected_mag).max() < 1e-12 * np.abs(expected_mag).max()


def test_a_sensor_a_whole_number_of_samples_late_shifts_the_motion_exactly():
    motion = profile("sine_rotation").motion({"inclination_deg": 20.0}).generate(10.0, FS)
    gyr, acc = ImuModel(latency=3.0 / FS).apply(motion)
    assert (gyr[3:] == motion.gyr[:-3]).all() and (acc[3:] == motion.acc[:-3]).all()
    assert (gyr[:3] == motion.gyr[0]).all()  # before the start: the first sample


@pytest.mark.parametrize("values, message", [
    ({"delta_n": -1.0}, "delta_n must be finite and non-negative, got -1.0"),
    ({"acc_noise": math.nan}, "acc_noise must be finite and non-negative, got nan"),
    ({"latency": math.inf}, "latency must be finite and non-negative, got inf"),
    ({"mag_noise": -0.1}, "mag_noise must be finite and non-negative, got -0.1"),
    ({"gyr_offset": (0.0, math.nan, 0.0)}, "gyr_offset must be 3 finite numbers, got (0.0, nan, 0.0)"),
    ({"acc_offset": (math.inf, 0.0, 0.0)}, "acc_offset must be 3 finite numbers, got (inf, 0.0, 0.0)"),
    ({"mag_offset": (0.0, 0.0, -math.inf)}, "mag_offset must be 3 finite numbers, got (0.0, 0.0, -inf)"),
    ({"gyr_scale": ((0.0, 0.0, 0.0), (0.0, 0.0, math.nan), (0.0, 0.0, 0.0))},
     "gyr_scale must be 3×3 finite numbers, got ((0.0, 0.0, 0.0), (0.0, 0.0, nan), (0.0, 0.0, 0.0))"),
    ({"gyr_scale": ((0.0, 0.0), (0.0, 0.0))}, "gyr_scale must be 3×3 finite numbers, got ((0.0, 0.0), (0.0, 0.0))"),
    ({"mag_soft_iron": ((0.0, 0.0, 0.0), (math.inf, 0.0, 0.0), (0.0, 0.0, 0.0))},
     "mag_soft_iron must be 3×3 finite numbers, got ((0.0, 0.0, 0.0), (inf, 0.0, 0.0), (0.0, 0.0, 0.0))"),
    ({"mag_soft_iron": (0.1, 0.0, 0.0)}, "mag_soft_iron must be 3×3 finite numbers, got (0.1, 0.0, 0.0)"),
])
def test_the_sensor_refuses_bad_parameters_in_its_words(values, message):
    with pytest.raises(ValueError) as refused:
        ImuModel(**values)
    assert str(refused.value) == message


def test_a_latency_longer_than_the_delay_line_is_refused():
    """The delay line holds 1021 samples: 10.2 s at 100 Hz fits, 11 s does not (the native
    sensor FMU refuses it alike: tests/test_native_chain.py)."""
    motion = HumanMotion().generate(1.0, FS, seed=1)
    assert ImuModel(latency=10.2).apply(motion)[0].shape == (100, 3)
    with pytest.raises(ValueError) as refused:
        ImuModel(latency=11.0).apply(motion)
    assert str(refused.value) == "latency 11.0 s at 100.0 Hz is longer than the delay line's 1021 samples"


def _density(x, fs):
    """The one-sided noise density (unit/√Hz) of each column of x: Welch's estimate averaged
    over the band, DC and Nyquist left out."""
    _, psd = welch(x, fs, nperseg=256, axis=0)
    return np.sqrt(psd[1:-1].mean(axis=0))


def test_the_noise_densities_measured_over_a_long_run_are_the_parameters():
    """500 s at 100 Hz at rest: the measured error's density is delta_n, acc_noise and
    mag_noise within 3 % (Welch's estimate scatters by about 0.3 % here; a per-sample s.d.
    of density·√fs instead of density·√(fs/2) is 41 % off), its mean the offset."""
    imu = ImuModel(delta_n=math.radians(0.1), acc_noise=0.02, mag_noise=0.3, gyr_offset=(0.01, 0.0, 0.0),
                   mag_offset=(5.0, 0.0, -2.0))
    motion = HumanMotion(delta_v=0.0, rot_rms=0.0).generate(500.0, FS, seed=1)
    gyr, acc = imu.apply(motion, seed=9)
    errors = (gyr - motion.gyr, acc - motion.acc, imu.apply_mag(motion, seed=9) - motion.mag)
    for error, density, offset in zip(errors, (imu.delta_n, imu.acc_noise, imu.mag_noise),
                                      (imu.gyr_offset, imu.acc_offset, imu.mag_offset)):
        assert _density(error - error.mean(axis=0), FS) == pytest.approx(np.full(3, density), rel=0.03)
        assert error.mean(axis=0) == pytest.approx(offset, abs=4 * density * math.sqrt(FS / 2) / math.sqrt(len(error)))
