/* scale_error.c: candidate scale errors scored in one pass (see scale_error.h). */
#include "stages/scale_error.h"

#include <string.h>

size_t scale_error_errors(const WienerLocalCoef *warm, const WienerLocalCoef *coefs, size_t count, size_t n,
                          size_t warm_up, const double *gyr, const double *acc, const double start[3], size_t m,
                          size_t block, double *gravity, double *work, double *means)
{
    WienerLocalState states[PREDICTION_MAX_COUNT];
    size_t first = warm_up >= m ? warm_up - m : 0;
    if (count == 0 || count > PREDICTION_MAX_COUNT || warm_up > n) return 0;
    wiener_local_initial_state(warm, start, &states[0]);
    if (warm_up > 0) { /* the warm-up, its estimates each candidate's before warm_up */
        wiener_local_gravities(&states[0], warm, 1, warm_up, gyr, acc, gravity, 3 * n);
        for (size_t c = 1; c < count; c++)
            memcpy(gravity + 3 * (c * n + first), gravity + 3 * first, 3 * (warm_up - first) * sizeof(double));
    }
    for (size_t c = 1; c < count; c++) states[c] = states[0];
    wiener_local_gravities(states, coefs, count, n - warm_up, gyr + 3 * warm_up, acc + 3 * warm_up,
                           gravity + 3 * warm_up, 3 * n);
    return prediction_errors_of(count, n - first, gyr + 3 * first, acc + 3 * first, gravity + 3 * first, 3 * n,
                                warm->Ts, m, block, work, means);
}
