/* errors.c: the attitude error per sample (see errors.h). */
#include "errors.h"

#include <math.h>

#include "quaternion.h"

double attitude_error(const double ghat[3], const double q[4])
{
    double r[9];
    quat_matrix(quat_load(q), r);
    {
        const double *up = r + 6; /* the third row: earth up in sensor coordinates */
        double cx = ghat[1] * up[2] - ghat[2] * up[1];
        double cy = ghat[2] * up[0] - ghat[0] * up[2];
        double cz = ghat[0] * up[1] - ghat[1] * up[0];
        return atan2(sqrt(cx * cx + cy * cy + cz * cz), ghat[0] * up[0] + ghat[1] * up[1] + ghat[2] * up[2]);
    }
}
