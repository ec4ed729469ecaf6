"""The simulations' one random generator: unit-normal noise streams from a seed.

Philox4x64-10 (Salmon, Moraes, Dror, Shaw 2011, "Parallel random numbers: as easy as 1, 2,
3"; numpy's `Philox` bit generator) is counter based: a block of four 64-bit words is a
function of a 256-bit counter and a 128-bit key alone. Here the key is (seed, stream) and
the counter (k, j, 0, 0): normal i of sample k (k = 0, 1, …) of a stream is lane i mod 4 of
block j = ⌊i/4⌋. The lanes (0, 1) and (2, 3) of a block become two normals each by
Box–Muller: with the uniforms u = ((word >> 12) + ½)·2⁻⁵² in (0, 1),
r = √(−2 ln u₀), z₀ = r·cos(2π·u₁), z₁ = r·sin(2π·u₁).

So a sample's noise depends on nothing but (seed, stream, k): a batch run and a step-by-step
one draw the same numbers, and the C twin (fmu_src/native/sim/noise.c) the same bits. The
streams: MOTION (HumanMotion's random motion, 6 normals a sample), SENSOR (ImuModel's gyro
and accelerometer noise, 6), MAGNETOMETER (ImuModel's magnetometer noise, 3), so that no
stream depends on another's settings.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from attitude_fmu.blocks.jit import kernel

MOTION, SENSOR, MAGNETOMETER = 0, 1, 2  # the streams' numbers, the key's second word
STREAM_WIDTHS = {MOTION: 6, SENSOR: 6, MAGNETOMETER: 3}  # normals a sample of each stream draws

_M0, _M1 = np.uint64(0xD2E7470EE14C6C93), np.uint64(0xCA5A826395121157)  # Philox4x64's multipliers
_W0, _W1 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBB67AE8584CAA73B)  # its key increments (Weyl)
_LOW32, _SHIFT32 = np.uint64(0xFFFFFFFF), np.uint64(32)
_SHIFT12 = np.uint64(12)
_ROUNDS = 10
_UNIT = 2.0**-52
_TWO_PI = 2.0 * math.pi


def check_seed(seed) -> int:
    """seed as an int, or ValueError: a whole number in [0, 2⁶⁴)."""
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= int(seed) < 2**64:
        raise ValueError(f"seed must be a whole number in [0, 2**64), got {seed!r}")
    return int(seed)


@kernel(inline=True)
def _mulhilo(a, b):
    """(high, low) 64-bit words of the 128-bit product a·b (uint64 a, b)."""
    a_lo, a_hi, b_lo, b_hi = a & _LOW32, a >> _SHIFT32, b & _LOW32, b >> _SHIFT32
    lo_lo, hi_lo, lo_hi = a_lo * b_lo, a_hi * b_lo, a_lo * b_hi
    cross = (lo_lo >> _SHIFT32) + (hi_lo & _LOW32) + lo_hi
    return a_hi * b_hi + (hi_lo >> _SHIFT32) + (cross >> _SHIFT32), a * b


@kernel(inline=True)
def philox4x64(c0, c1, c2, c3, k0, k1):
    """The Philox4x64-10 block (4 uint64) of counter (c0, c1, c2, c3) under key (k0, k1)."""
    for r in range(_ROUNDS):
        if r:
            k0 += _W0
            k1 += _W1
        hi0, lo0 = _mulhilo(_M0, c0)
        hi1, lo1 = _mulhilo(_M1, c2)
        c0, c1, c2, c3 = hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0
    return c0, c1, c2, c3


@kernel(inline=True)
def _box_muller(word0, word1):
    r = math.sqrt(-2.0 * math.log((np.float64(word0 >> _SHIFT12) + 0.5) * _UNIT))
    angle = _TWO_PI * ((np.float64(word1 >> _SHIFT12) + 0.5) * _UNIT)
    return r * math.cos(angle), r * math.sin(angle)


@kernel()
def _fill(seed, stream, first, out):
    for row in range(out.shape[0]):
        k = first + np.uint64(row)
        for j in range((out.shape[1] + 3) // 4):
            w0, w1, w2, w3 = philox4x64(k, np.uint64(j), np.uint64(0), np.uint64(0), seed, stream)
            z0, z1 = _box_muller(w0, w1)
            z2, z3 = _box_muller(w2, w3)
            for lane, z in enumerate((z0, z1, z2, z3)):
                i = 4 * j + lane
                if i < out.shape[1]:
                    out[row, i] = z


def normals(seed, stream: int, n: int, width: int | None = None, first: int = 0) -> np.ndarray:
    """n×width unit normals of samples first … first + n − 1 of a stream (MOTION, SENSOR,
    MAGNETOMETER; width: its STREAM_WIDTHS entry unless given) under seed (see the module)."""
    width = STREAM_WIDTHS[stream] if width is None else width
    out = np.empty((n, width))
    with np.errstate(over="ignore"):  # the words wrap modulo 2⁶⁴ (plain Python, without numba)
        _fill(np.uint64(check_seed(seed)), np.uint64(stream), np.uint64(first), out)
    return out


class NoiseStream:
    """A stream sample by sample: next() gives the normals of sample 0, then 1, …, equal to
    the rows of normals(seed, stream, n). Its state is k, the count of samples drawn."""

    def __init__(self, seed, stream: int):
        self.seed, self.stream, self.k = check_seed(seed), stream, 0
        self._key = (np.uint64(self.seed), np.uint64(stream))
        self._row = np.empty((1, STREAM_WIDTHS[stream]))

    def next(self) -> np.ndarray:
        """The normals of sample k (a new array), then k + 1."""
        with np.errstate(over="ignore"):
            _fill(*self._key, np.uint64(self.k), self._row)
        self.k += 1
        return self._row[0].copy()
