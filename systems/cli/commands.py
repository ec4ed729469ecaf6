"""The `attitude` command line: estimate, evaluate, sweep, plot, table1, verify, ssp, compare, bode, export,
simulate, bench."""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import signal
import sys
import time
from pathlib import Path

import numpy as np

from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.methods.registry import method as known_method
from attitude_fmu.blocks.params import GYRO_NOISE, TIME_S
from attitude_fmu.blocks.pipeline.causal import ESTIMATORS
from attitude_fmu.blocks.stages.timing import ACC_SAMPLES, GYR_SAMPLES, MAX_LATENCY_S
from attitude_fmu.systems.cli.simulate import add_parser as add_simulate_parser
from attitude_fmu.systems.cli.simulate import cmd_simulate
from attitude_fmu.systems.recordings.checks import RATE_RANGE_HZ
from attitude_fmu.systems.recordings.output import STDIO, check_output, interrupting, same_file
from attitude_fmu.systems.recordings.reading import MAX_GAP_S
from attitude_fmu.systems.recordings.recording import (
    ACC_UNITS,
    GYR_UNITS,
    KNOWN_COLUMNS,
    MAG_UNITS,
    MAT_VARIABLES,
    MOVEMENT_COLUMN,
    REF_COLUMNS,
    T_UNITS,
)
from attitude_fmu.systems.recordings.writing import output_name
from attitude_fmu.systems.simulation.recording import MAX_SCALE_ERROR

EXIT_BAD_INPUT = 2
EXIT_CHECK_FAILED = 1
EXIT_SIGNAL = 128  # plus the signal's number, as shells report a process ended by one
TABLE1_TOLERANCE = 0.07  # simulated cells must lie within ±7 % of eq. 50
# plausible ranges of the numeric flags (as blocks.params gives the tuning parameters theirs)
MAX_TIME_S = TIME_S["high"]  # s: durations and gaps; 1e12 s: never
MAX_SAMPLES = 10**8  # samples of a benchmark's recording or a table1 cell: arrays of them take gigabytes
TABLE1_FS = 100.0  # Hz: table1's default rate
MIN_CELL_SAMPLES = 1000  # samples of a table1 cell: fewer give no RMS error worth the name
MIN_BENCH_SAMPLES = 1000
MAX_REPEAT = 1000
MAX_WORKERS = 4096
MAX_SEED = 2**32 - 1
MAX_ACC_NOISE = 10.0  # m/s²/√Hz: an accelerometer's white noise, a hundred times a poor MEMS part's


def _param(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name}: {value!r} is not a number") from None
    return name.strip(), number


def _number(low: float, high: float, unit: str = "", whole: bool = False, above: bool = False,
            below: bool = False):
    """An argparse type for a numeric flag: a finite number (whole: an integer) from low to
    high in unit, each bound included unless above (value > low) or below (value < high);
    anything else is refused with the range, as --param's values are."""
    span = f"{'(' if above else '['}{low:g}, {high:g}{')' if below else ']'}{' ' + unit if unit else ''}"
    kind = "a whole number" if whole else "a number"

    def number(text: str):
        try:
            value = int(text) if whole else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}; plausible {span}") from None
        if not (math.isfinite(value) and (value > low if above else value >= low)
                and (value < high if below else value <= high)):
            raise argparse.ArgumentTypeError(f"{text} is outside the plausible {span}")
        return value

    return number


def _grid(text: str) -> tuple[str, tuple[float, ...]]:
    from attitude_fmu.systems.evaluation.sweep import parse_grid

    try:
        return parse_grid(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _column(text: str) -> tuple[str, str]:
    name, sep, header = text.partition("=")
    if not sep or not header.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=HEADER (e.g. gyr_x=Gyr_X) or NAME=#N (e.g. gyr_x=#3), "
                                         f"got {text!r}")
    if header.strip().startswith("#") and not re.fullmatch(r"#[1-9][0-9]*", header.strip()):
        raise argparse.ArgumentTypeError(f"a column by position is #N, N counted from 1 (e.g. gyr_x=#3), "
                                         f"got {text!r}")
    if name.strip() not in KNOWN_COLUMNS + MAT_VARIABLES:
        raise argparse.ArgumentTypeError(f"{name!r} is not a column read; NAME is one of {', '.join(KNOWN_COLUMNS)} "
                                         f"(a CSV) or {', '.join(MAT_VARIABLES)} (a .mat)")
    return name.strip(), header.strip()


def _axes(text: str) -> str:
    from attitude_fmu.systems.recordings.axes import parse_axes

    try:
        parse_axes(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _method_help() -> str:
    lines = []
    stages = [(f"{m.name}: {m.summary}", m.params) for m in METHODS.values()]
    runs_with = ("--gyro-offset on", "--heading mag and a magnetometer")  # in the order of ESTIMATORS
    stages += [(f"{name} ({when}):", ps) for (name, ps), when in zip(ESTIMATORS.items(), runs_with)]
    for title, params in stages:
        lines.append(title)
        for p in params:
            default = "unset" if p.default is None else f"{p.default:g}"
            lines.append(f"    {p.name} [{p.unit}] (default {default}): {p.doc}; plausible {p.range_text()}")
    return "\n".join(lines)


def _add_real_data_flags(parser) -> None:
    parser.add_argument("--offline", action="store_true",
                        help="forward-backward smoothing of the earth-frame filter (wiener: the Wiener smoother)")
    parser.add_argument("--gyro-offset", default="on", choices=["on", "off"],
                        help="estimate and remove the gyro offset, at rest and while moving (default on)")
    parser.add_argument("--heading", default="mag", choices=["mag", "gyro"],
                        help="heading from the magnetometer when the input has one (default), or the gyro's (6D)")


def _add_method_flags(parser, param_help: str = "a parameter of the method, the gyro-offset or the heading "
                      "estimator, in its unit (attitude estimate -h lists them); repeatable") -> None:
    parser.add_argument("--method", default="wiener", choices=sorted(METHODS),
                        help="the estimator (default wiener; attitude estimate -h says what each is)")
    parser.add_argument("--param", type=_param, action="append", default=[], metavar="NAME=VALUE", help=param_help)


def _add_json_flag(parser, instead_of: str = "the table") -> None:
    parser.add_argument("--json", action="store_true", help=f"print JSON instead of {instead_of}")


def _add_input_flags(parser) -> None:
    parser.add_argument("--fs", type=_number(*RATE_RANGE_HZ, "Hz"),
                        help="sample rate in Hz (required when a CSV has no t column; with one, it places the time "
                             "stamps on its grid, or the rows are taken as uniform at it)")
    unit_help = "; a CSV whose header writes another unit is refused without this flag"
    parser.add_argument("--gyr-unit", choices=list(GYR_UNITS), help=f"gyro unit (default rad/s{unit_help})")
    parser.add_argument("--acc-unit", choices=list(ACC_UNITS),
                        help="accelerometer unit (default m/s2; g and mg in standard gravity, 9.80665 m/s²"
                             f"{unit_help})")
    parser.add_argument("--mag-unit", choices=list(MAG_UNITS), help=f"magnetometer unit (default uT{unit_help})")
    parser.add_argument("--t-unit", choices=list(T_UNITS), help=f"unit of a CSV's t column (default s{unit_help})")
    parser.add_argument("--column", type=_column, action="append", default=[], metavar="NAME=HEADER",
                        help="read the CSV's column HEADER, or #N its N-th column counted from 1, as NAME (t, gyr_x, "
                             "acc_x, mag_x, ref_q_w, movement, ...), or a .mat's variable HEADER as NAME (imu_gyr, "
                             "imu_acc, imu_mag, opt_quat, movement, sampling_rate), for a file with other names; "
                             "repeatable")
    for sensor, what in (("gyr", "gyro"), ("acc", "accelerometer"), ("mag", "magnetometer")):
        parser.add_argument(f"--{sensor}-axes", type=_axes, metavar="MAP",
                            help=f"the {what}'s axes as the file's, signed: y,x,-z takes x from the file's y, y from "
                                 "its x and z from its −z (default x,y,z; one that begins with a minus as "
                                 f"--{sensor}-axes=-x,y,z); a sensor that does not turn as the gyro says is noted "
                                 "with the maps that fit")
    parser.add_argument("--max-gap", type=_number(0.0, MAX_TIME_S, "s"), default=MAX_GAP_S, metavar="S",
                        help="longest run of samples missing from a CSV's time stamps, or of gyro or "
                             "accelerometer values that are not finite, that is filled in (interpolated "
                             f"linearly; default {MAX_GAP_S:g} s)")
    parser.add_argument("--gyr-samples", default="mean", choices=list(GYR_SAMPLES),
                        help="mean: a gyro sample is the mean rate over the sample time before it (default; the "
                             "project's convention); point: the rate at the sample's time (simulations that sample "
                             "ω(t), most IMU drivers), turned into means by the trapezoid")
    parser.add_argument("--acc-samples", default="point", choices=list(ACC_SAMPLES),
                        help="point: an accelerometer sample is the specific force at the sample's time (default; "
                             "the project's convention); mean: its mean over the sample time before it (a "
                             "recording averaged down to a lower rate, a sensor that averages it as the gyro), "
                             "turned to the sample's time by half the step's rotation")
    parser.add_argument("--latency", type=_number(-MAX_LATENCY_S, MAX_LATENCY_S, "s"), default=0.0, metavar="S",
                        help="the IMU's delay behind the motion in seconds (its filters' group delay), counted in "
                             "the means the estimator takes (point samples taken S late, with --gyr-samples point): "
                             "estimates are carried forward over it with the gyro (default 0; attitude evaluate "
                             "measures it against the reference)")


def _add_cluster_flags(parser, jobs: str) -> None:
    parser.add_argument("--workers", type=_number(1, MAX_WORKERS, whole=True), metavar="N",
                        help=f"run the {jobs} on a local Dask cluster of N worker processes (default: the number "
                             "of cores); 1 runs them in this process. Results are those of the serial run, in order")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help=f"run the {jobs} on the Dask cluster whose scheduler is at ADDRESS (e.g. "
                             "tcp://host:8786); its workers need this package and the files at the paths given "
                             "(docs/distributed.md)")


def _jobs(args):
    """The Jobs of --workers and --scheduler; a progress bar unless --json."""
    from attitude_fmu.systems.cluster.jobs import Jobs, default_workers

    if args.scheduler is not None and args.workers is not None:
        raise ValueError("give --workers or --scheduler, not both: a cluster's workers are its own")
    return Jobs(args.workers or default_workers(), args.scheduler, bar=not getattr(args, "json", False))


def _timing(args) -> dict:
    """The sample-timing flags as keyword arguments of estimate, evaluate, plot and check_options."""
    return {"latency": args.latency, "gyr_samples": args.gyr_samples, "acc_samples": args.acc_samples}


def _read_options(args) -> dict:
    names = [name for name, _ in args.column]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise ValueError(f"--column gives {', '.join(twice)} more than once")
    return {"fs": args.fs, "gyr_unit": args.gyr_unit, "acc_unit": args.acc_unit, "mag_unit": args.mag_unit,
            "max_gap": args.max_gap, "t_unit": args.t_unit, "columns": dict(args.column),
            "gyr_axes": args.gyr_axes, "acc_axes": args.acc_axes, "mag_axes": args.mag_axes}


def _add_verify_flags(parser) -> None:
    parser.add_argument("--fmu-dir", default="dist", help="where the FMUs are, built there if missing or built from "
                        "other sources (default dist/)")
    parser.add_argument("--rebuild", action="store_true", help="build the FMUs even if present")
    parser.add_argument("--profile", action="append", help="only this profile (repeatable)")
    parser.add_argument("--method", action="append", help="only this method (repeatable)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="attitude", description="IMU attitude estimators (Rizun's optimal Wiener filter and peers).",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    est = sub.add_parser(
        "estimate", help="estimate attitude over a recording",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="methods and estimators, and their parameters (a name under several sets it in each):\n" + _method_help(),
    )
    est.add_argument("input", nargs="+", help="CSV (t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z[,mag_x,mag_y,mag_z]; "
                     "separated by commas, semicolons or tabs; - for standard input), Parquet (.parquet, the "
                     "same columns) or BROAD .mat; several: each is estimated with the same flags")
    est.add_argument("--out", required=True, help="output CSV: t,q_w,q_x,q_y,q_z,g_x,g_y,g_z (- for standard output; "
                     "a file is replaced once complete, a symbolic link's target written, a named pipe or a device "
                     "such as /dev/null written in place); or a folder that receives NAME.csv for input NAME.csv or "
                     "NAME.mat (with several inputs, made if absent)")
    est.add_argument("--euler", action="store_true",
                     help="add roll_deg,pitch_deg,yaw_deg to the output (Z-Y-X sequence of q, degrees)")
    est.add_argument("--offsets", action="store_true",
                     help="add gyr_offset_x,gyr_offset_y,gyr_offset_z (rad/s, the gyro-offset estimate after each "
                          "sample; 0 with --gyro-offset off) and, with magnetometer heading, mag_offset_x,mag_offset_y,"
                          "mag_offset_z (µT, the hard-iron estimate) and mag_delay (s, the magnetometer's delay "
                          "behind the gyro allowed for)")
    _add_method_flags(est, "parameter of the method, the gyro-offset or the heading estimator, in the unit listed "
                           "below; repeatable")
    _add_input_flags(est)
    _add_real_data_flags(est)

    ev = sub.add_parser("evaluate", help="errors against an optical reference (BROAD .mat, or a CSV with "
                                         f"{','.join(REF_COLUMNS)}[,{MOVEMENT_COLUMN}]), beside vqf and madgwick")
    ev.add_argument("files", nargs="+", metavar="FILE", help="recordings with a reference")
    _add_method_flags(ev)
    _add_json_flag(ev)
    ev.add_argument("--start-in-movement", type=_number(0.0, MAX_TIME_S, "s"), metavar="S",
                    help="begin each recording S seconds into its movement phase: no rest before, "
                         "a first sample in motion (a test of start-up and offset tracking)")
    ev.add_argument("--by", metavar="GROUPS", help="also the means over groups of recordings: 'broad' (BROAD's "
                    "groups, from its trial names) or TABLE.csv:COLUMN (a table of trials: its column name the "
                    "recordings' file names, COLUMN their group)")
    _add_reference_flags(ev)
    _add_input_flags(ev)
    _add_real_data_flags(ev)
    _add_cluster_flags(ev, "recordings")

    sw = sub.add_parser("sweep", help="every combination of a parameter grid on every recording with a reference: "
                                      "errors per recording and on average, and the best combination")
    sw.add_argument("files", nargs="+", metavar="FILE", help="recordings with a reference, on which every "
                    "combination is run")
    sw.add_argument("--method", default="wiener", choices=sorted(METHODS),
                    help="the estimator whose parameters the grid sets (default wiener)")
    sw.add_argument("--grid", type=_grid, action="append", default=[], metavar="NAME=V1,V2,...", required=True,
                    help="values of a parameter of the method, the gyro-offset or the heading estimator, in its "
                         "unit (attitude estimate -h lists them); repeatable: every combination is run")
    sw.add_argument("--param", type=_param, action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter held at VALUE in every combination; repeatable")
    sw.add_argument("--score-on", nargs="+", default=[], metavar="FILE",
                    help="other recordings on which the best combination is scored (a combination chosen on the "
                         "recordings it is scored on is tuned to them)")
    sw.add_argument("--by", default="inclination", choices=["inclination", "heading", "total"],
                    help="the mean RMSE the best combination has the lowest of (default inclination)")
    out = sw.add_mutually_exclusive_group()
    _add_json_flag(out)
    out.add_argument("--csv", metavar="OUT", help="also write every combination's errors per recording to OUT")
    sw.add_argument("--start-in-movement", type=_number(0.0, MAX_TIME_S, "s"), metavar="S",
                    help="begin each recording S seconds into its movement phase")
    _add_input_flags(sw)
    _add_real_data_flags(sw)
    _add_cluster_flags(sw, "combinations × recordings")

    pl = sub.add_parser("plot", help="a recording's error over time and its spectrum against eq. 42 (PNG); "
                        "without a reference, the estimate's angles over time")
    pl.add_argument("file", metavar="FILE", help="a recording, as attitude estimate reads it")
    pl.add_argument("--out", required=True, help="PNG to write")
    _add_method_flags(pl)
    _add_reference_flags(pl)
    _add_real_data_flags(pl)
    _add_input_flags(pl)

    t1 = sub.add_parser("table1", help="Rizun's Table 1: analytic (eq. 50) and simulated RMS attitude error")
    _add_json_flag(t1)
    t1.add_argument("--duration", type=_number(0.0, MAX_TIME_S, "s", above=True), default=20000.0,
                    help="simulated seconds per cell (default 20000)")
    t1.add_argument("--fs", type=_number(*RATE_RANGE_HZ, "Hz"), default=TABLE1_FS,
                    help=f"simulation sample rate, Hz (default {TABLE1_FS:g})")
    t1.add_argument("--seed", type=_number(0, MAX_SEED, whole=True), default=0,
                    help="random seed: cell j of row i simulates with seed + 10·i + j "
                    "(default 0)")
    _add_cluster_flags(t1, "cells")

    vf = sub.add_parser("verify", help="co-simulate every profile with every estimator as FMUs; exit 1 if a bound is missed")
    _add_json_flag(vf)
    _add_verify_flags(vf)
    _add_cluster_flags(vf, "co-simulations (profile × method)")
    vf.add_argument("--python", action="store_true", help="also run the pythonfmu chain and hold its estimator "
                    "outputs to the native chain's within 1e-9 (minutes instead of seconds)")
    vf.add_argument("--master", choices=("gauss-seidel", "jacobi"), default="gauss-seidel",
                    help="the co-simulation master: gauss-seidel (the default: each FMU takes its sources' outputs of "
                    "the same step) or jacobi (as OMSimulator and libcosim step: outputs of the step before, inputs "
                    "set in Initialization Mode, time summed with a last step of the shortfall; the estimator's "
                    "inputs 2 steps late, taken off against the truth)")
    vf.add_argument("--platforms", default="host", help="the native FMUs hold these platforms' binaries too, cross-"
                    "compiled where missing (needs ziglang): host (the default), all, or a comma-separated list of "
                    "x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin; the chain runs "
                    "the x86_64-linux one (glibc 2.17) where it is asked for")
    ss = sub.add_parser("ssp", help="write verify's SSP of each profile × method, the FMUs inside, for other tools")
    ss.add_argument("--out", type=Path, required=True, help="folder for the files <profile>_<method>.ssp")
    _add_verify_flags(ss)
    chain = ss.add_mutually_exclusive_group()
    chain.add_argument("--native", dest="chain", action="store_const", const="native", default="native",
                       help="the FMUs in C (DIR/native; default)")
    chain.add_argument("--python", dest="chain", action="store_const", const="python", help="the pythonfmu FMUs")
    ss.add_argument("--fmi-version", choices=("2.0", "3.0"), default="2.0",
                    help="the FMUs' FMI version (default 2.0); 3.0: the native FMI 3.0 FMUs (DIR/native/fmi3)")

    cp = sub.add_parser("compare", help="every estimator and the peers vqf, madgwick on every motion profile")
    cp.add_argument("--profile", action="append", help="only this profile (repeatable)")
    _add_json_flag(cp)
    cp.add_argument("--gyro-noise", type=_number(0.0, math.degrees(GYRO_NOISE["high"]), "°/s/√Hz"), default=0.02,
                    metavar="DEG_S_RTHZ",
                    help="the simulated gyro's white noise, °/s/√Hz (default 0.02)")
    cp.add_argument("--acc-noise", type=_number(0.0, MAX_ACC_NOISE, "m/s²/√Hz"), default=0.002, metavar="M_S2_RTHZ",
                    help="the simulated accelerometer's white noise, m/s²/√Hz (default 0.002)")
    cp.add_argument("--gyro-scale-error", type=_number(0.0, MAX_SCALE_ERROR, below=True), default=0.0,
                    metavar="FRACTION",
                    help="rms of each element of the simulated gyro's scale-factor and misalignment matrix, "
                         "drawn once (1 = 100 %%; default 0, an ideal scale)")
    cp.add_argument("--offline", action="store_true",
                    help="also the smoothers: every earth-frame method offline, and vqf's offline estimate")
    _add_cluster_flags(cp, "profiles")

    bd = sub.add_parser("bode", help="frequency response of a method's filter (tseng: also Tseng Figs. 6-7)")
    bd.add_argument("--method", default="tseng", choices=sorted(m for m in METHODS if METHODS[m].is_sensor_frame),
                    help="a method with an earth-frame filter (default tseng)")
    bd.add_argument("--out", help="PNG to write (default bode_METHOD.png)")

    ex = sub.add_parser("export", help="a python-control system (a diagram of state spaces, transfer functions and "
                        "the project's blocks) as a native FMU in C",
                        description="Export NAME of FILE.py (a python-control system, or a function of no arguments "
                        "returning one or (system, x0)) as a co-simulation FMU: after the doStep that ends at t[k+1], "
                        "with the inputs of sample k held over it, the outputs are the system's at sample k as "
                        "control.input_output_response computes them.")
    ex.add_argument("system", metavar="FILE.py:NAME", help="the system to export")
    ex.add_argument("--out", type=Path, required=True, metavar="PATH.fmu", help="the FMU to write")
    ex.add_argument("--step", type=_number(0.0, MAX_TIME_S, "s", above=True),
                    help="the DefaultExperiment's step (s): a continuous system's communication step (default 0.01 "
                         "s); a discrete one's must be its dt")
    ex.add_argument("--fmi-version", choices=("2.0", "3.0"), default="2.0", help="FMI version (default 2.0)")
    ex.add_argument("--platforms", default="host", help="binaries for: host (the default), all, or a comma-separated "
                    "list of x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin (needs ziglang)")
    ex.add_argument("--name", help="the FMU's model identifier (default the system's name)")
    ex.add_argument("--backend", choices=("native", "python"), default="native",
                    help="native: C, no Python where it runs (default); python: pythonfmu, any discrete system, "
                         "Python functions included (needs a Python with attitude_fmu where it runs)")
    ex.add_argument("--scalar-parameters", action="store_true",
                    help="FMI 3.0: one scalar parameter per matrix entry (A[0,1]) instead of an array per matrix, for "
                         "importers that read every Float64 as a scalar (OMSimulator); FMI 2.0 has scalars only")

    add_simulate_parser(sub, _number, _param)

    bn = sub.add_parser("bench", help="samples per second of the batch estimator, vqf and ahrs Madgwick")
    _add_json_flag(bn, "the lines")
    bn.add_argument("--samples", type=_number(MIN_BENCH_SAMPLES, MAX_SAMPLES, whole=True),
                    help="samples of the recording (default 100000; with --io 1000000)")
    bn.add_argument("--fmu", action="store_true",
                    help="per-step cost of AttitudeEstimator.fmu against a no-op FMU of the same interface, pythonfmu "
                         "and native, under fmpy; and of the native against the pythonfmu one in a C host")
    bn.add_argument("--io", action="store_true",
                    help="attitude estimate end to end on a 9D recording at 1 kHz (--samples, default here 1000000), "
                         "CSV to CSV and Parquet to Parquet, against pandas read_csv + vqf 9D + pandas to_csv; "
                         "peak memory (needs pip install 'attitude-fmu[bench]')")
    bn.add_argument("--repeat", type=_number(1, MAX_REPEAT, whole=True), default=10,
                    help="interleaved rounds; each method's best run counts "
                    "(default 10; with --io at most 3)")
    bn.add_argument("--workers", type=_number(1, MAX_WORKERS, whole=True), metavar="N",
                    help="instead: wall time of attitude evaluate on --recordings and of attitude table1 on a local "
                         "cluster of N worker processes against one process, start-up included, and their ratio")
    bn.add_argument("--recordings", nargs="+", default=[], metavar="FILE", help="with --workers: evaluate's files")
    bn.add_argument("--duration", type=_number(0.0, MAX_TIME_S, "s", above=True), default=20000.0,
                    help="with --workers: table1's simulated seconds per cell (default 20000)")
    return parser


def _check_out(path, source=None, figure: bool = False) -> None:
    """Refuse, before any work is done, an output file that cannot be written or that is
    the input file source (systems.recordings.output.check_output); a figure (figure=True)
    also one in a format matplotlib cannot write."""
    check_output(path, () if source is None else (source,))
    if figure:
        from matplotlib.figure import Figure

        formats = Figure().canvas.get_supported_filetypes()
        if str(path) == STDIO or Path(path).suffix.lstrip(".").lower() not in formats:
            raise ValueError(f"cannot write {path}: a figure's file name ends in one of "
                             f"{', '.join('.' + f for f in sorted(formats))} (e.g. .png)")


def _estimate_outputs(inputs, out) -> list:
    """The output file of each input: out itself for one input, unless out is a folder; for
    several, out is a folder (made here if absent, its parent must exist). In a folder,
    input NAME.ext gives out/NAME.csv (NAME.parquet for a Parquet input). Refused before
    any work: two inputs of one name, an output that is an input."""
    if len(inputs) == 1 and not Path(out).is_dir():
        _check_out(out, inputs[0])
        return [out]
    folder = Path(out)
    if str(out) == STDIO or folder.exists() and not folder.is_dir():
        raise ValueError(f"cannot write into {out}: with {len(inputs)} inputs --out is a folder, and it is "
                         f"{'standard output' if str(out) == STDIO else 'a file'}")
    stems = [Path(path).stem for path in inputs]
    repeated = sorted({stem for stem in stems if stems.count(stem) > 1})
    if repeated:
        raise ValueError(f"inputs share the names {', '.join(repeated)}: their outputs in {out} would overwrite "
                         "each other; estimate them in separate runs")
    if not folder.is_dir():
        _check_out(folder)  # the folder to make: its parent must exist
    outputs = [folder / output_name(path) for path in inputs]
    for path in outputs:
        if any(same_file(path, source) for source in inputs):
            raise ValueError(f"cannot write {path}: it is an input; choose another --out")
        if path.is_dir():
            raise ValueError(f"cannot write {path}: it is a folder")
        if folder.is_dir():
            check_output(path)
    folder.mkdir(exist_ok=True)
    return outputs


def cmd_estimate(args) -> int:
    """Each input in turn; one that fails is reported and the others still run (exit 2)."""
    from attitude_fmu.blocks.pipeline.batch import check_options

    check_options(args.method, dict(args.param), args.offline, args.gyro_offset == "on", args.heading == "mag",
                  **_timing(args))
    outputs = _estimate_outputs(args.input, args.out)
    failed = []
    for number, (path, out) in enumerate(zip(args.input, outputs), 1):
        prefix = f"[{number}/{len(outputs)}] " if len(outputs) > 1 else ""
        try:
            _estimate_one(args, path, out, prefix)
        except (ValueError, OSError, RuntimeError) as exc:
            if len(outputs) == 1:
                raise
            print(f"attitude: {prefix}error: {exc}", file=sys.stderr, flush=True)
            failed.append(path)
    if failed:
        written = f"the others are in {args.out}" if len(failed) < len(outputs) else "none was written"
        print(f"attitude: error: {len(failed)} of {len(outputs)} inputs failed ({', '.join(failed)}); {written}",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


def _estimate_one(args, path, out, prefix: str) -> None:
    from attitude_fmu.blocks.pipeline.batch import estimate
    from attitude_fmu.systems.recordings.checks import field_norm_note
    from attitude_fmu.systems.recordings.reading import read_recording
    from attitude_fmu.systems.recordings.recording import print_notes
    from attitude_fmu.systems.recordings.writing import write_estimate

    clock = time.perf_counter()

    def progress(text):  # reading and writing take about 3 s per million samples
        nonlocal clock
        now = time.perf_counter()
        print(f"attitude: {prefix}{text} ({now - clock:.1f} s)", file=sys.stderr, flush=True)
        clock = now

    rec = read_recording(path, **_read_options(args))
    filled = 0 if rec.filled is None else int(rec.filled.sum())  # rows put into gaps, not the input's
    progress(f"read {len(rec.gyr) - filled} samples at {rec.fs:g} Hz from {path}"
             + (f", and filled {filled} more into the gaps of its time stamps" if filled else ""))
    print_notes(rec.notes + ([field_norm_note(rec)] if args.heading == "mag" else []))
    result = estimate(rec.gyr, rec.acc, rec.fs, args.method, dict(args.param), offline=args.offline,
                      gyro_offset=args.gyro_offset == "on", mag=rec.mag if args.heading == "mag" else None,
                      **_timing(args))
    progress(f"estimated with {args.method}{' --offline' if args.offline else ''}")
    rows = slice(None) if rec.filled is None else ~rec.filled  # the input's rows, not those filled in
    extra = {}
    if args.offsets:
        extra["gyr_offset"] = np.zeros_like(rec.gyr) if result.offset is None else result.offset
        if result.mag_offset is not None:
            extra["mag_offset"], extra["mag_delay"] = result.mag_offset, result.mag_delay
    write_estimate(out, rec.t[rows], result.quat[rows], result.up[rows], euler=args.euler,
                   extra={name: values[rows] for name, values in extra.items()})
    progress(f"wrote {'standard output' if str(out) == STDIO else out}")
    if result.offset is not None:
        print(f"attitude: {prefix}gyro offset estimate at the end "
              f"({', '.join(f'{v:.3f}' for v in np.degrees(result.offset[-1]))}) °/s", file=sys.stderr)
    if result.chosen is not None:
        from attitude_fmu.blocks.stages import heading_choice, scale_error

        for name, value in result.chosen.items():
            text = scale_error.chosen_text(value) if name == "scale_error" else heading_choice.chosen_text(value)
            print(f"attitude: {prefix}{text}", file=sys.stderr)
    if result.mag_accepted is not None:
        sampled = np.isfinite(rec.mag).all(axis=1)  # rows where a slower magnetometer has a sample
        print(f"attitude: {prefix}magnetometer samples used for heading "
              f"{100 * result.mag_accepted[sampled].mean():.0f} %, hard-iron offset at the end "
              f"({', '.join(f'{v:.1f}' for v in result.mag_offset[-1])}) µT; {_mag_delay_text(result)}",
              file=sys.stderr)
    if result.lever_arm is not None:
        print(f"attitude: {prefix}lever arm taken: the sensor turns about a fixed centre from which it sits at "
              f"({', '.join(f'{v:.3f}' for v in result.lever_arm.position)}) m; the accelerometer was freed of "
              f"that turn's accelerations ({100 * result.lever_arm.explained:.1f} % of the specific force "
              f"beside gravity)", file=sys.stderr)
    if result.mag_soft_iron is not None:
        fitted = result.mag_soft_iron
        print(f"attitude: {prefix}soft iron taken: the field turned onto a sphere by an ellipsoid (centre "
              f"{', '.join(f'{v:.1f}' for v in fitted.centre)} µT, which leaves "
              f"{100 * fitted.variance / fitted.sphere_variance:.0f} % of the sphere's mean square distance)",
              file=sys.stderr)


def _mag_delay_text(result) -> str:
    delay, source = 1e3 * result.mag_delay[-1], result.mag_delay_source
    if source == "given":
        return f"its delay behind the gyro {delay:.1f} ms (given)"
    if delay == 0.0:
        return f"no delay behind the gyro that the recording shows{' so far' if source == 'online' else ''} " \
               "(--param mag_delay=S sets one)"
    how = "estimated online, at the end" if source == "online" else "measured from the whole recording"
    return f"its delay behind the gyro {delay:.1f} ms ({how}; --param mag_delay=S sets it)"


def _add_reference_flags(parser) -> None:
    """--reference-north and --align: how a reference is brought to the estimate's frames."""
    parser.add_argument("--reference-north", choices=["other", "magnetic"], default="other",
                        help="other (default): the reference's north is its own, and each estimate's constant "
                             "heading offset from it is removed before the heading error; magnetic: the reference "
                             "is aligned to magnetic north (BROAD's): the offset counts")
    parser.add_argument("--align", action="store_true",
                        help="bring the reference into the IMU's frames first: its lag, the rotation between the "
                             "IMU and the reference's body, its up axis and heading offset, found from the angular "
                             "rates and reported (JSON: alignment); refused where the rates do not match")


def _table_labels(result) -> list[str]:
    """Every label of any recording's table, in the order they first appear."""
    return list(dict.fromkeys(label for table in result["recordings"].values() for label in table))


def cmd_evaluate(args) -> int:
    from attitude_fmu.systems.evaluation.evaluate import METRICS, evaluate

    try:
        import ahrs  # noqa: F401
        import vqf  # noqa: F401
    except ImportError as exc:
        raise RuntimeError(f"attitude evaluate compares with vqf and ahrs ({exc}); "
                           "install them with: pip install 'attitude-fmu[peers]'") from None
    with _jobs(args) as jobs:
        result = evaluate(args.files, args.method, dict(args.param), args.offline, args.gyro_offset == "on",
                          args.heading == "mag", start_in_movement=args.start_in_movement,
                          read_options=_read_options(args), **_timing(args), jobs=jobs, align=args.align,
                          reference_north=args.reference_north, by=args.by)
    status = EXIT_BAD_INPUT if "failed" in result else 0
    if args.json:
        print(json.dumps(result, indent=2))
        return status
    if not result["recordings"]:
        return status
    labels = _table_labels(result)
    lags = {name: a["lag_s"] for name, a in result["alignment"].items()} if args.align else result["imu_latency_s"]
    north = "magnetic north kept" if args.reference_north == "magnetic" else "each one's heading offset removed"
    print(f"RMSE over the movement phase, degrees: inclination / heading / total ({north}); "
          f"{'the reference' if args.align else 'the IMU'} lags {'the IMU' if args.align else 'the reference'}, ms")
    print(f"{'recording':>45} " + " ".join(f"{label:>22}" for label in labels) + f" {'lag':>6}")

    def cells(table):  # "—" where a table lacks the label (a file without a magnetometer has no vqf_9d)
        return " ".join(f"{'/'.join(format(table[l][m], '.2f') for m in reversed(METRICS)) if l in table else '—':>22}"
                        for l in labels)

    for name, table in result["recordings"].items():
        lag = lags.get(name)
        print(f"{name:>45} {cells(table)} {'     —' if lag is None else format(1e3 * lag, '6.2f')}")
    print(f"{'mean':>45} {cells(result['mean'])}")
    for group, found in result.get("by_group", {}).items():
        name = f"{group} ({found['trials']})"
        print(f"{name:>45} {cells(found['mean'])}")
    if len(labels) > len(result["mean"]):
        print("—: a column not every recording has is left out of the mean (vqf_9d needs a magnetometer)")
    for name, found in result.get("alignment", {}).items():
        print(f"{name}: aligned: lag {found['lag_s']:+.4f} s, mounting [w, x, y, z] "
              f"{', '.join(format(c, '.4f') for c in found['mounting_quat'])}, up {found['up_axis']}, heading offset "
              f"{found['heading_offset_deg']:.2f}°, misfit {found['misfit']:.3f}")
    if "chosen" in result:
        from attitude_fmu.blocks.stages.scale_error import PREDICTION_HORIZON_S

        print(f"scale_error chosen from each recording (the best prediction of the accelerometer "
              f"{PREDICTION_HORIZON_S:g} s ahead; --param scale_error=V holds one): "
              + ", ".join(f"{name} {found['scale_error']:g}" for name, found in result["chosen"].items()))
        heading = {name: found["tau_heading"] for name, found in result["chosen"].items() if "tau_heading" in found}
        if heading:
            print("tau_heading chosen from each recording (from the gyro the scale_error choice found; --param "
                  "tau_heading=V holds one): " + ", ".join(f"{name} {tau:.4g} s" for name, tau in heading.items()))
    if "mag_used" in result:
        print("magnetometer samples the heading used over the movement (the guard refused the rest): "
              + ", ".join(f"{name} {100 * used:.0f} %" for name, used in result["mag_used"].items()))
    return status


def cmd_sweep(args) -> int:
    from attitude_fmu.systems.evaluation.evaluate import Setup
    from attitude_fmu.systems.evaluation.sweep import report, sweep, write_csv

    for source in (args.files + args.score_on) if args.csv else ():
        _check_out(args.csv, source)
    setup = Setup(args.method, dict(args.param), args.offline, args.gyro_offset == "on", args.heading == "mag",
                  args.start_in_movement, _read_options(args), **_timing(args))
    with _jobs(args) as jobs:
        result = sweep(args.files, args.grid, setup, args.score_on, args.by, jobs=jobs)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        report(result, args.method, args.score_on)
    if args.csv:
        write_csv(result, args.csv)
        print(f"attitude: wrote {args.csv}", file=sys.stderr)
    return EXIT_BAD_INPUT if "failed" in result or result["best"] is None else 0


def cmd_plot(args) -> int:
    from attitude_fmu.systems.cli.plots import plot_recording

    _check_out(args.out, args.file, figure=True)
    result = plot_recording(args.file, args.out, args.method, dict(args.param), args.offline,
                            args.gyro_offset == "on", args.heading == "mag", _read_options(args), **_timing(args),
                            align=args.align, reference_north=args.reference_north)
    if not result:
        print(f"attitude: wrote {args.out} (no reference to measure errors against: the estimate's roll, pitch "
              "and yaw over time)", file=sys.stderr)
        return 0
    heading = f", heading RMSE {result['heading_rmse_deg']:.2f}°" if "heading_rmse_deg" in result else ""
    print(f"attitude: wrote {args.out} (inclination RMSE {result['inclination_rmse_deg']:.2f}°{heading})",
          file=sys.stderr)
    return 0


def cmd_table1(args) -> int:
    from attitude_fmu.systems.evaluation.experiments import table1

    _check_cell_samples(args.duration, args.fs)
    with _jobs(args) as jobs:
        rows = table1(duration=args.duration, fs=args.fs, seed=args.seed, jobs=jobs)
    failed = [
        (row, cell) for row in rows for cell in row["cells"]
        if cell["simulated_deg"] is not None and abs(cell["simulated_deg"] / cell["analytic_deg"] - 1) > TABLE1_TOLERANCE
    ]
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print("Rizun (2008) Table 1: RMS attitude error, analytic (eq. 50) | simulated, degrees "
              f"(g = 9.8 m/s², {args.duration:g} s per cell at {args.fs:g} Hz)")
        print(f"{'δn °/s/√Hz':>11} {'δv m/s/√Hz':>11} {'1/ω_g s':>8}  "
              + "  ".join(f"{'a=' + format(c['a'], 'g'):>16}" for c in rows[0]["cells"]))
        for row in rows:
            cells = "  ".join(f"{c['analytic_deg']:7.3f} | "
                              + ("failed" if c["simulated_deg"] is None else f"{c['simulated_deg']:6.3f}")
                              for c in row["cells"])
            print(f"{row['delta_n_deg']:11.2f} {row['delta_v']:11.1f} {row['inv_omega_g_s']:8.2f}  {cells}")
    if jobs.failed:
        return EXIT_BAD_INPUT
    if failed:
        print(f"attitude: {len(failed)} simulated cells off eq. 50 by more than ±{TABLE1_TOLERANCE:.0%}",
              file=sys.stderr)
        return EXIT_CHECK_FAILED
    return 0


def _check_cell_samples(duration: float, fs: float) -> None:
    """Refuse a table1 cell of duration s at fs Hz with fewer than MIN_CELL_SAMPLES or more
    than MAX_SAMPLES samples."""
    samples = duration * fs
    if not MIN_CELL_SAMPLES <= samples <= MAX_SAMPLES:
        raise ValueError(f"--duration {duration:g} s at {fs:g} Hz gives {samples:.3g} samples per table1 cell; "
                         f"the plausible range is [{MIN_CELL_SAMPLES:g}, {MAX_SAMPLES:g}]")


def _verified_fmus(args) -> Path:
    """The FMU folder, built where needed, once the profiles and methods asked for are known."""
    from attitude_fmu.systems.fmi.build import ensure_built
    from attitude_fmu.systems.fmi.verify import SCENARIOS

    for name in args.profile or []:
        if name not in SCENARIOS:
            raise ValueError(f"unknown profile {name!r}; verified profiles: {', '.join(SCENARIOS)}")
    for name in args.method or []:
        known_method(name)  # refuses unknown names
    return ensure_built(args.fmu_dir, args.rebuild, log=lambda m: print(f"attitude: {m}", file=sys.stderr))


def cmd_ssp(args) -> int:
    from attitude_fmu.systems.fmi.verify import write_verify_ssps

    if args.fmi_version == "3.0" and args.chain == "python":
        raise ValueError("the pythonfmu FMUs are FMI 2.0 only: --fmi-version 3.0 takes the native ones")
    chain = "fmi3" if args.fmi_version == "3.0" else args.chain
    with interrupting():  # SIGTERM or SIGHUP: the SSP being written and its temporary file removed
        for path in write_verify_ssps(_verified_fmus(args), args.out, args.profile, args.method, chain):
            print(path)
    return 0


def cmd_verify(args) -> int:
    from attitude_fmu.systems.fmi.verify import verify
    from attitude_fmu.systems.simulation.motion import PROFILES

    fmu_dir = _verified_fmus(args)
    with _jobs(args) as jobs:
        rows = verify(fmu_dir, args.profile, args.method, python=args.python, jobs=jobs, platforms=args.platforms,
                      master=args.master)
    if args.json:
        print(json.dumps({"rows": rows}, indent=2))
    else:
        print(f"{'profile':>15} {'method':>14} {'rms °':>8} {'max °':>8} {'mean °':>9}  {'bound °':>8} {'on':>4}  result"
              f"  {'native Δ':>9}")
        for r in rows:
            bound = "       —" if r["bound_deg"] is None else f"{r['bound_deg']:8.3g}"
            result = "report" if r["bound_deg"] is None else "pass" if r["pass"] else "FAIL"
            native = "        —" if r["native_max_diff"] is None else \
                f"{r['native_max_diff']:9.2g}" + ("" if r["native_valid_equal"] else " (valid differs)")
            print(f"{r['profile']:>15} {r['method']:>14} {r['rms_deg']:8.3g} {r['max_deg']:8.3g} {r['mean_deg']:9.3g}"
                  f"  {bound} {r['metric']:>4}  {result:<6}  {native}")
        print("profiles: " + "; ".join(f"{n}: {PROFILES[n].summary}" for n in dict.fromkeys(r["profile"] for r in rows)))
        print(f"chain: {rows[0]['chain'] if rows else '—'}; native Δ: the largest difference between the estimator "
              "outputs (Euler angles aside) of the native chain (FMUs in C) and the pythonfmu one, with the same "
              "seeds (— without --python)")
    if jobs.failed:
        return EXIT_BAD_INPUT
    failed = [r for r in rows if not r["pass"]]
    if failed:
        print(f"attitude: {len(failed)} of {len(rows)} rows missed their bound", file=sys.stderr)
        return EXIT_CHECK_FAILED
    return 0


def cmd_compare(args) -> int:
    from attitude_fmu.systems.evaluation.compare import compare, imu_model
    from attitude_fmu.systems.simulation.motion import profile as known_profile

    for name in args.profile or []:
        known_profile(name)  # refuses unknown names
    imu = imu_model(args.gyro_noise, args.acc_noise, args.gyro_scale_error)
    with _jobs(args) as jobs:
        result = compare(args.profile, imu=imu, offline=args.offline, jobs=jobs)
    status = EXIT_BAD_INPUT if jobs.failed else 0
    if args.json:
        print(json.dumps(result, indent=2))
        return status
    print(f"inclination error, degrees: RMS / max / mean (bias); default parameters; gyro {args.gyro_noise:g} °/s/√Hz, "
          f"scale error {args.gyro_scale_error:g}, accelerometer {args.acc_noise:g} m/s²/√Hz")
    for profile, rows in result["profiles"].items():
        print(f"\n{profile}")
        for method, r in rows.items():
            print(f"  {method:>19} {r['rms_deg']:8.3f} {r['max_deg']:8.3f} {r['mean_deg']:9.4f}")
    return status


def cmd_bode(args) -> int:
    from attitude_fmu.systems.cli.bode import plot

    out = args.out or f"bode_{args.method}.png"
    _check_out(out, figure=True)
    plot(args.method, out)
    print(f"attitude: wrote {out}", file=sys.stderr)
    return 0


def cmd_bench(args) -> int:
    from attitude_fmu.systems.evaluation.bench import bench

    args.samples = args.samples or (1_000_000 if args.io else 100_000)
    if args.workers:
        _check_cell_samples(args.duration, TABLE1_FS)  # the table1 it runs has the default rate
        from attitude_fmu.systems.evaluation.bench import bench_workers

        result = bench_workers(args.recordings, args.workers, args.duration)
        if args.json:
            print(json.dumps(result, indent=2))
        else:
            for name in ("evaluate", "table1"):
                if name in result:
                    r = result[name]
                    print(f"{name:>8}, {r['jobs']} jobs: 1 process {r['serial_s']:.1f} s, {args.workers} workers "
                          f"{r['distributed_s']:.1f} s, ratio {r['ratio']:.2f}; results "
                          f"{'identical' if r['identical'] else 'DIFFER'}")
        return 0
    if args.io:
        from attitude_fmu.systems.cli.bench_io import bench_io, print_io

        result = bench_io(args.samples, repeat=min(args.repeat, 3))
        if args.json:
            print(json.dumps(result, indent=2))
        else:
            print_io(result)
        return 0
    if args.fmu:
        from attitude_fmu.systems.evaluation.bench import bench_fmu

        result = bench_fmu(steps=min(args.samples, 5000), repeat=args.repeat)
        if args.json:
            print(json.dumps(result, indent=2))
        else:
            print(f"{result['steps']} steps under fmpy, best of {args.repeat} interleaved rounds")
            for name, us in result["us_per_step"].items():
                print(f"{name:>24} {us:8.2f} µs/step")
            print(f"{'ratio':>24} {result['ratio_vs_noop']:8.2f}  (pythonfmu: estimator / no-op)")
            print(f"{'native ratio':>24} {result['native_ratio_vs_noop']:8.2f}  (in C: estimator / no-op; target ≤ 1.2)")
            print(f"in a C host with no Python, best of {args.repeat} rounds")
            for name, us in result["c_host_us_per_step"].items():
                print(f"{name:>24} {us:8.3f} µs/step")
            print(f"{'native speed-up':>24} {result['native_speedup_c_host']:8.1f}  (pythonfmu / native; target ≥ 20)")
            print(f"{'exported ratio':>24} {result['exported_ratio_c_host']:8.2f}  (export_fmu of the same pipeline "
                  f"from python-control blocks / native; target ≤ 1.2)")
        return 0
    result = bench(n=args.samples, repeat=args.repeat)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(f"{result['samples']} samples, best of up to {args.repeat} runs")
        print(f"{'method':>18} {'samples/s':>14} {'vs vqf':>8} {'vs vqf_9d':>10}")
        for name, rate in result["samples_per_s"].items():
            print(f"{name:>18} {rate:14.4g} {result['ratio_vs_vqf'][name]:8.2f} {result['ratio_vs_vqf_9d'][name]:10.2f}")
    return 0


def cmd_export(args) -> int:
    from attitude_fmu.systems.fmi.export.api import export_fmu
    from attitude_fmu.systems.fmi.export.source import load_system

    _check_out(args.out)
    with interrupting():  # SIGTERM or SIGHUP: the build folders and the temporary FMU removed, the output kept
        system, x0 = load_system(args.system)
        path = export_fmu(system, args.out, x0=x0, step=args.step, fmi_version=args.fmi_version,
                          platforms=args.platforms, name=args.name, backend=args.backend,
                          log=lambda m: print(f"attitude: {m}", file=sys.stderr),
                          scalar_parameters=args.scalar_parameters)
    print(path)
    return 0


def main(argv=None) -> int:
    try:
        args = build_parser().parse_args(argv)
        handler = {"estimate": cmd_estimate, "evaluate": cmd_evaluate, "sweep": cmd_sweep, "plot": cmd_plot,
                   "table1": cmd_table1, "verify": cmd_verify, "ssp": cmd_ssp, "compare": cmd_compare,
                   "bode": cmd_bode, "bench": cmd_bench, "export": cmd_export,
                   "simulate": lambda a: cmd_simulate(a, _check_out)}[args.command]
        return handler(args)
    except (ValueError, OSError, RuntimeError) as exc:
        print(f"attitude: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:  # SIGINT anywhere; SIGTERM or SIGHUP during a write (Interrupted)
        signum = getattr(exc, "signum", signal.SIGINT)
        print(f"attitude: interrupted by {signal.Signals(signum).name}; no output was left half-written",
              file=sys.stderr)
        return EXIT_SIGNAL + signum


def entry_point() -> None:
    """The console script: main(), then an immediate exit where FMUs were loaded
    (see systems.fmi.cosim.fmus_loaded)."""
    code = main()
    from attitude_fmu.systems.fmi.cosim import fmus_loaded

    if fmus_loaded():
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    entry_point()
