"""Fixtures shared by the test files, and the end of the test process: it ends right after
pytest has reported when FMUs were loaded in it (pythonfmu's export library finalises its
embedded Python state from a library destructor, which can crash at interpreter shutdown
after every test has run: systems.fmi.cosim.fmus_loaded)."""
import os
import sys

import pytest


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    """Every FMU, built once per session as the package builds them (attitude_fmu.build_fmus):
    the pythonfmu ones in the folder, the native ones in native/ and native/fmi3/. Tests
    only read it (one that changes an FMU copies it first)."""
    from attitude_fmu import build_fmus

    out = tmp_path_factory.mktemp("fmus")
    build_fmus(out)
    return out


def pytest_sessionfinish(session, exitstatus):
    session.config.attitude_exit_status = int(exitstatus)


def pytest_unconfigure(config):
    from attitude_fmu.systems.fmi.cosim import fmus_loaded

    status = getattr(config, "attitude_exit_status", None)
    if status is not None and fmus_loaded():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
