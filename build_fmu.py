"""Build the project's FMUs: python build_fmu.py [--out DIR] (default dist/)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from systems.fmu_build import build


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Build AttitudeEstimator.fmu, ImuSensor.fmu and MotionProfile.fmu.")
    parser.add_argument("--out", type=Path, default=Path("dist"), help="output directory (default dist/)")
    args = parser.parse_args(argv)
    for path in build(args.out):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
