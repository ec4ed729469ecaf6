"""The pythonfmu FMUs' guard (fmu_src/fmi2_guard.c) against calls FMI 2.0 does not allow
(under the sanitizers: tests/test_fmu.py's importer without Python); and the compiled
kernels a fresh extraction of the same FMU finds in the per-user cache (blocks.jit)."""
import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
from fmpy import extract
from fmpy.fmi1 import FMICallException

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.fmi.cosim import FmuRunner
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.test_fmu import FS, INPUTS, OUTPUTS, fmu_dir  # noqa: F401 (fmu_dir: the FMUs, built once here)


def test_calls_in_the_wrong_phase_or_on_the_wrong_type_end_in_fmi2_error_and_harm_nothing(fmu_dir, capsys):
    """Set and get on a value reference of another type or of none, doStep before
    initialisation and after fmi2Terminate, fmi2Terminate twice: fmi2Error (3) with a
    message, passed on to nothing; the instance then steps as the batch path, and after
    fmi2Reset runs again."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(1.0, FS, seed=41)
    gyr, acc = ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=42)
    runner = FmuRunner(fmu_dir / "AttitudeEstimator.fmu", {"gyro_offset": "off"}, INPUTS, OUTPUTS, logging=True)
    fmu, vr = runner.fmu, {n: v.valueReference for n, v in runner.variables.items()}

    def status(call) -> int:
        try:
            call()
        except FMICallException as exc:
            return exc.status
        return 0

    fmu.reset()
    statuses = {"doStep before initialisation": status(lambda: fmu.fmi2DoStep(fmu.component, 0.0, 1 / FS, 1))}
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    statuses.update({"setString on a Real": status(lambda: fmu.setString([vr["Ts"]], ["0.01"])),
                     "setReal on a String": status(lambda: fmu.setReal([vr["method"]], [1.0])),
                     "getReal on a Boolean": status(lambda: fmu.getReal([vr["valid"]])),
                     "setReal on no variable": status(lambda: fmu.setReal([100000], [1.0]))})
    fmu.setString([vr["gyro_offset"]], ["off"])
    fmu.exitInitializationMode()
    runner.time = 0.0
    out, _ = runner.run(np.hstack([gyr, acc]), 1 / FS)
    assert np.abs(out[:, :4] - estimate(gyr, acc, FS, gyro_offset=False).quat).max() < 1e-9
    fmu.terminate()
    statuses["doStep after terminate"] = status(lambda: fmu.fmi2DoStep(fmu.component, 1.0, 1 / FS, 1))
    statuses["terminate twice"] = status(lambda: fmu.fmi2Terminate(fmu.component))
    assert statuses == dict.fromkeys(statuses, 3), statuses
    log = capsys.readouterr().out
    for message in ("fmi2DoStep refused: not allowed before initialisation",
                    f"fmi2SetString refused: value reference {vr['Ts']} is a Real variable, not a String",
                    f"fmi2SetReal refused: value reference {vr['method']} is a String variable, not a Real",
                    "fmi2SetReal refused: value reference 100000 names no variable",
                    "fmi2DoStep refused: not allowed after fmi2Terminate"):
        assert message in log, log
    runner.fmu.reset()
    runner._initialise()
    again, _ = runner.run(np.hstack([gyr, acc]), 1 / FS)
    runner.close()
    assert np.array_equal(again, out)


def test_a_fresh_extraction_finds_the_kernels_another_extraction_compiled(fmu_dir, tmp_path):
    """Two extractions of one FMU in two processes, one per-user cache (ATTITUDE_FMU_CACHE):
    the second loads every kernel the first compiled and compiles none."""
    fmu = str(fmu_dir / "AttitudeEstimator.fmu")
    script = textwrap.dedent("""
        import sys, types
        package = types.ModuleType("attitude_fmu")  # the extraction's copy, whatever else is installed
        package.__path__ = [sys.argv[1] + "/attitude_fmu"]
        sys.modules["attitude_fmu"] = package
        import numpy as np
        from attitude_fmu.blocks.quaternion import integrate_rates
        assert integrate_rates.py_func.__code__.co_filename.startswith(sys.argv[1])
        quat = np.empty((5, 4))
        integrate_rates(np.full((5, 3), 0.1), 0.01, quat)
        print(quat[-1].tolist())
    """)
    env = {**os.environ, "ATTITUDE_FMU_CACHE": str(tmp_path / "cache"), "NUMBA_DEBUG_CACHE": "1"}
    env.pop("NUMBA_CACHE_DIR", None)
    runs = []
    for k in range(2):
        resources = Path(extract(fmu, unzipdir=str(tmp_path / f"x{k}"))) / "resources"
        runs.append(subprocess.run([sys.executable, "-c", script, str(resources)], capture_output=True, text=True,
                                   env=env, cwd=tmp_path, timeout=600))
        assert runs[-1].returncode == 0, runs[-1].stderr[-2000:]
    first, second = (run.stdout for run in runs)
    assert "data saved to" in first and "[cache] data loaded from" in second, second
    assert "data saved to" not in second and str(tmp_path / "cache") in second
    assert first.splitlines()[-1] == second.splitlines()[-1]


def test_the_kernels_compiled_at_the_build_seed_a_per_user_folder_that_has_none(tmp_path, monkeypatch):
    """blocks.jit._seed: a cache folder that does not exist starts as a copy of the
    package's kernel_cache/ (setup.py compiles it at the build); one that exists is left
    as it is."""
    from attitude_fmu.blocks import jit

    package = tmp_path / "attitude_fmu"
    shipped = package / jit.SHIPPED / "numba-x-py3" / "fingerprint" / "blocks"
    shipped.mkdir(parents=True)
    (shipped / "kernel.nbi").write_bytes(b"index")
    monkeypatch.setattr(jit, "PACKAGE_ROOT", package)
    folder = tmp_path / "user" / "numba-x-py3" / "fingerprint"
    folder.parent.mkdir(parents=True)
    jit._seed(folder)
    assert (folder / "blocks" / "kernel.nbi").read_bytes() == b"index"
    (shipped / "kernel.nbi").write_bytes(b"newer")
    jit._seed(folder)
    assert (folder / "blocks" / "kernel.nbi").read_bytes() == b"index"
    assert sorted(p.name for p in folder.parent.iterdir()) == ["fingerprint"]  # no staging folder left
