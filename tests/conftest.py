"""End the test process right after pytest has reported when FMUs were loaded in it:
pythonfmu's export library finalises its embedded Python state from a library destructor,
which can crash at interpreter shutdown after every test has run (systems.fmi.cosim.fmus_loaded)."""
import os
import sys


def pytest_sessionfinish(session, exitstatus):
    session.config.attitude_exit_status = int(exitstatus)


def pytest_unconfigure(config):
    from attitude_fmu.systems.fmi.cosim import fmus_loaded

    status = getattr(config, "attitude_exit_status", None)
    if status is not None and fmus_loaded():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
