"""The motion profiles' names, summaries and parameters (blocks.params.Param), in one table:
the source of systems.simulation.motion's profiles and of MotionProfile.fmu's variables
(systems.fmi.interface.simulation_variables). Only the standard library is imported, so that the build
writes the FMU's model description without the package's dependencies."""
from __future__ import annotations

import math

from attitude_fmu.blocks.params import GRAVITY_M_S2, Param
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY

EARTH_FIELD_UT = (0.0, 20.0, -45.0)  # magnetic field in ENU, µT: northwards and down
RATE_MAX = math.radians(4000.0)  # rad/s: the widest gyro range
GRAVITY = Param("g", STANDARD_GRAVITY, "m/s^2", "magnitude of gravity, every profile's", **GRAVITY_M_S2)

LEVER_M = 10.0  # m: the longest lever arm
# the sensor's position from the motion's point (body frame): the lever arm of a profile that takes one
LEVER = tuple(Param(f"lever_{c}", 0.0, "m", f"lever arm {c}: the sensor's offset from the motion's point, body frame",
                    True, -LEVER_M, LEVER_M) for c in "xyz")

# profile name → (summary, parameters in the order the profile's function takes them); each parameter's
# plausible range low ≤ value ≤ high (signed where a negative value has a meaning), and gravity's, is checked
# by the simulation's C core (systems/simulation/core/profile_params.c), in the table the build generates
# from this one (sim_profiles.h, by blocks/core/generate_tables.py)
PROFILES = {
    "human": ("band-limited human motion (Rizun eq. 14) with random rotation", (
        Param("delta_v", 1.0, "m/s/√Hz", "slosh: density of the velocity", True, 0.0, 100.0),
        Param("omega_c", 10.0, "rad/s", "band limit of the velocity", low=1e-4, high=1e5),
        Param("rot_rms", 1.0, "rad/s", "RMS angular rate per axis", True, 0.0, RATE_MAX),
        Param("rot_cutoff", 5.0, "rad/s", "band limit of the angular rate", low=1e-4, high=1e5),
        Param("grid", 1e-3, "s", "time grid of the motion: a noise draw per cell, rate and acceleration constant "
              "within one (the outputs at a time do not depend on the steps taken)", low=1e-6, high=1.0),
        *LEVER,
    )),
    "lever_arm": ("steady rotation about the vertical on a lever arm (Rizun §2.4)", (
        Param("rate", 2.0, "rad/s", "turn rate", True, -RATE_MAX, RATE_MAX),
        Param("radius", 0.2, "m", "arm length", True, 0.0, 100.0),
    )),
    "incline": ("harmonic motion along a 45° incline, peak √2·g (Rizun §2.5)", (
        Param("incline_deg", 45.0, "deg", "slope of the incline", True, -90.0, 90.0),
        Param("peak_acc_g", math.sqrt(2.0), "1", "peak acceleration in units of g", True, 0.0, 100.0),
        Param("frequency", 1.0, "Hz", "frequency of the oscillation", low=1e-4, high=1e3),
    )),
    "coning": ("Luinge's coning motion, theta = rate = 1", (
        Param("theta", 1.0, "rad", "half-angle of the cone", True, -math.pi, math.pi),
        Param("rate", 1.0, "rad/s", "coning rate", True, -RATE_MAX, RATE_MAX),
    )),
    "sine_rotation": ("Tseng 1-2: ±10° sinusoidal pitch, optionally inclined", (
        Param("amplitude_deg", 10.0, "deg", "pitch amplitude", True, -360.0, 360.0),
        Param("frequency", 0.5, "Hz", "pitch frequency", True, 0.0, 1e3),
        Param("inclination_deg", 0.0, "deg", "IMU inclination about x (Tseng 2: 20)", True, -180.0, 180.0),
    )),
    "step_rotation": ("Tseng 3: pitch steps of 5, 10, 20, 45, 90°", (
        Param("hold", 10.0, "s", "time each level is held", low=1e-3, high=1e6),
        Param("ramp", 0.2, "s", "duration of each raised-cosine step", True, 0.0, 1e6),
    )),
    "linear_motion": ("Tseng 4: back and forth along a line, IMU mounted at an angle", (
        Param("amplitude", 0.5, "m", "travel", True, 0.0, 1e3),
        Param("period", 4.0, "s", "period of the back-and-forth", low=1e-3, high=1e6),
        Param("mount_x_deg", 0.0, "deg", "mounting rotation about X", True, -360.0, 360.0),
        Param("mount_y_deg", 0.0, "deg", "mounting rotation about Y", True, -360.0, 360.0),
        Param("mount_z_deg", 0.0, "deg", "mounting rotation about Z", True, -360.0, 360.0),
    )),
    "offset_rotation": ("Tseng 5: 0.4 Hz yaw oscillation on a 20 cm arm", (
        Param("frequency", 0.4, "Hz", "yaw frequency", True, 0.0, 1e3),
        Param("amplitude_deg", 45.0, "deg", "yaw amplitude", True, -360.0, 360.0),
        Param("radius", 0.2, "m", "arm length", True, 0.0, 100.0),
        Param("inclination_deg", 0.0, "deg", "IMU inclination about x", True, -180.0, 180.0),
        Param("pitch_deg", 0.0, "deg", "IMU pitch about y", True, -180.0, 180.0),
    )),
    "phone_flat": ("a phone (mostly) flat on a table or a hand: small tilts, yaw, sliding about", (
        Param("tilt_deg", 3.0, "deg", "amplitude of roll and pitch", True, -90.0, 90.0),
        Param("yaw_deg", 20.0, "deg", "amplitude of the yaw", True, -360.0, 360.0),
        Param("frequency", 0.2, "Hz", "frequency of the roll (pitch 0.7, yaw 0.5 of it)", True, 0.0, 100.0),
        Param("travel", 0.05, "m", "amplitude of the sliding", True, 0.0, 100.0),
    )),
    "running": ("running: impacts at every step, forward and sideways surges, bobbing", (
        Param("step_frequency", 2.7, "Hz", "steps per second", low=0.01, high=100.0),
        Param("impact_g", 2.5, "1", "peak vertical acceleration at an impact, in units of g", True, 0.0, 100.0),
        Param("forward_g", 0.3, "1", "amplitude of the forward acceleration, in units of g", True, 0.0, 100.0),
        Param("sway_g", 0.15, "1", "amplitude of the sideways acceleration, in units of g", True, 0.0, 100.0),
        Param("pitch_deg", 5.0, "deg", "amplitude of the pitch, at the step frequency", True, -90.0, 90.0),
        Param("roll_deg", 5.0, "deg", "amplitude of the roll, at half of it", True, -90.0, 90.0),
        Param("yaw_deg", 5.0, "deg", "amplitude of the yaw, at half of it", True, -180.0, 180.0),
    )),
    "robot_arm": ("an industrial robot's wrist: smooth fast turns of minimum jerk between poses, little "
                  "linear acceleration", (
        Param("angle_deg", 90.0, "deg", "angle of a move (some moves turn half of it)", True, -360.0, 360.0),
        Param("move", 1.2, "s", "duration of a move", low=1e-3, high=1e6),
        Param("dwell", 0.5, "s", "rest after each move", True, 0.0, 1e6),
        *LEVER,
    )),
}
