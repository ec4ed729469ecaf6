"""`attitude bode`: frequency responses of the filters, drawn with python-control's bode_plot."""
from __future__ import annotations

import control
import numpy as np

from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.methods.registry import method as get_method
from attitude_fmu.systems.recordings.output import save_figure

HZ = np.logspace(-3, 1.5, 600)  # 0.001 … 31.6 Hz


def curves(method: str) -> dict:
    """Label → transfer function to draw: the method's earth-frame filter, and for `tseng`
    also its chains before and after compensation (Tseng Figs. 6–7)."""
    m = get_method(method)
    if not m.is_sensor_frame:
        raise ValueError(f"method {method!r} is not an LTI filter; bode needs one of the sensor-frame methods")
    drawn = {f"{method}: earth-frame filter": m.filter()}
    if method == "tseng":
        drawn["accelerometer + gyro chain, uncompensated (Fig. 6)"] = tseng.chain("acc")
        drawn["magnetometer + gyro chain, uncompensated (Fig. 7)"] = tseng.chain("mag")
        drawn["either chain with compensation"] = tseng.compensated_chain("acc")
    if method != "wiener":
        drawn["wiener: eq. 34 (default parameters)"] = get_method("wiener").filter()
    return drawn


def plot(method: str, out) -> None:
    """Magnitude (dB) and phase (deg) of every curve over HZ with control.bode_plot, saved to out (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    drawn = curves(method)
    fig = plt.figure(figsize=(8, 6.5))
    figure = control.bode_plot(list(drawn.values()), 2 * np.pi * HZ, label=list(drawn), Hz=True, dB=True, deg=True,
                               title=f"attitude bode --method {method}")
    mag, phase = figure.axes[:, 0]
    mag.axhspan(-1, 1, color="0.9", zorder=0, label="±1 dB")
    mag.set_ylim(-60, 10)
    mag.legend(fontsize=8)
    for ax in (mag, phase):
        ax.grid(True, which="both", alpha=0.3)
    save_figure(fig, out, dpi=120)
    plt.close(fig)
