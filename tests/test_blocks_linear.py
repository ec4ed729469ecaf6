"""The python-control blocks as a control engineer uses them: each marked with its C step, each
linearised at its rest state (rest_state, rest_point) with finite matrices whose DC gains are those
of the filter it runs, and the closed loop linearised at rest."""
import control
import numpy as np
import pytest
import scipy.linalg
from scipy.spatial.transform import Rotation

import attitude_fmu as af
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.methods.wiener_local import settled_filter
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.simulation.diagram import closed_loop
from attitude_fmu.systems.simulation.motion import TRUTH_OUTPUTS, HumanMotion, earth_field, profile
from attitude_fmu.systems.simulation.sensor_model import ImuModel

TS = 0.01  # s
GYR, ACC, GHAT = [0, 1, 2], [3, 4, 5], [0, 1, 2]  # an estimator's inputs and outputs
Z_CROSS = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])  # [ẑ]×
# finite differences for the DC gains: python-control's default 1e-6 against states up to 400 at rest
# (first_order's) leaves rounding that (I − A)⁻¹ amplifies 4000-fold; the steps are linear in acc and X
DC_EPS = 1e-4


def finite(lin) -> bool:
    return all(np.isfinite(np.asarray(m)).all() for m in (lin.A, lin.B, lin.C, lin.D))


def dc_gain(lin, outputs, inputs) -> np.ndarray:
    """The DC gain of a discrete linearisation, (I − A) singular or not (the orientation's heading and
    a clock are integrators): a steady state solving (I − A)·x = B·u exists, and the outputs do not
    depend on which (C annuls the null space of I − A)."""
    A, B, C, D = (np.asarray(m) for m in (lin.A, lin.B, lin.C, lin.D))
    M = np.eye(len(A)) - A
    x = np.linalg.lstsq(M, B[:, inputs], rcond=None)[0]
    assert np.allclose(M @ x, B[:, inputs], atol=1e-7)
    assert np.allclose(C[outputs] @ scipy.linalg.null_space(M, rcond=1e-9), 0.0, atol=1e-9)
    return C[outputs] @ x + D[np.ix_(outputs, inputs)]


def earth_filter_at_rest(name: str):
    """The earth-frame filter a method runs at rest: wiener's at its local densities' rest (no
    rotation, slosh at its floor), tseng_adaptive's complementary mode, a sensor-frame method's
    design; None for the kernels that have none (luinge, mahony)."""
    m = METHODS[name]
    if name == "wiener":
        return settled_filter(m.resolve(), 0.0, 0.0)
    return m.filter() if m.is_sensor_frame else (m.mode_filter() if m.mode_filter else None)


def lag(earth_filter, Ts: float) -> float:
    """How long (s) the sensor-frame step of earth_filter at Ts lags a ramp: its transfer function
    with the output after the update at k, G(z) = z·(Hd(z) − D) + D (Hd the zoh form python-control's
    c2d gives), follows r_k = k·Ts by τ = −Ts·G'(1) = Ts·(C(I − A)⁻²B − C(I − A)⁻¹B)."""
    d = control.c2d(control.ss(earth_filter), Ts, method="zoh")
    M = np.eye(d.nstates) - np.asarray(d.A)
    once = np.linalg.solve(M, np.asarray(d.B))
    return float(Ts * (np.asarray(d.C) @ (np.linalg.solve(M, once) - once)).item())


def test_every_block_is_marked_with_the_c_step_and_numbers_an_fmu_runs():
    step = af.c_step(af.estimator_system("wiener", {"tau_noise": 2, "delta_n": 0.001}, dt=TS))
    assert (step.kind, step.dt, step.text, step.start) == ("method", TS, "wiener", True)
    assert step.names == ("tau_noise", "delta_n") and step.numbers == (2.0, 0.001)  # as given, no more
    disc = DiscreteFilter.from_lti(af.butterworth(2.0), TS)
    step = af.c_step(af.sensor_frame_system(af.butterworth(2.0), TS))
    assert step.kind == "filter" and step.start
    assert np.array_equal(step.numbers, [2, *disc.Ad.ravel(), *disc.Bd, *disc.C, disc.D])
    assert af.c_step(af.sensor_frame_system(af.butterworth(2.0))) is None  # continuous: Python functions
    assert af.c_step(af.offset_system(TS, {"rest_time": 2.0})).names == ("rest_time",)
    assert af.c_step(af.heading_system(TS)).kind == "heading" and af.c_step(af.heading_system(TS)).start
    assert af.c_step(af.latency_system(TS, 0.004)).numbers == (0.004,)
    imu = ImuModel(delta_n=0.001, latency=0.003)
    assert np.array_equal(af.c_step(imu.system(100.0)).numbers, [*imu.vector, 100.0])  # fs: 1/dt is not always fs
    assert np.array_equal(af.c_step(af.magnetometer_system(imu, 100.0)).numbers, [*imu.vector, 100.0])
    human = HumanMotion()
    assert np.array_equal(af.c_step(human.system(100.0)).numbers, human.coefficients(100.0))
    motion = profile("coning").motion()
    step = af.c_step(motion.system(100.0))
    assert (step.kind, step.text, step.numbers) == ("closed_form", "coning", (*motion.params, motion.g))
    assert af.c_step(af.attitude_error_system(100.0)).kind == "error"


@pytest.mark.parametrize("name", list(METHODS))
def test_every_method_linearises_at_rest_with_the_dc_gains_of_its_filter(name):
    block = af.estimator_system(name, dt=TS)
    rest = af.rest_point(block)
    assert finite(control.linearize(block, rest))
    assert np.allclose(rest.outputs[:3], [0.0, 0.0, STANDARD_GRAVITY]) and np.allclose(rest.outputs[3:], [1, 0, 0, 0])
    moving = [i for i, label in enumerate(block.state_labels) if label != "t"]  # all but wiener's clock
    assert np.allclose(block.dynamics(0.0, rest.states, rest.inputs)[moving], rest.states[moving], atol=1e-12)
    lin = control.linearize(block, rest, eps=DC_EPS)
    H = earth_filter_at_rest(name)
    if H is None:  # ĝ = g·up, up settling on the accelerometer's direction: across gravity g/|acc|, along 0
        g = METHODS[name].resolve()["g"]
        expected = g / STANDARD_GRAVITY * np.diag([1.0, 1.0, 0.0])
        assert np.allclose(dc_gain(lin, GHAT, ACC), expected, atol=1e-4)
        return
    assert np.allclose(dc_gain(lin, GHAT, ACC), control.dcgain(H) * np.eye(3), atol=1e-5)
    # a constant rate ω turns the frame: in the gyro-estimated earth frame the accelerometer ramps at
    # ω × g (first order), the filter lags the ramp by τ, and ĝ stays behind by τ·(ω × g):
    # ∂ĝ/∂ω = τ·g·[ẑ]×; τ is the design's lag −H'(0) less half a sample (the output after the update)
    tau = lag(H, TS)
    S = control.ss(H)
    H_slope = -float((np.asarray(S.C) @ np.linalg.solve(S.A, np.linalg.solve(S.A, S.B))).item())  # H'(0)
    assert tau == pytest.approx(-H_slope - TS / 2, rel=1e-6)
    gain = tau * STANDARD_GRAVITY * Z_CROSS
    assert np.allclose(dc_gain(lin, GHAT, GYR), gain, atol=1e-5 * np.abs(gain).max())


def test_wiener_rest_is_an_operating_point_with_its_clock_held():
    block = af.estimator_system("wiener", dt=TS)
    rest = af.rest_point(block)
    clock = block.state_labels.index("t")  # time since the start (s): it never stands still
    # held, its update left free; the rest where ĝ_z is g, the accelerometer's z free (square: python-control
    # takes no empty list of outputs)
    found = control.find_operating_point(block, rest.states, rest.inputs, rest.outputs, iu=[0, 1, 2, 3, 4], iy=[2],
                                         ix=[clock], idx=[i for i in range(block.nstates) if i != clock],
                                         return_result=True)
    assert found.result.success
    assert np.allclose(found.states, rest.states, atol=1e-9) and np.allclose(found.inputs, rest.inputs, atol=1e-9)
    assert rest.states[clock] * rest.states[block.state_labels.index("omega_g")] > np.sqrt(2)  # past start-up


def test_the_gyro_offset_estimator_rests_on_a_constant_offset():
    offset = np.array([0.002, -0.001, 0.003])  # rad/s, inside rest_gyr_abs
    block = af.offset_system(TS)
    rest = af.rest_point(block, [*offset, 0.0, 0.0, STANDARD_GRAVITY])
    assert np.allclose(rest.outputs[3:6], offset, atol=1e-9) and np.allclose(rest.outputs[:3], 0.0, atol=1e-9)
    assert np.array_equal(rest.outputs[6:], rest.inputs[3:])  # the accelerometer as measured: no lever arm at rest
    assert finite(control.linearize(block, rest))


@pytest.mark.parametrize("block", [
    af.offset_system(TS), af.heading_system(TS), af.latency_system(TS, 0.005), ImuModel().system(1 / TS),
    ImuModel(latency=0.0123).system(1 / TS), HumanMotion().system(1 / TS), af.magnetometer_system(ImuModel(), 1 / TS),
    af.attitude_error_system(1 / TS),
], ids=lambda b: f"{b.name}-{b.nstates}")
def test_every_stage_linearises_at_rest(block):
    assert finite(control.linearize(block, af.rest_point(block)))


def test_a_closed_form_motion_samples_as_generate_and_linearises_behind_a_sensor():
    motion = profile("coning").motion()
    fs = 100.0
    system = motion.system(fs)
    out = control.input_output_response(system, np.arange(80) / fs, np.zeros((0, 80)), X0=[0.0]).outputs.T
    sampled = motion.generate(0.8, fs)
    assert np.allclose(out, np.hstack([sampled.gyr, sampled.acc, sampled.quat]), rtol=0, atol=1e-12)
    # python-control cannot linearise a system without inputs (B of shape n × 0): behind the IMU model
    noise = [f"{s}_{a}" for s in ("n", "na") for a in "xyz"]
    diagram = control.interconnect([system, ImuModel().system(fs)], inplist=noise,
                                   outlist=[f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"] + TRUTH_OUTPUTS[6:])
    assert finite(control.linearize(diagram, af.rest_state(diagram), np.zeros(6)))


@pytest.mark.parametrize("options", [{}, {"heading": True, "latency": 0.01}], ids=["default", "heading-latency"])
def test_the_closed_loop_linearises_at_rest(options):
    diagram, _ = closed_loop(HumanMotion(), ImuModel(), 1 / TS, **options)
    rest = af.rest_point(diagram)
    assert finite(control.linearize(diagram, rest))
    assert rest.outputs[0] == pytest.approx(0.0, abs=1e-12)  # the estimate on the truth: no error
    for i, block in enumerate(diagram.syslist):  # each block at rest on what the others give it at rest
        first = diagram.state_offset[i]
        # the heading on the magnetometer's earth field at the identity, the others on their own natural rest
        u = [1.0, 0.0, 0.0, 0.0, *earth_field([1.0, 0.0, 0.0, 0.0])] if block.name == "heading" else None
        assert np.array_equal(rest.states[first:first + block.nstates], af.rest_state(block, u)), block.name


def test_the_error_block_is_the_inclination_between_estimate_and_true_up():
    rng = np.random.default_rng(3)
    block = af.attitude_error_system(100.0)
    for _ in range(20):
        q, ghat = Rotation.random(random_state=rng).as_quat(scalar_first=True), rng.normal(size=3)
        up = Rotation.from_quat(q, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
        expected = np.arccos(np.clip(ghat @ up / np.linalg.norm(ghat), -1.0, 1.0))
        assert block.output(0.0, [], np.concatenate([ghat, q]))[0] == pytest.approx(expected, abs=1e-7)
