"""`attitude simulate`: a recording made by the simulator (systems.simulation.recording), written
as a CSV or Parquet file that `attitude estimate`, `evaluate` and `plot` read."""
from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

from attitude_fmu.systems.recordings.checks import RATE_RANGE_HZ
from attitude_fmu.systems.simulation.recording import DEFAULT_MOTION, MAX_SCALE_ERROR, SENSORS

MAX_DURATION_S = 1e6  # s: 11 days, some 10⁹ samples at 1 kHz
MAX_NOISE = 1e3  # the noise densities' plausible top, in each flag's unit
SENSOR_FLAGS = (  # flag, Sensor field, unit, meaning
    ("--gyro-noise", "gyro_noise_dps", "°/s/√Hz", "gyro white noise"),
    ("--acc-noise", "acc_noise", "m/s²/√Hz", "accelerometer white noise"),
    ("--gyro-scale-error", "gyro_scale_error", "1", ("rms of each element of the gyro's scale-factor and "
                                                     "misalignment matrix, drawn from the seed (1 = 100 %%)")),
    ("--gyro-offset", "gyro_offset_dps", "°/s", "norm of the gyro's constant offset, its direction drawn from the seed"),
    ("--gyro-range", "gyro_range_dps", "°/s", "full scale of each gyro axis (inf: none)"),
    ("--acc-range", "acc_range_g", "g", "full scale of each accelerometer axis (inf: none)"),
    ("--mag-noise", "mag_noise", "µT/√Hz", "magnetometer white noise"),
)


def add_parser(sub, number, param) -> None:
    """The subcommand's parser, with the command line's own argument types: number (a numeric
    flag's range) and param (NAME=VALUE)."""
    sm = sub.add_parser(
        "simulate", help="a simulated recording (rest, then human motion) of a sensor of a datasheet's figures at any "
        "rate, its exact orientation as the reference: a file attitude evaluate scores",
        description="Write a recording of REST seconds still and level, then DURATION seconds of band-limited human "
        "motion (Rizun eq. 14, the profile 'human'), measured by --sensor with any figure of it overridden, at --fs. "
        "Columns t, gyr_x..z (rad/s), acc_x..z (m/s²), mag_x..z (µT), ref_q_w..z (the true orientation, sensor → "
        "earth, ENU) and movement (0 over the rest). Sensors: " + "; ".join(
            f"{name}: " + ", ".join(f"{getattr(s, field):g}{'' if unit == '1' else ' ' + unit}"
                                    for _, field, unit, _ in SENSOR_FLAGS)
            for name, s in SENSORS.items()))
    sm.add_argument("--out", required=True, metavar="FILE", help="the recording to write (.csv, or .parquet)")
    sm.add_argument("--fs", type=number(*RATE_RANGE_HZ, "Hz"), default=100.0, help="sample rate, Hz (default 100)")
    sm.add_argument("--duration", type=number(0.0, MAX_DURATION_S, "s", above=True), default=300.0,
                    help="seconds of motion (default 300)")
    sm.add_argument("--rest", type=number(0.0, MAX_DURATION_S, "s"), default=10.0,
                    help="seconds at rest before the motion (default 10)")
    sm.add_argument("--sensor", choices=sorted(SENSORS), default="consumer", help="the sensor (default consumer)")
    for flag, field, unit, meaning in SENSOR_FLAGS:
        top = MAX_SCALE_ERROR if field == "gyro_scale_error" else MAX_NOISE
        sm.add_argument(flag, dest=field, type=_figure(number, top, unit, "range" in field),
                        help=f"{meaning}{'' if unit == '1' else ', ' + unit} (default: the sensor's)")
    sm.add_argument("--motion", type=param, action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the profile 'human': delta_v (m/s/√Hz), omega_c, rot_rms, rot_cutoff, grid (s); "
                         "default here " + ", ".join(f"{k}={v:g}" for k, v in DEFAULT_MOTION.items()) + ", the rest "
                         "the profile's (attitude compare's); repeatable")
    sm.add_argument("--no-mag", action="store_true", help="no magnetometer columns")
    sm.add_argument("--seed", type=number(0, 2**32 - 1, whole=True), default=0, help="the seed (default 0)")


def _figure(number, top: float, unit: str, positive: bool):
    """A sensor figure's type: a number in [0, top), or where positive (a range) one in (0, 1e9] or
    inf ("inf" or "none": no range)."""
    if positive:
        def full_scale(text: str) -> float:
            return math.inf if text.strip().lower() in ("inf", "none") else number(0.0, 1e9, unit, above=True)(text)
        return full_scale
    return number(0.0, top, "" if unit == "1" else unit, below=True)


def cmd_simulate(args, check_out) -> int:
    """Write the recording; check_out refuses an output that cannot be written before any work."""
    from attitude_fmu.systems.recordings.writing import write_recording
    from attitude_fmu.systems.simulation.recording import simulate_recording

    check_out(args.out)
    sensor = replace(SENSORS[args.sensor], **{field: getattr(args, field) for _, field, _, _ in SENSOR_FLAGS
                                             if getattr(args, field) is not None})
    rec = simulate_recording(args.fs, args.duration, args.rest, sensor, dict(args.motion), args.seed,
                             mag=not args.no_mag, name=Path(args.out).stem)
    for note in rec.notes:
        print(f"attitude: note: {note}", file=sys.stderr)
    write_recording(args.out, rec)
    print(f"attitude: wrote {args.out}: {len(rec.t)} samples at {args.fs:g} Hz ({args.rest:g} s at rest, then "
          f"{args.duration:g} s of motion), sensor {args.sensor}", file=sys.stderr)
    return 0
