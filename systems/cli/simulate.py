"""`attitude simulate`: a recording made by the simulator (systems.simulation.recording), or one of
its scenarios (systems.simulation.scenarios), written as a CSV or Parquet file that `attitude estimate`,
`evaluate` and `plot` read."""
from __future__ import annotations

import math
import sys
from dataclasses import replace
from pathlib import Path

from attitude_fmu.systems.recordings.checks import RATE_RANGE_HZ
from attitude_fmu.systems.simulation.recording import DEFAULT_MOTION, MAX_SCALE_ERROR, SENSORS
from attitude_fmu.systems.simulation.scenarios import SCENARIOS, Scenario, scenario

MAX_DURATION_S = 1e6  # s: 11 days, some 10⁹ samples at 1 kHz
MAX_NOISE = 1e3  # the noise densities' plausible top, in each flag's unit
# what the command makes without --scenario: the flags' defaults
PLAIN_SENSOR = "consumer"
PLAIN = Scenario("a rest, then band-limited human motion", "human", SENSORS[PLAIN_SENSOR], fs=100.0, duration=300.0,
                 rest=10.0, seed=0)
SENSOR_FLAGS = (  # flag, Sensor field, unit, meaning
    ("--gyro-noise", "gyro_noise_dps", "°/s/√Hz", "gyro white noise"),
    ("--acc-noise", "acc_noise", "m/s²/√Hz", "accelerometer white noise"),
    ("--gyro-scale-error", "gyro_scale_error", "1", ("rms of each element of the gyro's scale-factor and "
                                                     "misalignment matrix, drawn from the seed (1 = 100 %%)")),
    ("--gyro-offset", "gyro_offset_dps", "°/s",
     "norm of the gyro's constant offset, its direction drawn from the seed (or the scenario's)"),
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
            for name, s in SENSORS.items()) + ". Scenarios (--scenario), failure modes seen on other labs' "
        "recordings: " + "; ".join(f"{name}: {s.description}" for name, s in SCENARIOS.items()))
    sm.add_argument("--out", required=True, metavar="FILE", help="the recording to write (.csv, or .parquet)")
    sm.add_argument("--scenario", metavar="NAME", help=f"a scenario ({', '.join(SCENARIOS)}): its motion, sensor, "
                    "rate, durations and seed; any flag given overrides its value")
    sm.add_argument("--fs", type=number(*RATE_RANGE_HZ, "Hz"), help=f"sample rate, Hz (default {PLAIN.fs:g})")
    sm.add_argument("--duration", type=number(0.0, MAX_DURATION_S, "s", above=True),
                    help=f"seconds of motion (default {PLAIN.duration:g})")
    sm.add_argument("--rest", type=number(0.0, MAX_DURATION_S, "s"),
                    help=f"seconds at rest before the motion (default {PLAIN.rest:g})")
    sm.add_argument("--sensor", choices=sorted(SENSORS), help=f"the sensor (default {PLAIN_SENSOR})")
    for flag, field, unit, meaning in SENSOR_FLAGS:
        top = MAX_SCALE_ERROR if field == "gyro_scale_error" else MAX_NOISE
        sm.add_argument(flag, dest=field, type=_figure(number, top, unit, "range" in field),
                        help=f"{meaning}{'' if unit == '1' else ', ' + unit} (default: the sensor's)")
    sm.add_argument("--motion", type=param, action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the profile 'human' (or of a scenario's profile): delta_v (m/s/√Hz), "
                         "omega_c, rot_rms, rot_cutoff, grid (s), lever_x, lever_y, lever_z (m); default here "
                         + ", ".join(f"{k}={v:g}" for k, v in DEFAULT_MOTION.items()) + ", the rest "
                         "the profile's (attitude compare's); repeatable")
    sm.add_argument("--no-mag", action="store_true", help="no magnetometer columns")
    sm.add_argument("--seed", type=number(0, 2**32 - 1, whole=True), help=f"the seed (default {PLAIN.seed})")


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

    check_out(args.out)
    preset = PLAIN if args.scenario is None else scenario(args.scenario)
    given = {field: getattr(args, field) for _, field, _, _ in SENSOR_FLAGS if getattr(args, field) is not None}
    sensor = replace(preset.sensor if args.sensor is None else SENSORS[args.sensor], **given)
    chosen = replace(preset, sensor=sensor, **{k: getattr(args, k) for k in ("fs", "duration", "rest", "seed")
                                               if getattr(args, k) is not None})
    rec = chosen.recording(Path(args.out).stem, not args.no_mag, dict(args.motion))
    for note in rec.notes:
        print(f"attitude: note: {note}", file=sys.stderr)
    write_recording(args.out, rec)
    made = f"scenario {args.scenario}" if args.scenario else f"sensor {args.sensor or PLAIN_SENSOR}"
    print(f"attitude: wrote {args.out}: {len(rec.t)} samples at {chosen.fs:g} Hz ({chosen.rest:g} s at rest, then "
          f"{chosen.duration:g} s of motion), {made}", file=sys.stderr)
    return 0
