"""The seed estimators of Luinge and Tseng, Mahony's filter, and the papers' experiments."""
import json
import math
import warnings

import control
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import inclination_error, quaternion_errors, rms
from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.filters.sensor_frame import stepper_system
from attitude_fmu.blocks.methods.registry import METHODS, estimator_system, stepper
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.evaluation.compare import IMU, compare_profile
from attitude_fmu.systems.simulation.motion import PROFILES, profile
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0
HZ = np.logspace(-2, 1, 400)  # 0.01 … 10 Hz


@pytest.mark.parametrize("name", sorted(METHODS))
def test_block_from_python_controls_default_initial_state_starts_on_its_first_sample(name):
    """No X0: python-control starts every state at 0, a state no step can be in; the block
    starts at rest on its first sample, as the batch path does, and the outputs are finite
    and the batch path's from the first sample on."""
    rng = np.random.default_rng(7)
    gyr = rng.normal(0, 1.0, (200, 3))
    acc = rng.normal(0, 1.0, (200, 3)) + [0.5, -2.0, 9.6]
    resp = control.input_output_response(estimator_system(name, dt=1 / FS), np.arange(200) / FS,
                                         np.hstack([gyr, acc]).T)
    assert np.isfinite(resp.outputs).all()
    batch = estimate(gyr, acc, FS, name, gyro_offset=False)
    assert np.abs(resp.outputs.T - np.hstack([batch.gravity, batch.quat])).max() <= 1e-12


@pytest.mark.parametrize("name", sorted(METHODS))
def test_block_runs_its_step_once_per_sample(name):
    """python-control asks a discrete system for its output and its next state in two calls
    per step; the method's C step runs once for both (and gives the block's outputs)."""
    class Counted:
        def __init__(self, stepper):
            self.stepper, self.rows = stepper, 0
            self.state_names, self.initial_state = stepper.state_names, stepper.initial_state

        def run(self, state, gyr, acc, gravity, quat):
            self.rows += len(gyr)
            return self.stepper.run(state, gyr, acc, gravity, quat)

    rng = np.random.default_rng(8)
    n = 150
    signals = np.hstack([rng.normal(0, 1.0, (n, 3)), rng.normal(0, 1.0, (n, 3)) + [0, 0, 9.81]]).T
    counted = Counted(stepper(name, (), 1 / FS))
    response = control.input_output_response(stepper_system(counted, 1 / FS, name="under_test"), np.arange(n) / FS,
                                             signals)
    assert counted.rows == n
    expected = control.input_output_response(estimator_system(name, {}, 1 / FS), np.arange(n) / FS, signals)
    assert np.array_equal(response.outputs, expected.outputs)


def test_block_takes_the_python_control_argument_names():
    block = estimator_system(method="mahony", params={"k_P": 2.0}, dt=0.02, name="imu_filter")
    assert block.name == "imu_filter" and block.dt == 0.02
    assert block.input_labels == [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]


def _gyro_integration(gyr, q0):
    """Orientation from the gyro alone (the thin line of Luinge's Fig. 5)."""
    rotations = Rotation.from_rotvec(gyr / FS)
    out, current = np.empty((len(gyr), 4)), Rotation.from_quat(q0, scalar_first=True)
    for k in range(len(gyr)):
        current = current * rotations[k]
        out[k] = current.as_quat(scalar_first=True)
    return out


def test_luinge_fig5_on_coning():
    """θ = Ω = 1; gyro noise s.d. 1 rad/s per sample at 100 Hz; accelerometer = gravity, then
    gravity plus 1 m/s² along [1 1 1] in sensor coordinates."""
    motion = profile("coning").motion().generate(60.0, FS)
    q0 = Rotation.from_rotvec([1.0, 0.0, 0.0]).as_quat(scalar_first=True)  # R(0) = Rx(theta)
    delta_n = 1.0 / math.sqrt(FS / 2)  # s.d. 1 rad/s per sample
    t = np.arange(1, len(motion.gyr) + 1) / FS
    later = t > 5.0
    results = {}
    for offset in (0.0, 1.0):
        imu = ImuModel(delta_n=delta_n, acc_offset=tuple(np.full(3, offset / math.sqrt(3))))
        gyr, acc = imu.apply(motion, seed=5)
        filt = quaternion_errors(estimate(gyr, acc, FS, "luinge", {"delta_n": delta_n}, gyro_offset=False).quat, motion.quat)
        integ = quaternion_errors(_gyro_integration(gyr, q0), motion.quat)
        results[offset] = (filt, integ)
        # after the first seconds the filter's error stays below the gyro integration's
        assert rms(filt[0][later]) < 0.7 * rms(integ[0][later])
        # the heading part still walks: it dominates and grows, uncorrected
        assert rms(filt[1][later]) > 3 * rms(filt[2][later])
        assert rms(filt[1][t > 40]) > 2 * rms(filt[1][t <= 5])
    # the constant offset makes the (inclination) error larger
    assert rms(results[1.0][0][2][later]) > rms(results[0.0][0][2][later]) + math.radians(2.0)


def test_tseng_chain_is_within_1_db_of_unity_from_001_to_10_hz():
    w = 2j * np.pi * HZ
    for pair in ("acc", "mag"):
        uncompensated = np.abs(20 * np.log10(np.abs(tseng.chain(pair)(w)))).max()
        compensated = np.abs(20 * np.log10(np.abs(tseng.compensated_chain(pair)(w)))).max()
        assert uncompensated > 1.0  # Figs. 6-7: the residual the compensation removes
        assert compensated < 1.0
    # the compensation is stable (every zero of both chains in the left half-plane)
    for pair in ("acc", "mag"):
        assert np.all(np.real(control.poles(tseng.compensation(pair))) < 0)
    # the `tseng` method's earth filter is C·G_LA, and G_A's realisation is G_A up to 10 Hz
    assert np.allclose(METHODS["tseng"].filter()(w), (tseng.compensation("acc") * tseng.lowpass_acc())(w), rtol=1e-9)
    ratio = tseng.accelerometer_model()(w) / tseng.accelerometer()(w)
    assert np.abs(20 * np.log10(np.abs(ratio))).max() < 0.05  # 0.034 dB at 10 Hz


def test_euler_angles_from_gravity_and_field_match_scipy():
    rot = Rotation.random(50, random_state=3)
    roll, pitch, yaw = tseng.euler_from_gravity_mag(rot.inv().apply([0, 0, 1]), rot.inv().apply([0, 20, -45]))
    expected = rot.as_euler("ZYX")
    assert np.allclose(np.column_stack([yaw, pitch, roll]), expected, atol=1e-12)


def test_tseng4_mounting_at_90_deg():
    """An Euler-angle estimator hits the singularity of Tseng's Tables III/V at 90° about Y;
    every project estimator's inclination error at 90° stays within 0.2° of that at 0°."""
    errors = {}
    for axis in "xyz":
        for mount in (0.0, 90.0):
            motion = profile("linear_motion").motion({f"mount_{axis}_deg": mount}).generate(120.0, FS)
            gyr, acc = IMU.apply(motion, 1)
            kept = slice(2000, None)
            errors[axis, mount] = {m: rms(np.degrees(inclination_error(estimate(gyr, acc, FS, m, gyro_offset=False).up[kept],
                                                                       motion.up[kept]))) for m in METHODS}
            roll, _ = tseng.euler_complementary(gyr, acc, FS)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # scipy warns of the gimbal lock it resolves with roll = 0
                true_roll = Rotation.from_quat(motion.quat, scalar_first=True).as_euler("ZYX")[:, 2]
            errors[axis, mount]["euler_roll"] = rms(np.degrees(np.angle(np.exp(1j * (roll - true_roll))))[kept])
    assert errors["y", 90.0]["euler_roll"] > 5.0
    assert errors["y", 90.0]["euler_roll"] > 100 * errors["y", 0.0]["euler_roll"]
    for axis in "xyz":
        for m in METHODS:
            assert abs(errors[axis, 90.0][m] - errors[axis, 0.0][m]) < 0.2, (axis, m)


def test_offset_rotation_leaves_the_wiener_estimator_unbiased():
    """Tseng 5 / Rizun §2.4: 0.4 Hz yaw on a 20 cm arm."""
    table = compare_profile("offset_rotation", peers=())
    assert table["wiener"]["mean_deg"] < 0.05
    # Mahony's bias estimate integrates the centripetal term in sensor coordinates
    assert table["mahony"]["mean_deg"] > 10 * table["wiener"]["mean_deg"]


def test_profiles_have_exact_truth():
    for name, prof in PROFILES.items():
        motion = prof.motion().generate(30.0, FS, seed=2)
        rot = Rotation.from_quat(motion.quat, scalar_first=True)
        assert np.abs((rot[:-1].inv() * rot[1:]).as_rotvec() - motion.gyr[1:] / FS).max() < 1e-12, name


def test_compare_json_contract_and_peers_agree_on_an_easy_profile(capsys):
    assert main(["compare", "--json", "--profile", "sine_rotation", "--offline"]) == 0
    table = json.loads(capsys.readouterr().out)["profiles"]["sine_rotation"]
    smoothers = {f"{m}_offline" for m in METHODS if METHODS[m].is_sensor_frame}
    assert smoothers and set(table) == set(METHODS) | smoothers | {"vqf", "madgwick", "vqf_offline"}
    for row in table.values():
        assert set(row) == {"rms_deg", "max_deg", "mean_deg"}
    # conventions: every estimator, peers and smoothers included, follows a ±10° pitch within a degree
    assert max(row["rms_deg"] for row in table.values()) < 1.0


def test_compare_simulates_the_imu_it_is_given(capsys):
    """A gyro with a 2 % scale and misalignment error turns the pure rotation's gravity
    wrong by a share of the angle turned, which no filter fully removes; bad figures are
    refused naming the flag."""
    errors = []
    for scale in ("0", "0.02"):
        assert main(["compare", "--json", "--profile", "sine_rotation", "--gyro-scale-error", scale]) == 0
        errors.append(json.loads(capsys.readouterr().out)["profiles"]["sine_rotation"]["wiener"]["rms_deg"])
    assert errors[0] < 0.05 < 3 * errors[0] < errors[1]
    for flag, value, span in (("--gyro-noise", "-1", "[0, 57.2958] °/s/√Hz"), ("--acc-noise", "nan", "[0, 10] m/s²/√Hz"),
                              ("--gyro-scale-error", "0.5", "[0, 0.5)")):
        with pytest.raises(SystemExit) as refused:
            main(["compare", "--profile", "sine_rotation", flag, value])
        assert refused.value.code == 2
        assert f"argument {flag}: {value} is outside the plausible {span}" in capsys.readouterr().err


def test_bode_writes_a_png(tmp_path):
    out = tmp_path / "tseng.png"
    assert main(["bode", "--method", "tseng", "--out", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(SystemExit) as refused:  # argparse: not an LTI filter
        main(["bode", "--method", "luinge", "--out", str(out)])
    assert refused.value.code == 2


@pytest.mark.parametrize("offline", [False, True])
def test_wiener_is_vqf_core_at_the_matching_break_frequency(offline):
    """vqf low-passes the accelerometer in the gyro-integrated frame with a second-order
    Butterworth of time constant tau_acc: Rizun's filter (eq. 34) at omega_g = √2/tau_acc;
    offline it runs that Butterworth forward and backward (filtfilt): our smoother.
    With vqf's bias estimation off the two agree on the same samples, and the agreement
    is specific to that break frequency."""
    vqf = pytest.importorskip("vqf")
    motion = profile("human").motion().generate(200.0, FS, seed=3)
    gyr, acc = IMU.apply(motion, seed=4)
    tau = 3.0  # s, vqf's default
    params = {"tauAcc": tau, "motionBiasEstEnabled": False, "restBiasEstEnabled": False}
    if offline:
        q_vqf = vqf.offlineVQF(gyr, acc, None, 1 / FS, params)["quat6D"]
    else:
        q_vqf = vqf.VQF(1 / FS, **params).updateBatch(gyr, acc)["quat6D"]
    forgotten = int(15 * tau * FS)  # start-ups (vqf starts on a mean) and, offline, the end
    settled = slice(forgotten, -forgotten if offline else None)

    def rms_inclination(q, q_ref):
        return rms(np.degrees(quaternion_errors(q[settled], q_ref[settled])[2]))

    def rms_difference(omega_g):
        return rms_inclination(estimate(gyr, acc, FS, "wiener", {"omega_g": omega_g}, offline=offline, gyro_offset=False).quat, q_vqf)

    truth_error = rms_inclination(q_vqf, motion.quat)
    assert truth_error > 0.4  # vigorous motion: both are far from the truth ...
    assert rms_difference(math.sqrt(2) / tau) < (0.001 if offline else 0.05)  # ... and from each other by far less
    assert rms_difference(1.2 * math.sqrt(2) / tau) > 0.2
