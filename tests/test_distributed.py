"""Jobs on a real local Dask cluster (2 worker processes): `attitude evaluate` and `attitude
sweep` give the serial run's results bit for bit and in order, a damaged file among good
ones is reported while the others complete, a worker killed mid-run loses no result, and a
worker that ran FMUs ends with status 0 where a library destructor would crash it."""
import ctypes
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time

import cloudpickle
import numpy as np
import pytest
from scipy.io import savemat
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.cluster.jobs import Jobs
from attitude_fmu.systems.evaluation.evaluate import METRICS, evaluate
from attitude_fmu.systems.evaluation.sweep import TUNING_WARNING
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests import native
from tests.motions import ClosedFormMotion

FS = 100.0
GRID = ["--grid", "delta_n=0.001,0.003", "--grid", "scale_error=0.002,0.01"]

pytest.importorskip("vqf")
pytest.importorskip("ahrs")
cloudpickle.register_pickle_by_value(sys.modules[__name__])  # this module's jobs reach the workers by value


def _recording(path, seed: int, duration: float = 40.0):
    """A BROAD-like .mat: slow turns about two axes (the rates set by seed), a MEMS gyro and
    accelerometer, the earth's field, a reference with a gap, movement from 5 s."""
    rates = 0.2 + 0.3 * np.random.default_rng(seed).random(2)
    turns = ClosedFormMotion(lambda t: Rotation.from_euler("ZY", np.column_stack([
        0.8 * np.sin(rates[0] * t), 0.5 * np.sin(rates[1] * t)])))
    motion = turns.generate(duration, FS)
    gyr, acc = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002).apply(motion, seed=seed)
    ref = motion.quat.copy()
    ref[100:120] = np.nan
    savemat(path, {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": motion.mag, "sampling_rate": FS, "opt_quat": ref,
                   "movement": (np.arange(len(gyr)) > 500).astype(float)})
    return str(path)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp("recordings")
    return [_recording(folder / f"r{seed}.mat", seed) for seed in range(4)]


def _json(capsys, argv, status=0):
    assert main(argv) == status, argv
    out = capsys.readouterr()
    return out.out, out.err


def test_evaluate_on_two_workers_equals_the_serial_run_bit_for_bit(recordings, capsys):
    """The JSON (floats written by repr, so exact) of 4 recordings on 2 worker processes is
    the in-process run's, byte for byte, in the files' order."""
    serial, _ = _json(capsys, ["evaluate", "--json", "--workers", "1", *recordings])
    distributed, _ = _json(capsys, ["evaluate", "--json", "--workers", "2", *recordings])
    assert distributed == serial
    result = json.loads(serial)
    assert list(result["recordings"]) == ["r0", "r1", "r2", "r3"]
    assert result["mean"]["wiener"]["inclination_rmse_deg"] == pytest.approx(
        np.mean([r["wiener"]["inclination_rmse_deg"] for r in result["recordings"].values()]), rel=1e-15)


def test_sweep_on_two_workers_equals_the_serial_run_and_names_the_best(recordings, capsys):
    """2 × 2 combinations on 2 recordings: the JSON of 2 workers is the serial one's; every
    combination's errors are evaluate's with those parameters, the means their means, and the
    best the combination of the lowest mean inclination RMSE."""
    files = recordings[:2]
    serial, _ = _json(capsys, ["sweep", "--json", "--workers", "1", *files, *GRID])
    distributed, _ = _json(capsys, ["sweep", "--json", "--workers", "2", *files, *GRID])
    assert distributed == serial
    result = json.loads(serial)
    assert set(result) == {"grid", "results", "best"}
    assert result["grid"] == [{"name": "delta_n", "values": [0.001, 0.003]},
                              {"name": "scale_error", "values": [0.002, 0.01]}]
    assert [r["params"] for r in result["results"]] == [
        {"delta_n": dn, "scale_error": se} for dn in (0.001, 0.003) for se in (0.002, 0.01)]
    for r in result["results"]:
        assert set(r) == {"params", "mean", "recordings"} and list(r["recordings"]) == ["r0", "r1"]
        alone = evaluate(files, params=r["params"], progress=False)["recordings"]
        assert r["recordings"] == {name: table["wiener"] for name, table in alone.items()}
        assert r["mean"] == {m: float(np.mean([e[m] for e in r["recordings"].values()])) for m in METRICS}
    inclination = [r["mean"]["inclination_rmse_deg"] for r in result["results"]]
    assert len(set(inclination)) == 4  # the parameters matter
    best = result["results"][int(np.argmin(inclination))]
    assert result["best"] == {"params": best["params"], "by": "inclination_rmse_deg", "mean": best["mean"]}


def test_sweep_prints_the_table_and_the_tuning_warning_unless_scored_on_other_files(recordings, capsys, tmp_path):
    out, err = _json(capsys, ["sweep", "--workers", "1", *recordings[:2], *GRID, "--csv", str(tmp_path / "s.csv")])
    assert TUNING_WARNING in err and out.count("\n  ") >= 4 and "best (lowest mean inclination RMSE)" in out, out
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert rows[0] == "delta_n,scale_error,recording," + ",".join(METRICS) and len(rows) == 1 + 4 * 3
    text, err = _json(capsys, ["sweep", "--json", "--workers", "1", *recordings[:2], *GRID,
                               "--score-on", *recordings[2:]])
    assert TUNING_WARNING not in err
    best = json.loads(text)["best"]
    held = evaluate(recordings[2:], params=best["params"], progress=False)["recordings"]
    assert best["score_on"]["recordings"] == {name: table["wiener"] for name, table in held.items()}
    assert _json(capsys, ["sweep", *recordings[:2], *GRID, "--score-on", recordings[1]], 2)[1].count(
        "among the files the combination is chosen on and those it is scored on") == 1


def test_a_damaged_file_among_good_ones_is_reported_and_the_others_complete(recordings, capsys, tmp_path):
    damaged = tmp_path / "damaged.mat"
    damaged.write_bytes(b"MATLAB 5.0 MAT-file; the rest of it lost")
    files = [recordings[0], str(damaged), recordings[1]]
    out, err = _json(capsys, ["evaluate", "--json", "--workers", "2", *files], 2)
    result = json.loads(out)
    assert "[2/3] error:" in err and "not a readable" in err and "1 of 3 recordings failed" in err, err
    assert list(result["recordings"]) == ["r0", "r1"] and list(result["failed"]) == ["damaged"]
    assert result["recordings"] == evaluate([recordings[0], recordings[1]], progress=False)["recordings"]


def test_a_worker_killed_mid_run_loses_no_result(recordings):
    """SIGKILL to the worker process running a job: the scheduler reruns its jobs on the other
    worker (and the restarted one), and the result is the serial run's, complete."""
    # 8 jobs: the files under two spellings of their folder (stems repeat, so keyed by path)
    files = [*recordings, *(os.path.join(os.path.dirname(p), "..", os.path.basename(os.path.dirname(p)),
                                         os.path.basename(p)) for p in recordings)]
    serial = evaluate(files, progress=False)
    with Jobs(workers=2, bar=False) as jobs:
        outcome = {}
        run = threading.Thread(target=lambda: outcome.update(evaluate(files, progress=False, jobs=jobs)))
        run.start()
        killed = None
        deadline = time.monotonic() + 60
        while killed is None and time.monotonic() < deadline:
            busy = [address for address, keys in (jobs.client.processing() if jobs.client else {}).items() if keys]
            if busy:
                time.sleep(0.2)  # well into the job
                killed = jobs.client.run(os.getpid, workers=[busy[0]])[busy[0]]
                os.kill(killed, signal.SIGKILL)
            time.sleep(0.02)
        run.join(120)
        assert killed is not None and not run.is_alive()
        assert killed not in jobs.client.run(os.getpid).values()
    assert outcome == serial and "failed" not in outcome and len(outcome["recordings"]) == len(files)


def _load_and_step(fmu, library):
    """A job: the library whose destructor aborts, and AttitudeEstimator.fmu stepped 50 times
    at rest; the up-vector it ends on."""
    from attitude_fmu.systems.fmi.cosim import FmuRunner

    ctypes.CDLL(library)
    runner = FmuRunner(fmu, {"gyro_offset": "off"}, [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"],
                       ["g_x", "g_y", "g_z"])
    out, _ = runner.run(np.tile([0.0, 0.0, 0.0, 0.0, 0.0, 9.81], (50, 1)), 1 / FS)
    runner.close()
    return out[-1].tolist()


def test_a_worker_that_ran_fmus_ends_with_status_0_where_exit_would_crash_it(fmu_dir, monkeypatch):
    """A library whose destructor aborts at exit() (tests/crash_at_exit.c, as pythonfmu's can
    crash a process at interpreter shutdown) kills a process that loads it and exits. On a
    cluster of others (--scheduler), worker processes that load it and an FMU end by
    systems.cluster.worker_exit with status 0, their results in."""
    from distributed import LocalCluster
    from distributed.nanny import WorkerProcess

    library = native.build(["crash_at_exit"]) / "tests" / "crash_at_exit.so"
    alone = subprocess.run([sys.executable, "-c", f"import ctypes; ctypes.CDLL({str(library)!r})"])
    assert alone.returncode == -signal.SIGABRT
    statuses = []
    stopped = WorkerProcess.mark_stopped

    def record(self):  # the nanny's record of its worker process's end (distributed.nanny)
        if self.process is not None:
            statuses.append(self.process.exitcode)
        stopped(self)

    monkeypatch.setattr(WorkerProcess, "mark_stopped", record)
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address="127.0.0.1:0") as cluster:
        with Jobs(scheduler=cluster.scheduler_address, bar=False) as jobs:
            job = (str(fmu_dir / "AttitudeEstimator.fmu"), str(library))
            results = jobs.map(_load_and_step, [job, job], ["a", "b"])
    assert np.allclose(results, [[0.0, 0.0, 1.0]] * 2, atol=1e-9), results
    assert statuses == [0, 0], statuses


def _sleep(seconds: float) -> float:
    """A job that takes seconds."""
    time.sleep(seconds)
    return seconds


@pytest.fixture
def one_worker():
    """A local cluster of one worker process, and that process's id; the process is let go on (SIGCONT) after
    the test, whatever it did to it."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0") as cluster:
        with Client(cluster) as client:
            pid = next(iter(client.run(os.getpid).values()))
        try:
            yield cluster.scheduler_address, pid
        finally:
            os.kill(pid, signal.SIGCONT)


def test_a_stopped_worker_is_given_up_on_before_any_job(one_worker, monkeypatch):
    """Its only worker stopped (SIGSTOP) before the run: the check of the workers' version ends at
    PROBE_DEADLINE_S with a message that says so, not after the scheduler's own minutes."""
    from attitude_fmu.systems.cluster import jobs as cluster_jobs

    monkeypatch.setattr(cluster_jobs, "PROBE_DEADLINE_S", 3.0)
    address, pid = one_worker
    os.kill(pid, signal.SIGSTOP)
    start = time.monotonic()
    with pytest.raises(RuntimeError, match=f"the Dask scheduler at {address} or its workers did not answer in 3 s"):
        with Jobs(scheduler=address, bar=False) as jobs:
            jobs.map(_sleep, [(0.0,), (0.0,)], ["a", "b"])
    assert time.monotonic() - start < 15.0


def test_a_worker_stopped_mid_run_is_given_up_on(one_worker, monkeypatch):
    """Its only worker stopped while it runs a job: after SILENCE_S without a job ending, the workers are
    asked, and the one that does not answer within PROBE_DEADLINE_S ends the run with a message."""
    from attitude_fmu.systems.cluster import jobs as cluster_jobs

    monkeypatch.setattr(cluster_jobs, "SILENCE_S", 1.0)
    monkeypatch.setattr(cluster_jobs, "PROBE_DEADLINE_S", 2.0)
    address, pid = one_worker
    threading.Timer(1.5, os.kill, (pid, signal.SIGSTOP)).start()
    start = time.monotonic()
    with pytest.raises(RuntimeError, match="ran no job to its end for 1 s and one did not answer in 2 s"):
        with Jobs(scheduler=address, bar=False) as jobs:
            jobs.map(_sleep, [(30.0,), (30.0,)], ["a", "b"])
    assert time.monotonic() - start < 15.0


def test_slow_jobs_on_answering_workers_are_waited_for(one_worker, monkeypatch):
    """Jobs longer than SILENCE_S on a worker that answers: asked, it answers, and the run goes on."""
    from attitude_fmu.systems.cluster import jobs as cluster_jobs

    monkeypatch.setattr(cluster_jobs, "SILENCE_S", 0.5)
    with Jobs(scheduler=one_worker[0], bar=False) as jobs:
        assert jobs.map(_sleep, [(1.5,), (0.1,)], ["a", "b"]) == [1.5, 0.1]
