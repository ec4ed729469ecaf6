"""The `attitude` console script. Its command's modules take about a second and a half to load
(numpy, pyarrow, the extension); Ctrl-C in that time ends as it does later, with one line and
exit status 130, not with a traceback."""
from __future__ import annotations

import signal
import sys


def _interrupted_while_loading(signum, frame) -> None:
    print(f"attitude: interrupted by {signal.Signals(signum).name}; nothing was written", file=sys.stderr)
    raise SystemExit(128 + signum)


def entry_point() -> None:
    """Load the command with SIGINT ending it quietly, then run it (systems.cli.commands.entry_point),
    whose own handling of signals takes over."""
    previous = signal.signal(signal.SIGINT, _interrupted_while_loading)
    from attitude_fmu.systems.cli.commands import entry_point as run

    signal.signal(signal.SIGINT, previous)
    run()
