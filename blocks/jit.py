"""Compilation settings shared by every per-sample kernel."""
from __future__ import annotations

from numba import njit

# fast-math without the no-NaN/no-Inf assumptions: contraction to FMA, reassociation,
# reciprocal and signed-zero freedom; results stay within rounding of the plain order
FASTMATH = {"contract", "reassoc", "arcp", "nsz"}


def kernel(inline: bool = False):
    """numba.njit with the project's settings, cached on disk; inline=True for inner helpers."""
    return njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always" if inline else "never")
