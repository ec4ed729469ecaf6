"""Heading from the magnetometer (the "heading estimator" box of Rizun's Fig. 1).

Takes the attitude filter's orientation (heading from the integrated gyro) and turns it
about earth up by ψ_c, which follows the heading of the tilt-compensated field: with q'
= Rz(ψ_c)·q and m_e = R(q')·m, the field should point north (ENU y) in the horizontal
plane, so δψ = atan2(m_e,x, m_e,y) is the heading error's negative and ψ_c += a·clip(δψ) with
a = 1 − exp(−Ts/tau) and the innovation clipped to ±heading_clip (a robust update: a
disturbance that slips through the guard pulls by at most heading_clip/tau_heading per
second). The first accepted sample sets the heading at once. Guard against magnetic
disturbances: a sample is used only while the field's norm and dip stay within tolerance
of a reference, learned from the first sample and tracked slowly (tau_reference) over
accepted samples; otherwise the heading is the gyro's.
Inclination is untouched: the correction turns about the vertical only.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .methods import Param, resolve_params
from .quaternion import quat_multiply, quat_rotate

PARAMS = (
    Param("tau_heading", 10.0, "s", "time constant of the pull towards the magnetometer heading"),
    Param("mag_norm_tol", 0.1, "1", "largest relative deviation of the field norm from its reference"),
    Param("mag_dip_tol", math.radians(5.0), "rad", "largest deviation of the dip angle from its reference"),
    Param("tau_reference", 60.0, "s", "time constant of the reference norm and dip"),
    Param("heading_clip", math.radians(10.0), "rad", "largest heading innovation one sample may use"),
)


def resolve(overrides=None) -> dict:
    return resolve_params(PARAMS, overrides, "the heading estimator")


@kernel()
def run(quat, mag, a_heading, a_reference, norm_tol, dip_tol, clip, out, accepted):
    """Per sample: out (N×4) the orientation with magnetometer heading, accepted (N) whether
    the field passed the guard. quat N×4 (sensor → earth), mag N×3 (any unit)."""
    psi = 0.0
    ref_norm = -1.0  # not yet learned
    ref_dip = 0.0
    for k in range(quat.shape[0]):
        q = (quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3])
        half = 0.5 * psi
        turned = quat_multiply((math.cos(half), 0.0, 0.0, math.sin(half)), q)
        m = quat_rotate(turned, (mag[k, 0], mag[k, 1], mag[k, 2]))
        horizontal = math.sqrt(m[0] * m[0] + m[1] * m[1])
        norm = math.sqrt(horizontal * horizontal + m[2] * m[2])
        ok = False
        if norm > 0.0 and horizontal > 0.0:
            dip = math.atan2(-m[2], horizontal)
            if ref_norm < 0.0:
                ref_norm, ref_dip, ok = norm, dip, True
                psi = math.atan2(m[0], m[1])
            elif abs(norm - ref_norm) <= norm_tol * ref_norm and abs(dip - ref_dip) <= dip_tol:
                ok = True
                psi += a_heading * min(clip, max(-clip, math.atan2(m[0], m[1])))
                ref_norm += a_reference * (norm - ref_norm)
                ref_dip += a_reference * (dip - ref_dip)
        psi = math.atan2(math.sin(psi), math.cos(psi))
        half = 0.5 * psi
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = quat_multiply((math.cos(half), 0.0, 0.0, math.sin(half)), q)
        accepted[k] = ok


def with_magnetometer(quat, mag, fs: float, params=None):
    """(orientation with magnetometer heading N×4, accepted N) for a whole recording."""
    p = resolve(params)
    Ts = 1.0 / fs
    out = np.empty_like(quat)
    accepted = np.empty(len(quat), dtype=np.bool_)
    run(np.ascontiguousarray(quat), np.ascontiguousarray(mag, dtype=float),
        1.0 - math.exp(-Ts / p["tau_heading"]), 1.0 - math.exp(-Ts / p["tau_reference"]),
        p["mag_norm_tol"], p["mag_dip_tol"], p["heading_clip"], out, accepted)
    return out, accepted
