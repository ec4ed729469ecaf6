"""attitude_fmu: IMU attitude estimators as python-control blocks, FMUs and a batch path.

What a script needs, by task (each name's own docstring has its units and defaults):

- estimate over arrays: `estimate` → `AttitudeEstimate` (quat, up, offset, …); the
  methods by name: `METHODS`; per sample, as a co-simulation step: `OnlineEstimator`;
- recordings: `read_recording` → `Recording`, `write_estimate`; simulated ones that reproduce
  failure modes of other labs' recordings: `SCENARIOS`, `scenario` (`.recording()`);
- python-control blocks: `estimator_system` (any method), `sensor_frame_system` (any
  earth-frame filter carried into the sensor frame), the earth-frame filters `butterworth`,
  `wiener_band_limited`, `first_order` and `omega_g`, Tseng's transfer functions under
  `tseng` (`tseng.chain()`, `tseng.earth_filter()`, …), the stages `offset_system`,
  `heading_system`, `latency_system`, and the closed loop `closed_loop`,
  `simulate_closed_loop` over the motions `HumanMotion`, `profile` (each motion's
  `.system(fs)`), the sensor `ImuModel`, `magnetometer_system` and the error block
  `attitude_error_system`; a block's or a diagram's state at rest, where `control.linearize`
  and `control.find_operating_point` start: `rest_state`, `rest_point`; the C step an
  exported FMU runs for a block: `c_step` → `CStep`;
- Rizun's analytic accuracy: `rms_attitude_error`, `mean_square_error`, `error_spectrum`,
  `smoother_rms_attitude_error`, `smoother_error_spectrum`; errors against a reference:
  `quaternion_errors`, `inclination_error`;
- FMUs: `build_fmus`, `FmuRunner` (one FMU stepped from Python), `write_ssp`, `cosimulate`,
  `verify`; any python-control diagram of state spaces, transfer functions and these blocks as a
  native FMU: `export_fmu` (refusals: `ExportError`);
- scores: `evaluate` (recordings with a reference), `sweep` (a parameter grid on them),
  `compare` (simulated profiles, peers), `table1` (Rizun's Table 1); each takes `jobs=`, a
  `Jobs` that runs its jobs in this process or on a Dask cluster (docs/distributed.md).

Names load their module on first use, so `import attitude_fmu` stays light (an FMU
carries only the modules it imports).
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

# public name → module under attitude_fmu that defines it (or, for a namespace, the package that holds it)
_API = {
    "estimate": "blocks.pipeline.batch",
    "AttitudeEstimate": "blocks.pipeline.batch",
    "OnlineEstimator": "blocks.pipeline.online",
    "METHODS": "blocks.methods.registry",
    "estimator_system": "blocks.methods.registry",
    "read_recording": "systems.recordings.reading",
    "Recording": "systems.recordings.recording",
    "write_estimate": "systems.recordings.writing",
    "sensor_frame_system": "blocks.filters.sensor_frame",
    "tseng": "blocks.filters",
    "butterworth": "blocks.filters.earth_filters",
    "wiener_band_limited": "blocks.filters.earth_filters",
    "first_order": "blocks.filters.earth_filters",
    "omega_g": "blocks.filters.earth_filters",
    "offset_system": "blocks.stages.gyro_offset",
    "heading_system": "blocks.stages.heading",
    "latency_system": "blocks.stages.timing",
    "closed_loop": "systems.simulation.diagram",
    "simulate_closed_loop": "systems.simulation.diagram",
    "magnetometer_system": "systems.simulation.diagram",
    "attitude_error_system": "systems.simulation.diagram",
    "rest_state": "blocks.control_system",
    "rest_point": "blocks.control_system",
    "CStep": "blocks.control_system",
    "c_step": "blocks.control_system",
    "HumanMotion": "systems.simulation.motion",
    "profile": "systems.simulation.motion",
    "ImuModel": "systems.simulation.sensor_model",
    "SCENARIOS": "systems.simulation.scenarios",
    "scenario": "systems.simulation.scenarios",
    "rms_attitude_error": "blocks.filters.accuracy",
    "mean_square_error": "blocks.filters.accuracy",
    "error_spectrum": "blocks.filters.accuracy",
    "smoother_rms_attitude_error": "blocks.filters.accuracy",
    "smoother_error_spectrum": "blocks.filters.accuracy",
    "quaternion_errors": "blocks.errors",
    "inclination_error": "blocks.errors",
    "build_fmus": "systems.fmi.build",
    "export_fmu": "systems.fmi.export.api",
    "ExportError": "systems.fmi.export.flatten",
    "FmuRunner": "systems.fmi.cosim",
    "write_ssp": "systems.fmi.ssp",
    "cosimulate": "systems.fmi.cosim",
    "verify": "systems.fmi.verify",
    "evaluate": "systems.evaluation.evaluate",
    "compare": "systems.evaluation.compare",
    "table1": "systems.evaluation.experiments",
    "sweep": "systems.evaluation.sweep",
    "Jobs": "systems.cluster.jobs",
}
__all__ = list(_API)


def __getattr__(name: str):
    try:
        module = _API[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    parent = importlib.import_module(f"{__name__}.{module}")
    value = getattr(parent, name) if hasattr(parent, name) else importlib.import_module(f"{parent.__name__}.{name}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # the same names for type checkers and editors
    from .blocks.control_system import CStep, c_step, rest_point, rest_state
    from .blocks.errors import inclination_error, quaternion_errors
    from .blocks.filters.accuracy import (
        error_spectrum,
        mean_square_error,
        rms_attitude_error,
        smoother_error_spectrum,
        smoother_rms_attitude_error,
    )
    from .blocks.filters.earth_filters import butterworth, first_order, omega_g, wiener_band_limited
    from .blocks.filters import tseng
    from .blocks.filters.sensor_frame import sensor_frame_system
    from .blocks.methods.registry import METHODS, estimator_system
    from .blocks.pipeline.batch import AttitudeEstimate, estimate
    from .blocks.pipeline.online import OnlineEstimator
    from .blocks.stages.gyro_offset import offset_system
    from .blocks.stages.heading import heading_system
    from .blocks.stages.timing import latency_system
    from .systems.cluster.jobs import Jobs
    from .systems.evaluation.compare import compare
    from .systems.evaluation.evaluate import evaluate
    from .systems.evaluation.experiments import table1
    from .systems.evaluation.sweep import sweep
    from .systems.fmi.build import build_fmus
    from .systems.fmi.export.api import export_fmu
    from .systems.fmi.export.flatten import ExportError
    from .systems.fmi.cosim import FmuRunner, cosimulate
    from .systems.fmi.ssp import write_ssp
    from .systems.fmi.verify import verify
    from .systems.recordings.reading import read_recording
    from .systems.recordings.recording import Recording
    from .systems.recordings.writing import write_estimate
    from .systems.simulation.diagram import (
        attitude_error_system,
        closed_loop,
        magnetometer_system,
        simulate_closed_loop,
    )
    from .systems.simulation.motion import HumanMotion, profile
    from .systems.simulation.scenarios import SCENARIOS, scenario
    from .systems.simulation.sensor_model import ImuModel
