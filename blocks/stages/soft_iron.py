"""Soft iron, offline (the batch path's `offline=True`): the magnetometer's field as an ellipsoid.

A sensor's own soft iron (and a scale or axis error of the magnetometer) turns the earth's field
m_e into m = S·m_e + b: turning the sensor draws an ellipsoid, not the sphere the hard-iron fit
(blocks.stages.hard_iron) assumes, and the tilt-compensated heading then errs by an angle that
changes with the orientation. Over the field samples the heading stage used (freed of hard iron),
an algebraic ellipsoid u'·Q·u + p'·u = 1 is fitted by least squares to u = (m − b_s)/r, the field
about the sphere fit's centre b_s in units of its radius r, with a ridge of RIDGE per sample toward
the sphere (Q = I, p = 0), which holds the shape along any direction the samples leave unclear.
Its correction A = (Q/k)^½, k = 1 + c'·Q·c about the centre c = −Q⁻¹·p/2, turns a field sample
into A·(m − b), b = b_s + r·c, of norm about r.

It is taken only where it is proven:
- the samples cover every direction: their s.d. across their smallest axis is mag_cal_spread·r
  or more (the hard-iron fit's test);
- Q is positive definite;
- its distances to the samples leave at most SPHERE_SHARE of the mean square the sphere's leave,
  in units of r: Sampson's first-order distance f/|∇f| of f(u) = u'·Q·u + p'·u − 1 against
  |u| − 1 (a measure in the field's own unit: an ellipsoid far off, fitted to a cap of
  directions, shrinks its own norm along its thin axis but not these). Soft iron is then the
  field's main error; a field whose norm varies by disturbances, or by noise, is left to the guard.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import sqrtm

RIDGE = 1e-3  # per sample: the pull of the ellipsoid's coefficients toward the sphere's (u'u = 1)
SPHERE_SHARE = 0.5  # taken where the ellipsoid leaves at most this share of the sphere's norm variance
MIN_SAMPLES = 100  # fewer field samples: no fit


@dataclass(frozen=True)
class SoftIron:
    """A fitted ellipsoid: corrected field = matrix·(m − centre) (µT, the field's unit); variance:
    the mean square distance it leaves, against the sphere's (sphere_variance), both in units of
    the sphere's radius squared."""

    matrix: np.ndarray
    centre: np.ndarray
    variance: float
    sphere_variance: float

    def corrected(self, mag) -> np.ndarray:
        """mag (N×3; a row with a NaN stays so) turned onto the sphere."""
        return (np.asarray(mag, dtype=float) - self.centre) @ self.matrix.T


def _sphere(m):
    """(centre, radius) of the least-squares sphere |m|² = 2·b·m + c, or None where it has none."""
    design = np.column_stack([2.0 * m, np.ones(len(m))])
    solution = np.linalg.lstsq(design, (m * m).sum(axis=1), rcond=None)[0]
    centre = solution[:3]
    r2 = solution[3] + centre @ centre
    return (centre, float(np.sqrt(r2))) if r2 > 0.0 else None


def fit(field, spread_min: float) -> SoftIron | None:
    """The ellipsoid over field samples (N×3, µT, finite: those the heading used, freed of hard
    iron), or None where it is not proven (module docstring); spread_min: mag_cal_spread."""
    m = np.asarray(field, dtype=float)
    if len(m) < MIN_SAMPLES or not np.isfinite(m).all():
        return None
    sphere = _sphere(m)
    if sphere is None:
        return None
    centre, radius = sphere
    u = (m - centre) / radius
    if np.linalg.eigvalsh(np.cov(u.T))[0] < spread_min**2:
        return None
    x, y, z = u.T
    design = np.column_stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, x, y, z])
    ridge = RIDGE * len(u)
    prior = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    theta = np.linalg.solve(design.T @ design + ridge * np.eye(9), design.T @ np.ones(len(u)) + ridge * prior)
    q = np.array([[theta[0], theta[3], theta[4]], [theta[3], theta[1], theta[5]], [theta[4], theta[5], theta[2]]])
    if np.linalg.eigvalsh(q)[0] <= 0.0:
        return None
    c = -0.5 * np.linalg.solve(q, theta[6:])
    k = 1.0 + c @ q @ c
    matrix = np.real(sqrtm(q / k))
    gradient = np.linalg.norm(2.0 * u @ q + theta[6:], axis=1)  # of u'Qu + p'u - 1 at each sample
    sampson = (np.einsum("ij,jk,ik->i", u, q, u) + u @ theta[6:] - 1.0) / gradient
    variance = float(np.mean(sampson**2))
    sphere_variance = float(np.mean((np.linalg.norm(u, axis=1) - 1.0) ** 2))
    if not variance <= SPHERE_SHARE * sphere_variance:
        return None
    return SoftIron(matrix, centre + radius * c, variance, sphere_variance)
