/* errors.h: the attitude error of an estimate against the truth, per sample (the closed loop's
 * error block, systems.simulation.diagram.attitude_error_system, and the diagram FMU's). */
#ifndef AF_ERRORS_H
#define AF_ERRORS_H

/* The inclination error (rad, 0 ... pi) between the estimated gravity ghat (sensor coordinates,
 * any length) and the true up of q (sensor -> earth, [w, x, y, z]): the third row of R(q),
 * [2(xz - wy), 2(yz + wx), 1 - 2(x^2 + y^2)]; atan2(|ghat x up|, ghat . up). */
double attitude_error(const double ghat[3], const double q[4]);

#endif
