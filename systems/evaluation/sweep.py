"""`attitude sweep`: every combination of a parameter grid on every recording, the
dataset's errors (systems.evaluation.evaluate.METRICS) per recording and on average, and
the best combination; a combination chosen on the recordings it is scored on is tuned to
them, so a second set of files can score it (score_on)."""
from __future__ import annotations

import csv
import io
import itertools
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from attitude_fmu.systems.cluster.jobs import Failure, Jobs
from attitude_fmu.systems.evaluation.evaluate import (
    METRICS,
    Setup,
    evaluate_file,
    job_threads,
    method_label,
    recording_names,
)
from attitude_fmu.systems.recordings.output import replaced
from attitude_fmu.systems.recordings.recording import print_notes

BY = {"inclination": "inclination_rmse_deg", "heading": "heading_rmse_deg", "total": "total_rmse_deg"}
TUNING_WARNING = ("attitude: warning: the best combination was chosen on the recordings it is scored on, so its "
                  "figures are tuned to them; to know how it does on others, choose on some files and score it on "
                  "the rest: --score-on FILE...")


MAX_COMBINATIONS = 10_000  # combinations of one sweep, each run on every recording; counted before any is made


def parse_grid(text: str) -> tuple[str, tuple[float, ...]]:
    """NAME=V1,V2,... as (name, values); values are numbers in the parameter's unit."""
    name, sep, values = text.partition("=")
    name = name.strip()
    if not sep or not name or not values.strip():
        raise ValueError(f"expected NAME=V1,V2,... (e.g. omega_g=0.2,0.4,0.8), got {text!r}")
    try:
        numbers = tuple(float(value) for value in values.split(","))
    except ValueError:
        raise ValueError(f"{name}: {values!r} is not a list of numbers separated by commas") from None
    if len(set(numbers)) < len(numbers):
        raise ValueError(f"{name}: {values!r} repeats a value")
    return name, numbers


def combinations(grid) -> list[dict]:
    """Every {name: value} of the grid [(name, values), ...], the last name varying fastest."""
    names = [name for name, _ in grid]
    return [dict(zip(names, values)) for values in itertools.product(*(values for _, values in grid))]


def _with(setup: Setup, params: dict) -> Setup:
    return replace(setup, params={**(setup.params or {}), **params})


def _check(paths, grid, setup: Setup, score_on) -> None:
    names = [name for name, _ in grid]
    if not grid:
        raise ValueError("a sweep needs at least one --grid NAME=V1,V2,...")
    twice = sorted({name for name in names if names.count(name) > 1} | set(names) & set(setup.params or {}))
    if twice:
        raise ValueError(f"{', '.join(twice)} given more than once: a parameter takes one --grid or one --param")
    count = math.prod(len(values) for _, values in grid)
    if count > MAX_COMBINATIONS:
        raise ValueError(f"the grid makes {count} combinations ({' × '.join(str(len(v)) for _, v in grid)}); a sweep "
                         f"runs {MAX_COMBINATIONS} at most: give fewer values, or sweep the parameters in turn")
    for combination in combinations(grid):
        _with(setup, combination).check()
    both = sorted({str(Path(p).resolve()) for p in paths} & {str(Path(p).resolve()) for p in score_on})
    if both:
        raise ValueError(f"{', '.join(both)}: among the files the combination is chosen on and those it is "
                         "scored on; score it on other files")


def _runs(jobs: Jobs, runs, what: str) -> list:
    """evaluate_file without peers for each (path, setup, name) of runs: its result, or a Failure."""
    return jobs.map(evaluate_file, [(str(Path(path).absolute()), setup, False) for path, setup, _ in runs],
                    [name for *_, name in runs], what)


def _mean(errors) -> dict:
    errors = list(errors)
    return {m: float(np.mean([e[m] for e in errors])) for m in METRICS} if errors else {}


def sweep(paths, grid, setup: Setup | None = None, score_on=(), by: str = "inclination", progress: bool = True,
          jobs: Jobs | None = None) -> dict:
    """{"grid": [{"name", "values"}], "results": [{"params", "mean", "recordings"}] (one per
    combination, in combinations' order), "best": {"params", "by", "mean"}} of setup's method
    with each combination of grid [(name, values), ...] (on top of setup.params) on every
    file; errors per recording {name: {metric: degrees}} (names as recording_names), "mean"
    over the recordings every combination completed; best: the lowest mean of metric BY[by]
    (the first of equals); with score_on (files), best also has "score_on": {"recordings",
    "mean"}, its errors there. Each combination × recording is a job of jobs (default: this
    process, a bar when progress); "failed": [{"params", "recording", "error"}] lists the jobs
    that failed, where any did (best is None where no recording completed every
    combination). progress prints how each file was read, where it matters."""
    setup = setup or Setup()
    grid = [(name, tuple(values)) for name, values in grid]
    if by not in BY:
        raise ValueError(f"by must be one of {', '.join(BY)}, got {by!r}")
    _check(paths, grid, setup, score_on)
    jobs = jobs or Jobs(bar=progress)
    setup = replace(setup, threads=job_threads(jobs))
    label = method_label(setup.method, setup.offline)
    combos, names = combinations(grid), recording_names(paths)
    flat = _runs(jobs, [(path, _with(setup, combo), f"{path} with {_text(combo)}")
                        for combo in combos for path in paths], "runs")
    table = [flat[i * len(paths):(i + 1) * len(paths)] for i in range(len(combos))]  # [combination][recording]
    if progress:
        print_notes(note for run in table[0] if not isinstance(run, Failure) for note in run["notes"])
    complete = [j for j in range(len(paths)) if not any(isinstance(row[j], Failure) for row in table)]
    results = [{"params": combo, "mean": _mean(row[j]["table"][label] for j in complete),
                "recordings": {name: run["table"][label] for name, run in zip(names, row)
                               if not isinstance(run, Failure)}}
               for combo, row in zip(combos, table)]
    failed = [{"params": combo, "recording": name, "error": run.message}
              for combo, row in zip(combos, table) for name, run in zip(names, row) if isinstance(run, Failure)]
    out = {"grid": [{"name": name, "values": list(values)} for name, values in grid], "results": results, "best": None}
    if complete:
        best = min(results, key=lambda r: r["mean"][BY[by]])
        out["best"] = {"params": best["params"], "by": BY[by], "mean": best["mean"]}
        if score_on:
            held = _runs(jobs, [(path, _with(setup, best["params"]), str(path)) for path in score_on],
                         "recordings scored")
            scored = {}
            for name, run in zip(recording_names(score_on), held):
                if isinstance(run, Failure):
                    failed.append({"params": best["params"], "recording": name, "error": run.message})
                else:
                    scored[name] = run["table"][label]
            out["best"]["score_on"] = {"recordings": scored, "mean": _mean(scored.values())}
    if failed:
        out["failed"] = failed
    return out


def _text(params: dict) -> str:
    return ", ".join(f"{name}={value:g}" for name, value in params.items())


def format_table(result: dict, method: str) -> str:
    """The sweep as text: one line per combination (mean errors, the best marked *), then the
    best's errors per recording (and on the files it was scored on)."""
    names = [g["name"] for g in result["grid"]]
    recordings = {name for r in result["results"] for name in r["recordings"]}
    best = result["best"]
    lines = [(f"{method} over {len(result['results'])} combinations on {len(recordings)} recordings: RMSE over the "
              "movement phase, degrees, inclination / heading / total; mean over the recordings")]
    width = max(10, *(len(n) + 1 for n in names))
    lines.append("  " + "".join(f"{n:>{width}}" for n in names) + f" {'mean':>24}")

    def cell(errors):
        return "/".join(format(errors[m], ".3f") for m in reversed(METRICS)) if errors else "—"

    for r in result["results"]:
        mark = "*" if best is not None and r["params"] == best["params"] else " "
        lines.append(f"{mark} " + "".join(f"{r['params'][n]:>{width}g}" for n in names) + f" {cell(r['mean']):>24}")
    if best is None:
        lines.append("no recording completed every combination: no best")
        return "\n".join(lines)
    by = next(word for word, metric in BY.items() if metric == best["by"])
    lines.append(f"\nbest (lowest mean {by} RMSE): {_text(best['params'])}")
    chosen = next(r for r in result["results"] if r["params"] == best["params"])
    rows = list(chosen["recordings"].items()) + [("mean", chosen["mean"])]
    if "score_on" in best:
        rows += [(f"{name} (scored on)", errors) for name, errors in best["score_on"]["recordings"].items()]
        rows += [("mean (scored on)", best["score_on"]["mean"])]
    name_width = max(len(name) for name, _ in rows)
    lines += [f"  {name:>{name_width}} {cell(errors):>24}" for name, errors in rows]
    return "\n".join(lines)


def write_csv(result: dict, path) -> None:
    """The sweep as CSV: the grid's names, recording, then METRICS (degrees); one row per
    combination and recording, and a "mean" row after each combination's recordings; written
    as every output is (systems.recordings.output.replaced)."""
    names = [g["name"] for g in result["grid"]]
    text = io.StringIO(newline="")
    out = csv.writer(text)
    out.writerow([*names, "recording", *METRICS])
    for r in result["results"]:
        for recording, errors in [*r["recordings"].items(), ("mean", r["mean"])]:
            out.writerow([*(repr(r["params"][n]) for n in names), recording,
                          *(repr(errors.get(m, math.nan)) for m in METRICS)])
    with replaced(path) as fh:
        fh.write(text.getvalue().encode("utf-8"))


def report(result: dict, method: str, score_on) -> None:
    """Print the table, and the tuning warning where no other files scored the best."""
    print(format_table(result, method))
    if not score_on:
        print(TUNING_WARNING, file=sys.stderr)
