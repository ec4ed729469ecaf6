"""Heading from the magnetometer (the "heading estimator" box of Rizun's Fig. 1).

Takes the attitude filter's orientation (heading from the integrated gyro) and turns it
about earth up by ψ_c, which follows the heading of the tilt-compensated field: with q'
= Rz(ψ_c)·q and m_e = R(q')·m, the field should point north (ENU y) in the horizontal
plane, so δψ = atan2(m_e,x, m_e,y) is the heading error's negative and ψ_c += a·clip(δψ) with
a = 1 − exp(−Ts/tau) and the innovation clipped to ±heading_clip (a robust update: a
disturbance that slips through the guard pulls by at most heading_clip/tau_heading per
second). Start-up: over the first tau_heading seconds every sample is used, unclipped,
with the weight 1/n of a running mean, and the reference norm and dip are their running
means (the first samples may come in motion, while the tilt is still settling). Then
the guard against magnetic disturbances: a sample is used only while the field's norm
and dip stay within tolerance of the reference, which is tracked slowly (tau_reference)
over accepted samples; otherwise the heading is the gyro's. A new reference: a field
outside the reference's tolerance that stays steady (norm and dip within the same
tolerances of their own running mean) for mag_new_time while the sensor turns through
mag_new_angle is taken as proven: the estimator starts afresh from it, with the
start-up's running means. A homogeneous field keeps its norm and dip when the
sensor turns, a field fixed to the sensor (a magnet carried along) does not, so a wrong
reference from a disturbed start, or a move to a place whose field differs (another
room or building), no longer locks the magnetometer out for good. Turning cannot tell a
disturbance fixed in the room (a monitor beside a resting sensor) from the earth's field:
after mag_new_time of turning there it is taken too, and left the same way.
Before all this the field is freed of a hard-iron offset, a field fixed to the sensor,
when a sphere fit proves one (blocks.stages.hard_iron; its parameters are listed here too), and
a magnetometer that trails the gyro by mag_delay seconds (its own filters and sample
time; given, or unset estimated online by blocks.stages.mag_delay) is read against the
orientation it had then, q turned back by mag_delay at the rate of the last step: a
field seen late in a fast turn would otherwise show a heading error and a dip that
changes with the turn (which the guard refuses). Inclination is
untouched: the correction turns about the vertical only.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.control_system import sample_system
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.params import ANGLE_RAD, TIME_S, Param, resolve_params
from attitude_fmu.blocks.quaternion import quat_multiply, quat_rotate, rotvec_quat
from attitude_fmu.blocks.stages import hard_iron, mag_delay
from attitude_fmu.blocks.stages.hard_iron import hard_iron_step, pull

PARAMS = (
    Param("tau_heading", 10.0, "s", "time constant of the pull towards the magnetometer heading", **TIME_S),
    Param("mag_norm_tol", 0.1, "1", "largest relative deviation of the field norm from its reference",
          low=1e-6, high=10.0),
    Param("mag_dip_tol", math.radians(5.0), "rad", "largest deviation of the dip angle from its reference",
          **ANGLE_RAD),
    Param("tau_reference", 60.0, "s", "time constant of the reference norm and dip", **TIME_S),
    Param("heading_clip", math.radians(10.0), "rad", "largest heading innovation one sample may use", **ANGLE_RAD),
    Param("mag_new_time", 20.0, "s", "how long a field outside the reference's tolerance must stay steady to replace it",
          **TIME_S),
    Param("mag_new_angle", math.radians(90.0), "rad", "how far the sensor must turn meanwhile (0: no turn)",
          True, high=math.pi),
    Param("mag_delay", None, "s", "delay of the magnetometer behind the gyro; unset: estimated online "
          "(blocks.stages.mag_delay; offline, measured from the whole recording, blocks.stages.delays.mag_delay)",
          True, high=10.0),
) + hard_iron.PARAMS + mag_delay.PARAMS
STATE_NAMES = (
    "psi_c", "ref_norm", "ref_dip", "seen", "cand_norm", "cand_dip", "cand_n", "cand_dot",
    "cand_q0_w", "cand_q0_x", "cand_q0_y", "cand_q0_z", "steps", "cand_start", "gap",
    "q_prev_w", "q_prev_x", "q_prev_y", "q_prev_z",
    *(f"hard_iron_{n}" for n in hard_iron.STATE_NAMES),
    *(f"mag_delay_{n}" for n in mag_delay.STATE_NAMES),
)  # see initial_state
REF_NORM, REF_DIP, SEEN = 1, 2, 3
CAND_NORM, CAND_DIP, CAND_N, CAND_DOT, CAND_Q0 = 4, 5, 6, 7, 8  # q₀ in 8…11
STEPS, CAND_START, GAP, Q_PREV = 12, 13, 14, 15  # the last step's orientation in 15…18
HARD_IRON = slice(19, 19 + hard_iron.STATE_SIZE)  # blocks.stages.hard_iron's state
HARD_IRON_OFFSET = HARD_IRON.start + hard_iron.OFFSET.start  # its offset estimate in 3 entries from here
MAG_DELAY = slice(HARD_IRON.stop, HARD_IRON.stop + mag_delay.STATE_SIZE)  # blocks.stages.mag_delay's state
MAG_DELAY_IN_USE = MAG_DELAY.start + mag_delay.DELAY  # the delay allowed for (s): given, or the online estimate
HARD_IRON_COEF = slice(10, 10 + hard_iron.COEF_SIZE)  # blocks.stages.hard_iron's coefficients
MAG_DELAY_COEF = slice(HARD_IRON_COEF.stop, HARD_IRON_COEF.stop + mag_delay.COEF_SIZE)


def resolve(overrides=None) -> dict:
    return resolve_params(PARAMS, overrides, "the heading estimator")


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts/tau_heading, Ts/tau_reference, mag_norm_tol, mag_dip_tol, heading_clip, steps a
    new field must stay steady, cos(mag_new_angle/2), 1 − exp(−Ts/tau_heading),
    1 − exp(−Ts/tau_reference), mag_delay (s; unset: NaN, estimated online), then
    blocks.stages.hard_iron's and blocks.stages.mag_delay's coefficients]. Ts is the step (IMU sample) time."""
    return np.concatenate([[Ts / params["tau_heading"], Ts / params["tau_reference"],
                            params["mag_norm_tol"], params["mag_dip_tol"], params["heading_clip"],
                            params["mag_new_time"] / Ts, math.cos(0.5 * params["mag_new_angle"]),
                            1.0 - math.exp(-Ts / params["tau_heading"]), 1.0 - math.exp(-Ts / params["tau_reference"]),
                            math.nan if params["mag_delay"] is None else params["mag_delay"]],
                           hard_iron.coefficients(params, Ts), mag_delay.coefficients(params, Ts)])


def initial_state() -> np.ndarray:
    """[ψ_c (rad), reference norm, reference dip (rad), field samples since the start-up
    began, candidate norm, candidate dip (rad), field samples in the candidate, smallest
    |q·q₀| since the candidate began, q₀ (4, the orientation then), steps since the
    start-up began, the step the candidate began at, steps since the last field sample,
    the last step's orientation (4; 0: none yet), then blocks.stages.hard_iron's and
    blocks.stages.mag_delay's states]."""
    state = np.zeros(len(STATE_NAMES))
    state[CAND_DOT] = 1.0
    return state


@kernel(inline=True)
def _steady(norm, dip, ref_norm, ref_dip, norm_tol, dip_tol):
    return abs(norm - ref_norm) <= norm_tol * ref_norm and abs(dip - ref_dip) <= dip_tol


@kernel(inline=True)
def _new_reference(state, coef, q, norm, dip):
    """A sample outside the reference's tolerance: extend the candidate field (or begin one
    at this sample); True when the candidate has stayed steady for mag_new_time while the
    sensor turned through mag_new_angle: the heading estimator then starts afresh."""
    norm_tol, dip_tol, steps, cos_half = coef[2], coef[3], coef[5], coef[6]
    if state[CAND_N] > 0.0 and _steady(norm, dip, state[CAND_NORM], state[CAND_DIP], norm_tol, dip_tol):
        state[CAND_N] += 1.0
        state[CAND_NORM] += (norm - state[CAND_NORM]) / state[CAND_N]
        state[CAND_DIP] += (dip - state[CAND_DIP]) / state[CAND_N]
        dot = 0.0
        for i in range(4):
            dot += q[i] * state[CAND_Q0 + i]
        state[CAND_DOT] = min(state[CAND_DOT], abs(dot))
        if state[STEPS] - state[CAND_START] + 1.0 >= steps and state[CAND_DOT] <= cos_half:
            state[CAND_N] = 0.0
            return True
        return False
    state[CAND_NORM], state[CAND_DIP], state[CAND_N], state[CAND_DOT] = norm, dip, 1.0, 1.0
    state[CAND_START] = state[STEPS]
    for i in range(4):
        state[CAND_Q0 + i] = q[i]
    return False


@kernel(inline=True)
def _field_sample(state, coef, q, m, horizontal):
    """Take the field m (earth frame, turned by ψ_c; its horizontal norm > 0) into ψ_c and
    the reference; whether it was used."""
    clip = coef[4]
    norm = math.sqrt(horizontal * horizontal + m[2] * m[2])
    dip = math.atan2(-m[2], horizontal)
    gap, state[GAP] = state[GAP], 0.0
    if state[SEEN] == 0.0:
        state[STEPS] = 1.0
    state[SEEN] += 1.0
    start = 1.0 / state[STEPS] > coef[7]  # within tau_heading of the start
    ok = False
    if not start:
        ok = _steady(norm, dip, state[REF_NORM], state[REF_DIP], coef[2], coef[3])
        if ok:
            state[CAND_N] = 0.0
        elif _new_reference(state, coef, q, norm, dip):
            state[SEEN], state[STEPS], start = 1.0, 1.0, True  # a proven field: start afresh
    if start:  # running means, every sample
        ok = True
        state[0] += math.atan2(m[0], m[1]) / state[SEEN]
        state[REF_NORM] += (norm - state[REF_NORM]) / state[SEEN]
        state[REF_DIP] += (dip - state[REF_DIP]) / state[SEEN]
    elif ok:  # first-order pulls over the time since the last field sample
        state[0] += pull(gap, coef[0], coef[7]) * min(clip, max(-clip, math.atan2(m[0], m[1])))
        a_reference = pull(gap, coef[1], coef[8])
        state[REF_NORM] += a_reference * (norm - state[REF_NORM])
        state[REF_DIP] += a_reference * (dip - state[REF_DIP])
    return ok


@kernel(inline=True)
def step_turn(q_prev, q):
    """The rotation vector (rad, sensor frame) from q_prev to q."""
    d = quat_multiply((q_prev[0], -q_prev[1], -q_prev[2], -q_prev[3]), q)
    if d[0] < 0.0:
        d = (-d[0], -d[1], -d[2], -d[3])
    s = math.sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3])
    k = 2.0 * math.atan2(s, d[0]) / s if s > 0.0 else 2.0
    return (k * d[1], k * d[2], k * d[3])


@kernel(inline=True)
def turned_back(q, turn, steps):
    """q turned back in the sensor frame by steps times the last step's rotation turn
    (rad): the orientation steps sample times ago at the last step's rate."""
    return quat_multiply(q, rotvec_quat(-steps * turn[0], -steps * turn[1], -steps * turn[2]))


@kernel(inline=True)
def heading_step(state, coef, q, m_sensor):
    """One step: (q turned by the updated ψ_c, whether the field was used). q is the
    attitude filter's orientation (4-tuple), m_sensor the field (3-tuple; a NaN: no field
    sample this step, a slower magnetometer); state in place. Times count steps, so a
    slower magnetometer keeps the time constants in seconds. The field is read against q
    turned back by the delay in MAG_DELAY_IN_USE: coef[9] (s), or where that is NaN
    blocks.stages.mag_delay's online estimate."""
    state[GAP] += 1.0
    if state[SEEN] > 0.0:
        state[STEPS] += 1.0
    ok = False
    online = math.isnan(coef[9])
    if not online:
        state[MAG_DELAY_IN_USE] = coef[9]
    delay_coef = coef[MAG_DELAY_COEF]
    q_prev = (state[Q_PREV], state[Q_PREV + 1], state[Q_PREV + 2], state[Q_PREV + 3])
    turn = (0.0, 0.0, 0.0)  # the last step's rotation (rad), wanted online or for a given delay
    if (online or coef[9] != 0.0) and abs(q_prev[0]) + abs(q_prev[1]) + abs(q_prev[2]) + abs(q_prev[3]) > 0.0:
        turn = step_turn(q_prev, q)
    if online:
        mag_delay.turn(state[MAG_DELAY], delay_coef, turn)
    n2 = m_sensor[0] * m_sensor[0] + m_sensor[1] * m_sensor[1] + m_sensor[2] * m_sensor[2]
    # a field sample (not NaN: missing, not all 0: none, not infinite); math.isfinite is true of inf in a
    # kernel compiled with fast-math, math.isinf is not
    if n2 > 0.0 and not math.isinf(n2):
        m_sensor, proven = hard_iron_step(state[HARD_IRON], coef[HARD_IRON_COEF], m_sensor, state[GAP], coef[2],
                                          coef[5])
        if proven:  # a field freed of (or back without) an offset: start afresh from it
            state[SEEN] = 0.0
            mag_delay.restart(state[MAG_DELAY])
        steps = state[MAG_DELAY_IN_USE] / delay_coef[0]
        q_field = turned_back(q, turn, steps) if steps != 0.0 else q
        half = 0.5 * state[0]
        m = quat_rotate(quat_multiply((math.cos(half), 0.0, 0.0, math.sin(half)), q_field), m_sensor)
        horizontal = math.sqrt(m[0] * m[0] + m[1] * m[1])
        if horizontal > 0.0:  # a field with a heading
            ok = _field_sample(state, coef, q, m, horizontal)
        if online:
            rate = (turn[0] / delay_coef[0], turn[1] / delay_coef[0], turn[2] / delay_coef[0])
            mag_delay.field_sample(state[MAG_DELAY], delay_coef, m_sensor, rate, ok)
    for i in range(4):
        state[Q_PREV + i] = q[i]
    if abs(state[0]) > math.pi:
        state[0] = math.atan2(math.sin(state[0]), math.cos(state[0]))
    half = 0.5 * state[0]
    return quat_multiply((math.cos(half), 0.0, 0.0, math.sin(half)), q), ok


@kernel()
def run(state, coef, quat, mag, out, accepted, offset, delay):
    """Per sample: out (N×4) the orientation with magnetometer heading, accepted (N) whether
    the field passed the guard, offset (N×3) the hard-iron estimate, delay (N) the
    magnetometer's delay allowed for (s, given or estimated online). quat N×4 (sensor →
    earth), mag N×3 (any unit, the offset in the same; a row with a NaN is a missing
    sample, a magnetometer slower than the IMU); state (see initial_state) is carried over
    from call to call."""
    for k in range(quat.shape[0]):
        turned, ok = heading_step(state, coef, (quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3]),
                                  (mag[k, 0], mag[k, 1], mag[k, 2]))
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = turned
        accepted[k] = ok
        for i in range(3):
            offset[k, i] = state[HARD_IRON_OFFSET + i]
        delay[k] = state[MAG_DELAY_IN_USE]


def heading_system(dt: float, params=None, name: str = "heading"):
    """Discrete python-control system of the heading stage: inputs q_w..z (the attitude
    filter's orientation) and mag_x..z (µT); outputs qh_w..z, the orientation with
    magnetometer heading, and mag_offset_x..z, the hard-iron estimate. x0: initial_state(),
    or the zero state, which stands for it."""
    coef = coefficients(resolve(params), dt)

    def advance(state, u):
        out, accepted, offset = np.empty((1, 4)), np.empty(1, dtype=np.bool_), np.empty((1, 3))
        run(state, coef, u[0:4].reshape(1, 4).copy(), u[4:7].reshape(1, 3).copy(), out, accepted, offset, np.empty(1))
        return state, np.concatenate([out[0], offset[0]])

    return sample_system(advance, [f"q_{c}" for c in "wxyz"] + [f"mag_{c}" for c in "xyz"],
                         [f"qh_{c}" for c in "wxyz"] + [f"mag_offset_{c}" for c in "xyz"],
                         STATE_NAMES, dt, name, start=lambda u: initial_state())


def with_magnetometer(quat, mag, fs: float, params=None):
    """(orientation with magnetometer heading N×4, accepted N, hard-iron offset N×3 in the
    field's unit, the magnetometer's delay allowed for N in s) for a whole recording."""
    out = np.empty_like(quat)
    accepted = np.empty(len(quat), dtype=np.bool_)
    offset = np.empty((len(quat), 3))
    delay = np.empty(len(quat))
    run(initial_state(), coefficients(resolve(params), 1.0 / fs), np.ascontiguousarray(quat),
        np.ascontiguousarray(mag, dtype=float), out, accepted, offset, delay)
    return out, accepted, offset, delay
