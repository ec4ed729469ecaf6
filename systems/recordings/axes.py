"""Axis conventions of a recording: signed axis maps (--gyr-axes, --acc-axes, --mag-axes)
and a check that the accelerometer and the magnetometer turn as the gyro says they do.

A map such as "y,x,-z" gives each axis of the recording's frame (x, y, z in turn: the frame
of the estimate and of a reference) as a signed axis of one sensor's columns: x is the
file's y, y its x and z its −z (the magnetometer of the MPU-9250 sits so to its gyro and
accelerometer). Maps may be reflections: a left-handed sensor becomes right-handed.

The check: gravity and the earth's field are fixed in the earth, so in the frame integrated
from the gyro (attitude_fmu._core.integrate_rates) a sensor's vector stays put, up to the
motion's acceleration and, for the magnetometer, a hard-iron offset h fixed to the sensor
(fitted per map). Means over windows of WINDOW_S seconds take most of the acceleration out
(a window's mean is its change of velocity over WINDOW_S), and the change of the mean from
one window to the next, where the sensor turned by at least MIN_TURN_RAD between them,
scores a map: the mean square of that change. Every signed map of the vector is scored,
with the gyro as it is and reversed (a clockwise-positive gyro); a map that fits
MISMATCH_RATIO times better than the recording as given and than any other is named with
the flags that apply it, and nothing is said where the given axes' mismatch is below
SIGNIFICANT of the vector's mean square (the few degrees gyro drift and motion make).

A recording longer than CHECK_S is checked on PARTS stretches of CHECK_S/PARTS each, one at the
start of each of as many equal parts of it, joined (the gyro integrated on through a join, whose
pair of windows is left out): the cost stays that of CHECK_S whatever the length (on a 17-minute
recording at 1 kHz the whole of it took a quarter of a second, a fifth of `attitude estimate`'s
time on Parquet), and an axis convention, which holds for the whole recording, shows in any
stretch of it that turns.
"""
from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu._core import integrate_rates
from attitude_fmu.systems.recordings.recording import GYR_UNITS

AXES = "xyz"
WINDOW_S = 2.0  # s over which a measured vector is averaged (in the gyro's frame) before comparing
CHUNK_ROWS = 100_000  # samples whose frame matrices are held at once
MIN_TURN_RAD = 0.3  # windows turning less than this from one to the next tell the maps too little apart
MIN_WINDOWS = 20  # fewer turning pairs of windows than this: no verdict
MISMATCH_RATIO = 4.0  # how much better a map must fit to be named
SIGNIFICANT = 0.01  # nor is a mismatch below this share of the vector's mean square (≈ 6° of direction: drift's)
WINDOW_SAMPLES = 100  # at most about this many samples of a window, evenly spread, enter its means
CHECK_S = 300.0  # s: a longer recording is checked on PARTS stretches of CHECK_S/PARTS, spread over it
PARTS = 3


def parse_axes(text: str) -> np.ndarray:
    """The 3×3 signed permutation of a map "a,b,c" (each a signed x, y or z, every letter
    once): row i takes the file's axis named in place i."""
    parts = [p.strip().lower() for p in str(text).split(",")]
    letters = [p.lstrip("+-") for p in parts]
    if len(parts) != 3 or sorted(letters) != list(AXES) or any(len(p) - len(l) > 1 for p, l in zip(parts, letters)):
        raise ValueError(f"an axis map names x, y and z once each, signed, as x,y,z or y,x,-z; got {text!r}")
    matrix = np.zeros((3, 3))
    for row, (part, letter) in enumerate(zip(parts, letters)):
        matrix[row, AXES.index(letter)] = -1.0 if part.startswith("-") else 1.0
    return matrix


def axes_text(matrix) -> str:
    """The map "a,b,c" of a signed permutation (parse_axes' inverse)."""
    return ",".join(f"{'-' if row[np.argmax(np.abs(row))] < 0 else ''}{AXES[np.argmax(np.abs(row))]}"
                    for row in np.asarray(matrix))


MAPS = [np.diag(signs)[list(order)] for order in itertools.permutations(range(3))
        for signs in itertools.product((1.0, -1.0), repeat=3) if sum(signs) >= 1]
# the 24 signed permutations with at most one axis reversed, identity first: −P turns a
# vector as P does, so of each pair the one that changes fewer signs stands for both


def _orientations(gyr, fs: float, step: int = 1) -> Rotation:
    """The frame after each step-th gyro sample (rad/s, mean rates; integrated over every
    sample) in the frame before the first."""
    quat = np.empty((len(gyr), 4))
    integrate_rates(np.ascontiguousarray(gyr, dtype=float), 1.0 / fs, quat)
    return Rotation.from_quat(quat[step - 1::step], scalar_first=True)


def _step(fs: float) -> int:
    """Every how many samples one enters the window means at fs (Hz): WINDOW_SAMPLES a window."""
    return max(1, _window(fs) // WINDOW_SAMPLES)


def _window(fs: float) -> int:
    """Samples in a window of WINDOW_S seconds at fs (Hz)."""
    return max(1, int(round(WINDOW_S * fs)))


def _window_means(frames: Rotation, vectors, finite, window: int):
    """Per window of `window` samples, over its finite rows: the mean frame matrix Q (B×3×3)
    and the means of Q_ki·v_j (B×3×3×3), a map P's mean in the gyro frame being
    Σ_ij P_ij·(these)_kij; in chunks of about CHUNK_ROWS samples."""
    blocks = len(finite) // window
    count = np.maximum(finite.reshape(blocks, window).sum(axis=1), 1)
    mean_frame, products = np.empty((blocks, 3, 3)), np.empty((blocks, 3, 3, 3))
    step = max(1, CHUNK_ROWS // window)
    for start in range(0, blocks, step):
        b = slice(start, min(blocks, start + step))
        rows = slice(b.start * window, b.stop * window)
        used = finite[rows].reshape(-1, window)[:, :, None]
        q = frames[rows].as_matrix().reshape(-1, window, 3, 3) * used[..., None]
        mean_frame[b] = q.sum(axis=1) / count[b, None, None]
        v = vectors[rows].reshape(-1, window, 3) * used
        products[b] = np.einsum("bwki,bwj->bkij", q, v) / count[b, None, None, None]
    return mean_frame, products


def mismatches(frames: dict, vectors, fs: float, hard_iron: bool = False, maps=MAPS,
               min_turn: float = MIN_TURN_RAD, joins=()) -> dict | None:
    """{(map index in maps, gyro reversed): mean-square mismatch} (units² of vectors) of
    every map of vectors (N×3; rows with a NaN are not used), in frames ({gyro reversed:
    the N frames _orientations integrates from the gyro, or from its negative}): the gyro
    as it is and, where frames has it and unless hard_iron (the magnetometer: its offset is
    fitted per map), reversed; None where fewer than MIN_WINDOWS pairs of windows turn by
    min_turn (rad) or more. joins: the windows that begin a stretch joined to the one before
    (_checked_rows); the pair across each is left out."""
    window = _window(fs)
    blocks = len(vectors) // window
    if blocks < MIN_WINDOWS:
        return None
    n = blocks * window
    finite = np.isfinite(vectors[:n]).all(axis=1)
    vectors = np.where(finite[:, None], vectors[:n], 0.0)
    sampled = finite.reshape(blocks, window).any(axis=1)
    scores = {}
    for reversed_gyro in (False, True) if not hard_iron and True in frames else (False,):
        turned = frames[reversed_gyro][:n]
        centres = turned[window // 2::window]
        turn = (centres[:-1].inv() * centres[1:]).magnitude()
        pairs = np.flatnonzero((turn >= min_turn) & sampled[:-1] & sampled[1:])
        pairs = pairs[~np.isin(pairs + 1, joins)]
        if len(pairs) < MIN_WINDOWS:
            return None
        mean_frame, products = _window_means(turned, vectors, finite, window)
        lever = -(mean_frame[pairs + 1] - mean_frame[pairs])  # −Δ mean(Q)·h: the hard iron's part
        for index, matrix in enumerate(maps):
            means = np.einsum("bkij,ij->bk", products, matrix)
            residual = means[pairs + 1] - means[pairs]
            if hard_iron:
                h = np.linalg.lstsq(lever.reshape(-1, 3), residual.reshape(-1), rcond=None)[0]
                residual = residual - lever @ h
            scores[(index, reversed_gyro)] = float(np.mean(np.sum(residual**2, axis=1)))
    return scores


def axes_note(name: str, what: str, flag: str, unit: str, scores: dict | None, mean_square: float) -> str | None:
    """A note naming the flags that make `what` (measured in unit, of mean_square (unit)²)
    turn as the gyro says, where one map fits MISMATCH_RATIO times better than the
    recording as given and than any other; a vaguer one where the given axes fit that
    much worse than several maps. Nothing where the given mismatch is below SIGNIFICANT
    of mean_square."""
    if scores is None:
        return None
    ranked = sorted(scores, key=scores.get)
    best, runner_up, given = scores[ranked[0]], scores[ranked[1]], scores[(0, False)]
    if ranked[0] == (0, False) or given < max(MISMATCH_RATIO * best, SIGNIFICANT * mean_square):
        return None
    head = (f"{name}: {what} does not turn as the gyro says (mean-square change of its {WINDOW_S:g}-s means "
            f"in the gyro's frame {given:.3g} ({unit})²")
    if runner_up < MISMATCH_RATIO * best:
        return (f"{head}, {best:.3g} with other axes, which this motion does not single out); "
                f"check {flag} and --gyr-axes")
    index, reversed_gyro = ranked[0]
    flags = " ".join(([f"{flag}={axes_text(MAPS[index])}"] if index else [])
                     + (["--gyr-axes=-x,-y,-z"] if reversed_gyro else []))  # "=": a map may begin with "-"
    negative = (f"; {flag}={axes_text(-MAPS[index])}, the same with the sign of {what} reversed, fits as well"
                if index else "")
    return f"{head}); with {flags} it is {best:.3g}: pass that if the file's axes are so{negative}"


def axes_notes(name: str, gyr, acc, mag, fs: float, gyr_unit: str = "rad/s") -> list[str]:
    """The notes of axes_note on a recording's accelerometer and magnetometer (or None),
    or, where the gyro read in another unit than gyr_unit makes them turn as it says,
    gyro_unit_note's instead. The gyro is integrated over every sample, the windows'
    means are taken over every _step(fs)-th; beyond CHECK_S, on _checked_rows' stretches."""
    if len(gyr) // _window(fs) < MIN_WINDOWS:  # too short for a verdict (mismatches): nothing integrated
        return []
    rows, joins = _checked_rows(len(gyr), fs)
    gyr, acc, mag = gyr[rows], acc[rows], None if mag is None else mag[rows]
    step = _step(fs)
    frames = {False: _orientations(gyr, fs, step), True: _orientations(-gyr, fs, step)}  # for both sensors
    acc, mag, fs_used = acc[step - 1::step], None if mag is None else mag[step - 1::step], fs / step
    unit = gyro_unit_note(name, gyr, acc, mag, fs, gyr_unit, frames[False], joins)
    if unit:
        return [unit]
    mean_square = lambda v: float(np.nanmean(np.sum(v**2, axis=1)))
    notes = [axes_note(name, "the accelerometer", "--acc-axes", "m/s²",
                       mismatches(frames, acc, fs_used, joins=joins), mean_square(acc))]
    if mag is not None:
        notes.append(axes_note(name, "the magnetometer", "--mag-axes", "µT",
                               mismatches(frames, mag, fs_used, hard_iron=True, joins=joins), mean_square(mag)))
    return [note for note in notes if note]


def _checked_rows(n: int, fs: float) -> tuple[slice | np.ndarray, list[int]]:
    """(rows, joins) the check runs on in a recording of n samples at fs (Hz): every row where
    it is no longer than CHECK_S; else PARTS stretches of CHECK_S/PARTS each (whole windows of
    every _step(fs)-th sample), one at the start of each of as many equal parts, and joins, the
    window each stretch but the first begins with among the windows of the rows taken."""
    if n <= CHECK_S * fs:
        return slice(None), []
    per_window = _step(fs) * _window(fs / _step(fs))  # samples a window of the rows taken spans
    windows = max(1, int(CHECK_S / PARTS * fs) // per_window)
    starts = np.arange(PARTS) * n // PARTS
    return (starts[:, None] + np.arange(windows * per_window)).ravel(), [k * windows for k in range(1, PARTS)]


def gyro_unit_note(name: str, gyr, acc, mag, fs: float, gyr_unit: str, frames: Rotation, joins=()) -> str | None:
    """A note naming --gyr-unit where, with the gyro (at fs, Hz) read in another unit (a
    factor of 57.3 or 1000 from gyr_unit; frames: those integrated from it as read, at
    every _step(fs)-th sample, as acc and mag are taken), the
    accelerometer and the magnetometer (if any) stay put in the gyro's frame
    MISMATCH_RATIO times better than as read, on every pair of windows whether the gyro
    says they turn or not (the unit that fits best); nothing where the mismatch as read is below SIGNIFICANT of the
    accelerometer's mean square. joins: as mismatches takes them."""
    sensors = [(acc, False)] + ([(mag, True)] if mag is not None else [])
    step = _step(fs)
    score = lambda turned, v, hard_iron: (mismatches({False: turned}, v, fs / step, hard_iron, MAPS[:1], 0.0, joins)
                                          or {}).get((0, False))
    given = [score(frames, v, h) for v, h in sensors]
    if given[0] is None or given[0] < SIGNIFICANT * float(np.nanmean(np.sum(acc**2, axis=1))):
        return None
    candidates = {}  # unit → (scale, fits)
    for unit, factor in GYR_UNITS.items():
        if unit != gyr_unit:
            scale = factor / GYR_UNITS[gyr_unit]
            turned = _orientations(gyr * scale, fs, step)
            candidates[unit] = scale, [score(turned, v, h) for v, h in sensors]
    fitting = {unit: (scale, fits) for unit, (scale, fits) in candidates.items()
               if all(fit is not None and g is not None and MISMATCH_RATIO * fit < g for fit, g in zip(fits, given))}
    if not fitting:
        return None
    unit = min(fitting, key=lambda u: fitting[u][1][0])
    scale, fits = fitting[unit]
    what = "the accelerometer and the magnetometer turn" if mag is not None else "the accelerometer turns"
    return (f"{name}: {what} {scale:.4g} times {'more' if scale > 1 else 'less'} than the gyro read in "
            f"{gyr_unit} says (mean-square change of the accelerometer's {WINDOW_S:g}-s means in the gyro's "
            f"frame {given[0]:.3g} (m/s²)², read in {unit} {fits[0]:.3g}): is the gyro in {unit}? "
            f"pass --gyr-unit {unit}")
