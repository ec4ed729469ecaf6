"""Compilation settings shared by every per-sample kernel.

Without numba (an FMU's minimal environment: numpy, scipy, control) the kernels run as
the plain Python they are written in; tests prove both give the same numbers.
"""
from __future__ import annotations

try:
    from numba import njit
except ImportError:  # pragma: no cover - exercised by the FMU's fresh-environment test
    njit = None

# fast-math without the no-NaN/no-Inf assumptions: contraction to FMA, reassociation,
# reciprocal and signed-zero freedom; results stay within rounding of the plain order
FASTMATH = {"contract", "reassoc", "arcp", "nsz"}


def kernel(inline: bool = False):
    """numba.njit with the project's settings, cached on disk; inline=True for inner helpers."""
    if njit is None:
        return lambda function: function
    return njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always" if inline else "never")
