"""The default `wiener`: eq. 34 with its break frequency from locally measured noise
densities (blocks.methods.wiener_local), against the stationary filter and eq. 46."""
import math

import control
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu import _core
from attitude_fmu.blocks.errors import inclination_error, rms
from attitude_fmu.blocks.filters import accuracy
from attitude_fmu.blocks.methods import wiener_local
from attitude_fmu.blocks.methods.registry import method
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.evaluation.compare import peer_quaternions
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

DELTA_N = math.radians(0.1)  # rad/s/√Hz, the default
FS = 100.0
SETTLE = 30000  # samples: 300 s, ten time constants of the slowest filter here


def _human(delta_v, rot_rms=1.0, seed=0, duration=3000.0, scale=None, delta_n=DELTA_N):
    motion = HumanMotion(delta_v=delta_v, omega_c=10.0, rot_rms=rot_rms).generate(duration, FS, seed)
    imu = ImuModel(delta_n=delta_n) if scale is None else ImuModel(delta_n=delta_n, gyr_scale=scale)
    gyr, acc = imu.apply(motion, seed=seed + 1)
    return motion, gyr, acc


def _rms_deg(est, motion, stop=None):
    return math.degrees(rms(inclination_error(est.gravity[SETTLE:stop], motion.up[SETTLE:stop])))


def test_within_its_time_constant_the_start_up_is_the_mean_of_the_accelerometer_in_the_gyro_frame():
    """Within √2/ω_g of the start (over 1.08 s here: without the scale term, the local ω_g
    stays below √(g·δn/δv_min) = 1.31 rad/s) the estimate is the mean of the accelerometer so
    far, each sample turned into the frame of the start by the gyro, turned back to now."""
    motion, gyr, acc = _human(1.0, duration=5.0)
    gravity = estimate(gyr, acc, FS, "wiener", {"scale_error": 0.0}, gyro_offset=False).gravity
    frame, in_gyro_frame = Rotation.identity(), np.zeros(3)
    assert math.sqrt(2.0) / math.sqrt(9.81 * DELTA_N / 0.01) > 1.0
    for k in range(int(1.0 * FS)):
        if k:
            frame = frame * Rotation.from_rotvec(gyr[k] / FS)  # sensor k → the frame of the start
        in_gyro_frame += frame.apply(acc[k])
        assert np.abs(gravity[k] - frame.inv().apply(in_gyro_frame / (k + 1))).max() < 1e-9, k
    assert np.abs(gravity[int(1.0 * FS):] - gravity[int(1.0 * FS) - 1]).max() > 1.0  # the motion turns it


@pytest.mark.parametrize("delta_v", [1.0, 0.25])
def test_local_densities_reach_eq46_on_stationary_motion(delta_v):
    """On Rizun's model (no scale error) the local filter meets the optimum of eq. 46 for
    the motion's true slosh, which it is not told; the stationary filter at the nominal
    δv = 1 m/s/√Hz loses when the motion is gentler."""
    motion, gyr, acc = _human(delta_v)
    optimum = math.degrees(accuracy.rms_attitude_error(DELTA_N, delta_v, 1.0, 9.81))
    local = _rms_deg(estimate(gyr, acc, FS, "wiener", {"scale_error": 0.0}, gyro_offset=False), motion)
    nominal = _rms_deg(estimate(gyr, acc, FS, "wiener", {"stationary": 1}, gyro_offset=False), motion)
    print(f"δv={delta_v}: eq. 46 {optimum:.3f}°, local {local:.3f}°, stationary nominal {nominal:.3f}°")
    assert abs(local / optimum - 1) < 0.05
    if delta_v != 1.0:
        assert nominal > 1.15 * local


def test_local_filter_settles_where_its_noise_model_says():
    """With a 0.5 % scale term (the online default, given here: the batch path would choose
    0 for this perfect gyro, blocks.stages.scale_error) and a perfect gyro, the local filter
    behaves as eq. 34 at the break frequency settled_filter predicts: its error is eq. 41 for
    that filter (the bound `attitude verify` holds the FMU to)."""
    motion, gyr, acc = _human(1.0)  # rot_rms 1 rad/s per axis: ⟨|ω|²⟩ = 3 rad²/s²
    filt = wiener_local.settled_filter(method("wiener").resolve(), 3.0, 1.0)
    analytic = math.degrees(math.sqrt(2.0 * accuracy.mean_square_error(filt, DELTA_N, 1.0, 10.0, 9.81)) / 9.81)
    local = _rms_deg(estimate(gyr, acc, FS, "wiener", {"scale_error": 0.005}, gyro_offset=False), motion)
    print(f"settled ω_g {-np.real(control.poles(filt))[0] * math.sqrt(2):.3f} rad/s: eq. 41 {analytic:.3f}°, "
          f"local {local:.3f}°")
    assert abs(local / analytic - 1) < 0.10


@pytest.mark.parametrize("offline", [False, True])
def test_scale_error_term_lowers_the_error_of_a_miscalibrated_gyro(offline):
    """Gyro with a 0.5 % scale/misalignment matrix: the δn_eff term beats both the local
    filter without it and the stationary filter told the true slosh, online and offline."""
    scale = np.random.default_rng(5).normal(0.0, 0.005, (3, 3))
    motion, gyr, acc = _human(0.25, rot_rms=2.0, scale=scale)
    stop = len(acc) - SETTLE

    def error(params):
        return _rms_deg(estimate(gyr, acc, FS, "wiener", params, offline=offline, gyro_offset=False), motion, stop)

    with_term, without, told = error({}), error({"scale_error": 0.0}), error({"delta_v": 0.25})
    print(f"scale error 0.5 %, offline={offline}: local {with_term:.3f}°, without the term {without:.3f}°, "
          f"stationary {told:.3f}°")
    assert with_term < 0.85 * without
    assert with_term < 0.85 * told


@pytest.mark.parametrize("delta_v, rot_rms", [(0.1, 0.3), (0.1, 3.0), (2.0, 0.3), (2.0, 3.0)])
def test_with_a_real_gyro_the_defaults_meet_the_best_fixed_filter_and_beat_vqf(delta_v, rot_rms):
    """A gyro with a 0.5 % scale/misalignment matrix, 0.1 °/s/√Hz of noise, and motions
    from quiet to vigorous in slosh and rotation: the defaults, told nothing about the
    motion, come within 5 % of the best of eq. 34's fixed break frequencies (0.05 to
    3.2 rad/s, chosen with the truth) and at or below vqf."""
    scale = np.random.default_rng(5).normal(0.0, 0.005, (3, 3))
    motion = HumanMotion(delta_v=delta_v, omega_c=10.0, rot_rms=rot_rms).generate(600.0, FS, 3)
    gyr, acc = ImuModel(delta_n=DELTA_N, gyr_scale=scale, acc_noise=0.01).apply(motion, seed=4)
    kept = slice(int(100 * FS), None)
    error = lambda up: math.degrees(rms(inclination_error(up[kept], motion.up[kept])))
    ours = error(estimate(gyr, acc, FS, gyro_offset=False).up)
    best = min(error(estimate(gyr, acc, FS, params={"omega_g": w}, gyro_offset=False).up) for w in 0.05 * 2.0 ** np.arange(7))
    vqf = error(Rotation.from_quat(peer_quaternions("vqf", gyr, acc, FS), scalar_first=True).inv().apply([0, 0, 1]))
    print(f"δv {delta_v} m/s/√Hz, rotation {rot_rms} rad/s: defaults {ours:.3f}°, best fixed {best:.3f}°, "
          f"vqf {vqf:.3f}°")
    assert ours < 1.05 * best
    assert ours < 1.01 * vqf


def test_offline_local_smoother_meets_the_smoother_optimum():
    motion, gyr, acc = _human(0.25)
    stop = len(acc) - SETTLE
    online = _rms_deg(estimate(gyr, acc, FS, "wiener", {"scale_error": 0.0}, gyro_offset=False), motion, stop)
    offline = _rms_deg(estimate(gyr, acc, FS, "wiener", {"scale_error": 0.0}, offline=True, gyro_offset=False), motion, stop)
    optimum = math.degrees(accuracy.smoother_rms_attitude_error(DELTA_N, 0.25, 1.0, 9.81))
    print(f"offline {offline:.3f}° (smoother optimum {optimum:.3f}°), online {online:.3f}°")
    assert abs(offline / optimum - 1) < 0.10
    assert offline < online


@pytest.mark.parametrize("params", [{"stationary": 0.5}, {"scale_error": -0.01}, {"tau_noise": 0.0}])
def test_bad_local_parameters_are_refused(params):
    with pytest.raises(ValueError):
        estimate(np.zeros((5, 3)), np.tile([0.0, 0.0, 9.81], (5, 1)), FS, "wiener", params, gyro_offset=False)


def test_a_start_under_strong_acceleration_settles():
    """The slosh statistic is the accelerometer band-passed in the gyro frame, so the
    filter's own start-up error does not inflate it: starting on a sample far from g with
    a quiet gyro (so a slow filter), the error meets eq. 46 once the filter has settled."""
    quiet = math.radians(0.02)
    motion, gyr, acc = _human(1.0, duration=1500.0, seed=3, delta_n=quiet)
    err = inclination_error(estimate(gyr, acc, FS, "wiener", {"delta_n": quiet, "scale_error": 0.0}, gyro_offset=False).gravity,
                            motion.up)
    optimum = math.degrees(accuracy.rms_attitude_error(quiet, 1.0, 1.0, 9.81))
    settled = math.degrees(rms(err[SETTLE:]))
    print(f"|acc[0]| {np.linalg.norm(acc[0]):.0f} m/s²; max error {math.degrees(err.max()):.1f}°; "
          f"after 300 s {settled:.3f}° (eq. 46: {optimum:.3f}°)")
    assert np.linalg.norm(acc[0]) > 30.0
    assert abs(settled / optimum - 1) < 0.15


@pytest.mark.parametrize("omega_m, tau_v", [(10.0, 1.0), (1.0, 1.0), (0.2, 3.0), (300.0, 0.01)])
def test_the_closed_form_slosh_integral_equals_its_quadrature(omega_m, tau_v):
    """The C step's coefficient 1/J (attitude_fmu._core.wiener_local_coefficients): the integral of x⁴/((1 + x²)²·(1 + x²/c²)) over x ≥ 0 by
    scipy's quad (the independent truth) against its closed form."""
    from scipy.integrate import quad

    c = omega_m * tau_v
    J = quad(lambda x: x**4 / ((1.0 + x * x) ** 2 * (1.0 + (x / c) ** 2)), 0.0, np.inf, epsabs=0, epsrel=1e-13,
             limit=200)[0] / (2.0 * math.pi * tau_v)
    params = {**method("wiener").resolve(), "omega_m": omega_m, "tau_v": tau_v}
    assert _core.wiener_local_coefficients(params, 0.01)[4] == pytest.approx(1.0 / J, rel=1e-11)
