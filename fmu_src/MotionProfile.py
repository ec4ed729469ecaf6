"""MotionProfile.fmu: the project's motion profiles with exact truth (systems.simulation.motion).

Each doStep(t, h) outputs the interval (t, t+h]: the mean angular rate over it, and the
specific force, magnetic field and true orientation at t+h. Profile parameters are
named <profile>_<parameter> and start at the profile's defaults; profile is an Enumeration of
the profiles' names.
"""
from __future__ import annotations

from attitude_fmu.fmu_src.fmu_support import ProjectSlave
from attitude_fmu.systems.fmi.interface.simulation_variables import motion_profile
from attitude_fmu.systems.simulation.motion import earth_field, profile


class MotionProfile(ProjectSlave):
    author = "attitude-fmu"
    description = "Motion profiles with exact truth: ideal gyro, specific force, magnetic field, orientation"
    internal_state = ("stream",)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.register_table(motion_profile())
        self.stream = None

    def initialise(self):
        try:
            prof = profile(self.item("profile"))
            motion = prof.motion({p.name: getattr(self, f"{prof.name}_{p.name}") for p in prof.params}, g=self.g)
            self.stream = motion.stream(self.seed)
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        gyr, f, q = self.stream.step(current_time + step_size, step_size)
        self.omega_x, self.omega_y, self.omega_z = (float(v) for v in gyr)
        self.f_x, self.f_y, self.f_z = (float(v) for v in f)
        self.qt_w, self.qt_x, self.qt_y, self.qt_z = (float(v) for v in q)
        self.m_x, self.m_y, self.m_z = (float(v) for v in earth_field(q))
        return True
