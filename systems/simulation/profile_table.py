"""The motion profiles' names, summaries and parameters (blocks.params.Param), in one table:
the source of systems.simulation.motion's profiles and of MotionProfile.fmu's variables
(fmu_src.simulation_variables). Only the standard library is imported, so that the build
writes the FMU's model description without the package's dependencies."""
from __future__ import annotations

import math

from attitude_fmu.blocks.params import Param

EARTH_FIELD_UT = (0.0, 20.0, -45.0)  # magnetic field in ENU, µT: northwards and down

# profile name → (summary, parameters in the order the profile's function takes them)
PROFILES = {
    "human": ("band-limited human motion (Rizun eq. 14) with random rotation", (
        Param("delta_v", 1.0, "m/s/√Hz", "slosh: density of the velocity"),
        Param("omega_c", 10.0, "rad/s", "band limit of the velocity"),
        Param("rot_rms", 1.0, "rad/s", "RMS angular rate per axis"),
        Param("rot_cutoff", 5.0, "rad/s", "band limit of the angular rate"),
    )),
    "lever_arm": ("steady rotation about the vertical on a lever arm (Rizun §2.4)", (
        Param("rate", 2.0, "rad/s", "turn rate"),
        Param("radius", 0.2, "m", "arm length"),
    )),
    "incline": ("harmonic motion along a 45° incline, peak √2·g (Rizun §2.5)", (
        Param("incline_deg", 45.0, "deg", "slope of the incline"),
        Param("peak_acc_g", math.sqrt(2.0), "1", "peak acceleration in units of g"),
        Param("frequency", 1.0, "Hz", "frequency of the oscillation"),
    )),
    "coning": ("Luinge's coning motion, theta = rate = 1", (
        Param("theta", 1.0, "rad", "half-angle of the cone"),
        Param("rate", 1.0, "rad/s", "coning rate"),
    )),
    "sine_rotation": ("Tseng 1-2: ±10° sinusoidal pitch, optionally inclined", (
        Param("amplitude_deg", 10.0, "deg", "pitch amplitude"),
        Param("frequency", 0.5, "Hz", "pitch frequency"),
        Param("inclination_deg", 0.0, "deg", "IMU inclination about x (Tseng 2: 20)", True),
    )),
    "step_rotation": ("Tseng 3: pitch steps of 5, 10, 20, 45, 90°", (
        Param("hold", 10.0, "s", "time each level is held"),
        Param("ramp", 0.2, "s", "duration of each raised-cosine step"),
    )),
    "linear_motion": ("Tseng 4: back and forth along a line, IMU mounted at an angle", (
        Param("amplitude", 0.5, "m", "travel"),
        Param("period", 4.0, "s", "period of the back-and-forth"),
        Param("mount_x_deg", 0.0, "deg", "mounting rotation about X", True),
        Param("mount_y_deg", 0.0, "deg", "mounting rotation about Y", True),
        Param("mount_z_deg", 0.0, "deg", "mounting rotation about Z", True),
    )),
    "offset_rotation": ("Tseng 5: 0.4 Hz yaw oscillation on a 20 cm arm", (
        Param("frequency", 0.4, "Hz", "yaw frequency"),
        Param("amplitude_deg", 45.0, "deg", "yaw amplitude"),
        Param("radius", 0.2, "m", "arm length"),
        Param("inclination_deg", 0.0, "deg", "IMU inclination about x", True),
        Param("pitch_deg", 0.0, "deg", "IMU pitch about y", True),
    )),
}
