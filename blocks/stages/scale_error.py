"""The Wiener filter's gyro scale error chosen from the recording (the batch path, where the
whole recording is at hand; online, the parameter's value holds).

The local densities (blocks.methods.wiener_local) count a gyro error that grows with the
rotation, σ_s·|ω| (scale_error, σ_s; 0.005 a consumer datasheet's figure). A calibrated gyro
has far less, and then the break frequency comes out too high: on a simulated calibrated
sensor (0.05 % scale error) the default gives twice the inclination error of scale_error 0.
Rule: unless scale_error is given, each of SCALE_ERRORS runs the method (on the gyro freed of
its offset as the pipeline frees it), and the one whose estimate of gravity predicts the
accelerometer best PREDICTION_HORIZON_S ahead through the gyro is taken where the recording
shows it (below; blocks/core/stages/prediction.h): with no acceleration but gravity that prediction error is
the estimate's mean-square error plus the gyro's drift over the horizon, the same for every
candidate; the motion's acceleration adds its own power, also the same, and a cross term
where it persists beyond the horizon, which favours a higher break frequency. The candidates
therefore stop at the datasheet's figure: the recording may show a better gyro, never
a worse one. The choice is a statistic of the recording: on 120 s of simulated motion it
takes 0 for a calibrated gyro (0.05 %) and 0.005 for one of 1 %, within 5 % of the best
candidate's error (tests/test_scale_error.py), and a start-up within the first seconds weighs
on it.

Shown, not guessed: the candidates' errors differ by 10⁻⁶ to 10⁻⁴ of their size, about as
much as they scatter from one stretch of motion to the next. The rows scored are cut into
blocks of BLOCK_S (beyond the filter's memory and the horizon), and a candidate below the
default is taken only where its blocks' paired differences from the default's lie more than
SIGNIFICANCE (0.5) standard errors below 0; of those, the one of least error. On 600 s of a
gyro of 0.5 % in vigorous motion (δv 2 m/s/√Hz, 3 rad/s) the plain least error took 0 on a
minute scored (2.54° against 0.005's 1.87°); with the rule the default holds, and it holds
where the least error took 0.002 (up to 8 % above 0.005's error). Calibrated gyros lie 1.5 to
2.3 standard errors below it on a minute and are still taken. On BROAD the rule at 0.5 holds
every mean or betters it; at 1.0 offline inclination lost 0.0004°, at 1.5 0.0025°.

Where: a recording longer than WINDOWS·(WARM_UP_S + SCORED_S) (140 s) is not run whole but on
WINDOWS windows (subset), one after another, each at the start of one of as many equal parts:
the first holds the recording's start, where a rest lets the offset pass (carried from
window to window) find the gyro's offset (windows in the parts' middles missed it, and chose
0.005 for a calibrated gyro with 2 °/s of offset). Each window starts at rest on its first
sample and runs WARM_UP_S with the default alone, unscored: the start's tilt decays with the
filter's time constant, and on BROAD a window's estimate is within 0.3° of the whole run's
after 10 s in 9 windows of 10 (0.01° in half; 7° at the start), while warm-ups of 3 and 5 s
chose worse (inclination 0.84° against 0.70°). Every candidate then goes on from that state
over SCORED_S, scored. The candidates' errors differ by 10⁻⁴ of their size on simulated
motion, so the choice wants minutes scored: 2 × 60 s chose as the whole recording did on the
simulated sensors above (300 s at 40 and 125 Hz, δv 0.1 and 0.3) and held or bettered BROAD's
means; with the rule, 2 × 30 s took 0.002 for the 0.5 % sensor (0.47° against 0.44°), 2 × 45 s
0.001 (0.50°), 4 × 30 s 0.002; 2 × 5 s and 2 × 15 s did not either. The cost is the cap's,
whatever the recording's length: at 100 Hz 14000 rows of the offset pass and one pass over each
window for every candidate (block_errors: the orientation, the local densities and the warm-up
computed once), about 5 ms on one thread; the batch path makes the choice while the gyro-offset
stage runs ahead on the other (blocks.pipeline.causal.run's choose).
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from attitude_fmu import _core

SCALE_ERRORS = (0.0, 0.001, 0.002, 0.005)  # the candidates: the default and below it
PREDICTION_HORIZON_S = 0.5  # s: beyond the white noise's and a tap's correlation, within the filter's memory
WINDOWS = 2  # windows of a recording longer than their total the choice runs on (see above)
WARM_UP_S = 10.0  # s: each window's start, run with the default alone, not scored
SCORED_S = 60.0  # s: each window's rest, run with every candidate and scored
BLOCK_S = 5.0  # s: the rows scored are compared candidate against default block by block
SIGNIFICANCE = 0.5  # standard errors of the blocks' mean difference a candidate must lie below the default by


def applies(method: str, params) -> bool:
    """Whether the rule chooses for method with its own params (a mapping): the Wiener
    filter with local densities and no scale_error given."""
    return "scale_error" not in params and _core.method_kernel(method, dict(params)) == "wiener_local"


def prediction_error(gyr, acc, gravity, fs: float, horizon: float = PREDICTION_HORIZON_S) -> float:
    """The mean of |a(t + h) − R(t → t + h)ᵀ·ĝ(t)|² over the recording (m²/s⁴): gyr N×3 rad/s,
    acc and the estimate gravity N×3 m/s², fs Hz, horizon h s (blocks/core/stages/prediction.h)."""
    return _core.prediction_error(*_rows(gyr, acc, gravity), 1.0 / fs, max(1, round(horizon * fs)))


def prediction_errors(gyr, acc, gravity, fs: float, block: int,
                      horizon: float = PREDICTION_HORIZON_S) -> np.ndarray:
    """prediction_error's means over consecutive blocks of `block` samples predicted (the last
    holds those left over), m²/s⁴."""
    return _core.prediction_errors(*_rows(gyr, acc, gravity), 1.0 / fs, max(1, round(horizon * fs)), block)


def _rows(*arrays) -> list[np.ndarray]:
    return [np.ascontiguousarray(a, dtype=float) for a in arrays]


def subset(n: int, fs: float) -> tuple[np.ndarray, list[tuple[int, int, int]]] | None:
    """(rows, windows) the choice runs on in a recording of n samples at fs Hz: rows, the
    indices of WINDOWS windows, each at the start of one of as many equal parts of the
    recording, one after another; windows, (first, first scored, end) of each within rows.
    None where the windows would take the whole recording (the choice runs on every row)."""
    warm_up, length = round(WARM_UP_S * fs), round((WARM_UP_S + SCORED_S) * fs)
    if n <= WINDOWS * length:
        return None
    starts = np.arange(WINDOWS) * n // WINDOWS
    return ((starts[:, None] + np.arange(length)).ravel(),
            [(i * length, i * length + warm_up, (i + 1) * length) for i in range(WINDOWS)])


def block_errors(warm: _core.Step, candidates: Sequence[_core.Step], gyr, acc, fs: float, windows=None,
                 initial_gravity=None, workers: int = 1) -> np.ndarray | None:
    """The candidates' prediction errors (m²/s⁴) over blocks of BLOCK_S: an array of a row per
    candidate (its Step, the Wiener filter with local densities alone, as SCALE_ERRORS's values
    make it) over gyr (N×3 rad/s, freed of its offset) and acc (N×3 m/s²) at fs Hz, in one pass
    over each window (blocks/core/stages/scale_error.h: the orientation integrated and the local
    densities computed once for all). windows: (first, first scored, end) triples as subset gives
    them, each started at rest on its first row (start_gravity) and run with warm (the method's
    default) up to its first row scored, each candidate on from there; the rows scored, from the
    horizon before them, predicted. None: every candidate over every row from initial_gravity
    (m/s²; None: start_gravity), scored from the horizon on. workers: windows at once on threads
    (the C core runs without Python's lock), the result the same. None where no row is scored."""
    m, block = max(1, round(PREDICTION_HORIZON_S * fs)), max(1, round(BLOCK_S * fs))
    gyr, acc = _rows(gyr, acc)
    spans = [(0, 0, len(gyr))] if windows is None else windows
    given = None if initial_gravity is None or windows is not None else np.asarray(initial_gravity, dtype=float)

    def window(span) -> np.ndarray:
        first, scored, end = span
        return _core.scale_error_errors(warm, list(candidates), gyr[first:end], acc[first:end], scored - first, given,
                                        m, block)

    if workers > 1 and len(spans) > 1:
        with ThreadPoolExecutor(max_workers=min(workers, len(spans))) as pool:
            per_window = list(pool.map(window, spans))
    else:
        per_window = [window(span) for span in spans]
    errors = np.concatenate(per_window, axis=1)
    return errors if errors.shape[1] else None


def choose(per_block: Mapping[float, np.ndarray]) -> tuple[float, dict[float, float]] | None:
    """(the chosen scale error, {candidate: prediction error}) from each of SCALE_ERRORS's
    prediction errors over the same blocks (per_block: candidate → array, m²/s⁴, as block_errors
    gives them). A candidate below the default is taken only where its error is below the
    default's by more than SIGNIFICANCE standard errors of the blocks' paired differences (of
    those, the least error), else the default. None where no error is finite."""
    errors = {c: float(np.mean(per_block[c])) for c in SCALE_ERRORS}
    default = SCALE_ERRORS[-1]
    if not all(math.isfinite(e) for e in errors.values()):
        return (default, errors) if math.isfinite(errors[default]) else None
    better = [c for c in SCALE_ERRORS[:-1] if _below(per_block[c] - per_block[default])]
    return min(better, key=lambda c: (errors[c], -c)) if better else default, errors


def _below(differences: np.ndarray) -> bool:
    """Whether the blocks' paired differences lie below 0 by more than SIGNIFICANCE standard errors."""
    if len(differences) < 2:
        return False
    return float(np.mean(differences)) < -SIGNIFICANCE * float(np.std(differences, ddof=1)) / math.sqrt(len(differences))


def chosen_text(value: float) -> str:
    """The note that says what the rule chose and how to fix it."""
    return (f"scale_error {value:g} chosen from the recording (of {', '.join(f'{c:g}' for c in SCALE_ERRORS)}, the "
            f"one whose estimate predicts the accelerometer best {PREDICTION_HORIZON_S:g} s ahead through the gyro); "
            f"--param scale_error={value:g} holds it, as the FMU's parameter of that name does")
