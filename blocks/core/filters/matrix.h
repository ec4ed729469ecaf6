/* matrix.h: the two matrix functions the zero-order hold needs (row-major, n x n), as
 * scipy.linalg.expm and numpy.linalg.solve compute them for control.c2d, and the hold itself,
 * for any size, in a workspace the caller gives. */
#ifndef AF_MATRIX_H
#define AF_MATRIX_H

/* X = A^-1 B by Gaussian elimination with partial pivoting (LAPACK's dgesv); B is n x m
 * (row-major), overwritten by X; A is overwritten by its factors. */
void solve(int n, double *A, int m, double *B);

#define EXPM_WORK(n) (11 * (n) * (n)) /* doubles of expm_work's workspace */

/* E = exp(M) by scaling and squaring with a diagonal Pade approximant of degree 3 to 13
 * chosen by the 1-norm of M (Higham 2005; scipy.linalg.expm refines the choice from norms of
 * powers of M, Al-Mohy and Higham 2009: the two agree to rounding); M and E n x n, distinct;
 * work EXPM_WORK(n) doubles, apart from M and E. */
void expm_work(int n, const double *M, double *E, double *work);

#define ZERO_ORDER_HOLD_WORK(n, m) (2 * ((n) + (m)) * ((n) + (m)) + EXPM_WORK((n) + (m))) /* doubles */

/* control.c2d(ss(A, B, ...), h, "zoh"): Ad (n x n) and Bd (n x m) of dx/dt = A x + B u held over
 * h (s), the blocks of exp([[A, B], [0, 0]] h); A n x n, B n x m (Ad, Bd may be A, B: held in place);
 * work ZERO_ORDER_HOLD_WORK(n, m) doubles, apart from the others. */
void zero_order_hold(int n, int m, const double *A, const double *B, double h, double *Ad, double *Bd,
                     double *work);

#endif
