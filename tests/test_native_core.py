"""The C core's filters, methods and timing (fmu_src/native/core: filters, methods,
stages/timing, params, messages) held to their Python twins through ctypes: the generated
tables against the Python Param tables, the realisations and zero-order holds against
python-control's ss and c2d, the closed form of wiener_local's J against quad, the refusals
of bad parameters with Python's messages, and every method's step, state by state, over
hard motion with the sample time changed midway."""
import ctypes
import dataclasses
import importlib
import math
import os
import re
import subprocess

import control
import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import quad

from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter, start_gravity
from attitude_fmu.blocks.methods import luinge, mahony, registry, tseng_adaptive, wiener_local
from attitude_fmu.blocks.params import Param, resolve_params
from attitude_fmu.blocks.quaternion import quat_multiply, quat_normalized, rotvec_quat, up_in_sensor
from attitude_fmu.blocks.stages import timing
from attitude_fmu.fmu_src.variables import tuning_parameters
from attitude_fmu.systems.fmi import native_tables
from attitude_fmu.systems.fmi.native_tables import stages
from tests.native import CORE, SANITIZE, compiler, core_library, sanitized_pytest

TUNING = list(tuning_parameters())  # af_params.h's order
STAGES = stages()
MAX_ORDER = 5
COEF_MAX = 7 + 3 * MAX_ORDER + MAX_ORDER * MAX_ORDER
STEP_RTOL = 1e-12  # per step, of each quantity's scale
SOURCES = ["quaternion.c", "messages.c", "params.c", "filters/earth_filters.c", "filters/matrix.c",
           "filters/sensor_frame.c", "filters/tseng.c", "methods/registry.c", "methods/wiener_local.c",
           "methods/luinge.c", "methods/mahony.c", "methods/tseng_adaptive.c", "stages/timing.c"]

D3, D4 = ctypes.c_double * 3, ctypes.c_double * 4


class Vec3(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in "xyz"]


class Quat(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in "wxyz"]


class EarthFilter(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("A", ctypes.c_double * MAX_ORDER ** 2), ("B", ctypes.c_double * MAX_ORDER),
                ("C", ctypes.c_double * MAX_ORDER), ("D", ctypes.c_double)]

    def matrices(self):
        n = self.n
        return (np.array(self.A[: n * n]).reshape(n, n), np.array(self.B[:n]), np.array(self.C[:n]), self.D)


class DiscreteFilterC(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("Ad", ctypes.c_double * MAX_ORDER ** 2), ("Bd", ctypes.c_double * MAX_ORDER),
                ("C", ctypes.c_double * MAX_ORDER), ("D", ctypes.c_double), ("Ts", ctypes.c_double)]


class AfMethod(ctypes.Structure):
    _fields_ = [("method", ctypes.c_int), ("kernel", ctypes.c_int), ("params", ctypes.c_double * len(TUNING)),
                ("filter", EarthFilter)]


class AfStepper(ctypes.Structure):
    _fields_ = [("kernel", ctypes.c_int), ("Ts", ctypes.c_double), ("state_size", ctypes.c_int),
                ("disc", DiscreteFilterC), ("coef", ctypes.c_double * COEF_MAX)]


class AfStageParam(ctypes.Structure):
    _fields_ = [("index", ctypes.c_int), ("name", ctypes.c_char_p), ("default_value", ctypes.c_double),
                ("unit", ctypes.c_char_p), ("doc", ctypes.c_char_p), ("allow_zero", ctypes.c_int),
                ("low", ctypes.c_double), ("high", ctypes.c_double), ("choices", ctypes.POINTER(ctypes.c_double)),
                ("n_choices", ctypes.c_int)]


SIZES = """#include <stddef.h>
#include "methods/registry.h"
size_t sizeof_method(void) { return sizeof(AfMethod); }
size_t sizeof_stepper(void) { return sizeof(AfStepper); }
size_t sizeof_stage_param(void) { return sizeof(AfStageParam); }
"""

ARRAY = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")
SIGNATURES = {  # name: (restype, argtypes)
    "float_repr": (ctypes.c_char_p, [ctypes.c_double, ctypes.c_char_p]),
    "str_repr": (ctypes.c_char_p, [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t]),
    "stage_param": (ctypes.POINTER(AfStageParam), [ctypes.c_int, ctypes.c_int]),
    "resolve_params": (ctypes.c_int, [ctypes.c_int, ARRAY, ARRAY, ctypes.c_char_p, ctypes.c_size_t]),
    "state_space": (None, [ARRAY, ctypes.c_int, ARRAY, ctypes.c_int, ctypes.POINTER(EarthFilter)]),
    "tseng_earth_filter": (None, [ctypes.POINTER(EarthFilter)]),
    "expm": (None, [ctypes.c_int, ARRAY, ARRAY]),
    "solve": (None, [ctypes.c_int, ARRAY, ctypes.c_int, ARRAY]),
    "discrete_filter": (ctypes.c_int, [ctypes.POINTER(EarthFilter), ctypes.c_double, ctypes.POINTER(DiscreteFilterC),
                                       ctypes.c_char_p, ctypes.c_size_t]),
    "rest_state": (None, [ctypes.POINTER(DiscreteFilterC), ARRAY, ARRAY]),
    "start_gravity": (None, [ARRAY, ARRAY, ctypes.c_double, ARRAY]),
    "level_on": (None, [ARRAY, ARRAY]),
    "band_pass_variance": (ctypes.c_double, [ctypes.c_double, ctypes.c_double]),
    "butterworth_zoh": (None, [ctypes.c_double, ARRAY, ARRAY]),
    "method_index": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t]),
    "method_configure": (ctypes.c_int, [ctypes.POINTER(AfMethod), ctypes.c_int, ARRAY, ctypes.c_char_p,
                                        ctypes.c_size_t]),
    "stepper_at": (ctypes.c_int, [ctypes.POINTER(AfStepper), ctypes.POINTER(AfMethod), ctypes.c_double,
                                  ctypes.c_char_p, ctypes.c_size_t]),
    "stepper_initial_state": (None, [ctypes.POINTER(AfStepper), ARRAY, ARRAY]),
    "stepper_run": (None, [ctypes.POINTER(AfStepper), ARRAY, ARRAY, ARRAY, ARRAY, ARRAY]),
    "check_samples": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t]),
    "same_step": (ctypes.c_int, [ctypes.c_double, ctypes.c_double]),
    "check_latency": (ctypes.c_int, [ctypes.c_double, ctypes.c_char_p, ctypes.c_size_t]),
    "interval_mean": (Vec3, [Vec3, Vec3]),
    "carry_forward": (None, [Quat, Vec3, Vec3, ctypes.c_double, ctypes.POINTER(Quat), ctypes.POINTER(Vec3)]),
    "interval_end": (Vec3, [Vec3, Vec3, ctypes.c_double]),
    "sizeof_method": (ctypes.c_size_t, []),
    "sizeof_stepper": (ctypes.c_size_t, []),
    "sizeof_stage_param": (ctypes.c_size_t, []),
}
for _kernel, _refuses in (("wiener_local", False), ("luinge", False), ("mahony", True), ("tseng_adaptive", True)):
    SIGNATURES[f"{_kernel}_coefficients"] = (ctypes.c_int if _refuses else None, [ARRAY, ctypes.c_double, ARRAY] + (
        [ctypes.c_char_p, ctypes.c_size_t] if _refuses else []))
    SIGNATURES[f"{_kernel}_initial_state"] = (None, [ARRAY, ARRAY, ARRAY])
    SIGNATURES[f"{_kernel}_run"] = (None, [ARRAY, ARRAY, ARRAY, ARRAY, ARRAY, ARRAY])


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    folder = tmp_path_factory.mktemp("native_core_a")
    (folder / "sizes.c").write_text(SIZES)
    library = core_library(folder, [*(CORE / s for s in SOURCES), folder / "sizes.c"])
    for name, (restype, argtypes) in SIGNATURES.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes
    assert (library.sizeof_method(), library.sizeof_stepper(), library.sizeof_stage_param()) == (
        ctypes.sizeof(AfMethod), ctypes.sizeof(AfStepper), ctypes.sizeof(AfStageParam))
    return library


def _message():
    return ctypes.create_string_buffer(1024)


def _vector(values) -> np.ndarray:
    """values (name → value) as the C core's parameter array (AF_P_<name> order), NaN elsewhere."""
    vector = np.full(len(TUNING), np.nan)
    for name, value in values.items():
        vector[TUNING.index(name)] = value
    return vector


def _python_error(function, *args):
    """The message of the ValueError (or OverflowError) function(*args) raises, or None."""
    try:
        function(*args)
    except (ValueError, OverflowError) as exc:
        return str(exc)
    return None


def _close(python, c, what, rtol=STEP_RTOL):
    """python and c (steps × values) equal within rtol of each column's largest magnitude."""
    python, c = np.asarray(python, dtype=float), np.asarray(c, dtype=float)
    scale = np.maximum(np.abs(python).max(axis=0, keepdims=True), 1e-300)
    worst = float((np.abs(python - c) / scale).max())
    assert worst <= rtol, f"{what}: largest difference {worst:.3g} of the scale"
    return worst


# ---- the generated tables and Python's messages

def test_the_generated_tables_are_the_python_ones(lib):
    for stage, (name, owner, label, params) in enumerate(STAGES):
        own = {p.name: p for p in params}
        for index, parameter in enumerate(TUNING):
            entry = lib.stage_param(stage, index)
            if parameter not in own:
                assert not entry, f"{name} has no {parameter}"
                continue
            p, c = own[parameter], entry.contents
            assert (c.index, c.name.decode(), c.unit.decode(), c.doc.decode(), bool(c.allow_zero), c.low, c.high) == (
                index, p.name, p.unit, p.doc, p.allow_zero, p.low, p.high)
            assert (math.isnan(c.default_value) if p.default is None else c.default_value == p.default)
            assert (not c.choices if p.choices is None else tuple(c.choices[:c.n_choices]) == p.choices)
    f = EarthFilter()
    lib.tseng_earth_filter(ctypes.byref(f))
    ss = control.ss(tseng.earth_filter())
    for c, python in zip(f.matrices(), (ss.A, ss.B.ravel(), ss.C.ravel(), ss.D.item())):
        np.testing.assert_array_equal(c, python)


def test_a_field_param_grows_is_carried_into_the_header(tmp_path, monkeypatch):
    """Fields added to blocks.params.Param (here an optional string and an optional tuple)
    appear in AfStageParam with every stage's value, without a change to the generator: a
    tuple as a static array and its count, None as NULL; a type C cannot hold is refused."""
    @dataclasses.dataclass(frozen=True)
    class GrownParam(Param):
        source: str | None = None
        marks: tuple[float, ...] | None = None

    grown = [(name, owner, label, tuple(GrownParam(**dataclasses.asdict(p), source="datasheet" if i else None,
                                                   marks=(0.5, float(i)) if i == 1 else None)
                                        for i, p in enumerate(ps))) for name, owner, label, ps in STAGES]
    monkeypatch.setattr(native_tables, "Param", GrownParam)
    monkeypatch.setattr(native_tables, "stages", lambda: grown)
    (tmp_path / "af_params.h").write_text(native_tables.header_text())
    (tmp_path / "use.c").write_text(
        '#include "af_params.h"\n'
        "double luinge_tilt_mark(void) { return AF_STAGE_PARAMS_luinge[1].marks[AF_STAGE_PARAMS_luinge[1].n_marks - 1]; }\n"
        "int luinge_source(void) { return AF_STAGE_PARAMS_luinge[0].source == NULL; }\n")
    subprocess.run([*compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-fsyntax-only", f"-I{tmp_path}",
                    str(tmp_path / "use.c")], check=True)
    header = (tmp_path / "af_params.h").read_text()
    assert "static const double AF_STAGE_PARAMS_luinge_tilt_sd_marks[2] = {0.5, 1.0};" in header
    assert '{AF_P_tilt_sd, "tilt_sd", 0.05, "rad", ' in header
    assert '"datasheet", AF_STAGE_PARAMS_luinge_tilt_sd_marks, 2},' in header  # luinge's second parameter
    assert ", NULL, NULL, 0}," in header  # and a first one: no source, no marks

    @dataclasses.dataclass(frozen=True)
    class WrongParam(Param):
        flags: dict | None = None

    monkeypatch.setattr(native_tables, "Param", WrongParam)
    with pytest.raises(ValueError, match=r"Param.flags: no C type for 'dict \| None'"):
        native_tables.header_text()


@pytest.mark.parametrize("value", [0.0, -0.0, 1.0, -1.5, 0.1, 0.01, 1e-4, 1e-5, 1.5e-5, 123.456, 100.0, 1e15, 1e16,
                                   123456789012345678.0, 2.5e300, 1e300, 5e-324, 1.7976931348623157e308,
                                   math.radians(0.1), 1 / 3, math.inf, -math.inf, math.nan])
def test_float_repr_is_pythons(lib, value):
    out = ctypes.create_string_buffer(32)
    assert lib.float_repr(value, out).decode() == repr(value)


def test_float_repr_of_random_values_is_pythons(lib):
    out = ctypes.create_string_buffer(32)
    values = np.random.default_rng(5).standard_normal(300) * 10.0 ** np.random.default_rng(6).integers(-30, 30, 300)
    assert [lib.float_repr(v, out).decode() for v in values] == [repr(float(v)) for v in values]
    for text in ("wiener", "it's", 'say "x"', "tab\there", ""):
        assert lib.str_repr(text.encode(), out, 32).decode() == repr(text)


@pytest.mark.parametrize("stage", range(len(STAGES)), ids=[s[0] for s in STAGES])
def test_resolve_params_refuses_as_python(lib, stage):
    _, owner, _, params = STAGES[stage]
    resolved = np.empty(len(TUNING))
    cases = [{p.name: v} for p in params for v in (-1.0, 0.0, 0.5, 2.5, 1e300, math.inf, -math.inf, p.low, p.high,
                                                   p.low * 0.5, p.high * (1 + 1e-15), p.high * 10.0)]
    cases.append({next(t for t in TUNING if t not in {p.name for p in params}): 1.0})  # a name the stage lacks
    for given in cases:
        expected = _python_error(resolve_params, params, given, owner)
        message = _message()
        status = lib.resolve_params(stage, _vector(given), resolved, message, len(message))
        assert (status, message.value.decode() if status else None) == (-1 if expected else 0, expected), given
        if not expected:
            for k, v in resolve_params(params, given, owner).items():
                c = resolved[TUNING.index(k)]
                assert (math.isnan(c) if v is None else c == v), k


def test_method_refusals_are_pythons(lib):
    message = _message()
    assert lib.method_index(b"kalman", message, len(message)) == -1
    assert message.value.decode() == _python_error(registry.method, "kalman")
    assert lib.method_index(None, message, len(message)) == -1
    assert message.value.decode() == _python_error(registry.method, None)
    assert [lib.method_index(n.encode(), message, len(message)) for n in registry.METHODS] == list(range(6))
    m = AfMethod()
    for name, given in (("wiener", {"stationary": 0.5}), ("wiener", {"omega_c": 0.05}),
                        ("first_order", {"omega_c": 1e-300, "omega_g": 1e-300}), ("mahony", {"k_P": -1.0}),
                        ("wiener", {"delta_n": 1e300, "delta_v": 1e-300})):
        status = lib.method_configure(ctypes.byref(m), lib.method_index(name.encode(), None, 0), _vector(given),
                                      message, len(message))
        in_order = tuple((p.name, given[p.name]) for p in registry.method(name).params if p.name in given)
        expected = _python_error(registry.stepper, name, in_order, 0.01)  # in the method's order, as split_params
        assert status == -1 and message.value.decode() == expected, (name, given)


@pytest.mark.parametrize("name, given", [("wiener", {"omega_g": 1e200}), ("first_order", {"omega_g": 1e100}),
                                         ("luinge", {"delta_n": 1e300}), ("wiener", {"delta_n": 1e300})])
def test_overflowing_parameters_are_refused_with_a_message(lib, name, given):
    """Values whose coefficients would overflow lie beyond their parameter's plausible range:
    the C core refuses them at configuration with Python's message."""
    m, message = AfMethod(), _message()
    status = lib.method_configure(ctypes.byref(m), lib.method_index(name.encode(), None, 0), _vector(given),
                                  message, len(message))
    assert status == -1
    assert message.value.decode() == _python_error(registry.stepper, name, tuple(given.items()), 0.01)
    assert "outside its plausible range" in message.value.decode()


def test_the_sample_time_is_refused_as_python_refuses_it(lib):
    m, s, message = AfMethod(), AfStepper(), _message()
    for name in ("tseng", "luinge"):
        assert lib.method_configure(ctypes.byref(m), lib.method_index(name.encode(), None, 0), _vector({}),
                                    message, len(message)) == 0
        for Ts in (0.0, -0.01, math.inf, math.nan):
            assert lib.stepper_at(ctypes.byref(s), ctypes.byref(m), Ts, message, len(message)) == -1
            assert message.value.decode() == _python_error(registry.stepper, name, (), Ts)


TWIN = re.compile(r"Python twin: (blocks/[\w/]+)\.py")
DEFINE = re.compile(r"^#define (\w+) ([-+]?[0-9][0-9.eE+-]*)\b", re.MULTILINE)


def _python_constant(module, name):
    """The number module holds under name, or under name without the module's prefix
    (WIENER_LOCAL_W2 → wiener_local.W2; a slice: its start; STATE_SIZE: len(STATE_NAMES)); None."""
    for candidate in (name, name.removeprefix(module.__name__.rsplit(".", 1)[1].upper() + "_")):
        if candidate == "STATE_SIZE" and hasattr(module, "STATE_NAMES"):
            return len(module.STATE_NAMES)
        value = getattr(module, candidate, None)
        if isinstance(value, slice):
            return value.start
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return value
    return None


def test_the_constants_of_every_header_are_its_python_twins():
    """Every numeric #define of a core header whose Python twin has the name equals it."""
    checked = set()
    for header in sorted(CORE.rglob("*.h")):
        text = header.read_text()
        twin = TWIN.search(text)
        if twin is None:
            continue
        module = importlib.import_module("attitude_fmu." + twin.group(1).replace("/", "."))
        for name, literal in DEFINE.findall(text):
            value = _python_constant(module, name)
            if value is not None:
                assert float(literal) == value, f"{header.relative_to(CORE)}: {name} = {literal}, Python {value!r}"
                checked.add(name)
    assert {"STEP_TOLERANCE", "MAX_LATENCY_S", "NOMINAL_DELTA_V", "STANDARD_GRAVITY", "SERIES_ANGLE2",
            "WIENER_LOCAL_STATE_SIZE", "WIENER_LOCAL_W2", "WIENER_LOCAL_T", "WIENER_LOCAL_QUAT",
            "LUINGE_STATE_SIZE", "MAHONY_STATE_SIZE"} <= checked, checked
    defines = dict(DEFINE.findall((CORE / "filters" / "earth_filters.h").read_text()))
    assert float(defines["SQRT2"]) == math.sqrt(2.0) == wiener_local.SQRT2
    assert int(defines["MAX_ORDER"]) == MAX_ORDER == len(tseng.earth_filter().den_array[0, 0]) - 1  # the largest


# ---- filters: realisation, zero-order hold, matrix functions

SENSOR_FRAME = [("wiener", {"stationary": 1.0}), ("wiener", {"delta_v": 0.3, "delta_n": 0.004}),
                ("wiener", {"omega_c": 5.0}), ("wiener", {"omega_g": 2.0, "omega_c": 3.0}),
                ("first_order", {}), ("first_order", {"omega_f": 0.7}), ("tseng", {})]


def _configured(lib, name, given):
    m, message = AfMethod(), _message()
    status = lib.method_configure(ctypes.byref(m), lib.method_index(name.encode(), None, 0), _vector(given),
                                  message, len(message))
    assert status == 0, message.value.decode()
    return m


@pytest.mark.parametrize("name, given", SENSOR_FRAME)
def test_the_earth_filter_is_control_ss_of_the_design(lib, name, given):
    m = _configured(lib, name, given)
    assert m.kernel == 0
    ss = control.ss(registry.method(name).filter(given))
    for c, python, what in zip(m.filter.matrices(), (ss.A, ss.B.ravel(), ss.C.ravel(), ss.D.item()), "ABCD"):
        np.testing.assert_allclose(c, python, rtol=1e-15, atol=0, err_msg=what)


@pytest.mark.parametrize("name, given", SENSOR_FRAME)
def test_the_zero_order_hold_is_c2d(lib, name, given):
    m = _configured(lib, name, given)
    message = _message()
    for Ts in (1e-4, 0.0037, 0.01, 0.04, 0.3, 3.0):
        disc = DiscreteFilterC()
        assert lib.discrete_filter(ctypes.byref(m.filter), Ts, ctypes.byref(disc), message, len(message)) == 0
        python = DiscreteFilter.from_lti(registry.method(name).filter(given), Ts)
        n = python.order
        np.testing.assert_allclose(np.array(disc.Ad[: n * n]).reshape(n, n), python.Ad, rtol=0, atol=2e-14)
        np.testing.assert_allclose(disc.Bd[:n], python.Bd, rtol=0, atol=2e-14 * np.abs(python.Bd).max())
        # the rest state solves (I − Ad)·x = Bd: a rounding of Ad grows by ‖(I − Ad)⁻¹‖ (large for
        # a slow filter at a short Ts); both sides within that of the continuous equilibrium −A⁻¹·B
        acc0 = np.array([0.3, -1.2, 9.7])
        X = np.empty(3 * n)
        lib.rest_state(ctypes.byref(disc), acc0, X)
        ss = control.ss(registry.method(name).filter(given))
        exact = np.outer(-np.linalg.solve(ss.A, ss.B).ravel(), acc0)
        tolerance = 8 * np.finfo(float).eps * np.linalg.norm(np.linalg.inv(np.eye(n) - python.Ad), 2) * \
            np.abs(exact).max()
        assert np.abs(X.reshape(n, 3) - exact).max() <= tolerance
        assert np.abs(python.rest_state(acc0) - exact).max() <= tolerance


def test_the_local_wieners_zero_order_hold_is_pythons_and_c2d(lib):
    """wiener_local's closed form for d/dt[ĝ, u] = ω_g·M·[ĝ, u] + ω_g·[0, 1]·y_a, M = [[0, 1], [−1, −√2]]."""
    M = np.array([[0.0, 1.0], [-1.0, -math.sqrt(2.0)]])
    for wg in (0.05, 0.13, 1.0, 7.0):
        for Ts in (1e-4, 0.01, 0.04, 0.3):
            Ad, Bd = np.empty(4), np.empty(2)
            lib.butterworth_zoh(wg * Ts, Ad, Bd)
            Ad_py, Bd_py = np.empty((2, 2)), np.empty(2)
            wiener_local.butterworth_zoh(wg * Ts, Ad_py, Bd_py)
            np.testing.assert_allclose(Ad.reshape(2, 2), Ad_py, rtol=0, atol=4e-16)  # numba's fast-math: an ulp
            np.testing.assert_allclose(Bd, Bd_py, rtol=0, atol=4e-16)
            # within rounding of the state it updates (the closed form's Bd[0] cancels where ω_g·Ts is tiny)
            disc = control.c2d(control.ss(wg * M, wg * np.array([[0.0], [1.0]]), np.eye(2), 0.0), Ts, "zoh")
            np.testing.assert_allclose(Ad.reshape(2, 2), disc.A, rtol=0, atol=1e-14)
            np.testing.assert_allclose(Bd, disc.B.ravel(), rtol=0, atol=1e-14)


def test_expm_and_solve_are_scipys_and_numpys(lib):
    rng = np.random.default_rng(3)
    for n in range(1, 7):
        for scale in (1e-4, 0.02, 0.3, 1.0, 4.0, 30.0, 300.0):
            M = rng.standard_normal((n, n))
            M = scale * (M - (np.abs(np.linalg.eigvals(M).real).max() + 0.1) * np.eye(n))  # stable, so exp(M) is tame
            E = np.empty(n * n)
            lib.expm(n, np.ascontiguousarray(M).ravel(), E)
            expected = scipy.linalg.expm(M)
            assert np.abs(E.reshape(n, n) - expected).max() <= 1e-12 * np.abs(expected).max()
            A, B = rng.standard_normal((n, n)) + n * np.eye(n), rng.standard_normal((n, 2))
            X = B.copy()
            lib.solve(n, A.copy().ravel(), 2, X.ravel() if X.flags.c_contiguous else X)
            np.testing.assert_allclose(X, np.linalg.solve(A, B), rtol=1e-13, atol=1e-14)


def test_band_pass_variance_closed_form_is_the_integral(lib):
    """J = (1/2π)∫ (ωτ_v)⁴/(1+ω²τ_v²)²/(1+ω²/ω_m²) dω, integrated with quad (wiener_local.coefficients
    has the same closed form: test_kernel_coefficients_and_initial_states_are_pythons holds its 1/J
    to C's exactly)."""
    for omega_m in (0.05, 0.5, 1.0, 3.0, 10.0, 40.0, 500.0):
        for tau_v in (0.1, 1.0, 3.0):
            value = quad(lambda x, c: x**4 / ((1.0 + x * x) ** 2 * (1.0 + (x / c) ** 2)), 0.0, np.inf,
                         args=(omega_m * tau_v,), epsabs=0.0, epsrel=1e-13, limit=200)[0]
            assert lib.band_pass_variance(omega_m, tau_v) == pytest.approx(value / (2.0 * math.pi * tau_v), rel=1e-12)


@pytest.mark.parametrize("kernel", [wiener_local, luinge, mahony, tseng_adaptive])
def test_kernel_coefficients_and_initial_states_are_pythons(lib, kernel):
    name = kernel.__name__.rsplit(".", 1)[1]
    method = {"wiener_local": "wiener"}.get(name, name)
    for given in ({}, {"delta_n": 0.003, "g": 9.8, "k_P": 2.0, "tilt_sd": 0.1, "tol": 0.3, "tau_v": 0.5,
                       "omega_m": 3.0, "scale_error": 0.0, "tau_noise": 2.0}):
        own = {k: v for k, v in given.items() if any(p.name == k for p in registry.method(method).params)}
        params = registry.method(method).resolve(own)
        resolved = _configured(lib, method, own).params
        for Ts in (0.001, 0.01, 0.037):
            python = kernel.coefficients(params, Ts)
            c = np.empty(len(python))
            args = (np.array(resolved), Ts, c) + ((None, 0) if kernel in (mahony, tseng_adaptive) else ())
            assert getattr(lib, f"{name}_coefficients")(*args) in (None, 0)
            if kernel is tseng_adaptive:  # its zero-order hold: expm's, within rounding
                np.testing.assert_allclose(c, python, rtol=0, atol=1e-13 * np.abs(python).max())
            else:  # the same formulas, operation for operation (wiener_local's closed-form J too)
                np.testing.assert_array_equal(c, python)
            for acc0 in ([0.1, 0.2, 9.8], [0.0, 0.0, -9.81], [3.0, -4.0, 0.5]):
                state = np.empty(len(kernel.STATE_NAMES))
                getattr(lib, f"{name}_initial_state")(python, np.array(acc0), state)
                np.testing.assert_allclose(state, kernel.initial_state(python, np.array(acc0)), rtol=1e-15,
                                           atol=1e-15)


# ---- every method's step over hard motion, with the sample time changed midway

SEGMENTS = ((0.01, 1200), (0.0037, 900), (0.025, 900))  # (Ts s, samples): 3000 samples in all


def _hard_motion(seed=7):
    """Gyro (rad/s) and accelerometer (m/s²) samples of a fast tumbling motion: rates up to
    about 12 rad/s about changing axes (turns of more than SERIES_ANGLE2 per sample, upside
    down on the way), linear accelerations of ±6 m/s² (the norm leaves g by more than
    tseng_adaptive's tol), and a few samples with no accelerometer (all 0)."""
    rng = np.random.default_rng(seed)
    Ts = np.concatenate([np.full(n, h) for h, n in SEGMENTS])
    t = np.cumsum(Ts)
    freq, phase = rng.uniform(0.2, 2.5, (3, 4)), rng.uniform(0, 2 * np.pi, (3, 4))
    amplitude = np.array([4.0, 3.0, 2.0, 1.5])
    gyr = np.stack([(amplitude * np.sin(freq[i] * t[:, None] + phase[i])).sum(axis=1) for i in range(3)], axis=1)
    gyr[t > 20.0] *= 0.1  # then slow, so that the filters' states settle and the start-up ends
    up = np.empty((len(t), 3))
    q = (1.0, 0.0, 0.0, 0.0)
    for k in range(len(t)):  # the orientation, integrated at each sample's own Ts, and up in its sensor frame
        q = quat_normalized(quat_multiply(q, rotvec_quat(*(gyr[k] * Ts[k]))))
        up[k] = up_in_sensor(q)
    acc = 9.81 * up + 6.0 * np.sin(np.outer(t, [0.7, 1.3, 2.1]) + 1.0) * (np.sin(0.4 * t)[:, None] > 0.3)
    acc[[1300, 1301, 2500]] = 0.0
    return Ts, gyr + 0.01 * rng.standard_normal(gyr.shape), acc


def test_the_hard_motion_takes_every_branch():
    """The stream the steps are compared on: tseng_adaptive switches both ways, rotations on
    both sides of rotvec_quat's series, upside down (level_quat's other branches)."""
    Ts, gyr, acc = _hard_motion()
    norm = np.linalg.norm(acc, axis=1)
    assert 0.2 < np.mean(np.abs(norm - 9.81) > 0.5) < 0.8 and 0.2 < np.mean(np.abs(norm - 9.81) > 2.0)
    angle2 = (np.linalg.norm(gyr, axis=1) * Ts) ** 2
    assert 0.05 < np.mean(angle2 >= 1e-2) < 0.95
    assert (acc[:, 2] / np.maximum(norm, 1e-300)).min() < -0.99 and (norm == 0).sum() == 3


STEP_CASES = [("wiener", {}), ("wiener", {"scale_error": 0.02, "tau_noise": 0.3}), *SENSOR_FRAME,
              ("tseng_adaptive", {}), ("tseng_adaptive", {"tol": 2.0, "k_I": 0.0}), ("luinge", {}),
              ("luinge", {"tilt_sd": 0.01}), ("mahony", {}), ("mahony", {"k_P": 4.0, "k_I": 1.0})]


@pytest.mark.parametrize("name, given", STEP_CASES, ids=[f"{n}-{'-'.join(g) or 'defaults'}" for n, g in STEP_CASES])
def test_every_method_steps_as_its_python_twin(lib, name, given):
    """Same inputs; each side discretises for itself at every change of Ts; the state, the
    gravity estimate and q equal Python's within STEP_RTOL of their scale, step by step."""
    Ts, gyr, acc = _hard_motion()
    m, s, message = _configured(lib, name, given), AfStepper(), _message()
    params = tuple(sorted(given.items()))
    python_stepper = None
    n = len(Ts)
    states_py, states_c = [], []
    out_py, out_c = np.empty((n, 7)), np.empty((n, 7))
    for k in range(n):
        if k == 0 or Ts[k] != Ts[k - 1]:
            python_stepper = registry.stepper(name, params, Ts[k])
            assert lib.stepper_at(ctypes.byref(s), ctypes.byref(m), Ts[k], message, len(message)) == 0
            assert s.state_size == len(python_stepper.state_names)
        if k == 0:
            gravity0 = start_gravity(gyr[0], acc[0], Ts[0])
            state_py = python_stepper.initial_state(gravity0)
            state_c = np.empty(s.state_size)
            lib.stepper_initial_state(ctypes.byref(s), np.ascontiguousarray(gravity0), state_c)
            assert np.abs(state_py - state_c).max() <= STEP_RTOL * np.abs(state_py).max(), "initial state"
        g, q = np.empty((1, 3)), np.empty((1, 4))
        python_stepper.run(state_py, gyr[k:k + 1], acc[k:k + 1], g, q)
        out_py[k, :3], out_py[k, 3:] = g[0], q[0]
        gc, qc = np.empty(3), np.empty(4)
        lib.stepper_run(ctypes.byref(s), state_c, np.ascontiguousarray(gyr[k]), np.ascontiguousarray(acc[k]), gc, qc)
        out_c[k, :3], out_c[k, 3:] = gc, qc
        states_py.append(state_py.copy())
        states_c.append(state_c.copy())
    _close(out_py[:, :3], out_c[:, :3], "gravity")
    _close(out_py[:, 3:], out_c[:, 3:], "q")
    _close(states_py, states_c, "state")


# ---- timing

def test_timing_is_pythons(lib):
    message = _message()
    for reference in (0.01, 1e-3):
        for Ts in (reference, reference * (1 + 5e-10), reference * (1 + 2e-9), reference * (1 - 2e-9), 2 * reference):
            assert bool(lib.same_step(Ts, reference)) == timing.same_step(Ts, reference)
    for latency in (0.0, 0.5, -0.5, 0.02, 0.5000001, -3.0, math.inf, math.nan):
        expected = _python_error(timing.check_latency, latency)
        status = lib.check_latency(latency, message, len(message))
        assert (status, message.value.decode() if status else None) == (-1 if expected else 0, expected)
    for gyr_samples, acc_samples in (("mean", "point"), ("point", "mean"), ("average", "point"), ("mean", "")):
        expected = _python_error(timing.check_samples, gyr_samples, acc_samples)
        status = lib.check_samples(gyr_samples.encode(), acc_samples.encode(), message, len(message))
        assert (status, message.value.decode() if status else None) == (-1 if expected else 0, expected)
    rng = np.random.default_rng(11)
    for _ in range(200):
        q = rng.standard_normal(4)
        q /= np.linalg.norm(q)
        up, gyr, before = rng.standard_normal(3) * 9.0, rng.standard_normal(3) * 8.0, rng.standard_normal(3)
        latency, Ts = rng.uniform(-0.5, 0.5), rng.uniform(1e-4, 0.05)
        qo, uo = Quat(), Vec3()
        lib.carry_forward(Quat(*q), Vec3(*up), Vec3(*gyr), latency, ctypes.byref(qo), ctypes.byref(uo))
        q_py, up_py = timing.carry_forward(tuple(q), tuple(up), tuple(gyr), latency)
        np.testing.assert_allclose([qo.w, qo.x, qo.y, qo.z], q_py, rtol=0, atol=1e-15)
        np.testing.assert_allclose([uo.x, uo.y, uo.z], up_py, rtol=0, atol=1e-15 * np.linalg.norm(up))
        end = lib.interval_end(Vec3(*gyr), Vec3(*up), Ts)
        np.testing.assert_allclose([end.x, end.y, end.z], timing.interval_end(tuple(gyr), tuple(up), Ts), rtol=0,
                                   atol=1e-15 * np.linalg.norm(up))
        mean = lib.interval_mean(Vec3(*before), Vec3(*gyr))
        assert [mean.x, mean.y, mean.z] == list(timing.interval_mean(before, gyr))


def test_start_gravity_and_level_on_are_pythons(lib):
    rng = np.random.default_rng(12)
    for acc0 in [*rng.standard_normal((50, 3)) * 9.0, np.array([0.0, 0.0, -9.81]), np.array([1e-9, 0.0, -9.81])]:
        gyr0, Ts = rng.standard_normal(3) * 10.0, rng.uniform(1e-3, 0.05)
        out = np.empty(3)
        lib.start_gravity(np.ascontiguousarray(gyr0), np.ascontiguousarray(acc0), Ts, out)
        np.testing.assert_allclose(out, start_gravity(gyr0, acc0, Ts), rtol=0, atol=1e-14)
        q = np.empty(4)
        lib.level_on(np.ascontiguousarray(acc0), q)
        np.testing.assert_allclose(q, mahony.level_on(acc0), rtol=0, atol=1e-15)


# ---- the same, built with the sanitizers

@pytest.mark.skipif(bool(os.environ.get(SANITIZE)), reason="this is the sanitized run")
def test_the_core_runs_clean_under_the_sanitizers():
    """This file's tests again on the core built with -fsanitize=address,undefined: any
    out-of-bounds access, use of uninitialised stack or undefined behaviour fails them."""
    run = sanitized_pytest(__file__, "-x")
    if run is None:
        pytest.skip("the C compiler names no address-sanitizer runtime")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert "runtime error" not in run.stderr and "Sanitizer" not in run.stderr, run.stderr[-3000:]
