"""A CSV's time stamps as a uniform grid of samples: the rate, where rows are missing, and
what the stamps' jitter or rounding says.

Without --fs the stamps are read in turn as
1. steps of whole median steps (sample_grid): jitter below a quarter of a step passes, a
   longer step is a run of missing samples, the rate is that of the whole span. Taken where
   no sample is missing.
2. a uniform grid that the stamps round (uniform_line): the least-squares line through the
   stamps against the row number. Where every stamp lies within half the stamps' resolution
   (the coarsest power of ten of seconds of which every step is a whole multiple) of the
   line, the rows are taken as uniform at its slope, no row missing: 90 Hz stamped to 10 ms
   steps by 10 and 20 ms, which 1. reads as 100 Hz with a sample missing every ninth.
3. where 1. refuses the stamps, the same line, accepted where every stamp lies within a
   quarter of a step plus half the resolution of it (jitter on top of rounding).
4. else 1.'s reading (its rows missing filled in) or its refusal.
With --fs the stamps are placed on the grid at that rate (_given_rate) where each lies
within half a step of its grid point (rows missing filled in); else the rows are taken as
uniform at --fs, unless the stamps' own rate differs from it by more than FS_AGREEMENT.
"""
from __future__ import annotations

import numpy as np

from attitude_fmu.systems.recordings.checks import check_rate
from attitude_fmu.systems.recordings.recording import RecordingError

JITTER_NOTE = 0.1  # time stamps off the uniform grid by more than this share of a step are noted
RESOLUTIONS = 10.0 ** -np.arange(10)  # s: the roundings of stamps recognised, 1 s down to 1 ns
FS_AGREEMENT = 0.1  # --fs farther than this share from every rate the stamps give (1., 2.): refused
TIGHT = 8 * np.finfo(float).eps  # relative rounding error of stamps as doubles


def timing(path, name: str, t: np.ndarray, fs: float | None, max_gap: float):
    """(index of each row on a uniform grid, None where no row is missing; rate in Hz; notes)
    of time stamps t (s, finite, at least two) by the rules above; fs: --fs or None."""
    if fs is not None:
        return _given_rate(path, name, t, fs, max_gap)
    problem = None
    try:
        index, rate, off_grid = sample_grid(path, t, max_gap)
    except RecordingError as refused:
        problem = refused
    else:
        if index[-1] + 1 == len(index):
            note = (f"{name}: time stamps up to {off_grid:.0%} of a step off a uniform grid; the samples are taken "
                    f"as uniform at {rate:.6g} Hz")
            return None, rate, [note] if off_grid > JITTER_NOTE else []
    line = uniform_line(t)
    if line is not None:
        slope, departure, resolution = line
        if departure <= resolution / 2 + TIGHT * np.abs(t).max() or \
                problem is not None and departure <= slope / 4 + resolution / 2:
            check_rate(path, 1.0 / slope)
            rounded = f"rounded to {resolution:g} s" if resolution else "not rounded"
            return None, 1.0 / slope, [
                f"{name}: time stamps {rounded}, every one within {departure / slope:.0%} of a step of the uniform "
                f"{1.0 / slope:.6g} Hz grid they {'round' if resolution else 'jitter about'} (the least-squares "
                "line through them): the samples are taken as uniform at that rate, none missing; if samples are "
                "missing instead, give the sensor's rate with --fs HZ to place the stamps on its grid"]
    if problem is not None:
        raise problem
    return index, rate, []


def sample_grid(path, t: np.ndarray, max_gap: float) -> tuple[np.ndarray, float, float]:
    """(index of each row on a uniform grid, its rate in Hz, largest distance of a time
    stamp from the grid in steps). Each time step counts as the whole number of median
    steps nearest to it, so jitter below half a step is tolerated and a longer step is a
    run of missing samples; the rate comes from the whole span, so rounded time stamps
    do not bias it."""
    dt = np.diff(t)
    if np.any(dt <= 0):
        r = int(np.argmax(dt <= 0))
        raise RecordingError(f"{path}: column t must increase strictly (row {r + 2}: {t[r + 1]:g} s after {t[r]:g} s)")
    step = float(np.median(dt))
    count = np.rint(dt / step)
    if np.any(count < 1):
        r = int(np.argmax(count < 1))
        raise RecordingError(f"{path}: column t is irregular: the step to row {r + 2} is {dt[r]:g} s, "
                             f"less than half the usual {step:g} s (if the sample rate does not change, give it with "
                             "--fs HZ)")
    index = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
    fs = float(index[-1] / (t[-1] - t[0]))
    check_rate(path, fs)  # before the gaps, which a wrong time unit makes look long
    off_grid = float(np.max(np.abs(t - t[0] - index / fs)) * fs)
    if off_grid > 0.5:
        raise RecordingError(f"{path}: column t is irregular: time stamps up to {off_grid:.1f} steps off "
                             f"a uniform grid at {fs:.6g} Hz (does the sample rate change? If not, give it with "
                             "--fs HZ)")
    _check_gap(path, t, index, fs, max_gap)
    return index, fs, off_grid


def _check_gap(path, t, index, fs: float, max_gap: float) -> None:
    count = np.diff(index)
    r = int(np.argmax(count))
    if (count[r] - 1) / fs > max_gap:
        raise RecordingError(f"{path}: {int(count[r]) - 1} samples missing after row {r + 1} (t = {t[r]:g} s), "
                             f"a gap of {(count[r] - 1) / fs:g} s, longer than --max-gap {max_gap:g} s; "
                             "split the recording there or raise --max-gap")


def resolution(t: np.ndarray) -> float:
    """The coarsest of RESOLUTIONS (s) of which every step of t is a whole multiple (to 1 % of
    it), 0 where none is: what the stamps were rounded to."""
    dt = np.diff(t)
    for q in RESOLUTIONS:
        if np.all(np.abs(dt / q - np.rint(dt / q)) <= 0.01):
            return float(q)
    return 0.0


def uniform_line(t: np.ndarray) -> tuple[float, float, float] | None:
    """(slope in s per row, largest distance of a stamp from it in s, the stamps'
    resolution in s) of the least-squares line through the stamps t against the row
    number; None where it does not rise."""
    k = np.arange(len(t)) - (len(t) - 1) / 2
    rel = t - t[0]
    slope = float(k @ (rel - rel.mean()) / (k @ k))
    if not slope > 0:
        return None
    departure = float(np.max(np.abs(rel - rel.mean() - slope * k)))
    return slope, departure, resolution(t)


def _given_rate(path, name: str, t: np.ndarray, fs: float, max_gap: float):
    """timing's answer where --fs gives the rate fs (Hz): the stamps placed on its grid if
    each lies within half a step of a grid point (its phase the stamps' circular mean
    within a step), rows missing filled in; else the rows uniform at fs, the stamps kept for
    the output only. Refused where neither the stamps' rate read by sample_grid nor that
    of uniform_line (nor, with neither, rows over span) is within FS_AGREEMENT of fs."""
    line = uniform_line(t)
    rates = [1.0 / line[0]] if line is not None else []
    try:
        rates.insert(0, sample_grid(path, t, np.inf)[1])
    except RecordingError:
        pass
    rates = rates or [(len(t) - 1) / (t[-1] - t[0]) if t[-1] != t[0] else np.inf]
    if not any(abs(rate / fs - 1) <= FS_AGREEMENT for rate in rates):
        raise RecordingError(f"{path}: --fs {fs:g} Hz disagrees with the time stamps' {rates[0]:.6g} Hz by more "
                             f"than {FS_AGREEMENT:.0%}: is --fs or --t-unit wrong?")
    x = (t - t[0]) * fs
    phase = np.angle(np.mean(np.exp(2j * np.pi * x))) / (2 * np.pi)  # the stamps' mean place within a step
    index = np.rint(x - phase)
    departure = x - index
    off_grid = float(departure.max() - departure.min()) / 2
    if np.all(np.diff(index) >= 1) and off_grid < 0.5:
        index = (index - index[0]).astype(np.int64)
        _check_gap(path, t, index, fs, max_gap)
        return index, fs, [f"{name}: --fs {fs:g} Hz given: the time stamps, up to {off_grid:.0%} of a step off "
                           "its grid, place the rows on it"]
    return None, fs, [f"{name}: --fs {fs:g} Hz given: the rows are taken as uniform at it; the time stamps "
                      f"({rates[0]:.6g} Hz, not on its grid) are kept for the output only"]
