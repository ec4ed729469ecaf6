"""The Wiener filter's scale_error chosen from the recording (blocks.stages.scale_error): its
criterion (blocks/core/stages/prediction.h) against scipy's rotations and closed forms, the
binding's refusals, the choice against the true inclination error of simulated recordings
(systems.simulation.recording), and where the rule applies."""
import json
import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu import _core
from attitude_fmu.blocks.errors import inclination_error, rms
from attitude_fmu.blocks.methods.registry import method
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.stages import scale_error
from attitude_fmu.blocks.stages.scale_error import SCALE_ERRORS
from attitude_fmu.systems.simulation.recording import SENSORS, simulate_recording

FS = 100.0
G = 9.81
DEFAULT = method("wiener").resolve()["scale_error"]  # the parameter's default, the rule's top candidate
HORIZON = 50  # samples: PREDICTION_HORIZON_S at FS


def _criterion(gyr, acc, gravity, Ts, m) -> float:
    """The mean over k ≥ m of |R_k·a_k − R_(k−m)·g_(k−m)|² with R_k = R_(k−1)·exp(ω_k·Ts) from scipy's
    Rotation (m²/s⁴)."""
    turns = Rotation.from_rotvec(np.asarray(gyr) * Ts)
    frames = [turns[0]]
    for turn in turns[1:]:
        frames.append(frames[-1] * turn)
    frames = Rotation.concatenate(frames)
    predicted, measured = frames.apply(gravity), frames.apply(acc)
    return float(np.mean(np.sum((measured[m:] - predicted[:-m]) ** 2, axis=1)))


@cache
def _recording(sensor: str, seed: int, offset_dps: float | None = None):
    """Two minutes of human motion after 10 s of rest at FS, no magnetometer (offset_dps: the
    sensor's gyro offset replaced, °/s)."""
    figures = SENSORS[sensor] if offset_dps is None else replace(SENSORS[sensor], gyro_offset_dps=offset_dps)
    return simulate_recording(FS, 120.0, 10.0, figures, seed=seed, mag=False)


def _error(est, rec) -> float:
    """The RMS inclination error over the movement (rad), against the reference's up."""
    up = Rotation.from_quat(rec.quat_ref, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    return rms(inclination_error(est.gravity[rec.movement], up[rec.movement]))


def _errors(rec, **options) -> dict[float, float]:
    """{candidate: its true error} with scale_error given."""
    return {c: _error(estimate(rec.gyr, rec.acc, rec.fs, params={"scale_error": c}, **options), rec)
            for c in SCALE_ERRORS}


def _same(a, b) -> bool:
    """Two estimates bit for bit (gravity and quat)."""
    return np.array_equal(a.gravity, b.gravity) and np.array_equal(a.quat, b.quat)


@pytest.mark.parametrize("m", [1, 7, 50])
def test_the_criterion_is_scipys_on_random_rows(m):
    """Random rates up to 3 rad/s per axis, accelerometer and estimate: the C criterion is the
    mean scipy's rotations give, within 1e-9; scale_error.prediction_error takes the horizon of
    PREDICTION_HORIZON_S at the rate."""
    rng = np.random.default_rng(m)
    n, Ts = 400, 1.0 / FS
    gyr = rng.uniform(-3.0, 3.0, (n, 3))
    acc = rng.normal(0.0, 4.0, (n, 3)) + [0.0, 0.0, G]
    gravity = rng.normal(0.0, 2.0, (n, 3)) + [0.0, 0.0, G]
    assert _core.prediction_error(gyr, acc, gravity, Ts, m) == pytest.approx(_criterion(gyr, acc, gravity, Ts, m),
                                                                              rel=1e-9)
    for fs, horizon in ((FS, HORIZON), (30.0, 15)):
        assert scale_error.prediction_error(gyr, acc, gravity, fs) == pytest.approx(
            _criterion(gyr, acc, gravity, 1.0 / fs, horizon), rel=1e-9)


@pytest.mark.parametrize("block", [1, 37, 350, 351, 1000])
def test_the_block_means_are_scipys_over_each_block(block):
    """prediction_errors: the criterion's squared differences (scipy's rotations) averaged over
    consecutive blocks of the k ≥ m, the last holding those left over, within 1e-9; one block
    of every row is prediction_error."""
    rng = np.random.default_rng(block)
    n, m, Ts = 400, 50, 1.0 / FS
    gyr = rng.uniform(-3.0, 3.0, (n, 3))
    acc = rng.normal(0.0, 4.0, (n, 3)) + [0.0, 0.0, G]
    gravity = rng.normal(0.0, 2.0, (n, 3)) + [0.0, 0.0, G]
    turns = Rotation.from_rotvec(gyr * Ts)
    frames = [turns[0]]
    for turn in turns[1:]:
        frames.append(frames[-1] * turn)
    frames = Rotation.concatenate(frames)
    squared = np.sum((frames.apply(acc)[m:] - frames.apply(gravity)[:-m]) ** 2, axis=1)
    expected = [np.mean(squared[i:i + block]) for i in range(0, n - m, block)]
    got = _core.prediction_errors(gyr, acc, gravity, Ts, m, block)
    assert got == pytest.approx(expected, rel=1e-9)
    if block >= n - m:
        assert got[0] == _core.prediction_error(gyr, acc, gravity, Ts, m)
    with pytest.raises(ValueError, match="block must be 1 sample or more"):
        _core.prediction_errors(gyr, acc, gravity, Ts, m, 0)


@pytest.mark.parametrize("z, taken", [(-3.0, True), (-scale_error.SIGNIFICANCE - 0.05, True),
                                      (-scale_error.SIGNIFICANCE + 0.05, False), (0.0, False), (2.0, False)])
def test_a_lower_candidate_is_taken_only_where_its_blocks_show_it(z, taken):
    """scale_error.choose compares each candidate's block errors with the default's, pair by pair.
    A still sensor, the accelerometer gravity alone; the default's estimate is off by D on z,
    0's by D + δ_j in block j, so that its block errors differ from the default's by
    (D + δ_j)² − D² = s + ε·(−1)^j over 12 blocks (s.e. of the mean ε/√11); 0.001 and 0.002 are
    far worse. 0 is taken where s lies more than SIGNIFICANCE standard errors below 0, here s =
    z·ε/√11."""
    blocks, D, noise = 12, 0.1, 1e-4
    block, m = round(scale_error.BLOCK_S * FS), HORIZON
    n = blocks * block + m
    gyr, acc = np.zeros((n, 3)), np.tile([0.0, 0.0, G], (n, 1))
    differences = z * noise / math.sqrt(blocks - 1) + noise * (-1.0) ** np.arange(blocks)
    default = np.tile([0.0, 0.0, G + D], (n, 1))

    def run(candidate: float) -> np.ndarray:
        if candidate == DEFAULT:
            return default
        out = default + [0.0, 0.0, 1.0]
        if candidate == 0.0:  # the estimate at k − m predicts row k: block j's rows of estimate
            for j, difference in enumerate(differences):
                out[j * block:(j + 1) * block, 2] = G + math.sqrt(D**2 + difference)
        return out

    found, errors = scale_error.choose({c: scale_error.prediction_errors(gyr, acc, run(c), FS, block) for c in SCALE_ERRORS})
    assert errors[DEFAULT] == pytest.approx(D**2, rel=1e-12)
    assert errors[0.0] - errors[DEFAULT] == pytest.approx(np.mean(differences), rel=1e-6, abs=1e-15)
    assert found == (0.0 if taken else DEFAULT)


@pytest.mark.parametrize("windowed", [True, False])
def test_one_pass_scores_each_candidate_as_its_own_run_does(windowed):
    """scale_error.block_errors (one pass over each window for every candidate) gives, bit for bit,
    the block errors of each candidate run alone through the causal pipeline (warm-up with the
    default, then the candidate from its state; or from initial_gravity over every row) and
    scored by prediction_errors from the horizon before its first row scored."""
    from copy import copy

    from attitude_fmu.blocks.pipeline.causal import State, at, configure, run

    rec = _recording("consumer", 1)
    gyr, acc = np.ascontiguousarray(rec.gyr[:9000]), np.ascontiguousarray(rec.acc[:9000])
    windows = [(0, 1000, 4000), (4000, 5500, 9000)] if windowed else None
    start = None if windowed else np.array([0.3, -0.2, 9.7])
    block, m = round(scale_error.BLOCK_S * FS), HORIZON

    def alone(params):
        pipeline = configure("wiener", params, gyro_offset=False)
        return pipeline, at(pipeline, 1.0 / FS)

    expected = {c: [] for c in SCALE_ERRORS}
    for first, scored, end in windows or [(0, 0, len(gyr))]:
        state, gravity = State(), np.empty((end - first, 3))
        if scored > first:
            gravity[:scored - first] = run(*alone({}), state, gyr[first:scored], acc[first:scored]).gravity
        for c in SCALE_ERRORS:
            gravity[scored - first:] = run(*alone({"scale_error": c}), copy(state), gyr[scored:end], acc[scored:end],
                                           initial_gravity=start).gravity
            a = max(scored - m, first)
            expected[c].append(scale_error.prediction_errors(gyr[a:end], acc[a:end], gravity[a - first:], FS, block))
    got = scale_error.block_errors(alone({})[1].core, [alone({"scale_error": c})[1].core for c in SCALE_ERRORS],
                                   gyr, acc, FS, windows, start, workers=2)
    assert got.shape == (len(SCALE_ERRORS), sum(len(e) for e in expected[DEFAULT]))
    for row, c in zip(got, SCALE_ERRORS):
        assert np.array_equal(row, np.concatenate(expected[c]))


def test_one_pass_refuses_what_it_cannot_score():
    """The kernel scores the Wiener filter with local densities at one sample time alone."""
    from attitude_fmu.blocks.pipeline.causal import at, configure

    def step(method="wiener", params=None, Ts=0.01):
        return at(configure(method, params, gyro_offset=False), Ts).core

    rows = np.zeros((100, 3))
    with pytest.raises(ValueError, match="local densities alone"):
        _core.scale_error_errors(step(), [step("wiener", {"stationary": 1})], rows, rows, 10, None, 5, 10)
    with pytest.raises(ValueError, match="share the sample time"):
        _core.scale_error_errors(step(), [step(Ts=0.02)], rows, rows, 10, None, 5, 10)
    with pytest.raises(ValueError, match="1 to 8 candidates"):
        _core.scale_error_errors(step(), [], rows, rows, 10, None, 5, 10)
    with pytest.raises(ValueError, match="warm-up is longer"):
        _core.scale_error_errors(step(), [step()], rows, rows, 101, None, 5, 10)


@pytest.mark.parametrize("theta", [0.0, 0.1, 1.0])
def test_a_steady_turn_leaves_only_the_estimates_tilt(theta):
    """A sensor turning at a constant rate (about an axis off the vertical) from a tilted
    start, the accelerometer gravity alone, the estimate tilted by θ about x in the earth
    frame: the criterion is |ẑ − Rx(θ)·ẑ|²·g² = 4·g²·sin²(θ/2) (0 for the true gravity)."""
    n, rate = 500, np.array([1.2, -0.7, 2.0])  # rad/s
    turned = Rotation.from_rotvec([0.3, -0.2, 1.0]) * Rotation.from_rotvec(np.arange(1, n + 1)[:, None] * rate / FS)
    acc = turned.inv().apply([0.0, 0.0, G])
    gravity = turned.inv().apply(Rotation.from_rotvec([theta, 0.0, 0.0]).apply([0.0, 0.0, G]))
    got = _core.prediction_error(np.tile(rate, (n, 1)), acc, gravity, 1.0 / FS, HORIZON)
    assert got == pytest.approx(4.0 * G**2 * math.sin(theta / 2.0) ** 2, rel=1e-9, abs=1e-20 * G**2)


def test_a_still_sensor_gives_the_squared_difference_exactly():
    """No rotation, constant accelerometer a and estimate b (dyadic, so every sum is exact): |a − b|²."""
    n, a, b = 200, np.array([0.5, -1.25, 9.75]), np.array([0.0, 0.25, 9.5])
    got = _core.prediction_error(np.zeros((n, 3)), np.tile(a, (n, 1)), np.tile(b, (n, 1)), 0.01, 10)
    assert got == float(np.sum((a - b) ** 2))


@pytest.mark.parametrize("change, message", [
    ({"horizon": 0}, "horizon must be 1 to 100 - 1 samples, got 0"),
    ({"horizon": 100}, "horizon must be 1 to 100 - 1 samples, got 100"),
    ({"horizon": 250}, "got 250"),
    ({"acc": np.zeros((99, 3))}, "acc has 99 rows, not 100"),
    ({"gravity": np.zeros((101, 3))}, "gravity has 101 rows, not 100"),
    ({"Ts": 0.0}, "Ts must be a finite positive"),
    ({"Ts": -0.01}, "Ts must be a finite positive"),
    ({"Ts": math.nan}, "Ts must be a finite positive"),
    ({"Ts": math.inf}, "Ts must be a finite positive"),
])
def test_the_binding_refuses_what_has_no_criterion(change, message):
    """A horizon outside 1 … N − 1, rows of other lengths, a sample time not finite and positive."""
    rows = np.zeros((100, 3))
    args = {"gyr": rows, "acc": rows, "gravity": rows, "Ts": 0.01, "horizon": 10}
    with pytest.raises(ValueError, match=message):
        _core.prediction_error(**{**args, **change})


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("sensor, best", [("calibrated", 0.0), ("low_range", DEFAULT)])
def test_the_choice_has_the_true_error_of_the_best_candidate(sensor, best, seed):
    """A calibrated gyro (0.05 % scale error) gets 0 and at most 0.6 of the default's true
    error; a 1 % one gets the default. Either way the choice's error is within 5 % of the best
    candidate's, and the estimate is the one with the chosen value given."""
    rec = _recording(sensor, seed)
    est, errors = estimate(rec.gyr, rec.acc, rec.fs), _errors(rec)
    print(sensor, seed, est.chosen, {c: f"{math.degrees(e):.4f}°" for c, e in errors.items()})
    assert est.chosen == {"scale_error": best}
    assert errors[best] <= 1.05 * min(errors.values())
    if sensor == "calibrated":
        assert errors[best] <= 0.6 * errors[DEFAULT]
    assert _same(est, estimate(rec.gyr, rec.acc, rec.fs, params=est.chosen))


@pytest.mark.parametrize("offline", [False, True])
@pytest.mark.parametrize("given", [0.003, DEFAULT])
def test_a_given_scale_error_holds(given, offline):
    """scale_error given: nothing chosen, and the estimate is not the default's, which chose 0 here
    (tests/test_golden.py holds estimates with it given to those frozen before the rule)."""
    rec = _recording("calibrated", 0)
    est = estimate(rec.gyr, rec.acc, rec.fs, params={"scale_error": given}, offline=offline)
    default = estimate(rec.gyr, rec.acc, rec.fs, offline=offline)
    assert est.chosen is None and default.chosen == {"scale_error": 0.0}
    assert not np.array_equal(est.gravity, default.gravity)


@pytest.mark.parametrize("method, params, applies", [
    ("wiener", {}, True), ("wiener", {"tau_noise": 0.3}, True), ("wiener", {"stationary": 1.0}, False),
    ("wiener", {"omega_g": 1.0}, False), ("first_order", {}, False), ("luinge", {}, False), ("mahony", {}, False),
    ("tseng", {}, False), ("tseng_adaptive", {}, False),
])
def test_the_rule_chooses_for_the_local_wiener_filter_alone(method, params, applies):
    """Only wiener with its local densities (not stationary, no ω_g given) gets a choice."""
    rec = _recording("calibrated", 0)
    assert (estimate(rec.gyr, rec.acc, rec.fs, method, params).chosen is not None) == applies


@pytest.mark.parametrize("n", [30, HORIZON, HORIZON + 1])
def test_a_recording_no_longer_than_the_horizon_keeps_the_default(n):
    """No more samples than the horizon (50 at 100 Hz): nothing to predict, nothing chosen,
    the default's estimate; one more and the rule chooses."""
    rec = _recording("calibrated", 0)
    gyr, acc = rec.gyr[-n:], rec.acc[-n:]
    est = estimate(gyr, acc, rec.fs)
    if n <= HORIZON:
        assert est.chosen is None
        assert _same(est, estimate(gyr, acc, rec.fs, params={"scale_error": DEFAULT}))
    else:
        assert est.chosen is not None


@pytest.mark.parametrize("sensor, best", [("calibrated", 0.0), ("low_range", DEFAULT)])
def test_a_long_recording_is_chosen_on_its_windows_alone(sensor, best):
    """30 min with a magnetometer: the choice runs on scale_error.subset's rows alone, as many
    whatever the length (WINDOWS·(WARM_UP_S + SCORED_S)·fs): every other row replaced by a
    steady turn leaves scale_error and tau_heading as they were, and the choice is the
    sensor's (0 for a calibrated gyro, the default for one of 1 %); a recording no longer
    than the windows is used whole (subset None)."""
    rec = simulate_recording(FS, 1800.0, 10.0, SENSORS[sensor], seed=3)
    rows, windows = scale_error.subset(len(rec.gyr), rec.fs)
    cap = scale_error.WINDOWS * round((scale_error.WARM_UP_S + scale_error.SCORED_S) * FS)
    assert len(rows) == cap == windows[-1][2] and len(set(rows)) == cap
    assert scale_error.subset(cap, FS) is None and scale_error.subset(cap + 1, FS) is not None
    outside = np.ones(len(rec.gyr), dtype=bool)
    outside[rows] = False
    gyr, acc = rec.gyr.copy(), rec.acc.copy()
    gyr[outside], acc[outside] = [0.0, 0.0, 1.0], [0.0, 0.0, G]
    est = estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag)
    print(sensor, est.chosen)
    assert est.chosen["scale_error"] == best
    assert estimate(gyr, acc, rec.fs, mag=rec.mag).chosen == est.chosen


def test_offline_the_same_choice_is_made_and_used():
    """offline=True: the choice of the causal path, and the offline estimate with it given."""
    rec = _recording("calibrated", 0)
    est = estimate(rec.gyr, rec.acc, rec.fs, offline=True)
    assert est.chosen == estimate(rec.gyr, rec.acc, rec.fs).chosen == {"scale_error": 0.0}
    assert _same(est, estimate(rec.gyr, rec.acc, rec.fs, params=est.chosen, offline=True))


def test_the_choice_is_made_on_the_gyro_as_the_pipeline_frees_it():
    """A calibrated gyro with a 2 °/s offset: with the gyro-offset stage the offset is removed
    before the choice, which is 0 as for the sensor's own 0.05 °/s; without the stage the choice
    is made on the gyro as it is, and has the true error of the best candidate within 5 %."""
    rec = _recording("calibrated", 0, offset_dps=2.0)
    assert estimate(rec.gyr, rec.acc, rec.fs).chosen == {"scale_error": 0.0}
    est, errors = estimate(rec.gyr, rec.acc, rec.fs, gyro_offset=False), _errors(rec, gyro_offset=False)
    print(est.chosen, {c: f"{math.degrees(e):.3f}°" for c, e in errors.items()})
    assert est.chosen is not None
    assert errors[est.chosen["scale_error"]] <= 1.05 * min(errors.values())
    assert _same(est, estimate(rec.gyr, rec.acc, rec.fs, params=est.chosen, gyro_offset=False))


def test_the_command_line_says_what_it_chose(tmp_path, capsys):
    """`attitude estimate` notes the choice with the flag that holds it; `attitude evaluate` lists
    each recording's under its table and under "chosen" in its JSON."""
    from attitude_fmu.systems.cli.commands import main
    from attitude_fmu.systems.recordings.writing import write_recording

    rec = _recording("calibrated", 0)
    path = tmp_path / "calibrated.csv"
    write_recording(path, rec)
    assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 0
    assert "scale_error 0 chosen from the recording" in capsys.readouterr().err
    assert main(["evaluate", "--workers", "1", "--reference-north", "magnetic", str(path)]) == 0
    assert "scale_error chosen from each recording" in capsys.readouterr().out
    assert main(["evaluate", "--json", "--workers", "1", "--reference-north", "magnetic", str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["chosen"] == {"calibrated": {"scale_error": 0.0}}
    assert main(["evaluate", "--json", "--workers", "1", "--param", "scale_error=0.005", str(path)]) == 0
    assert "chosen" not in json.loads(capsys.readouterr().out)


def test_the_choice_is_the_same_on_any_threads():
    """threads (the causal pipeline's; the candidates run one after another) 1, 2 or None: the
    same choice, the same estimate bit for bit."""
    rec = _recording("calibrated", 1)
    one = estimate(rec.gyr, rec.acc, rec.fs, threads=1)
    for threads in (2, None):
        est = estimate(rec.gyr, rec.acc, rec.fs, threads=threads)
        assert est.chosen == one.chosen and _same(est, one)
