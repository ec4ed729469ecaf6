"""The tuning parameters of every method and stage, in one table: the one source of their
names, defaults, units, meanings and plausible ranges (blocks.params.Param).

The C core's parameter header (af_params.h) is generated from it by the build
(blocks/core/generate_tables.py), the FMUs' variables from it (systems.fmi.interface.variables), the
command line's help from it; the methods (blocks.methods.registry) and stages
(blocks.stages) take theirs from here. Only the standard library is imported, so that the
build runs it without the package's dependencies.
"""
from __future__ import annotations

import math

from attitude_fmu.blocks.params import (
    ANGLE_RAD,
    FRACTION,
    FREQUENCY_RAD_S,
    GRAVITY_M_S2,
    GYRO_NOISE,
    RATE_RAD_S,
    SLOSH,
    TIME_S,
    Param,
)

STANDARD_GRAVITY = 9.81  # m/s², the value the project uses for |g|
NOMINAL_DELTA_V = 1.0  # m/s/√Hz: vigorous human motion (Rizun's Table 1), when delta_v is unset
GUARD_NOISE_MARGIN = 5.0  # tau_mag_guard unset: the guard's tightest tolerance in s.d. of the noise left
DRIFT_BLOCK_TAUS = 0.25  # the heading's drift estimate measures the field heading's noise over blocks of this × tau_heading
DRIFT_SIGMAS = 4.0  # the heading follows the drift rate it estimates once the rate is this many s.d. from 0
REST_NOISE_SIGMAS = 4.5  # the least rest_gyr in units of the gyro noise's per-axis s.d. through tau_short

NOISE_PARAMS = (
    Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density, one-sided (datasheet)", **GYRO_NOISE),
    Param("delta_v", None, "m/s/√Hz",
          f"slosh: density of the velocity of the motion (eq. 14); unset: {NOMINAL_DELTA_V:g} for the stationary filter",
          **SLOSH),
    Param("g", STANDARD_GRAVITY, "m/s²", "magnitude of gravity", **GRAVITY_M_S2),
)
MAHONY_GAINS = (  # Mahony's filter, alone and in Tseng's adaptive switch
    Param("k_P", 1.0, "1/s", "Mahony: proportional gain on the gravity-direction error", low=1e-6, high=1e4),
    Param("k_I", 0.3, "1/s²", "Mahony: integral gain of the gyro-bias estimate; 0: no bias estimate", True, high=1e4),
)
LOCAL_NOISE_PARAMS = (
    Param("stationary", 0.0, "1", "0: omega_g from noise densities measured over the last tau_noise s "
          "(blocks.methods.wiener_local); 1, or omega_g, omega_c or delta_v given: the stationary filter",
          True, high=1.0, choices=(0.0, 1.0)),
    Param("scale_error", 0.005, "1", "rms of each element of the gyro's scale-factor and misalignment "
          "error (datasheet)", True, high=1.0),
    Param("omega_m", 10.0, "rad/s", "band limit of the motion (velocity and rate) in the local densities",
          **FREQUENCY_RAD_S),
    Param("tau_noise", 1.0, "s", "averaging time of the local densities", **TIME_S),
    Param("tau_v", 1.0, "s", "time constant of the band-pass that turns the accelerometer into the "
          "slosh velocity", **TIME_S),
    Param("delta_v_min", 0.01, "m/s/√Hz", "floor of the local slosh density (rest)", **SLOSH),
)
GRAVITY = Param("g", STANDARD_GRAVITY, "m/s²", "magnitude of gravity (scales the gravity output)", **GRAVITY_M_S2)

# method name → (summary, parameters), in the order `attitude estimate --method` lists them
METHODS = {
    "wiener": (
        "Rizun's optimal Wiener filter: eq. 34 (Butterworth) with omega_g from local noise densities; "
        "with stationary=1 eq. 34 at fixed densities, or eq. 33 when omega_c is given",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "break frequency; default sqrt(g·delta_n/delta_v), eq. 25",
                  **FREQUENCY_RAD_S),
            Param("omega_c", None, "rad/s", "band limit of the motion; given, eq. 33 replaces eq. 34",
                  **FREQUENCY_RAD_S),
        ) + LOCAL_NOISE_PARAMS,
    ),
    "tseng": (
        "Tseng's complementary filter (eqs. 6-11 with compensation), in the gyro-estimated earth frame",
        (),
    ),
    "tseng_adaptive": (
        "Tseng's adaptive filter: complementary filter, Mahony's filter while |acc| leaves g by > tol",
        (
            Param("tol", 0.5, "m/s²", "accelerometer norm's distance from g that switches to Mahony's filter",
                  low=1e-4, high=400.0 * 9.80665),
            *MAHONY_GAINS,
            Param("g", STANDARD_GRAVITY, "m/s²", "magnitude of gravity", **GRAVITY_M_S2),
        ),
    ),
    "luinge": (
        "Luinge's tilt Kalman filter: gyro orientation, 2-state KF on the tilt difference",
        (
            Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density (process noise of the tilt)",
                  **GYRO_NOISE),
            Param("tilt_sd", 0.05, "rad", "s.d. of the accelerometer's tilt (acceleration as noise)", **ANGLE_RAD),
            GRAVITY,
        ),
    ),
    "mahony": (
        "Mahony's complementary filter on SO(3) with gyro-bias estimation (IEEE TAC 53, 2008)",
        MAHONY_GAINS + (GRAVITY,),
    ),
    "first_order": (
        "Rizun §4.2: first-order low-pass in the gyro-estimated earth frame",
        NOISE_PARAMS + (
            Param("omega_g", None, "rad/s", "Wiener break frequency the best cut-off derives from", **FREQUENCY_RAD_S),
            Param("omega_c", 10.0, "rad/s", "band limit of the motion (for the best cut-off)", **FREQUENCY_RAD_S),
            Param("omega_f", None, "rad/s", "cut-off; default (omega_g⁴/(2·omega_c))^(1/3), the best",
                  **FREQUENCY_RAD_S),
        ),
    ),
}

# parameters of the gyro-offset and the heading estimators both (a value given reaches both)
GYRO_DENSITY = Param("delta_n", math.radians(0.1), "rad/s/√Hz", "gyro noise density, one-sided (datasheet): each "
                     "sample's weight at rest, and the heading's random walk between field samples", **GYRO_NOISE)
SIGMA_MOTION = Param("sigma_motion", math.radians(0.1), "rad/s", "uncertainty the offset tracking while moving settles "
                     "on (per axis); the heading leaves a drift within it to its pull alone", **RATE_RAD_S)

GYRO_OFFSET = (
    Param("rest_gyr", math.radians(2.0), "rad/s",
          "largest deviation of the gyro (through tau_short) from its low-pass at rest; at least "
          f"{REST_NOISE_SIGMAS:g} times delta_n's noise through tau_short", **RATE_RAD_S),
    Param("rest_gyr_abs", math.radians(10.0), "rad/s", "largest low-passed gyro norm at rest (offset included): "
          "a raw MEMS gyro's zero-rate offset, ±5 °/s per axis in consumer datasheets, is 8.7 °/s at most",
          **RATE_RAD_S),
    Param("rest_acc", 0.5, "m/s²",
          "largest deviation of the accelerometer (through tau_short) from its low-pass at rest",
          low=1e-4, high=400.0 * 9.80665),
    Param("rest_time", 1.5, "s", "time the rest conditions must hold", **TIME_S),
    Param("tau_lp", 0.5, "s", "time constant of the low-passes of the rest detection", **TIME_S),
    Param("tau_short", 0.02, "s", "time constant of the low-pass that takes white noise out of the samples the rest "
          "detection compares with its low-passes (human motion lies below 8 Hz)", **TIME_S),
    Param("tau_rest", 0.15, "s", "time constant of the low-pass of the gyro whose samples at rest measure the offset: "
          "a rest's last tremor, and a turn that has not quite stopped, averaged out", **TIME_S),
    GYRO_DENSITY,
    Param("tau_acc", 3.0, "s", "time constant of the accelerometer low-pass in the gyro frame (motion tracking)",
          **TIME_S),
    Param("sigma_init", math.radians(0.5), "rad/s", "uncertainty of the offset before any rest (per axis)",
          **RATE_RAD_S),
    SIGMA_MOTION,
    Param("tau_motion", 100.0, "s", "time in which the offset may drift by sigma_motion; 0: no tracking while moving",
          allow_zero=True, high=1e6),
    Param("tau_arm", 30.0, "s", "memory of the online lever-arm fit (a sensor turned about a fixed centre: its "
          "accelerations removed from the accelerometer where the fit explains them); 0, or tau_motion 0: no lever arm",
          allow_zero=True, high=1e6),
)

HARD_IRON = (
    Param("mag_cal_time", 60.0, "s", "time over which the hard-iron fit forgets its samples (0: no hard-iron estimate)",
          True, high=1e6),
    Param("mag_cal_spread", 0.1, "1", "least s.d. of the field across its smallest axis, relative to the fit's radius",
          **FRACTION),
    Param("mag_cal_tol", 0.05, "1", "largest rms distance of the field from the fitted sphere, relative to its radius",
          **FRACTION),
    Param("mag_cal_recent", 2.0, "s", "time constant over which the latest field samples are held against the sphere "
          "the window fits; when they leave it, the fit starts afresh", **TIME_S),
)
MAG_DELAY = (
    Param("tau_mag_delay", 60.0, "s", "memory of the online estimate of the magnetometer's delay (mag_delay unset)",
          **TIME_S),
)
HEADING = (
    Param("tau_heading", 10.0, "s", "time constant of the pull towards the magnetometer heading (for a gyro of "
          "delta_n and no drift)", **TIME_S),
    GYRO_DENSITY,
    Param("heading_drift", math.radians(5.0), "rad/s", "largest drift of the gyro's heading the magnetometer may "
          "show (a gyro offset along the vertical that the gyro-offset estimator cannot see): the prior s.d. of the "
          "heading's drift rate; 0: no drift rate estimated", True, high=math.radians(4000.0)),
    SIGMA_MOTION,
    Param("mag_norm_tol", 0.1, "1", "largest relative deviation of the field norm from its reference",
          low=1e-6, high=10.0),
    Param("mag_dip_tol", math.radians(5.0), "rad", "largest deviation of the dip angle from its reference",
          **ANGLE_RAD),
    Param("tau_mag_guard", None, "s", "time constant of the low-pass of the tilt-compensated field that the guard "
          "judges and the heading follows: the magnetometer's noise averaged over it, not judged sample by sample; "
          "unset: from the noise the magnetometer shows, measured online (the guard's tightest tolerance "
          f"{GUARD_NOISE_MARGIN:g} s.d. of the noise left, blocks.stages.heading)", **TIME_S),
    Param("tau_reference", 60.0, "s", "time constant of the reference norm and dip", **TIME_S),
    Param("heading_clip", math.radians(10.0), "rad", "largest heading innovation one sample may use", **ANGLE_RAD),
    Param("mag_new_time", 20.0, "s", "how long a field outside the reference's tolerance must stay steady to replace it",
          **TIME_S),
    Param("mag_new_angle", math.radians(90.0), "rad", "how far the sensor must turn meanwhile (0: no turn)",
          True, high=math.pi),
    Param("mag_delay", None, "s", "delay of the magnetometer behind the gyro; unset: estimated online "
          "(blocks.stages.mag_delay; offline, measured from the whole recording, blocks.stages.delays.mag_delay)",
          True, high=10.0),
) + HARD_IRON + MAG_DELAY

# the estimators around the method: label as messages name them → parameters (C names: gyro_offset, heading)
ESTIMATORS = {"the gyro-offset estimator": GYRO_OFFSET, "the heading estimator": HEADING}


def uses() -> dict[str, list[tuple[str, Param]]]:
    """Every parameter name once, in the order the methods (METHODS) and then the estimators
    (ESTIMATORS) list them: the stages that have it, as (owner, its Param there); the order
    of the C core's parameter indices and of the estimator FMU's tuning variables."""
    found: dict[str, list[tuple[str, Param]]] = {}
    for owner, stage in (*((f"method {name}", params) for name, (_, params) in METHODS.items()), *ESTIMATORS.items()):
        for p in stage:
            found.setdefault(p.name, []).append((owner, p))
    return found
