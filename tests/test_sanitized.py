"""The C core, its Python extension and the native FMUs built with -fsanitize=address,undefined
(CMake, through tests/native.py), run over the golden streams, the refusals, the simulation and the lever-arm fit
again, and through the FMU-state, count and step refusals of tests/test_fmu_state.py: the same
results, and no report of an out-of-bounds access, a use of freed or uninitialised memory or
undefined behaviour; and diagrams exported by export_fmu, built with the sanitizers."""
import pytest

from tests import native

REPORTS = ("runtime error", "Sanitizer", "LeakSanitizer")

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(native.sanitized_build() is not None, reason="this is the sanitized run")]


def assert_clean(*test_files):
    """pytest on the test files in the sanitized run: every test passed, no sanitizer's report."""
    run = native.sanitized_pytest(*test_files, timeout=3600)
    if run is None:
        pytest.skip("the C compiler names no address-sanitizer runtime")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert not [r for r in REPORTS if r in run.stderr], run.stderr[-3000:]
    assert " passed" in run.stdout and " failed" not in run.stdout and " skipped" not in run.stdout


def test_the_golden_streams_refusals_and_simulation_run_clean_on_the_sanitized_build():
    assert_clean("tests/test_golden.py", "tests/test_refusals.py", "tests/test_simulation.py",
                 "tests/test_quaternion.py", "tests/test_lever_arm.py")


def test_the_fmu_state_refusals_run_clean_on_the_sanitized_build():
    assert_clean("tests/test_fmu_state.py")


def test_exported_diagrams_run_clean_on_the_sanitized_build():
    """Exported diagrams' generated C (fmu_src/diagram, models/Diagram.c) built with the sanitizers: random
    state spaces, continuous ones across a change of step, wiener alone, behind a prefilter and in the
    closed loop, FMU states and forged ones."""
    assert_clean("tests/test_export.py", "-k", "random or continuous or wiener or states")


def test_the_one_pass_choice_and_the_choice_beside_the_run_run_clean_on_the_sanitized_build():
    """scale_error's candidates in one pass (blocks/core/stages/scale_error.c) and a choice made on one
    thread while the other runs ahead (blocks/core/bindings/threads.cpp)."""
    assert_clean("tests/test_scale_error.py", "tests/test_batch_threads.py", "-k", "one_pass or choice")
