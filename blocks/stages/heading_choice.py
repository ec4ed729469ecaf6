"""The heading's time constant chosen from the recording (the batch path, where the whole
recording is at hand; online, the parameter's value holds): where the Wiener filter's
scale_error was chosen (blocks.stages.scale_error) and tau_heading is not given, the
heading's time constant follows the gyro that choice found (time_constant): tau_heading
holds for the datasheet's scale error, and the time constant of the best blend of the
magnetometer's heading with the gyro's lengthens for a better gyro.
"""
from __future__ import annotations

import numpy as np


def time_constant(tau_heading: float, datasheet_density: float, density: float, offset_variance: float) -> float:
    """The heading's time constant (s) for a gyro whose scale error the recording showed
    (blocks.stages.scale_error's choice), where tau_heading (s) holds for the datasheet's.

    ψ_c blends the magnetometer's heading with the gyro's through a first-order filter of
    time constant τ, whose heading error has the variance J(τ) = P_b·τ² + q·τ/2 + r/(2τ): the
    gyro offset estimate's residual (variance P_b per axis) held over τ, the gyro's drift (a
    random walk of rate q = δn_eff²/2, δn_eff² the one-sided density of the Wiener filter's
    local densities, blocks.methods.wiener_local.gyro_density), and the magnetometer's noise
    (density r). J is least where 4·P_b·τ³ + q·τ² = r. r is the magnetometer's, the same for
    every gyro: the one for which tau_heading is best with the datasheet's scale error. The τ
    returned is best with the one chosen (longer for a better gyro; tau_heading for the
    datasheet's).

    Parameters: datasheet_density and density, δn_eff² ((rad/s)²/Hz) with the datasheet's
    scale error and with the one chosen, over the recording's motion; offset_variance P_b
    ((rad/s)², the gyro-offset stage's variance averaged over the recording, 0 with no offset
    left)."""
    if density == datasheet_density:
        return tau_heading
    r = 4.0 * offset_variance * tau_heading**3 + 0.5 * datasheet_density * tau_heading**2
    roots = np.roots([4.0 * offset_variance, 0.5 * density, 0.0, -r])  # one positive: the left rises with τ
    return float(max(root.real for root in roots if abs(root.imag) <= 1e-9 * abs(root)))


def chosen_text(value: float) -> str:
    """The note that says what the rule chose for tau_heading and how to hold it."""
    return (f"tau_heading {value:.4g} s chosen from the gyro the scale_error choice found; --param "
            f"tau_heading={value:.4g} holds it, as the FMU's parameter of that name does")
