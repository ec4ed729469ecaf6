"""MotionProfile.fmu: the project's motion profiles with exact truth (systems.simulation.motion).

Each doStep(t, h) outputs the interval (t, t+h]: the mean angular rate over it, and the
specific force, magnetic field and true orientation at t+h; before the first step (in
Initialization Mode and after it) the outputs are the motion's at the start time, that
instant's rate and specific force. Profile parameters are
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
            self.stream = self._stream()
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def _stream(self):
        """The profile's motion from the parameters, sample by sample (ValueError: one refused)."""
        prof = profile(self.item("profile"))
        motion = prof.motion({p.name: getattr(self, f"{prof.name}_{p.name}") for p in prof.params}, g=self.g)
        return motion.stream(self.seed)

    def start_values(self):
        """The motion at the start time: that instant's rate and specific force (a step of 0 s)."""
        try:
            return self._outputs(*self._stream().step(self.start_time, 0.0))
        except ValueError:
            return None

    @staticmethod
    def _outputs(gyr, f, q) -> dict[str, float]:
        names = ("omega_x", "omega_y", "omega_z", "f_x", "f_y", "f_z", "qt_w", "qt_x", "qt_y", "qt_z",
                 "m_x", "m_y", "m_z")
        return dict(zip(names, (float(v) for v in (*gyr, *f, *q, *earth_field(q)))))

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        try:
            outputs = self._outputs(*self.stream.step(current_time + step_size, step_size))
        except ValueError as exc:  # the human motion refuses the interval, or the arithmetic overflows
            return self.fail(str(exc))
        for name, value in outputs.items():
            setattr(self, name, value)
        return True
