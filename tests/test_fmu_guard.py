"""The pythonfmu FMUs' guard (fmu_src/fmi2_guard.c) against calls FMI 2.0 does not allow
(under the sanitizers: tests/test_fmu.py's importer without Python)."""
import math

import numpy as np
from fmpy.fmi1 import FMICallException

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.fmi.cosim import FmuRunner, set_value
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.test_fmu import FS, INPUTS, OUTPUTS


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
                     "setReal on an Enumeration": status(lambda: fmu.setReal([vr["method"]], [1.0])),
                     "getReal on a Boolean": status(lambda: fmu.getReal([vr["valid"]])),
                     "setReal on no variable": status(lambda: fmu.setReal([100000], [1.0]))})
    set_value(fmu, runner.variables["gyro_offset"], "off")
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
                    f"fmi2SetReal refused: value reference {vr['method']} is an Integer variable, not a Real",
                    "fmi2SetReal refused: value reference 100000 names no variable",
                    "fmi2DoStep refused: not allowed after fmi2Terminate"):
        assert message in log, log
    runner.fmu.reset()
    runner._initialise()
    again, _ = runner.run(np.hstack([gyr, acc]), 1 / FS)
    runner.close()
    assert np.array_equal(again, out)
