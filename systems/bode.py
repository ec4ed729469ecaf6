"""`attitude bode`: frequency responses of the filters, drawn with matplotlib."""
from __future__ import annotations

import numpy as np

from blocks import tseng
from blocks.methods import method as get_method

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
    """Magnitude (dB) and phase (deg) of every curve over HZ, saved to out (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (mag, phase) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    for label, tf in curves(method).items():
        response = np.asarray(tf(2j * np.pi * HZ))
        mag.semilogx(HZ, 20 * np.log10(np.abs(response)), label=label)
        phase.semilogx(HZ, np.degrees(np.unwrap(np.angle(response))), label=label)
    mag.axhspan(-1, 1, color="0.9", zorder=0, label="±1 dB")
    mag.set_ylabel("gain, dB")
    mag.set_ylim(-60, 10)
    phase.set_ylabel("phase, deg")
    phase.set_xlabel("frequency, Hz")
    mag.legend(fontsize=8)
    mag.set_title(f"attitude bode --method {method}")
    for ax in (mag, phase):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
