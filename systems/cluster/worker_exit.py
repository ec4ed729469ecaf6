"""How a Dask worker process ends once its worker has closed.

A worker process (the nanny's child, or `dask worker --no-nanny` itself) leaves through
interpreter shutdown after its worker has closed: the nanny's target returns and
multiprocessing calls sys.exit. Two things go wrong there. pythonfmu's export library can
crash the process (systems.fmi.cosim.fmus_loaded), after its results were sent but with a
signal for exit status, which a nanny logs and a batch system counts as a failed job. And
finalising an interpreter that holds scipy, python-control and dask takes seconds on a
loaded machine, past the 4 s a nanny waits before it kills the process. WorkerExit, a
worker plugin the client registers on every worker, ends such a process right away, with
status 0, as the console script and the test session end theirs.
"""
from __future__ import annotations

import atexit
import logging
import os
import sys

from distributed.diagnostics.plugin import WorkerPlugin


def end_process(always: bool) -> None:
    """os._exit(0) after flushing logs and standard streams, always or where this process
    loaded an FMU; registered with atexit, it runs before the interpreter finalises anything."""
    cosim = sys.modules.get("attitude_fmu.systems.fmi.cosim")
    if always or (cosim is not None and cosim.fmus_loaded()):
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)


class WorkerExit(WorkerPlugin):
    """On the worker's normal close (teardown), end_process becomes the process's last atexit
    handler, and so its first: for every process with always (the workers of a local cluster
    started for one command), else for those that loaded an FMU (a cluster of others)."""

    def __init__(self, always: bool = False):
        self.always = always

    def teardown(self, worker) -> None:
        atexit.register(end_process, self.always)
