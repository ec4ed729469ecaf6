"""Build the project's FMUs: python build_fmu.py [--out DIR] (default dist/): the pythonfmu
FMUs into DIR, the native estimator (in C, no Python) into DIR/native.

Run from a clone, it builds from the clone's own sources (this folder is the package
attitude_fmu); installed, it is attitude_fmu.build_fmu (python -m attitude_fmu.build_fmu).
"""
from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path


def _package():
    """attitude_fmu: the package this file belongs to, or, run as a script, this clone's folder under that name."""
    if __package__:
        return sys.modules[__package__]
    root = Path(__file__).resolve().parent
    spec = importlib.util.spec_from_file_location("attitude_fmu", root / "__init__.py",
                                                  submodule_search_locations=[str(root)])
    package = importlib.util.module_from_spec(spec)
    sys.modules["attitude_fmu"] = package
    spec.loader.exec_module(package)
    return package


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Build AttitudeEstimator.fmu, ImuSensor.fmu and MotionProfile.fmu "
                                                 "(pythonfmu) and native/AttitudeEstimator.fmu (in C, no Python).")
    parser.add_argument("--out", type=Path, default=Path("dist"), help="output directory (default dist/)")
    args = parser.parse_args(argv)
    for path in _package().build_fmus(args.out):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
