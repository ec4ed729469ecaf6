"""The simulation's C twins (fmu_src/native/sim) held to their Python twins (systems/simulation)
through ctypes: the random generator bit for bit, and against numpy's Philox; the closed-form
profiles and the human motion within 1e-12 per sample; the sensor model with every error; the
noise densities measured over a long run in both against their parameters."""
import ctypes
import math
import os

import numpy as np
import pytest
from scipy.signal import welch

from attitude_fmu.systems.simulation import noise
from attitude_fmu.systems.simulation.motion import PROFILES, HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.native import CORE, SANITIZE, core_library, sanitized_pytest

NATIVE = CORE.parent
FS = 100.0
CLOSED_FORMS = ["lever_arm", "incline", "coning", "sine_rotation", "step_rotation", "linear_motion",
                "offset_rotation"]  # sim/closed_form.h's ClosedFormProfile, in its order
_DOUBLES = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")
_U64 = ctypes.c_uint64


class ClosedForm(ctypes.Structure):
    _fields_ = [("profile", ctypes.c_int), ("p", ctypes.c_double * 5), ("g", ctypes.c_double)]


class HumanParams(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in ("delta_v", "omega_c", "rot_rms", "rot_cutoff", "g")]


class HumanStream(ctypes.Structure):
    _fields_ = [("params", HumanParams), ("seed", _U64), ("k", _U64), ("h", ctypes.c_double),
                ("coef", ctypes.c_double * 6), ("state", ctypes.c_double * 10)]


class ImuParams(ctypes.Structure):
    _fields_ = [("delta_n", ctypes.c_double), ("gyr_offset", ctypes.c_double * 3), ("gyr_scale", ctypes.c_double * 9),
                ("acc_noise", ctypes.c_double), ("acc_offset", ctypes.c_double * 3), ("latency", ctypes.c_double),
                ("mag_noise", ctypes.c_double), ("mag_offset", ctypes.c_double * 3)]


class DelayLine(ctypes.Structure):
    _fields_ = [("latency", ctypes.c_double), ("fs", ctypes.c_double), ("rows", ctypes.c_int), ("head", ctypes.c_int),
                ("x", ctypes.c_double * (1024 * 6))]


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    """sim/*.c with the core's quaternions and messages."""
    lib = core_library(tmp_path_factory.mktemp("native_sim"),
                       [CORE / "quaternion.c", CORE / "messages.c", *sorted((NATIVE / "sim").glob("*.c"))],
                       include=[NATIVE])
    lib.philox4x64.argtypes = [ctypes.POINTER(_U64), ctypes.POINTER(_U64), ctypes.POINTER(_U64)]
    lib.noise_normals.argtypes = [_U64, _U64, _U64, ctypes.c_int, _DOUBLES]
    lib.closed_form_at.argtypes = [ctypes.POINTER(ClosedForm), ctypes.c_double, ctypes.c_double, _DOUBLES, _DOUBLES,
                                   _DOUBLES]
    lib.human_check.argtypes = [ctypes.POINTER(HumanParams), ctypes.c_char_p, ctypes.c_size_t]
    lib.human_stream_init.argtypes = [ctypes.POINTER(HumanStream), ctypes.POINTER(HumanParams), _U64]
    lib.human_stream_step.argtypes = [ctypes.POINTER(HumanStream), ctypes.c_double, _DOUBLES]
    lib.imu_check.argtypes = [ctypes.POINTER(ImuParams), ctypes.c_char_p, ctypes.c_size_t]
    lib.imu_measure.argtypes = [ctypes.POINTER(ImuParams), _DOUBLES, _DOUBLES, _DOUBLES, ctypes.c_double, _DOUBLES,
                                _DOUBLES]
    lib.imu_measure_mag.argtypes = [ctypes.POINTER(ImuParams), _DOUBLES, _DOUBLES, ctypes.c_double, _DOUBLES]
    lib.delay_init.argtypes = [ctypes.POINTER(DelayLine), ctypes.c_double, ctypes.c_double, _DOUBLES, ctypes.c_char_p,
                               ctypes.c_size_t]
    lib.delay_step.argtypes = [ctypes.POINTER(DelayLine), _DOUBLES, _DOUBLES]
    return lib


def _c_normals(lib, seed, stream, n, width):
    out = np.empty((n, width))
    for k in range(n):
        lib.noise_normals(seed, stream, k, width, out[k])
    return out


@pytest.mark.parametrize("counter, key", [((0, 0, 0, 0), (0, 0)), ((7, 1, 0, 0), (5, 1)),
                                          ((2**64 - 1, 3, 9, 2**63), (2**64 - 1, 2))])
def test_the_generator_is_numpys_philox4x64_10(lib, counter, key):
    """The C block equals numpy's Philox bit generator on the same counter and key (numpy
    counts its counter up before each block, hence counter − 1)."""
    before = (sum(c << (64 * i) for i, c in enumerate(counter)) - 1) % 2**256
    expected = np.random.Philox(counter=before, key=key[0] + (key[1] << 64)).random_raw(4)
    out = (_U64 * 4)()
    lib.philox4x64((_U64 * 4)(*counter), (_U64 * 2)(*key), out)
    assert list(out) == [int(w) for w in expected]


def test_the_normals_are_box_muller_of_philox_blocks():
    """normals: sample k's lanes are Box–Muller pairs of the words of block (k, j) under the key
    (seed, stream), recomputed here from numpy's Philox and numpy's log, cos and sin."""
    seed, n = 2**40 + 3, 500
    got = noise.normals(seed, noise.SENSOR, n)
    key = seed + (noise.SENSOR << 64)
    words = np.array([[np.random.Philox(counter=(k + (j << 64) - 1) % 2**256, key=key).random_raw(4) for j in range(2)]
                      for k in range(n)]).reshape(n, 8)
    u = ((words >> np.uint64(12)).astype(float) + 0.5) * 2.0**-52
    r, angle = np.sqrt(-2.0 * np.log(u[:, 0::2])), 2.0 * math.pi * u[:, 1::2]
    expected = np.stack([r * np.cos(angle), r * np.sin(angle)], axis=2).reshape(n, 8)[:, :6]
    assert np.abs(got - expected).max() < 1e-13


@pytest.mark.parametrize("seed, stream", [(0, noise.MOTION), (7, noise.SENSOR), (2**64 - 1, noise.MAGNETOMETER)])
def test_python_and_c_draw_the_same_bits(lib, seed, stream):
    width = noise.STREAM_WIDTHS[stream]
    python = noise.normals(seed, stream, 5000, width)
    assert (python == _c_normals(lib, seed, stream, 5000, width)).all()
    one = noise.NoiseStream(seed, stream)
    assert all((one.next() == row).all() for row in python[:200])  # sample by sample: the same rows
    assert (noise.normals(seed, stream, 10, width, first=4990) == python[4990:]).all()


def test_the_streams_are_unit_normal_and_independent():
    z = np.hstack([noise.normals(3, s, 100_000) for s in (noise.MOTION, noise.SENSOR, noise.MAGNETOMETER)])
    assert np.abs(z.mean(axis=0)).max() < 5 / math.sqrt(len(z))
    assert np.abs(z.std(axis=0) - 1.0).max() < 0.01
    assert np.abs(np.corrcoef(z.T) - np.eye(z.shape[1])).max() < 5 / math.sqrt(len(z))
    assert np.abs(np.corrcoef(z[1:, 0], z[:-1, 0])[0, 1]) < 5 / math.sqrt(len(z))  # from one sample to the next
    # the tails of a normal: P(|z| > 4) = 6.3e-5
    assert np.mean(np.abs(z) > 4.0) == pytest.approx(6.334e-5, rel=0.25)


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, True])
def test_a_seed_outside_0_to_2_64_is_refused(seed):
    with pytest.raises(ValueError, match="seed must be a whole number"):
        noise.normals(seed, noise.MOTION, 1)


@pytest.mark.parametrize("name", CLOSED_FORMS)
@pytest.mark.parametrize("changed", [False, True])
def test_closed_form_profiles_equal_their_python_truth(lib, name, changed):
    """Every closed-form profile, at its defaults and with every parameter changed, over 60 s
    (many turns of the rotating ones): gyr, specific force and quaternion within 1e-12."""
    prof = PROFILES[name]
    overrides = {p.name: 1.3 * p.default + 0.7 for p in prof.params} if changed else {}
    values = [overrides.get(p.name, p.default) for p in prof.params]
    motion = prof.motion(overrides, g=9.79)
    t = np.arange(1, 6001) / FS
    gyr, acc, quat = motion.at(t, 1.0 / FS)
    c = ClosedForm(CLOSED_FORMS.index(name), (ctypes.c_double * 5)(*values), 9.79)
    out = np.empty((len(t), 10))
    for k in range(len(t)):
        lib.closed_form_at(ctypes.byref(c), t[k], 1.0 / FS, out[k, 0:3], out[k, 3:6], out[k, 6:10])
    assert np.abs(out[:, 0:3] - gyr).max() < 1e-12
    assert np.abs(out[:, 3:6] - acc).max() < 1e-12
    assert np.abs(out[:, 6:10] - quat).max() < 1e-12


def _human_c(lib, motion, seed, n, h):
    params = HumanParams(motion.delta_v, motion.omega_c, motion.rot_rms, motion.rot_cutoff, motion.g)
    stream, out = HumanStream(), np.empty((n, 10))
    lib.human_stream_init(ctypes.byref(stream), ctypes.byref(params), seed)
    for k in range(n):
        lib.human_stream_step(ctypes.byref(stream), h, out[k])
    return out


@pytest.mark.parametrize("motion, seed", [(HumanMotion(), 0), (HumanMotion(0.4, 6.0, 2.5, 9.0, 9.79), 2**33 + 5)])
def test_the_human_profile_equals_python_with_the_same_seed(lib, motion, seed):
    """600 s at 100 Hz: the C stream equals HumanMotion.generate per sample within 1e-12 of each
    quantity's scale (the specific force reaches 200 m/s²: the rounding of 60000 integrated
    rotations, numba's contracted multiply-adds against C's plain ones, turns it by 1e-14 rad),
    and the Python stream (the pythonfmu FMU's) equals generate exactly."""
    n = 60000
    batch = motion.generate(n / FS, FS, seed)
    out = _human_c(lib, motion, seed, n, 1.0 / FS)
    for got, expected in ((out[:, 0:3], batch.gyr), (out[:, 3:6], batch.acc), (out[:, 6:10], batch.quat)):
        assert np.abs(got - expected).max() < 1e-12 * max(1.0, np.abs(expected).max())
    stream = motion.stream(seed)
    for k in range(300):
        gyr, f, q = stream.step((k + 1) / FS, 1.0 / FS)
        assert (gyr == batch.gyr[k]).all() and (f == batch.acc[k]).all() and (q == batch.quat[k]).all()


@pytest.mark.parametrize("values", [{"delta_v": 0.0}, {"omega_c": math.nan}, {"rot_cutoff": -1.0},
                                    {"g": math.inf}, {"rot_rms": -0.5}])
def test_the_human_profile_refuses_what_python_refuses(lib, values):
    params = {"delta_v": 1.0, "omega_c": 10.0, "rot_rms": 1.0, "rot_cutoff": 5.0, "g": 9.81, **values}
    with pytest.raises(ValueError) as python:
        HumanMotion(**params)
    message = ctypes.create_string_buffer(256)
    assert lib.human_check(ctypes.byref(HumanParams(**params)), message, 256) == -1
    assert message.value.decode() == str(python.value)


SENSOR = dict(delta_n=math.radians(0.1), gyr_offset=(0.01, -0.02, 0.03),
              gyr_scale=((0.01, -0.002, 0.0), (0.003, 0.0, 0.005), (0.0, 0.004, -0.02)), acc_noise=0.01,
              acc_offset=(0.1, -0.2, 0.3), latency=0.0234, mag_noise=0.5, mag_offset=(8.0, -3.0, 12.0))


def _imu_params(imu: ImuModel) -> ImuParams:
    return ImuParams(imu.delta_n, (ctypes.c_double * 3)(*imu.gyr_offset),
                     (ctypes.c_double * 9)(*np.ravel(imu.gyr_scale)), imu.acc_noise,
                     (ctypes.c_double * 3)(*imu.acc_offset), imu.latency, imu.mag_noise,
                     (ctypes.c_double * 3)(*imu.mag_offset))


def _sensor_c(lib, imu, motion, seed):
    """The C sensor over a motion as the native FMU steps it: the delay line started on the first
    sample, noise from the streams SENSOR and MAGNETOMETER."""
    params, line, fs = _imu_params(imu), DelayLine(), motion.fs
    truth = np.ascontiguousarray(np.hstack([motion.gyr, motion.acc]))
    mag_true = np.ascontiguousarray(motion.mag)
    gyr, acc, mag = np.empty_like(motion.gyr), np.empty_like(motion.gyr), np.empty_like(motion.gyr)
    signals, n6, n3 = np.empty(6), np.empty(6), np.empty(3)
    if imu.latency:
        assert lib.delay_init(ctypes.byref(line), imu.latency, fs, truth[0], None, 0) == 0
    for k in range(len(truth)):
        if imu.latency:
            lib.delay_step(ctypes.byref(line), truth[k], signals)
        else:
            signals[:] = truth[k]
        lib.noise_normals(seed, noise.SENSOR, k, 6, n6)
        lib.imu_measure(ctypes.byref(params), signals[0:3], signals[3:6], n6, fs, gyr[k], acc[k])
        lib.noise_normals(seed, noise.MAGNETOMETER, k, 3, n3)
        lib.imu_measure_mag(ctypes.byref(params), mag_true[k], n3, fs, mag[k])
    return gyr, acc, mag


@pytest.mark.parametrize("latency", [0.0, 0.0234, 0.05])
def test_the_sensor_equals_python_with_the_same_seed(lib, latency):
    """Noise, offsets, scale and misalignment, latency (between samples and a whole number of
    them), magnetometer noise and hard iron: the C sensor equals ImuModel.apply and apply_mag
    per sample within 1e-12 on 60 s of human motion."""
    imu = ImuModel(**{**SENSOR, "latency": latency})
    motion = HumanMotion().generate(60.0, FS, seed=3)
    gyr, acc = imu.apply(motion, seed=4)
    mag = imu.apply_mag(motion, seed=4)
    c_gyr, c_acc, c_mag = _sensor_c(lib, imu, motion, 4)
    assert np.abs(c_gyr - gyr).max() < 1e-12
    assert np.abs(c_acc - acc).max() < 1e-12
    assert np.abs(c_mag - mag).max() < 1e-12


def test_a_latency_too_long_for_the_delay_line_is_refused(lib):
    message = ctypes.create_string_buffer(256)
    assert lib.delay_init(ctypes.byref(DelayLine()), 11.0, 100.0, np.zeros(6), message, 256) == -1
    assert message.value.decode() == "latency 11.0 s at 100.0 Hz is longer than the delay line's 1021 samples"
    assert lib.delay_init(ctypes.byref(DelayLine()), 10.2, 100.0, np.zeros(6), message, 256) == 0


@pytest.mark.parametrize("values", [{"delta_n": -1.0}, {"acc_noise": math.nan}, {"latency": math.inf},
                                    {"mag_noise": -0.1}, {"gyr_offset": (0.0, math.nan, 0.0)},
                                    {"acc_offset": (math.inf, 0.0, 0.0)}, {"mag_offset": (0.0, 0.0, -math.inf)},
                                    {"gyr_scale": ((0.0, 0.0, 0.0), (0.0, 0.0, math.nan), (0.0, 0.0, 0.0))}])
def test_the_sensor_refuses_what_python_refuses(lib, values):
    with pytest.raises(ValueError) as python:
        ImuModel(**{**SENSOR, **values})
    params = _imu_params(ImuModel())
    for name, value in values.items():
        setattr(params, name, type(getattr(params, name))(*np.ravel(value)) if isinstance(value, tuple) else value)
    message = ctypes.create_string_buffer(256)
    assert lib.imu_check(ctypes.byref(params), message, 256) == -1
    assert message.value.decode() == str(python.value)


def _density(x, fs):
    """The one-sided noise density (unit/√Hz) of each column of x: Welch's estimate averaged
    over the band, DC and Nyquist left out."""
    _, psd = welch(x, fs, nperseg=256, axis=0)
    return np.sqrt(psd[1:-1].mean(axis=0))


def test_the_noise_densities_measured_over_a_long_run_are_the_parameters(lib):
    """500 s at 100 Hz at rest: the measured error's density is delta_n, acc_noise and
    mag_noise within 3 %, in the Python and in the C sensor (Welch's estimate scatters by
    about 0.3 % here; a per-sample s.d. of density·√fs instead of density·√(fs/2) is 41 % off)."""
    imu = ImuModel(delta_n=math.radians(0.1), acc_noise=0.02, mag_noise=0.3, gyr_offset=(0.01, 0.0, 0.0))
    motion = HumanMotion(delta_v=1e-12, rot_rms=0.0).generate(500.0, FS, seed=1)
    gyr, acc = imu.apply(motion, seed=9)
    python = (gyr - motion.gyr, acc - motion.acc, imu.apply_mag(motion, seed=9) - motion.mag)
    native = [x - truth for x, truth in zip(_sensor_c(lib, imu, motion, 9), (motion.gyr, motion.acc, motion.mag))]
    for errors in (python, native):
        for error, density in zip(errors, (imu.delta_n, imu.acc_noise, imu.mag_noise)):
            assert _density(error - error.mean(axis=0), FS) == pytest.approx(np.full(3, density), rel=0.03)


@pytest.mark.skipif(bool(os.environ.get(SANITIZE)), reason="this is the sanitized run")
def test_the_simulation_twins_run_clean_under_the_sanitizers():
    """This file's C comparisons again on sim/ built with -fsanitize=address,undefined."""
    run = sanitized_pytest(__file__, "-x", "-k", "not long_run and not independent and not box_muller")
    if run is None:
        pytest.skip("the C compiler names no address-sanitizer runtime")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "runtime error" not in run.stderr and "Sanitizer" not in run.stderr, run.stderr[-3000:]
