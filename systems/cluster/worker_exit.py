"""How a Dask worker process that ran FMUs ends.

A worker process (the nanny's child, or `dask worker --no-nanny` itself) leaves through
interpreter shutdown once its worker has closed: the nanny's target returns and
multiprocessing calls sys.exit. There pythonfmu's export library can crash the process
(systems.fmi.cosim.fmus_loaded), after its results were sent but with a signal for exit
status, which a nanny logs and a batch system counts as a failed job. FmuWorkerExit, a
worker plugin the client registers on every worker, makes the normal close end such a
process right away, with status 0, as the console script and the test session do.
"""
from __future__ import annotations

import atexit
import logging
import os
import sys

from distributed.diagnostics.plugin import WorkerPlugin


def end_if_fmus_loaded() -> None:
    """os._exit(0) after flushing logs and standard streams, where this process loaded an FMU;
    registered with atexit, it runs before the interpreter finalises anything."""
    cosim = sys.modules.get("attitude_fmu.systems.fmi.cosim")
    if cosim is not None and cosim.fmus_loaded():
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)


class FmuWorkerExit(WorkerPlugin):
    """On the worker's normal close (teardown), the process's last atexit handler, and so its
    first: end_if_fmus_loaded."""

    def teardown(self, worker) -> None:
        atexit.register(end_if_fmus_loaded)
