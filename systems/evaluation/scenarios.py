"""The scenario suite scored (systems.simulation.scenarios.SCENARIOS): each scenario's recording
estimated with the defaults and by vqf, online and offline, without the magnetometer (6D) and with it
(9D), and the RMS errors over its movement phase (systems.evaluation.evaluate.errors_on_movement):
inclination, and heading — 9D against the simulation's north, 6D after the constant heading offset
is removed (a 6D estimate has no north)."""
from __future__ import annotations

import numpy as np

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.evaluation.evaluate import errors_on_movement
from attitude_fmu.systems.simulation.scenarios import SCENARIOS, scenario

# (column, metric, estimate kind): kinds are (offline, with the magnetometer)
COLUMNS = (("inclination online", "inclination_rmse_deg", (False, False)),
           ("inclination offline", "inclination_rmse_deg", (True, False)),
           ("heading 6D", "heading_rmse_deg", (False, False)),
           ("heading 9D", "heading_rmse_deg", (False, True)),
           ("heading 9D offline", "heading_rmse_deg", (True, True)))


def _quaternions(rec) -> dict:
    """{(offline, 9D): (ours, vqf's)} orientations (N×4, sensor → earth) of rec."""
    import vqf

    gyr, acc, mag = (np.ascontiguousarray(a, dtype=float) for a in (rec.gyr, rec.acc, rec.mag))
    online = vqf.VQF(1.0 / rec.fs).updateBatch(gyr, acc, mag)
    offline = vqf.offlineVQF(gyr, acc, mag, 1.0 / rec.fs)
    peer = {(False, False): online["quat6D"], (False, True): online["quat9D"],
            (True, False): offline["quat6D"], (True, True): offline["quat9D"]}
    return {(off, nine): (estimate(gyr, acc, rec.fs, mag=mag if nine else None, offline=off).quat, peer[off, nine])
            for off, nine in peer}


def score(name: str) -> dict:
    """{column: {"ours": RMS deg, "vqf": RMS deg}} for the scenario of that name (COLUMNS; vqf's
    online or offline estimate as ours)."""
    rec = scenario(name).recording(name=name)
    quats = _quaternions(rec)
    out = {}
    for column, metric, kind in COLUMNS:
        north = kind[1]  # 9D: the simulation's north is the magnetometer's
        ours, peer = (errors_on_movement(q, rec, magnetic_north=north)[metric] for q in quats[kind])
        out[column] = {"ours": ours, "vqf": peer}
    return out


def score_all() -> dict:
    """{scenario: score(scenario)} over SCENARIOS."""
    return {name: score(name) for name in SCENARIOS}
