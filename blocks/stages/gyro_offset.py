"""Gyroscope-offset estimator (the "gyro offset estimator" box of Rizun's Fig. 1).

At rest: the gyro and the accelerometer, each through a short low-pass (tau_short, which
takes the white noise above human motion's band out), must stay close to their values
low-passed over tau_lp (rest_gyr, rest_acc), and the gyro low-passed over tau_lp must
stay small (rest_gyr_abs), for rest_time seconds; then each gyro sample measures the offset
with the variance of the gyro's white noise, delta_n²·fs/2, in the same Kalman filter as
the tracking while moving: a first rest after an uncertain start gives the running mean
of the rest's samples, and a long rest settles on a window of delta_n/sigma_motion·
√(tau_motion/2) s (7 s by default), whatever the sample rate. Without the short low-pass
(raw samples, as vqf tests them) a gyro whose white noise alone comes near rest_gyr
(δn·√(3·fs/2), e.g. 0.1 °/s/√Hz at 250 Hz) would seldom or never rest; through it the
noise is δn·√(3/(4·tau_short)), 0.6 °/s for 0.1 °/s/√Hz at any rate. A noisier gyro
(delta_n given) raises the threshold to REST_NOISE_SIGMAS times its per-axis noise
there, δn/√(4·tau_short), so that its own noise does not break every rest (up to
0.125 °/s/√Hz the default rest_gyr is above that floor).

While moving, the offset's effect on the accelerometer is tracked in the gyro frame (the
frame integrated from the corrected gyro; R its sensor → gyro-frame rotation), the way
vqf (Laidig & Seel 2023) does. There the accelerometer is low-passed by eq. 34's
Butterworth at √2/tau_acc, which averages the motion's acceleration out as in Rizun's
filter, and an offset error Δb turns gravity at the rate R·Δb, so the low-passed
direction turns at c = H·Δb with H = Π·LP(R) (Π: the projection across gravity; LP the
same low-pass). A Kalman filter (variance from sigma_init, process noise such that the
variance settles on sigma_motion² and forgets in tau_motion) updates the estimate from
c. Guards, all from the same model:
- while the sensor turns quickly about an axis, LP(R) averages out the offset's
  components across it; directions in which H keeps less than half of them are left
  alone, since a sensor-fixed (e.g. centripetal) acceleration looks the same there;
- innovations are clipped at 4·sigma_init, the fastest turn a plausible offset makes;
- over the first tau_acc the accelerometer's low-pass is the running mean of its samples
  in the gyro frame (as the Wiener filter starts), not a Butterworth from the first
  sample, which in motion can be off by metres per second squared and would turn the
  low-passed direction for several tau_acc after; no update in the first 3·tau_acc,
  while the low-passes forget their start.
The corrected gyro is the measured one minus the estimate after its sample. Causal, one
compiled step per sample.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.control_system import sample_system
from attitude_fmu.blocks.filters.sensor_frame import time_reversed
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.methods.wiener_local import butterworth_zoh
from attitude_fmu.blocks.params import GYRO_NOISE, RATE_RAD_S, TIME_S, Param, resolve_params
from attitude_fmu.blocks.quaternion import quat_matrix, quat_multiply, quat_normalized, rotvec_quat

REST_NOISE_SIGMAS = 4.5  # the least rest_gyr in units of the gyro noise's per-axis s.d. through tau_short
PARAMS = (
    Param("rest_gyr", math.radians(2.0), "rad/s",
          "largest deviation of the gyro (through tau_short) from its low-pass at rest; at least "
          f"{REST_NOISE_SIGMAS:g} times delta_n's noise through tau_short", **RATE_RAD_S),
    Param("rest_gyr_abs", math.radians(5.0), "rad/s", "largest low-passed gyro norm at rest (offset included)",
          **RATE_RAD_S),
    Param("rest_acc", 0.5, "m/s²",
          "largest deviation of the accelerometer (through tau_short) from its low-pass at rest",
          low=1e-4, high=400.0 * 9.80665),
    Param("rest_time", 1.5, "s", "time the rest conditions must hold", **TIME_S),
    Param("tau_lp", 0.5, "s", "time constant of the low-passes of the rest detection", **TIME_S),
    Param("tau_short", 0.02, "s", "time constant of the low-pass that takes white noise out of the samples the rest "
          "detection compares with its low-passes (human motion lies below 8 Hz)", **TIME_S),
    Param("delta_n", math.radians(0.1), "rad/s/√Hz",
          "gyro noise density, one-sided (datasheet): each sample's weight at rest", **GYRO_NOISE),
    Param("tau_acc", 3.0, "s", "time constant of the accelerometer low-pass in the gyro frame (motion tracking)",
          **TIME_S),
    Param("sigma_init", math.radians(0.5), "rad/s", "uncertainty of the offset before any rest (per axis)",
          **RATE_RAD_S),
    Param("sigma_motion", math.radians(0.1), "rad/s", "uncertainty the tracking while moving settles on (per axis)",
          **RATE_RAD_S),
    Param("tau_motion", 100.0, "s", "time in which the offset may drift by sigma_motion; 0: no tracking while moving",
          allow_zero=True, high=1e6),
)
STATE_NAMES = (
    "glp_x", "glp_y", "glp_z", "alp_x", "alp_y", "alp_z",  # low-passed gyro (rad/s) and accelerometer (m/s²)
    "rest_s", "b_x", "b_y", "b_z",  # time at rest (s), offset estimate (rad/s)
    "t",  # time since the start (s)
    "q_w", "q_x", "q_y", "q_z",  # sensor → gyro frame
    *(f"a{r}_{i}" for r in "xu" for i in "xyz"),  # Butterworth rows of the accelerometer in the gyro frame
    *(f"R{r}_{i}{j}" for r in "xu" for i in "123" for j in "123"),  # Butterworth rows of R
    *(f"Rb{r}_{i}" for r in "xu" for i in "xyz"),  # Butterworth rows of R·b (rad/s)
    *(f"P_{i}{j}" for i in "xyz" for j in "xyz"),  # covariance of the offset estimate, (rad/s)²
    "gsh_x", "gsh_y", "gsh_z", "ash_x", "ash_y", "ash_z",  # gyro and accelerometer through the short low-pass
)
T, QUAT, ACC_LP, R_LP, RB_LP, COV, SHORT = 10, slice(11, 15), slice(15, 21), slice(21, 39), slice(39, 45), slice(45, 54), 54
OBSERVED = 0.5  # the least share of an offset's effect H must keep in a direction to update it
CLIP_SIGMAS = 4.0  # innovations clipped at this many sigma_init
SETTLE_TAUS = 3.0  # no update before this many tau_acc (the low-pass forgetting its start)


def resolve(overrides=None) -> dict:
    return resolve_params(PARAMS, overrides, "the gyro-offset estimator")


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts, a_lp, r, rest_gyr, rest_gyr_abs, rest_acc, rest_time, ω_acc·Ts, P0, V, W, a_short]:
    a_* = 1 − exp(−Ts/τ_*), r = δn²/(2·Ts) the variance of a gyro sample's white noise
    ((rad/s)²), rest_gyr at least REST_NOISE_SIGMAS·δn/√(4·τ_short), ω_acc = √2/τ_acc
    (rad/s); the Kalman filter has the initial variance P0 = σ_init², the process noise
    V = σ_motion²·Ts/τ_motion per sample and, while moving, the measurement noise
    W = σ_motion⁴/V + σ_motion², with which its variance settles on σ_motion² (V = 0: no
    tracking while moving)."""
    tau_motion, s2 = params["tau_motion"], params["sigma_motion"] ** 2
    V = s2 * Ts / tau_motion if tau_motion > 0 else 0.0
    return np.array([Ts, 1.0 - math.exp(-Ts / params["tau_lp"]), params["delta_n"] ** 2 / (2.0 * Ts),
                     max(params["rest_gyr"], REST_NOISE_SIGMAS * params["delta_n"] / math.sqrt(4 * params["tau_short"])),
                     params["rest_gyr_abs"], params["rest_acc"], params["rest_time"],
                     math.sqrt(2.0) / params["tau_acc"] * Ts, params["sigma_init"] ** 2, V,
                     s2 * s2 / V + s2 if V > 0 else 0.0, 1.0 - math.exp(-Ts / params["tau_short"])])


def initial_state(coef, gyr0, acc0) -> np.ndarray:
    """Low-passes (both) on the first samples, not at rest, no offset (variance P0), the gyro
    frame on the sensor, the low-pass of R settled on I (that of the accelerometer starts
    as the running mean of the first samples)."""
    state = np.zeros(len(STATE_NAMES))
    state[0:3], state[3:6] = gyr0, acc0
    state[SHORT:SHORT + 3], state[SHORT + 3:SHORT + 6] = gyr0, acc0
    state[QUAT] = (1.0, 0.0, 0.0, 0.0)
    state[R_LP][0:9] = np.eye(3).ravel()
    state[COV] = coef[8] * np.eye(3).ravel()
    return state


@kernel(inline=True)
def lowpass_step(rows, j, x, Ad, Bd):
    """Column j of the Butterworth's two state rows after the input x."""
    x0, x1 = rows[0, j], rows[1, j]
    rows[0, j] = Ad[0, 0] * x0 + Ad[0, 1] * x1 + Bd[0] * x
    rows[1, j] = Ad[1, 0] * x0 + Ad[1, 1] * x1 + Bd[1] * x


@kernel(inline=True)
def _dot(u, v):
    """u·v of two 3-vectors."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@kernel(inline=True)
def _mat_vec(M, v):
    """M·v for M 3×3 row-major (9 entries) and a 3-vector v."""
    return (M[0] * v[0] + M[1] * v[1] + M[2] * v[2], M[3] * v[0] + M[4] * v[1] + M[5] * v[2],
            M[6] * v[0] + M[7] * v[1] + M[8] * v[2])


@kernel(inline=True)
def _mat_t_vec(M, v):
    """Mᵀ·v for M 3×3 row-major (9 entries) and a 3-vector v."""
    return (M[0] * v[0] + M[3] * v[1] + M[6] * v[2], M[1] * v[0] + M[4] * v[1] + M[7] * v[2],
            M[2] * v[0] + M[5] * v[1] + M[8] * v[2])


@kernel(inline=True)
def scalar_update(b, P, h, z, w):
    """Kalman update of the offset b (P its covariance, both in place) from one scalar
    measurement z of h·b with noise variance w."""
    Ph = (P[0, 0] * h[0] + P[0, 1] * h[1] + P[0, 2] * h[2],
          P[1, 0] * h[0] + P[1, 1] * h[1] + P[1, 2] * h[2],
          P[2, 0] * h[0] + P[2, 1] * h[1] + P[2, 2] * h[2])
    inv_s = 1.0 / (_dot(h, Ph) + w)
    innovation = (z - _dot(h, b)) * inv_s
    for i in range(3):
        b[i] += Ph[i] * innovation
        for j in range(3):
            P[i, j] -= Ph[i] * Ph[j] * inv_s


@kernel(inline=True)
def plane_basis(n):
    """Two orthonormal vectors across the unit vector n."""
    # the axis least along n, crossed with n
    if abs(n[0]) <= abs(n[1]) and abs(n[0]) <= abs(n[2]):
        e = (0.0, n[2], -n[1])
    elif abs(n[1]) <= abs(n[2]):
        e = (-n[2], 0.0, n[0])
    else:
        e = (n[1], -n[0], 0.0)
    norm = math.sqrt(_dot(e, e))
    e1 = (e[0] / norm, e[1] / norm, e[2] / norm)
    return e1, (n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0])


@kernel(inline=True)
def motion_update(b, P, old, new, r_lp, rb_lp, Ts, W, clip):
    """Kalman update of the offset b (P its covariance) from the turn of the low-passed
    accelerometer from old to new (gyro frame); r_lp, rb_lp: LP(R) (row-major) and LP(R·b).

    The turn rate plus Π·LP(R·b̂) measures H·b, H = Π·LP(R) (the low-pass delays the turn
    after a change of b̂); the innovation is clipped per component. H has rank 2 at most
    (Π projects across gravity): its singular directions are those of the 2×2 problem in
    a basis (e1, e2) across gravity, in closed form. Only directions H keeps
    at least OBSERVED of are used, each as a scalar measurement u·e of (Hᵀu)·b with
    variance W (u orthonormal: the joint update, taken one direction at a time)."""
    n2 = _dot(new, new)
    if n2 == 0.0:
        return
    norm = math.sqrt(n2)
    n = (new[0] / norm, new[1] / norm, new[2] / norm)
    e1, e2 = plane_basis(n)
    b0 = (b[0], b[1], b[2])
    s = 1.0 / (n2 * Ts)
    turn = ((old[1] * new[2] - old[2] * new[1]) * s, (old[2] * new[0] - old[0] * new[2]) * s,
            (old[0] * new[1] - old[1] * new[0]) * s)
    Lb = _mat_vec(r_lp, b)
    d = (rb_lp[0] - Lb[0], rb_lp[1] - Lb[1], rb_lp[2] - Lb[2])  # LP(R·b̂) − LP(R)·b̂, across gravity below
    along = _dot(d, n)
    e = (min(max(turn[0] + d[0] - along * n[0], -clip), clip),
         min(max(turn[1] + d[1] - along * n[1], -clip), clip),
         min(max(turn[2] + d[2] - along * n[2], -clip), clip))
    # M = (e1, e2)ᵀ·LP(R), 2×3; the eigenvectors of M·Mᵀ are H's left singular directions
    m1, m2 = _mat_t_vec(r_lp, e1), _mat_t_vec(r_lp, e2)
    p11, p12, p22 = _dot(m1, m1), _dot(m1, m2), _dot(m2, m2)
    half, mean = 0.5 * (p11 - p22), 0.5 * (p11 + p22)
    radius = math.sqrt(half * half + p12 * p12)
    # M·Mᵀ's eigenvalues mean ± radius are H's squared singular values; the eigenvector of
    # the larger, in its well-conditioned form
    c, sn = (half + radius, p12) if half >= 0.0 else (p12, radius - half)
    length = math.sqrt(c * c + sn * sn)
    c, sn = (c / length, sn / length) if length > 0.0 else (1.0, 0.0)
    for a in range(2):
        if a == 1:
            c, sn = -sn, c
        if mean + (radius if a == 0 else -radius) < OBSERVED * OBSERVED:
            continue
        u = (c * e1[0] + sn * e2[0], c * e1[1] + sn * e2[1], c * e1[2] + sn * e2[2])
        h = (c * m1[0] + sn * m2[0], c * m1[1] + sn * m2[1], c * m1[2] + sn * m2[2])  # Hᵀ·u
        # u·e measures h·b at the b the innovation was taken at; later directions see the update
        z = _dot(u, e) + _dot(h, b0)
        scalar_update(b, P, h, z, W)


@kernel()
def run(state, coef, gyr, acc, offset, variance):
    """Over N samples: the offset estimate after each sample (N×3, rad/s) and its variance
    per axis (N×3, (rad/s)²)."""
    Ts, a_lp, r, rest_gyr, rest_gyr_abs, rest_acc, rest_time, wt, P0, V, W, a_short = (
        coef[0], coef[1], coef[2], coef[3], coef[4], coef[5], coef[6], coef[7], coef[8], coef[9], coef[10], coef[11])
    start_mean = math.sqrt(2.0) * Ts / wt  # tau_acc
    settle = SETTLE_TAUS * start_mean
    clip = CLIP_SIGMAS * math.sqrt(P0)
    Ad, Bd = np.empty((2, 2)), np.empty(2)
    butterworth_zoh(wt, Ad, Bd)
    b = state[7:10]
    acc_lp = state[ACC_LP].reshape((2, 3))
    r_lp = state[R_LP].reshape((2, 9))
    rb_lp = state[RB_LP].reshape((2, 3))
    P = state[COV].reshape((3, 3))
    for k in range(gyr.shape[0]):
        dg2 = 0.0
        da2 = 0.0
        g2 = 0.0
        for i in range(3):
            state[i] += a_lp * (gyr[k, i] - state[i])
            state[3 + i] += a_lp * (acc[k, i] - state[3 + i])
            state[SHORT + i] += a_short * (gyr[k, i] - state[SHORT + i])
            state[SHORT + 3 + i] += a_short * (acc[k, i] - state[SHORT + 3 + i])
            dg2 += (state[SHORT + i] - state[i]) ** 2
            da2 += (state[SHORT + 3 + i] - state[3 + i]) ** 2
            g2 += state[i] ** 2
        still = dg2 < rest_gyr * rest_gyr and da2 < rest_acc * rest_acc and g2 < rest_gyr_abs * rest_gyr_abs
        state[6] = state[6] + Ts if still else 0.0
        old = (acc_lp[0, 0], acc_lp[0, 1], acc_lp[0, 2])
        if V > 0.0:  # tracking while moving: the gyro frame and its low-passes
            q = quat_normalized(quat_multiply(  # turned by the corrected gyro
                (state[11], state[12], state[13], state[14]),
                rotvec_quat((gyr[k, 0] - b[0]) * Ts, (gyr[k, 1] - b[1]) * Ts, (gyr[k, 2] - b[2]) * Ts)))
            state[11], state[12], state[13], state[14] = q
            state[T] += Ts
            # the accelerometer, R·b and R (row-major) low-passed
            R = quat_matrix(q)
            a = _mat_vec(R, (acc[k, 0], acc[k, 1], acc[k, 2]))
            rb = _mat_vec(R, b)
            mean = state[T] <= start_mean
            for i in range(3):
                if mean:  # the running mean, derivative row at rest
                    acc_lp[0, i] += Ts / state[T] * (a[i] - acc_lp[0, i])
                    acc_lp[1, i] = 0.0
                else:
                    lowpass_step(acc_lp, i, a[i], Ad, Bd)
                lowpass_step(rb_lp, i, rb[i], Ad, Bd)
            for i in range(9):
                lowpass_step(r_lp, i, R[i], Ad, Bd)
        for i in range(3):
            P[i, i] = min(P[i, i] + V, P0)
        if state[6] >= rest_time:  # each axis of the gyro sample measures b with variance r
            for i in range(3):
                scalar_update(b, P, (1.0 if i == 0 else 0.0, 1.0 if i == 1 else 0.0, 1.0 if i == 2 else 0.0),
                              gyr[k, i], r)
        elif V > 0.0 and state[T] > settle:
            motion_update(b, P, old, acc_lp[0], r_lp[0], rb_lp[0], Ts, W, clip)
        for i in range(3):
            offset[k, i] = b[i]
            variance[k, i] = P[i, i]


def offset_system(dt: float, params=None, name: str = "gyro_offset"):
    """Discrete python-control system of the estimator: inputs gyr_raw_x..z (rad/s, the
    measured gyro) and acc_x..z (m/s²); outputs gyr_x..z, the gyro less the offset
    estimate after the sample (rad/s), and offset_x..z. x0: initial_state, or the zero
    state, with which it starts at rest on its first sample."""
    coef = coefficients(resolve(params), dt)

    def advance(state, u):
        offset, variance = np.empty((1, 3)), np.empty((1, 3))
        run(state, coef, u[0:3].reshape(1, 3).copy(), u[3:6].reshape(1, 3).copy(), offset, variance)
        return state, np.concatenate([u[0:3] - offset[0], offset[0]])

    return sample_system(advance, [f"{s}_{a}" for s in ("gyr_raw", "acc") for a in "xyz"],
                         [f"{s}_{a}" for s in ("gyr", "offset") for a in "xyz"], STATE_NAMES, dt, name,
                         start=lambda u: initial_state(coef, u[0:3], u[3:6]))


def correct(gyr, acc, fs: float, params=None, offline: bool = False):
    """(corrected gyro, offset estimate), both N×3 rad/s, over a whole recording. offline:
    the estimates of a forward and a backward pass in time (whose gyro is
    blocks.filters.sensor_frame.time_reversed, its offset the negative), each axis weighted by
    the inverse of its pass's variance: every sample's offset from all rests and motion."""
    gyr = np.ascontiguousarray(gyr, dtype=float)
    acc = np.ascontiguousarray(acc, dtype=float)
    coef = coefficients(resolve(params), 1.0 / fs)

    def one_pass(g, a):
        state = initial_state(coef, g[0], a[0])
        offset, variance = np.empty_like(g), np.empty_like(g)
        run(state, coef, g, a, offset, variance)
        return offset, variance

    offset, variance = one_pass(gyr, acc)
    if offline:
        back, back_variance = one_pass(time_reversed(gyr), np.ascontiguousarray(acc[::-1]))
        weight = back_variance[::-1] / (variance + back_variance[::-1])
        offset = weight * offset - (1.0 - weight) * back[::-1]
    return gyr - offset, offset
