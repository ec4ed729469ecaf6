"""The closed-loop diagram motion → IMU sensor model → estimator → attitude error,
assembled from python-control blocks with control.interconnect."""
from __future__ import annotations

import control
import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, with_c_step
from attitude_fmu.blocks.filters.sensor_frame import GRAVITY_OUTPUTS, QUAT_NAMES
from attitude_fmu.blocks.methods.registry import estimator_system, stepper
from attitude_fmu.blocks.pipeline.causal import split_params
from attitude_fmu.blocks.stages import gyro_offset as offset_stage
from attitude_fmu.blocks.stages.heading import heading_system
from attitude_fmu.blocks.stages.heading import initial_state as heading_initial_state
from attitude_fmu.blocks.stages.timing import latency_system
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.simulation.motion import AXES, HumanMotion, earth_field
from attitude_fmu.systems.simulation.noise import MAGNETOMETER, MOTION, SENSOR, normals
from attitude_fmu.systems.simulation.sensor_model import ImuModel

NOISE_INPUTS = [f"eps_{s}_{a}" for s in "vw" for a in AXES] + [f"{s}_{a}" for s in ("n", "na") for a in AXES]
MAG_NOISE_INPUTS = [f"nm_{a}" for a in AXES]  # the magnetometer's, with the heading stage


def attitude_error_system(fs: float, name: str = "error"):
    """Static block: inclination error incl_err (rad) between ghat_* (m/s²) and the true up of
    qt_* (sensor → earth), the C core's (blocks/core/errors.h). Marked with its C step, "error"."""
    def output(t, x, u, params):
        return [_core.attitude_error(u[0:3], u[3:7])]

    system = control.nlsys(None, output, inputs=GRAVITY_OUTPUTS + ["qt_w", "qt_x", "qt_y", "qt_z"],
                           outputs=["incl_err"], dt=1.0 / fs, name=name)
    return with_c_step(system, CStep("error", 1.0 / fs, rest_inputs=(0.0, 0.0, STANDARD_GRAVITY, 1.0, 0.0, 0.0, 0.0)))


def magnetometer_system(imu: ImuModel, fs: float, name: str = "magnetometer"):
    """Static block: the field mag_* (µT, sensor coordinates) the magnetometer of imu
    measures (ImuModel.measure_mag, unit-normal noise nm_*) at the orientation qt_*
    (systems.simulation.motion.earth_field, as Motion.mag). Marked with its C step,
    "magnetometer" (numbers: imu.vector)."""
    def output(t, x, u, params):
        return imu.measure_mag(earth_field(u[0:4]), u[4:7], fs)

    system = control.nlsys(None, output, inputs=["qt_w", "qt_x", "qt_y", "qt_z", *MAG_NOISE_INPUTS],
                           outputs=[f"mag_{a}" for a in AXES], dt=1.0 / fs, name=name)
    return with_c_step(system, CStep("magnetometer", 1.0 / fs, numbers=(*imu.vector, float(fs)),
                                     rest_inputs=(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)))


def closed_loop(motion: HumanMotion, imu: ImuModel, fs: float, method: str = "wiener",
                params: dict | None = None, gyro_offset: bool = True, heading: bool = False, latency: float = 0.0):
    """The diagram and its initial state (estimator at rest on g·ẑ, motion level at rest).
    params: as blocks.pipeline.causal.split_params, for the method and the stages below.

    gyro_offset (default on, as everywhere): the gyro-offset estimator
    (blocks.stages.gyro_offset, its low-passes at rest on g·ẑ) between sensor and estimator;
    heading: the heading stage (blocks.stages.heading) on the estimator's orientation and the
    magnetometer. Inputs: NOISE_INPUTS (unit-normal
    samples; with heading also MAG_NOISE_INPUTS); outputs: incl_err (rad), ghat_*, q_*,
    with gyro_offset the gyro offset estimate offset_* (rad/s), with heading qh_* and the
    hard-iron estimate mag_offset_* (µT);
    latency (s, non-zero): the latency stage (blocks.stages.timing) on the last orientation and
    ghat_*, outputs ql_* and ghatl_*.
    """
    dt = 1.0 / fs
    params, offset_params, heading_params = split_params(method, params, gyro_offset, heading)
    sensor = imu.system(fs)
    estimator = [estimator_system(method, params, dt)]
    states = [motion.initial_state()]
    if imu.latency:  # the sensor's delay line, on a motion at rest, level, before the start
        states.append(imu.delay_state(fs, [0.0, 0.0, 0.0, 0.0, 0.0, motion.g]))
    if gyro_offset:
        sensor.update_names(outputs=[f"{s}_{a}" for s in ("gyr_raw", "acc_raw") for a in AXES])
        estimator.insert(0, offset_stage.offset_system(dt, offset_params))
        states.append(offset_stage.initial_state(offset_stage.coefficients(offset_stage.resolve(offset_params), dt),
                                                np.zeros(3), np.array([0.0, 0.0, motion.g])))
    states.append(stepper(method, tuple(sorted(params.items())), dt).initial_state([0.0, 0.0, motion.g]))
    outputs = ["incl_err"] + GRAVITY_OUTPUTS + QUAT_NAMES + ([f"offset_{a}" for a in AXES] if gyro_offset else [])
    if heading:
        estimator += [magnetometer_system(imu, fs), heading_system(dt, heading_params)]
        states.append(heading_initial_state())
        outputs += [f"qh_{c}" for c in "wxyz"] + [f"mag_offset_{a}" for a in AXES]
    if latency:
        estimator.append(latency_system(dt, latency, [f"q{'h' if heading else ''}_{c}" for c in "wxyz"]))
        outputs += [f"ql_{c}" for c in "wxyz"] + [f"ghatl_{a}" for a in AXES]
    diagram = control.interconnect([motion.system(fs), sensor, *estimator, attitude_error_system(fs)],
                                   inplist=NOISE_INPUTS + (MAG_NOISE_INPUTS if heading else []), outlist=outputs,
                                   outputs=outputs, name="closed_loop")
    return diagram, np.concatenate(states)


def simulate_closed_loop(motion: HumanMotion, imu: ImuModel, fs: float, duration: float,
                         method: str = "wiener", params: dict | None = None, seed: int = 0,
                         gyro_offset: bool = True, heading: bool = False, latency: float = 0.0):
    """Short run of the diagram (see closed_loop) with fixed-seed noise: (noise N×12, or
    N×15 with heading; response). The noise is that of HumanMotion.generate, ImuModel.apply
    and ImuModel.apply_mag with the same seed (systems.simulation.noise's streams MOTION,
    SENSOR and MAGNETOMETER)."""
    diagram, x0 = closed_loop(motion, imu, fs, method, params, gyro_offset, heading, latency)
    n = int(round(duration * fs))
    streams = (MOTION, SENSOR, MAGNETOMETER) if heading else (MOTION, SENSOR)
    noise = np.hstack([normals(seed, stream, n) for stream in streams])
    t = np.arange(n) / fs
    return noise, control.input_output_response(diagram, t, noise.T, X0=x0)
