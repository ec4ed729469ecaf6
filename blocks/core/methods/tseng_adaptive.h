/* tseng_adaptive.h: Tseng's adaptive complementary filter: the complementary filter (the
 * `tseng` earth filter in the sensor frame) while the accelerometer norm stays within tol of
 * g, Mahony's filter (methods/mahony.h, gyro-dominated, with bias estimate) while it does not;
 * leaving Mahony's filter, the complementary filter restarts at rest on its estimate. */
#ifndef AF_TSENG_ADAPTIVE_H
#define AF_TSENG_ADAPTIVE_H

#include "af_params.h"
#include "filters/sensor_frame.h"
#include "filters/tseng.h"
#include "methods/mahony.h"

/* The state: the complementary filter's state rows, then Mahony's state (the orientation both
 * modes share, and the gyro-bias estimate). */
typedef struct {
    Vec3 X[TSENG_ORDER];
    MahonyState mahony;
} TsengAdaptiveState;

typedef struct {
    DiscreteFilter disc;          /* the complementary filter: the tseng filter held over Ts */
    double tol;                   /* m/s^2: the accelerometer norm's distance from g that switches modes */
    double g;                     /* m/s^2 */
    double k_P, k_I;              /* Mahony's gains, 1/s and 1/s^2 */
    double x_rest[TSENG_ORDER];   /* the filter's state per unit of constant input */
} TsengAdaptiveCoef;

/* coefficients(params, disc): the complementary filter disc (TSENG_ORDER states) with the method's
 * resolved parameters; Mahony's gains are checked at disc->Ts by the caller (mahony_check_gains). */
void tseng_adaptive_coefficients(const double params[AF_N_PARAMS], const DiscreteFilter *disc,
                                 TsengAdaptiveCoef *coef);

/* At rest on acc0 (m/s^2), q the identity, no bias. */
void tseng_adaptive_initial_state(const TsengAdaptiveCoef *coef, const double acc0[3], TsengAdaptiveState *state);

/* run on one sample: writes the gravity estimate (m/s^2) and q. */
void tseng_adaptive_run(TsengAdaptiveState *state, const TsengAdaptiveCoef *coef, const double gyr[3],
                        const double acc[3], double gravity[3], double quat[4]);

#endif
