"""The batch path on two threads (blocks/core/bindings/threads.cpp: the stages pipelined over
them) gives bit for bit what one thread gives: every method, with and without the gyro offset
and the magnetometer, the latency and the sample conventions, on a 9D recording long enough
for many of the threads' hand-overs; and a recording in blocks carries the stages' state on."""
import numpy as np
import pytest

from attitude_fmu import HumanMotion, ImuModel
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.pipeline.causal import State, at, configure, run

FS = 100.0
ROWS = 200_000
OUTPUTS = ("gravity", "quat", "offset", "mag_accepted", "mag_offset", "mag_delay")


@pytest.fixture(scope="module")
def recording():
    """A 9D human-motion recording of ROWS samples: (gyr, acc, mag), magnetometer samples missing here and there."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(ROWS / FS, FS, seed=4)
    imu = ImuModel(delta_n=np.radians(0.01), mag_noise=0.1, mag_offset=(8.0, -3.0, 5.0))
    gyr, acc = imu.apply(motion, seed=5)
    mag = imu.apply_mag(motion, seed=5)
    mag[::97] = np.nan
    return gyr, acc, mag


def assert_same(one, two):
    for name in OUTPUTS:
        a, b = getattr(one, name), getattr(two, name)
        assert (a is None) == (b is None), name
        if a is not None:
            rows = (a != b).reshape(len(a), -1).any(axis=1)
            assert not rows.any(), f"{name} differs on {int(rows.sum())} rows, the first {int(np.argmax(rows))}"


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("gyro_offset", [True, False])
@pytest.mark.parametrize("with_mag", [True, False])
def test_two_threads_give_what_one_gives(recording, method, gyro_offset, with_mag):
    gyr, acc, mag = recording
    mag = mag if with_mag else None
    one = estimate(gyr, acc, FS, method, gyro_offset=gyro_offset, mag=mag, threads=1)
    assert_same(one, estimate(gyr, acc, FS, method, gyro_offset=gyro_offset, mag=mag, threads=2))


@pytest.mark.parametrize("with_mag", [True, False])
def test_two_threads_with_latency_and_sample_conventions(recording, with_mag):
    """Stage 5 reads the hand-over (the offset-free gyro) on the second thread; point gyro and
    mean accelerometer samples are turned by stage 1 on the first."""
    gyr, acc, mag = recording
    options = dict(mag=mag if with_mag else None, latency=0.012, gyr_samples="point", acc_samples="mean",
                   initial_gravity=[0.0, 0.5, 9.8])
    assert_same(estimate(gyr, acc, FS, threads=1, **options), estimate(gyr, acc, FS, threads=2, **options))


def test_a_recording_in_blocks_on_two_threads(recording):
    """run over blocks of rows, the state carried on, each on two threads: the whole on one."""
    gyr, acc, mag = recording
    pipeline = configure("wiener", None, gyro_offset=True, heading=True)
    step = at(pipeline, 1.0 / FS)
    whole = run(pipeline, step, State(), gyr, acc, mag, threads=1)
    state, blocks = State(), []
    for rows in (slice(0, 30_000), slice(30_000, 30_005), slice(30_005, ROWS)):
        blocks.append(run(pipeline, step, state, gyr[rows], acc[rows], mag[rows], threads=2))
    for name in ("gravity", "quat", "offset", "offset_variance", "mag_accepted", "mag_offset", "mag_delay"):
        assert np.array_equal(getattr(whole, name), np.concatenate([getattr(b, name) for b in blocks])), name


def test_threads_must_be_at_least_one(recording):
    gyr, acc, _ = recording
    with pytest.raises(ValueError, match="threads must be at least 1, got 0"):
        estimate(gyr[:10], acc[:10], FS, threads=0)


@pytest.mark.parametrize("with_mag", [True, False])
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("wait", [0.0, 0.3])
def test_a_choice_before_the_method_gives_the_run_with_the_chosen_step(recording, with_mag, threads, wait):
    """run's choose: called once with the threads it may use, before the method's first row, its
    step then runs the method and the heading: bit for bit the run with that step from the start.
    On two threads the stages before the method run ahead while it chooses: a choice that takes
    0.3 s (the first thread far ahead: over 2.5 × 200 000 rows, past the hand-over's 262 144 rows
    it may lead by) gives the same."""
    import time

    gyr, acc, mag = (np.concatenate([a, a]) for a in recording)
    mag = mag if with_mag else None
    pipeline = configure("wiener", None, gyro_offset=True, heading=with_mag)
    given = configure("wiener", {"scale_error": 0.001, **({"tau_heading": 7.0} if with_mag else {})},
                      gyro_offset=True, heading=with_mag)
    calls = []

    def choose(workers):
        calls.append(workers)
        time.sleep(wait)
        return at(given, 1.0 / FS)

    chosen = run(pipeline, at(pipeline, 1.0 / FS), State(), gyr, acc, mag, threads=threads, choose=choose)
    assert calls == [1]
    assert_same(chosen, run(given, at(given, 1.0 / FS), State(), gyr, acc, mag, threads=1))
    kept = run(pipeline, at(pipeline, 1.0 / FS), State(), gyr, acc, mag, threads=threads, choose=lambda workers: None)
    assert_same(kept, run(pipeline, at(pipeline, 1.0 / FS), State(), gyr, acc, mag, threads=1))


@pytest.mark.parametrize("with_mag", [True, False])
@pytest.mark.parametrize("threads", [1, 2])
def test_a_choice_that_fails_stops_the_run_and_says_why(recording, with_mag, threads):
    """An exception in choose goes on to run's caller, on one thread or two (the first thread,
    ahead, stops); a step of another configuration is refused."""
    gyr, acc, mag = recording
    pipeline = configure("wiener", None, gyro_offset=True, heading=with_mag)
    step = at(pipeline, 1.0 / FS)

    def fails(workers):
        raise RuntimeError("no choice")

    with pytest.raises(RuntimeError, match="no choice"):
        run(pipeline, step, State(), gyr, acc, mag if with_mag else None, threads=threads, choose=fails)
    other = configure("wiener", {"rest_gyr": 0.5}, gyro_offset=True, heading=with_mag)
    with pytest.raises(ValueError, match="differ in the method's and the heading's coefficients alone"):
        run(pipeline, step, State(), gyr, acc, mag if with_mag else None, threads=threads,
            choose=lambda workers: at(other, 1.0 / FS))
