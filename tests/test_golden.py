"""Every path to the estimator and the simulation held to the golden outputs of tests/golden.py
(frozen from the implementation the C core replaced, which the tests of that time held equal
to the C core step by step): the Python API's cases within 1e-9 of each quantity's scale, the
native FMUs' (FMI 2.0 and 3.0, built as the package builds them) within 1e-12; again on the
sanitized build (tests/test_sanitized.py)."""
from pathlib import Path

import numpy as np
import pytest

from tests import golden, native

CASES = golden.cases()
FROZEN = golden.load()
FROZEN_FMUS = golden.load_fmus()
RTOL = 1e-9  # of each quantity's largest magnitude
FMU_ATOL = 1e-12  # of each output's largest magnitude, at least 1
ONLINE_COLUMNS = dict(zip(golden.ONLINE_OUTPUTS, (4, 3, 3, 3, 3, 1)))  # the columns of run_online's "out"
ANGLES = "euler"  # radians that wrap at ±π


def _quantities(case: str, arrays: dict) -> dict:
    """The arrays of a case, run_online's "out" split into the quantities it holds (each its own scale)."""
    out = {}
    for key, value in arrays.items():
        if key == "out" and (case.startswith("online") or case.startswith("method")):
            start = 0
            for name, width in ONLINE_COLUMNS.items():
                if start < value.shape[1]:
                    out[f"out {name}"] = value[:, start:start + width]
                start += width
        else:
            out[key] = value
    return out


def assert_close(got, frozen, what: str, rtol: float = RTOL, floor: float = 0.0, angles: bool = False) -> float:
    """got equals frozen: booleans exactly, numbers with NaN (and ±inf) in the same places and
    within rtol of max(floor, the frozen array's largest finite magnitude); angles compared on
    the circle. The largest difference relative to that scale."""
    got, frozen = np.asarray(got), np.asarray(frozen)
    assert got.shape == frozen.shape, f"{what}: shape {got.shape}, frozen {frozen.shape}"
    if frozen.dtype == bool:
        assert got.dtype == bool and np.array_equal(got, frozen), f"{what}: differs at {np.flatnonzero(got != frozen)[:8]}"
        return 0.0
    got, frozen = got.astype(float), frozen.astype(float)
    finite = np.isfinite(frozen)
    assert np.array_equal(np.isnan(got), np.isnan(frozen)), f"{what}: NaN in other places"
    assert np.array_equal(got[np.isinf(frozen)], frozen[np.isinf(frozen)]), f"{what}: infinities differ"
    if not finite.any():
        return 0.0
    scale = max(floor, float(np.abs(frozen[finite]).max()), 1e-300)
    difference = np.abs(got[finite] - frozen[finite])
    if angles:
        difference = np.abs(np.angle(np.exp(1j * (got[finite] - frozen[finite]))))
    worst = float(difference.max()) / scale
    assert worst <= rtol, f"{what}: largest difference {worst:.3g} of the scale {scale:.3g}"
    return worst


def test_every_frozen_case_is_run():
    """The cases and the frozen file name the same cases (the BROAD ones only where the recording is)."""
    broad = {"broad online", "broad offline"}
    assert set(CASES) | broad >= set(FROZEN) >= set(CASES), set(FROZEN) ^ set(CASES)
    assert set(FROZEN) - set(CASES) <= (set() if golden.BROAD_RECORDING.exists() else broad)


@pytest.mark.parametrize("name", list(CASES))
def test_the_case_gives_its_frozen_outputs(name):
    got, frozen = _quantities(name, CASES[name]()), _quantities(name, FROZEN[name])
    assert set(got) == set(frozen)
    worst = max(assert_close(got[key], frozen[key], f"{name}: {key}", angles=ANGLES in key) for key in frozen)
    print(f"{name}: largest difference {worst:.2g} of the scale")


@pytest.fixture(scope="session")
def fmu_outputs(request):
    """The native FMUs' outputs on the frozen streams (tests/golden.py's fmu_cases): those the
    package builds (fmu_dir), or in the sanitized run (tests/native.py) the sanitized build's."""
    sanitized = native.sanitized_build()
    return golden.fmu_cases(sanitized / "built" if sanitized else request.getfixturevalue("fmu_dir"))


@pytest.mark.parametrize("name", list(FROZEN_FMUS))
def test_the_native_fmu_gives_its_frozen_outputs(fmu_outputs, name):
    """Every output column within FMU_ATOL of its largest magnitude (at least 1)."""
    got, frozen = golden.rows(fmu_outputs[name]["out"], 5), FROZEN_FMUS[name]
    assert got.shape == frozen.shape
    for column in range(frozen.shape[1]):
        assert_close(got[:, column], frozen[:, column], f"{name}: output {column}", FMU_ATOL, floor=1.0)


@pytest.mark.skipif(native.sanitized_build() is None, reason="only in the sanitized run (tests/test_sanitized.py)")
def test_the_sanitized_run_runs_the_sanitized_build():
    from attitude_fmu import _core

    assert Path(_core.__file__).resolve().parent == native.sanitized_build().resolve()
