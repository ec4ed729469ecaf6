"""MotionProfile.fmu: the project's motion profiles with exact truth (systems.simulation.motion).

Each doStep(t, h) outputs the interval (t, t+h]: the mean angular rate over it, and the
specific force, magnetic field and true orientation at t+h. Profile parameters are
named <profile>_<parameter> and start at the profile's defaults.
"""
from __future__ import annotations

from scipy.spatial.transform import Rotation

from attitude_fmu.fmu_src.fmu_support import INTEGER, OUT, PAR, ProjectSlave, fmi_unit
from attitude_fmu.systems.simulation.motion import EARTH_FIELD_UT, PROFILES, profile


class MotionProfile(ProjectSlave):
    author = "attitude-fmu"
    description = "Motion profiles with exact truth: ideal gyro, specific force, magnetic field, orientation"
    internal_state = ("stream",)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.vector("omega", (0.0, 0.0, 0.0), "rad/s", "true angular rate {c}, mean over the step", OUT)
        self.vector("f", (0.0, 0.0, 9.81), "m/s2", "true specific force {c}, sensor coordinates", OUT)
        self.vector("m", EARTH_FIELD_UT, "uT", "true magnetic field {c}, sensor coordinates", OUT)
        self.vector("qt", (1.0, 0.0, 0.0, 0.0), "1", "true orientation quaternion {c}, sensor -> earth (ENU)", OUT,
                    "wxyz")
        self.parameter("profile", "human", f"motion profile: {', '.join(PROFILES)}")
        self.parameter("seed", 0, "seed of random profiles", INTEGER)
        self.real("g", 9.81, "m/s2", "magnitude of gravity", PAR)
        for prof in PROFILES.values():
            for p in prof.params:
                self.real(f"{prof.name}_{p.name}", p.default, fmi_unit(p.unit), f"{prof.name}: {p.doc}", PAR)
        self.stream = None

    def initialise(self):
        try:
            prof = profile(self.profile)
            motion = prof.motion({p.name: getattr(self, f"{prof.name}_{p.name}") for p in prof.params}, g=self.g)
            self.stream = motion.stream(self.seed)
            # a closed-form motion leaves no state when stepped (and pickle cannot hold its functions)
            self.internal_state = () if self.stream is motion else ("stream",)
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        gyr, f, q = self.stream.step(current_time + step_size, step_size)
        self.omega_x, self.omega_y, self.omega_z = (float(v) for v in gyr)
        self.f_x, self.f_y, self.f_z = (float(v) for v in f)
        self.qt_w, self.qt_x, self.qt_y, self.qt_z = (float(v) for v in q)
        m = Rotation.from_quat(q, scalar_first=True).inv().apply(EARTH_FIELD_UT)
        self.m_x, self.m_y, self.m_z = (float(v) for v in m)
        return True
