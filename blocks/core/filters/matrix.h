/* matrix.h: the two matrix functions the zero-order hold needs, for matrices of at most
 * MATRIX_MAX rows (row-major, n x n), as scipy.linalg.expm and numpy.linalg.solve compute them
 * for control.c2d. */
#ifndef AF_MATRIX_H
#define AF_MATRIX_H

#include "filters/earth_filters.h"

#define MATRIX_MAX (MAX_ORDER + 1) /* an earth filter's A with its B beside it */

/* X = A^-1 B by Gaussian elimination with partial pivoting (LAPACK's dgesv); B is n x m
 * (row-major), overwritten by X; A is overwritten by its factors. */
void solve(int n, double *A, int m, double *B);

/* E = exp(M) by scaling and squaring with a diagonal Pade approximant of degree 3 to 13
 * chosen by the 1-norm of M (Higham 2005; scipy.linalg.expm refines the choice from norms of
 * powers of M, Al-Mohy and Higham 2009: the two agree to rounding); M and E n x n, distinct. */
void expm(int n, const double *M, double *E);

#endif
