"""The kernels the command line's first run needs, compiled ahead: at the package's build
(setup.py) into the wheel's kernel_cache/, which blocks.jit hands to the per-user cache on
first use, so that `attitude estimate` right after `pip install .` reads and estimates
without compiling for seconds first.

    python -m attitude_fmu.systems.cli.first_run FOLDER   (numba's cache of these sources into FOLDER)
"""
from __future__ import annotations

import math
import sys

import numpy as np


def compile_kernels() -> None:
    """Run, on a short synthetic recording (60 s at 100 Hz, long enough for the axes
    check), what `attitude estimate` runs on one with its defaults, with and without a
    magnetometer: numba compiles each kernel for the argument types the command line
    gives them, into the cache blocks.jit names."""
    from attitude_fmu.blocks.pipeline.batch import estimate
    from attitude_fmu.systems.recordings.axes import axes_notes

    fs, n = 100.0, 6000
    t = np.arange(1, n + 1) / fs
    gyr = np.column_stack([np.sin(t), np.cos(0.7 * t), 0.5 * np.sin(0.3 * t)])
    tilt = 0.3 * np.sin(0.5 * t)
    acc = np.column_stack([9.81 * np.sin(tilt), np.zeros(n), 9.81 * np.cos(tilt)])
    mag = np.column_stack([20.0 * np.cos(t), 20.0 * np.sin(t), np.full(n, -40.0)])
    axes_notes("first run", gyr, acc, mag, fs)
    estimate(gyr, acc, fs)
    estimate(gyr, acc, fs, mag=mag)
    assert math.isfinite(float(estimate(gyr[:10], acc[:10], fs).quat[-1, 0]))


if __name__ == "__main__":
    import os

    if len(sys.argv) != 2:
        sys.exit(__doc__)
    os.environ["ATTITUDE_FMU_CACHE"] = sys.argv[1]  # before blocks.jit is imported
    compile_kernels()
