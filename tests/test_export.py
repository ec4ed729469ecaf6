"""export_fmu and `attitude export` (issue 38): python-control systems as native FMUs, checked against
control.input_output_response run on the same system, with fmpy as the importer: random discrete MIMO
state spaces, continuous state spaces and transfer functions held by zero-order hold (with a change of
step), every method's estimator alone, behind a prefilter and in the closed loop; the refusals; the
pythonfmu backend; the command line."""
import math
import subprocess
import sys
import warnings
import zipfile
from pathlib import Path

import control
import numpy as np
import pytest
from elftools.elf.dynamic import DynamicSection
from elftools.elf.elffile import ELFFile
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from attitude_fmu.blocks.methods.registry import METHODS, estimator_system
from attitude_fmu.systems.fmi.export.api import export_fmu
from attitude_fmu.systems.fmi.export.flatten import ExportError
from attitude_fmu.systems.simulation.diagram import closed_loop
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.noise import MOTION, SENSOR, normals
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests import native

TOLERANCE = 1e-9
# the generated C warning-free (-Wall -Wextra as errors), with the sanitizers in the sanitized run (tests/native.py)
BUILD = ("AF_WERROR=ON", *(("AF_SANITIZE=ON",) if native.sanitized_build() is not None else ()))
warnings.filterwarnings("ignore", message=".*(duplicate|Unused|multiple connections).*")


def export(system, path, **options):
    """export_fmu of the native backend as the tests build it (BUILD)."""
    return export_fmu(system, path, cmake_options=BUILD, **options)


def fmu_outputs(path, inputs: np.ndarray, h: float, system) -> np.ndarray:
    """The FMU's outputs after each step of h (s) with the rows of inputs (N×m) held over it, under
    fmpy's simulate_fmu (FMI 2.0 or 3.0): row k is the system's output at sample k."""
    n = len(inputs)
    t = np.arange(n) * h
    signals = None
    if system.ninputs:
        signals = np.zeros(n, dtype=[("time", float)] + [(label, float) for label in system.input_labels])
        signals["time"] = t
        for j, label in enumerate(system.input_labels):
            signals[label] = inputs[:, j]
    result = simulate_fmu(str(path), start_time=0.0, stop_time=n * h, step_size=h, output_interval=h,
                          input=signals, output=list(system.output_labels))
    return np.column_stack([result[label] for label in system.output_labels])[1:n + 1]


def reference(system, inputs: np.ndarray, h: float, x0=None) -> np.ndarray:
    """control.input_output_response of system over the rows of inputs (N×m) at sample time h."""
    t = np.arange(len(inputs)) * h
    return control.input_output_response(system, t, inputs.T, X0=0 if x0 is None else x0).outputs.reshape(
        system.noutputs, -1).T


def stable_discrete(draw_seed: int, states: int, inputs: int, outputs: int, feedthrough: bool, dt: float):
    """A random stable discrete state space (spectral radius 0.95 at most), from a fixed seed."""
    rng = np.random.default_rng(draw_seed)
    A = rng.normal(size=(states, states))
    A *= 0.95 / max(1e-9, np.max(np.abs(np.linalg.eigvals(A)))) if states else 1.0
    return control.ss(A, rng.normal(size=(states, inputs)), rng.normal(size=(outputs, states)),
                      rng.normal(size=(outputs, inputs)) if feedthrough else np.zeros((outputs, inputs)), dt,
                      name="random")


@pytest.mark.parametrize("fmi", ["2.0", "3.0"])
@seed(38)
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(draw_seed=st.integers(0, 2**32 - 1), states=st.integers(1, 6), inputs=st.integers(1, 3),
       outputs=st.integers(1, 3), feedthrough=st.booleans())
def test_random_discrete_state_spaces(tmp_path, fmi, draw_seed, states, inputs, outputs, feedthrough):
    dt = 0.05
    system = stable_discrete(draw_seed, states, inputs, outputs, feedthrough, dt)
    x0 = np.random.default_rng(draw_seed + 1).normal(size=states)
    path = export(system, tmp_path / "random.fmu", x0=x0, fmi_version=fmi)
    u = np.random.default_rng(draw_seed + 2).normal(size=(80, inputs))
    np.testing.assert_allclose(fmu_outputs(path, u, dt, system), reference(system, u, dt, x0), rtol=0,
                               atol=TOLERANCE)
    assert validate_fmu(str(path)) == []


def steps_fmi2(path, system, inputs, steps) -> np.ndarray:
    """An FMI 2.0 FMU stepped with the rows of inputs over the steps (s, one per row)."""
    md = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="steps")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    out, t = [], 0.0
    for row, h in zip(inputs, steps):
        fmu.setReal([refs[label] for label in system.input_labels], list(row))
        fmu.doStep(t, h)
        t += h
        out.append(fmu.getReal([refs[label] for label in system.output_labels]))
    fmu.terminate()
    fmu.freeInstance()
    return np.array(out)


@pytest.mark.parametrize("kind", ["tf", "ss"])
def test_continuous_systems_held_by_zero_order_hold(tmp_path, kind):
    """Continuous systems: each step is exact for inputs held over it (control.c2d(sys, h, 'zoh')), at
    two step sizes, and across a change of step midway."""
    if kind == "tf":
        system = control.tf([2.0, 3.0], [1.0, 0.8, 4.0, 1.5], name="plant")
    else:
        rng = np.random.default_rng(5)
        A = rng.normal(size=(4, 4)) - 3 * np.eye(4)
        system = control.ss(A, rng.normal(size=(4, 2)), rng.normal(size=(3, 4)), rng.normal(size=(3, 2)),
                            name="plant")
    path = export(system, tmp_path / "plant.fmu", step=0.01)
    u = np.random.default_rng(7).normal(size=(120, system.ninputs))
    for h in (0.01, 0.037):
        discrete = control.c2d(control.ss(system), h, "zoh")
        np.testing.assert_allclose(steps_fmi2(path, system, u, [h] * len(u)), reference(discrete, u, h),
                                   rtol=0, atol=TOLERANCE)
    # 60 steps of 0.01 s, then 60 of 0.037 s: the second discretisation continues from the first's state
    first, second = control.c2d(control.ss(system), 0.01, "zoh"), control.c2d(control.ss(system), 0.037, "zoh")
    part = control.input_output_response(first, np.arange(60) * 0.01, u[:60].T, return_x=True)
    x = np.asarray(first.A @ part.states[:, -1] + first.B @ u[59])
    expected = np.vstack([reference(first, u[:60], 0.01), reference(second, u[60:], 0.037, x)])
    np.testing.assert_allclose(steps_fmi2(path, system, u, [0.01] * 60 + [0.037] * 60), expected, rtol=0,
                               atol=TOLERANCE)
    assert validate_fmu(str(path)) == []


def imu_stream(n: int, dt: float, seed_: int = 3) -> np.ndarray:
    """n rows gyr (rad/s), acc (m/s²) of a simulated motion, through ImuModel's noise."""
    motion = HumanMotion().generate(n * dt, 1.0 / dt, seed=seed_)
    gyr, acc = ImuModel().apply(motion, seed=seed_)
    return np.hstack([gyr, acc])


def prefilter(dt: float):
    """The test's own prefilter: a discrete first-order low-pass on each accelerometer axis, its output
    a·x[k] + (1 − a)·u[k] (direct feedthrough: non-zero from the first sample on), the gyro through."""
    a = 0.6
    A, B = a * np.eye(3), np.hstack([np.zeros((3, 3)), (1 - a) * np.eye(3)])
    C = np.vstack([np.zeros((3, 3)), a * np.eye(3)])
    D = np.block([[np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), (1 - a) * np.eye(3)]])
    names = [f"{s}_{x}" for s in ("gyr", "acc") for x in "xyz"]
    return control.ss(A, B, C, D, dt, inputs=[f"raw_{n}" for n in names], outputs=names, name="prefilter")


def links_no_python(path: Path) -> None:
    """The FMU's Linux binary needs no libpython and the FMU holds no Python file."""
    with zipfile.ZipFile(path) as zf:
        names = zf.namelist()
        binary = next(n for n in names if n.startswith("binaries/") and n.endswith(".so"))
        data = zf.read(binary)
    assert not any(n.endswith(".py") for n in names)
    import io

    needed = [tag.needed for section in ELFFile(io.BytesIO(data)).iter_sections()
              if isinstance(section, DynamicSection) for tag in section.iter_tags() if tag.entry.d_tag == "DT_NEEDED"]
    assert not any("python" in lib for lib in needed), needed


@pytest.mark.parametrize("method", sorted(METHODS))
def test_every_method_alone_behind_a_prefilter_and_in_the_closed_loop(tmp_path, method):
    dt = 0.01
    u = imu_stream(150, dt)
    alone = estimator_system(method, dt=dt)
    path = export(alone, tmp_path / "alone.fmu")
    np.testing.assert_allclose(fmu_outputs(path, u, dt, alone), reference(alone, u, dt), rtol=0, atol=TOLERANCE)
    links_no_python(path)
    assert validate_fmu(str(path)) == []

    behind = control.interconnect([prefilter(dt), estimator_system(method, dt=dt)], name="behind",
                                  inplist=[f"prefilter.raw_{s}_{x}" for s in ("gyr", "acc") for x in "xyz"],
                                  outlist=["estimator.ghat_x", "estimator.ghat_y", "estimator.ghat_z",
                                           "estimator.q_w", "estimator.q_x", "estimator.q_y", "estimator.q_z"])
    path = export(behind, tmp_path / "behind.fmu")
    np.testing.assert_allclose(fmu_outputs(path, u, dt, behind), reference(behind, u, dt), rtol=0, atol=TOLERANCE)
    assert validate_fmu(str(path)) == []

    diagram, x0 = closed_loop(HumanMotion(), ImuModel(), 1.0 / dt, method)
    n = 120
    noise = np.hstack([normals(4, MOTION, n), normals(4, SENSOR, n)])
    path = export(diagram, tmp_path / "loop.fmu", x0=x0, fmi_version="3.0" if method == "wiener" else "2.0")
    np.testing.assert_allclose(fmu_outputs(path, noise, dt, diagram), reference(diagram, noise, dt, x0), rtol=0,
                               atol=TOLERANCE)
    links_no_python(path)
    assert validate_fmu(str(path)) == []


def test_refusals_name_the_blocks(tmp_path):
    dt = 0.1
    a = control.ss([], [], [], [[1.0]], dt, inputs="x", outputs="z", name="first")
    b = control.nlsys(None, lambda t, x, u, p: np.tanh(u), inputs="z", outputs="x", dt=dt, name="second")
    python_block = control.interconnect([a, b], inplist=["first.x"], outlist=["second.x"], name="loop",
                                        connections=[["second.z", "first.z"]])
    with pytest.raises(ExportError, match="'second'.*Python functions.*backend='python'"):
        export_fmu(python_block, tmp_path / "loop.fmu")
    with pytest.raises(ExportError, match="^block 'second' \\(NonlinearIOSystem\\) has no C step"):  # alone, named
        export_fmu(b, tmp_path / "second.fmu")
    c = estimator_system("wiener", dt=dt, name="est1")
    d = control.ss([], [], [], np.hstack([np.zeros((6, 3)), np.zeros((6, 4))]) + np.eye(6, 7), dt,
                   inputs=[f"ghat_{x}" for x in "xyz"] + [f"q_{x}" for x in "wxyz"],
                   outputs=[f"{s}_{x}" for s in ("gyr", "acc") for x in "xyz"], name="feedback")
    loop = control.interconnect([c, d], inplist=[], outlist=["est1.q_w"], name="loop", connections=[
        [f"est1.{s}_{x}", f"feedback.{s}_{x}"] for s in ("gyr", "acc") for x in "xyz"] + [
        [f"feedback.{n}", f"est1.{n}"] for n in [f"ghat_{x}" for x in "xyz"] + [f"q_{x}" for x in "wxyz"]])
    with pytest.raises(ExportError, match=r"algebraic loop: .*est1.*feedback|algebraic loop: .*feedback.*est1"):
        export_fmu(loop, tmp_path / "algebraic.fmu")


def test_python_backend_exports_a_python_function_block(tmp_path):
    """A control.nlsys of Python functions through pythonfmu (with the project's guard): run by fmpy in a
    process of its own (pythonfmu's library may not be unloaded from a process that goes on), it equals
    input_output_response; in steps of dt/2 (each input held over two) it runs on the grid of dt and gives
    the same outputs after every second step; before the first step its output is sample 0's."""
    dt = 0.1
    system = control.nlsys(lambda t, x, u, p: 0.5 * x + u[:1], lambda t, x, u, p: 2 * np.tanh(x[0] + u),
                           inputs=["a"], outputs=["b"], states=1, dt=dt, name="saturating")
    path = export_fmu(system, tmp_path / "saturating.fmu", backend="python")
    with zipfile.ZipFile(path) as zf:
        assert "resources/system.pickle" in zf.namelist() and "resources/python_environment.txt" in zf.namelist()
    u = np.sin(3 * np.arange(40) * dt)[:, None]
    np.save(tmp_path / "u.npy", u)
    script = ("import os, sys, numpy as np\n"
              "sys.path.insert(0, sys.argv[1])\n"
              "from tests.test_export import fmu_outputs\n"
              "import control\n"
              "system = control.nlsys(None, lambda t, x, u, p: u, inputs=['a'], outputs=['b'], dt=0.1)\n"
              "h, repeat = float(sys.argv[2]), int(sys.argv[3])\n"
              "u = np.repeat(np.load('u.npy'), repeat, axis=0)\n"
              "np.save(f'y{repeat}.npy', fmu_outputs('saturating.fmu', u, h, system))\n"
              "sys.stdout.flush()\n"
              "os._exit(0)\n")
    for h, repeat in ((dt, 1), (dt / 2, 2)):
        run = subprocess.run([sys.executable, "-c", script, str(Path(__file__).resolve().parent.parent), str(h),
                              str(repeat)], cwd=tmp_path, capture_output=True, text=True)
        assert run.returncode == 0, run.stderr[-3000:]
    np.testing.assert_allclose(np.load(tmp_path / "y1.npy"), reference(system, u, dt), rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(np.load(tmp_path / "y2.npy")[1::2], reference(system, u, dt), rtol=0, atol=TOLERANCE)
    # before the first step, in Initialization Mode and after it: sample 0's output, 2 tanh(x0 + u) at x0 = 0
    script = ("import os, fmpy\n"
              "from fmpy.fmi2 import FMU2Slave\n"
              "md = fmpy.read_model_description('saturating.fmu')\n"
              "vr = {v.name: v.valueReference for v in md.modelVariables}\n"
              "fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract('saturating.fmu'),\n"
              "                modelIdentifier=md.coSimulation.modelIdentifier, instanceName='start')\n"
              "fmu.instantiate(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode()\n"
              "fmu.setReal([vr['a']], [0.7])\n"
              "during = fmu.getReal([vr['b']])[0]\n"
              "fmu.exitInitializationMode()\n"
              "print(during, fmu.getReal([vr['b']])[0], flush=True)\n"
              "os._exit(0)\n")
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    np.testing.assert_allclose([float(v) for v in run.stdout.split()], [2 * np.tanh(0.7)] * 2, rtol=0, atol=1e-15)


def _export_command(spec: str, out, *flags, status: int = 0) -> subprocess.CompletedProcess:
    """`attitude export spec --out out flags` in a process of its own, which ends with status."""
    done = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", "export", spec, "--out", str(out),
                           *flags], capture_output=True, text=True)
    assert done.returncode == status, done.stderr
    return done


def test_command_line_exports_a_file_the_test_writes(tmp_path):
    source = tmp_path / "plant.py"
    source.write_text("import control\n\n\ndef plant():\n"
                      "    return control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], 0.1, name='plant'), [1.5]\n")
    out = tmp_path / "plant.fmu"
    done = _export_command(f"{source}:plant", out, "--fmi-version", "3.0")
    assert done.stdout.strip() == str(out)
    system = control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], 0.1, name="plant")
    u = np.ones((10, 1))
    np.testing.assert_allclose(fmu_outputs(out, u, 0.1, system), reference(system, u, 0.1, [1.5]), rtol=0,
                               atol=TOLERANCE)
    assert validate_fmu(str(out)) == []
    missing = _export_command(f"{source}:nothing", out, status=2)
    assert missing.returncode != 0 and "defines no 'nothing'" in missing.stderr and "plant" in missing.stderr


def test_the_guide_runs_and_shows_what_it_says(tmp_path):
    text = (Path(__file__).resolve().parent.parent / "docs" / "guide" / "export.md").read_text(encoding="utf-8")
    code = "".join(text.split("```python\n")[i].split("```")[0] for i in range(1, text.count("```python\n") + 1))
    (tmp_path / "guide.py").write_text(code, encoding="utf-8")
    run = subprocess.run([sys.executable, "guide.py"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.split() == ["True", "True", "True"]
    assert (tmp_path / "OffsetAndWiener.fmu").is_file() and (tmp_path / "LowPass.fmu").is_file()


STATE_HEADER = 152  # bytes of a serialised FMU state's header, its checksum the last 8 (fmu_src/fmi2/fmu_state.h)


def _fnv(data: bytes) -> int:
    h = 14695981039346656037
    for byte in data:
        h = ((h ^ byte) * 1099511628211) & ((1 << 64) - 1)
    return h


def test_fmu_states_come_back_and_forged_ones_are_refused(tmp_path):
    """A closed-form motion → sensor → tseng → error diagram: a serialised state set back steps as the
    first time; a state whose closed form's sample count is not a whole number, or not finite, with its
    checksum made to agree, is refused with fmi2Error and the instance steps on as before."""
    import struct

    from fmpy.fmi1 import FMICallException

    from attitude_fmu.systems.simulation.diagram import attitude_error_system
    from attitude_fmu.systems.simulation.motion import profile

    fs = 100.0
    diagram = control.interconnect(
        [profile("coning").motion().system(fs), ImuModel().system(fs), estimator_system("tseng", dt=1 / fs),
         attitude_error_system(fs)], inplist=[f"{s}_{a}" for s in ("n", "na") for a in "xyz"],
        outlist=["incl_err", "q_w", "q_x", "q_y", "q_z"], name="coning")
    path = export(diagram, tmp_path / "coning.fmu")
    md = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier="coning", instanceName="state")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    noise = np.random.default_rng(9).normal(size=(40, 6))

    def steps(first: int, count: int) -> np.ndarray:
        out = []
        for k in range(first, first + count):
            fmu.setReal([refs[n] for n in diagram.input_labels], list(noise[k]))
            fmu.doStep(k / fs, 1 / fs)
            out.append(fmu.getReal([refs[n] for n in diagram.output_labels]))
        return np.array(out)

    steps(0, 20)
    saved = fmu.serializeFMUstate(fmu.getFMUstate())
    first = steps(20, 10)
    fmu.setFMUstate(fmu.deSerializeFMUstate(saved))
    assert np.array_equal(steps(20, 10), first)
    count = struct.pack("<d", 20.0)  # the closed form's state: 20 samples taken
    assert saved.count(count) >= 1  # the state and the next state a step computed
    for value in (2.5, math.nan, -1.0):
        forged = bytearray(saved.replace(count, struct.pack("<d", value)))
        struct.pack_into("<Q", forged, STATE_HEADER - 8, _fnv(bytes(forged[STATE_HEADER:])))
        with pytest.raises(FMICallException):
            fmu.deSerializeFMUstate(bytes(forged))
        fmu.setFMUstate(fmu.deSerializeFMUstate(saved))
        assert np.array_equal(steps(20, 10), first)
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("kind", ["2.0", "3.0", "3.0 scalar"])
def test_the_matrices_are_parameters_set_before_initialisation(tmp_path, kind):
    """A state space's A, B, C, D: FMI 2.0 scalars A[i,j], FMI 3.0 arrays with their dimensions (or scalars
    A[i,j] with scalar_parameters, for OMSimulator), each with the exported values as start; set before
    initialisation, the FMU steps the state space they make."""
    from fmpy.fmi3 import FMU3Slave

    dt = 0.05
    fmi, scalar = kind.split()[0], kind != "3.0"
    system = stable_discrete(11, 3, 2, 2, True, dt)
    path = export(system, tmp_path / "random.fmu", fmi_version=fmi, scalar_parameters=kind == "3.0 scalar")
    md = read_model_description(str(path))
    variables = {v.name: v for v in md.modelVariables}
    if not scalar:
        assert [int(d.start) for d in variables["A"].dimensions] == [3, 3]
        assert "A[0,0]" not in variables
    else:
        assert float(variables["A[1,2]"].start) == system.A[1, 2] and "A" not in variables
        assert not any(v.dimensions for v in md.modelVariables) and validate_fmu(str(path)) == []
    other = stable_discrete(12, 3, 2, 2, True, dt)
    slave = (FMU3Slave if fmi == "3.0" else FMU2Slave)(
        guid=md.instantiationToken if fmi == "3.0" else md.guid, unzipDirectory=extract(str(path)),
        modelIdentifier="random", instanceName="matrices")
    slave.instantiate()
    if fmi == "2.0":
        slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    set_real, get_real = (slave.setFloat64, slave.getFloat64) if fmi == "3.0" else (slave.setReal, slave.getReal)
    for matrix in "ABCD":
        values = np.asarray(getattr(other, matrix))
        if not scalar:
            slave.setFloat64([variables[matrix].valueReference], list(values.ravel()))  # nValues: its size
        else:
            set_real([variables[f"{matrix}[{i},{j}]"].valueReference for i in range(values.shape[0])
                      for j in range(values.shape[1])], list(values.ravel()))
    slave.exitInitializationMode()
    u = np.random.default_rng(13).normal(size=(30, 2))
    out = []
    for k, row in enumerate(u):
        set_real([variables[n].valueReference for n in system.input_labels], list(row))
        slave.doStep(k * dt, dt)
        out.append(get_real([variables[n].valueReference for n in system.output_labels]))
    if not scalar:
        got = slave.getFloat64([variables["B"].valueReference], nValues=6)
        assert np.array_equal(got, np.asarray(other.B).ravel())
    slave.terminate()
    slave.freeInstance()
    np.testing.assert_allclose(np.array(out), reference(other, u, dt), rtol=0, atol=TOLERANCE)


def test_command_line_writes_scalar_parameters_in_fmi_3_0(tmp_path):
    """attitude export --fmi-version 3.0 --scalar-parameters: A[0,0] and its kin, no array, a valid FMU."""
    source = tmp_path / "plant.py"
    source.write_text("import control\n\nplant = control.ss([[0.5, 0.1], [0.0, 0.3]], [[1.0], [0.0]], [[2.0, 1.0]], "
                      "[[0.0]], 0.1, name='plant')\n")
    out = tmp_path / "plant.fmu"
    _export_command(f"{source}:plant", out, "--fmi-version", "3.0", "--scalar-parameters")
    md = read_model_description(str(out))
    names = {v.name for v in md.modelVariables}
    assert {"A[0,0]", "A[0,1]", "A[1,0]", "A[1,1]", "B[0,0]", "C[0,1]", "D[0,0]"} <= names and "A" not in names
    assert validate_fmu(str(out)) == []
