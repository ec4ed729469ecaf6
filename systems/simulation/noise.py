"""The simulations' one random generator: unit-normal noise streams from a seed.

Philox4x64-10 (Salmon, Moraes, Dror, Shaw 2011, "Parallel random numbers: as easy as 1, 2,
3"; numpy's `Philox` bit generator) is counter based: a block of four 64-bit words is a
function of a 256-bit counter and a 128-bit key alone. Here the key is (seed, stream) and
the counter (k, j, 0, 0): normal i of sample k (k = 0, 1, …) of a stream is lane i mod 4 of
block j = ⌊i/4⌋. The lanes (0, 1) and (2, 3) of a block become two normals each by
Box–Muller: with the uniforms u = ((word >> 12) + ½)·2⁻⁵² in (0, 1),
r = √(−2 ln u₀), z₀ = r·cos(2π·u₁), z₁ = r·sin(2π·u₁).

So a sample's noise depends on nothing but (seed, stream, k): a batch run and a step-by-step
one draw the same numbers, the FMUs too. The generator is the C core's
(systems/simulation/core/noise.c, bound as attitude_fmu._core.normals). The streams: MOTION
(HumanMotion's random motion, 6 normals a sample), SENSOR (ImuModel's gyro and accelerometer
noise, 6), MAGNETOMETER (ImuModel's magnetometer noise, 3), so that no stream depends on
another's settings. A seed is a whole number in [0, 2⁶⁴).
"""
from __future__ import annotations

import numpy as np

from attitude_fmu import _core

MOTION, SENSOR, MAGNETOMETER = _core.MOTION, _core.SENSOR, _core.MAGNETOMETER  # the key's second word
STREAM_WIDTHS = {MOTION: _core.MOTION_WIDTH, SENSOR: _core.SENSOR_WIDTH,
                 MAGNETOMETER: _core.MAGNETOMETER_WIDTH}  # normals a sample of each stream draws


def normals(seed, stream: int, n: int, width: int | None = None, first: int = 0) -> np.ndarray:
    """n×width unit normals of samples first … first + n − 1 of a stream (MOTION, SENSOR,
    MAGNETOMETER; width: its STREAM_WIDTHS entry unless given) under seed (see the module)."""
    out = np.empty((n, STREAM_WIDTHS[stream] if width is None else width))
    _core.normals(seed, stream, first, out)
    return out


class NoiseStream:
    """A stream sample by sample: next() gives the normals of sample 0, then 1, …, equal to
    the rows of normals(seed, stream, n). Its state is k, the count of samples drawn."""

    def __init__(self, seed, stream: int):
        self.seed, self.stream, self.k = _core.check_seed(seed), stream, 0
        self.width = STREAM_WIDTHS[stream]

    def next(self) -> np.ndarray:
        """The normals of sample k (a new array), then k + 1."""
        row = normals(self.seed, self.stream, 1, self.width, self.k)[0]
        self.k += 1
        return row
