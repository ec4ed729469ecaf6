"""One test body over every way a step of the estimator is reached, each held to the golden
outputs (tests/golden.py), as VQF's test_implementation_comparison.py runs one body over its
implementations: the online estimator (OnlineEstimator, through the streams' changes of sample time),
and, where the stream's sample time is constant (up to its first change), the native FMU stepped by
fmpy (its own C configuration, design and discretisation), the pythonfmu FMU (both run on the grid
of their fixed Ts: tests/test_sample_grid.py), the batch path (estimate) and the python-control
block (estimator_system under control.input_output_response)."""
import copy
import math
import pickle
import shutil

import control
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from attitude_fmu import OnlineEstimator, estimate, estimator_system
from attitude_fmu.systems.fmi.cosim import set_value
from tests import golden
from tests.test_golden import FROZEN, assert_close

INPUTS = [f"{s}_{a}" for s in ("gyr", "acc", "mag") for a in "xyz"]
OUTPUTS = ["q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z", "roll", "pitch", "yaw", *(f"gyr_offset_{a}" for a in "xyz"),
           *(f"mag_offset_{a}" for a in "xyz"), "mag_delay_used"]  # golden.run_online's columns
QUANTITIES = {"quat": slice(0, 4), "up": slice(4, 7), "euler": slice(7, 10), "offset": slice(10, 13),
              "mag_offset": slice(13, 16), "mag_delay": slice(16, 17)}
CONSTANT_TS = 1200  # hard_motion's first samples, all at 10 ms


class Fmu:
    """An FMI 2.0 estimator FMU extracted once, instantiated for each run (fmpy's FMU2Slave)."""

    def __init__(self, path, folder):
        self.md = read_model_description(str(path))
        self.folder = extract(str(path), str(folder))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.variables = {v.name: v for v in self.md.modelVariables}

    def run(self, start: dict, gyr, acc, mag, Ts):
        """The outputs after each step (N×17) and valid (N), each step as long as its Ts."""
        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.folder,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="paths")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        for name, value in start.items():
            set_value(fmu, self.variables[name], value)
        fmu.exitInitializationMode()
        vin, vout, valid_vr = [self.vr[n] for n in INPUTS], [self.vr[n] for n in OUTPUTS], [self.vr["valid"]]
        out, valid, t = np.empty((len(gyr), len(OUTPUTS))), np.empty(len(gyr), dtype=bool), 0.0
        for k in range(len(gyr)):
            fmu.setReal(vin, [*map(float, gyr[k]), *map(float, acc[k]), *map(float, mag[k])])
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=float(Ts[k]))
            t += float(Ts[k])
            out[k], valid[k] = fmu.getReal(vout), fmu.getBoolean(valid_vr)[0]
        fmu.terminate()
        fmu.freeInstance()
        return out, valid


@pytest.fixture(scope="module")
def fmus(fmu_dir, tmp_path_factory):
    folder = tmp_path_factory.mktemp("paths")
    yield {"fmu": Fmu(fmu_dir / "native" / "AttitudeEstimator.fmu", folder / "native"),
           "pythonfmu": Fmu(fmu_dir / "AttitudeEstimator.fmu", folder / "pythonfmu")}
    shutil.rmtree(folder, ignore_errors=True)


def _fmu_start(config: dict, Ts0: float) -> dict:
    """The FMU's start values for an OnlineEstimator configuration."""
    start = {"method": config.get("method", "wiener"), "Ts": Ts0,
             "heading": "mag" if config.get("heading", False) else "gyro",
             "gyro_offset": "on" if config.get("gyro_offset", True) else "off"}
    start.update({k: config[k] for k in ("gyr_samples", "acc_samples", "latency") if k in config})
    return {**start, **(config.get("params") or {})}


def _online(config, gyr, acc, mag, Ts):
    return _online_continued(OnlineEstimator(**config), gyr, acc, mag, Ts)


def _assert_frozen(out, taken, frozen, what, columns=len(OUTPUTS)):
    """out (N×17 after each step) and taken against a case's frozen rows (golden.rows of the
    first `columns` outputs), as far as out goes."""
    n = len(out)
    keep = np.unique(np.r_[np.arange(0, len(frozen["taken"]), golden.DECIMATE), len(frozen["taken"]) - 1])
    within = keep < n
    assert np.array_equal(taken, frozen["taken"][:n]), f"{what}: samples taken differ"
    got, expected = out[keep[within]], frozen["out"][within]
    for name, part in QUANTITIES.items():
        if part.start < columns:
            assert_close(got[:, part], expected[:, part], f"{what}: {name}", angles=name == "euler")


METHOD_CASES = {f"method {n} {' '.join(f'{k}={v}' for k, v in g.items())}": (n, g) for n, g in golden.METHOD_CASES}


@pytest.mark.parametrize("path", ["online", "fmu", "pythonfmu", "estimate", "estimator_system"])
@pytest.mark.parametrize("case", list(METHOD_CASES))
def test_every_path_to_a_methods_step_gives_its_frozen_outputs(fmus, case, path):
    """Each method alone (no gyro offset, no heading) over golden.hard_motion: fast tumbling,
    upside down, linear accelerations, no accelerometer for three samples, the sample time
    changed twice (the paths whose sample time is fixed, the FMUs, the batch path and the block: up
    to the first change)."""
    name, given = METHOD_CASES[case]
    Ts, gyr, acc = golden.hard_motion()
    mag = np.full_like(gyr, np.nan)
    config = dict(method=name, params=given, gyro_offset=False)
    if path != "online":
        assert np.all(Ts[:CONSTANT_TS] == Ts[0]) and Ts[CONSTANT_TS] != Ts[0]
        Ts, gyr, acc = Ts[:CONSTANT_TS], gyr[:CONSTANT_TS], acc[:CONSTANT_TS]
    if path == "online":
        out, taken = _online(config, gyr, acc, mag, Ts)
    elif path in ("fmu", "pythonfmu"):
        out, taken = fmus[path].run(_fmu_start(config, Ts[0]), gyr, acc, mag, Ts)
    elif path == "estimate":
        est = estimate(gyr, acc, 1.0 / Ts[0], name, golden.as_online(name, given), gyro_offset=False)
        out, taken = np.hstack([est.quat, est.up, np.zeros((len(gyr), 10))]), np.ones(len(gyr), dtype=bool)
    else:
        block = estimator_system(name, given, dt=Ts[0])
        response = control.input_output_response(block, np.arange(len(gyr)) * Ts[0], np.hstack([gyr, acc]).T)
        gravity, quat = response.outputs[:3].T, response.outputs[3:7].T
        up = gravity / np.linalg.norm(gravity, axis=1, keepdims=True)
        out, taken = np.hstack([quat, up, np.zeros((len(gyr), 10))]), np.ones(len(gyr), dtype=bool)
    _assert_frozen(out, taken, FROZEN[case], f"{case} by {path}", columns=7)


ONLINE_CASES = dict(golden.online_configs())
PYTHONFMU_CASES = [name for name in ONLINE_CASES if "latency" in name or "tseng_adaptive heading=True" in name]


@pytest.mark.parametrize("path", ["online", "fmu"])
@pytest.mark.parametrize("case", list(ONLINE_CASES))
def test_every_path_to_the_online_pipeline_gives_its_frozen_outputs(fmus, case, path):
    """The whole causal pipeline (method, gyro offset, heading with the hard-iron fit and the
    magnetometer's delay, sampling and latency) over golden.human_stream: rest, fast turns,
    the sample time changed, a late magnetometer at a third of the rate, non-finite and
    beyond-range samples, no accelerometer at first."""
    config = ONLINE_CASES[case]
    gyr, acc, mag, Ts = golden.human_stream()
    if path == "online":
        out, taken = _online(config, gyr, acc, mag, Ts)
    else:
        out, taken = fmus[path].run(_fmu_start(config, Ts[0]), *_constant_ts(gyr, acc, mag, Ts))
    assert not taken[:3].any() and taken[3:600].all() and not taken[600:605].any()
    _assert_frozen(out, taken, FROZEN[case], f"{case} by {path}")


@pytest.mark.parametrize("case", PYTHONFMU_CASES)
def test_the_pythonfmu_estimator_gives_the_frozen_online_outputs(fmus, case):
    gyr, acc, mag, Ts = golden.human_stream()
    out, taken = fmus["pythonfmu"].run(_fmu_start(ONLINE_CASES[case], Ts[0]), *_constant_ts(gyr, acc, mag, Ts))
    _assert_frozen(out, taken, FROZEN[case], f"{case} by the pythonfmu FMU")


def test_the_paths_are_compared_where_they_differ():
    """The streams above take what each path must handle: a changed sample time, invalid
    samples, a magnetometer with gaps (else the comparison would prove less)."""
    Ts, gyr, acc = golden.hard_motion()
    assert len(set(Ts.tolist())) == 3 and (np.linalg.norm(acc, axis=1) == 0).sum() == 3
    gyr, acc, mag, Ts = golden.human_stream()
    assert len(set(Ts.tolist())) == 2 and not np.isfinite(np.hstack([gyr, acc])).all()
    assert 0.3 < np.isnan(mag[:, 0]).mean() < 0.7 and math.isinf(mag[606, 2])


def test_a_copy_of_the_online_estimator_continues_as_the_original_and_a_reset_starts_afresh():
    """copy.deepcopy and pickle (an FMU's saved state) taken midway carry every stage's state:
    the copies continue exactly as the original; after reset() it runs as a fresh one, the
    frozen outputs again."""
    case = "online method=tseng_adaptive heading=True gyro_offset=True gyr_samples=point"
    gyr, acc, mag, Ts = golden.human_stream()
    est = OnlineEstimator(**ONLINE_CASES[case])
    for k in range(700):
        est.step(gyr[k], acc[k], Ts[k], mag[k])
    copies = [copy.deepcopy(est), pickle.loads(pickle.dumps(est))]
    rest = [a[700:] for a in (gyr, acc, mag, Ts)]
    runs = [_online_continued(e, *rest) for e in (est, *copies)]
    assert all(np.array_equal(run[0], runs[0][0]) and np.array_equal(run[1], runs[0][1]) for run in runs[1:])
    est.reset()
    assert not est.ready
    _assert_frozen(*_online_continued(est, gyr, acc, mag, Ts), FROZEN[case], f"{case} after a reset")


def _constant_ts(*columns):
    """The rows of columns (their last the sample times) up to the first change of sample time: an FMU's Ts is
    fixed at initialisation, and a step of another size runs on its grid, not at its own size."""
    Ts = columns[-1]
    n = int(np.argmax(Ts != Ts[0])) or len(Ts)
    return [c[:n] for c in columns]


def _online_continued(est, gyr, acc, mag, Ts):
    """An online estimator's outputs (N×17) and taken over more samples."""
    out, taken = np.empty((len(gyr), len(OUTPUTS))), np.empty(len(gyr), dtype=bool)
    for k in range(len(gyr)):
        taken[k] = est.step(gyr[k], acc[k], Ts[k], mag[k])
        out[k] = np.concatenate([est.quat, est.up, est.euler, est.offset, est.mag_offset, [est.mag_delay]])
    return out, taken
