"""The interfaces of the simulation's FMUs, ImuSensor and MotionProfile: tables of FMU variables
(systems.fmi.interface.variables.Table), from which the pythonfmu FMU registers its variables and the native
one's modelDescription.xml and C header are written (systems/fmi/interface/generate.py, by the build), so one
can take the other's place in an SSP. fmu_src/ImuSensor.py and fmu_src/MotionProfile.py say what
each step does. Only the standard library is imported (and systems/simulation/profile_table.py)."""
from __future__ import annotations

from functools import cache

from attitude_fmu.systems.fmi.interface.variables import IN, INTEGER, OUT, PAR, Table, Variable, fmi_unit
from attitude_fmu.systems.simulation.profile_table import EARTH_FIELD_UT, PROFILES


@cache
def imu_sensor() -> tuple[Variable, ...]:
    """ImuSensor's interface (systems.simulation.sensor_model.ImuModel's parameters)."""
    t = Table()
    t.vector("omega", (0.0, 0.0, 0.0), "rad/s", "true angular rate {c}, mean over the step", IN)
    t.vector("f", (0.0, 0.0, 9.81), "m/s2", "true specific force {c}", IN)
    t.vector("m", EARTH_FIELD_UT, "uT", "true magnetic field {c}", IN)
    t.vector("gyr", (0.0, 0.0, 0.0), "rad/s", "measured angular rate {c}", OUT, calculated=True)
    t.vector("acc", (0.0, 0.0, 9.81), "m/s2", "measured specific force {c}", OUT, calculated=True)
    t.vector("mag", EARTH_FIELD_UT, "uT", "measured magnetic field {c}", OUT, calculated=True)
    t.real("delta_n", 0.0, "rad/s/sqrt(Hz)", "gyro white-noise density, one-sided", PAR)
    t.vector("gyr_offset", (0.0, 0.0, 0.0), "rad/s", "constant gyro offset {c}", PAR)
    for row in "xyz":
        t.vector(f"gyr_scale_{row}", (0.0, 0.0, 0.0), "1",
                 f"gyro scale and misalignment error: share of the true rate's {{c}} in gyr_{row}", PAR)
    t.real("acc_noise", 0.0, "m/s2/sqrt(Hz)", "accelerometer white-noise density, one-sided", PAR)
    t.vector("acc_offset", (0.0, 0.0, 0.0), "m/s2", "constant accelerometer offset {c}", PAR)
    t.real("latency", 0.0, "s", "how long gyr and acc lag the motion (a fixed step needed)", PAR)
    t.real("mag_noise", 0.0, "uT/sqrt(Hz)", "magnetometer white-noise density, one-sided", PAR)
    t.vector("mag_offset", (0.0, 0.0, 0.0), "uT", "hard iron: a field {c} fixed to the sensor", PAR)
    for row in "xyz":
        t.vector(f"mag_soft_iron_{row}", (0.0, 0.0, 0.0), "1",
                 f"soft iron: share of the true field's {{c}} in mag_{row}", PAR)
    t.parameter("seed", 1, "seed of the noise generator (systems.simulation.noise)", INTEGER)
    return tuple(t)


@cache
def motion_profile() -> tuple[Variable, ...]:
    """MotionProfile's interface: the truth it outputs, the profile, and every profile's parameters
    as <profile>_<parameter> at the profile's defaults."""
    t = Table()
    t.vector("omega", (0.0, 0.0, 0.0), "rad/s", "true angular rate {c}, mean over the step", OUT, calculated=True)
    t.vector("f", (0.0, 0.0, 9.81), "m/s2", "true specific force {c}, sensor coordinates", OUT, calculated=True)
    t.vector("m", EARTH_FIELD_UT, "uT", "true magnetic field {c}, sensor coordinates", OUT, calculated=True)
    t.vector("qt", (1.0, 0.0, 0.0, 0.0), "1", "true orientation quaternion {c}, sensor -> earth (ENU)", OUT, "wxyz",
             calculated=True)
    t.choice("profile", PROFILES, "human", "motion profile")
    t.parameter("seed", 0, "seed of random profiles (systems.simulation.noise)", INTEGER)
    t.real("g", 9.81, "m/s2", "magnitude of gravity", PAR)
    for name, (_, params) in PROFILES.items():
        for p in params:
            t.real(f"{name}_{p.name}", p.default, fmi_unit(p.unit), f"{name}: {p.doc}", PAR)
    return tuple(t)
