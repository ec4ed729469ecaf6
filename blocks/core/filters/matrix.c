/* matrix.c: the matrix exponential and a linear solve (see matrix.h). */
#include "matrix.h"

#include <math.h>
#include <string.h>

void solve(int n, double *A, int m, double *B)
{
    int i, j, k;
    for (k = 0; k < n; k++) {
        int pivot = k;
        for (i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > fabs(A[pivot * n + k])) pivot = i;
        if (pivot != k) {
            for (j = 0; j < n; j++) {
                double t = A[k * n + j];
                A[k * n + j] = A[pivot * n + j];
                A[pivot * n + j] = t;
            }
            for (j = 0; j < m; j++) {
                double t = B[k * m + j];
                B[k * m + j] = B[pivot * m + j];
                B[pivot * m + j] = t;
            }
        }
        for (i = k + 1; i < n; i++) {
            double l = A[i * n + k] / A[k * n + k];
            for (j = k + 1; j < n; j++) A[i * n + j] -= l * A[k * n + j];
            for (j = 0; j < m; j++) B[i * m + j] -= l * B[k * m + j];
        }
    }
    for (k = n - 1; k >= 0; k--)
        for (j = 0; j < m; j++) {
            double s = B[k * m + j];
            for (i = k + 1; i < n; i++) s -= A[k * n + i] * B[i * m + j];
            B[k * m + j] = s / A[k * n + k];
        }
}

static void multiply(int n, const double *P, const double *Q, double *R)
{
    int i, j, k;
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) {
            double s = 0.0;
            for (k = 0; k < n; k++) s += P[i * n + k] * Q[k * n + j];
            R[i * n + j] = s;
        }
}

static double norm1(int n, const double *M)
{
    double largest = 0.0;
    int i, j;
    for (j = 0; j < n; j++) {
        double column = 0.0;
        for (i = 0; i < n; i++) column += fabs(M[i * n + j]);
        if (column > largest) largest = column;
    }
    return largest;
}

/* the coefficients b_0 ... b_m of the diagonal Pade approximants, and the largest 1-norm
 * each is accurate to double precision for (Higham 2005, Table 2.3) */
static const double PADE3[] = {120.0, 60.0, 12.0, 1.0};
static const double PADE5[] = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
static const double PADE7[] = {17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0};
static const double PADE9[] = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0, 30270240.0,
                               2162160.0, 110880.0, 3960.0, 90.0, 1.0};
static const double PADE13[] = {64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                                1187353796428800.0, 129060195264000.0, 10559470521600.0, 670442572800.0,
                                33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0};
static const struct {
    int degree;
    double theta;
    const double *b;
} PADE[] = {{3, 1.495585217958292e-2, PADE3}, {5, 2.539398330063230e-1, PADE5},
            {7, 9.504178996162932e-1, PADE7}, {9, 2.097847961257068e0, PADE9},
            {13, 5.371920351148152e0, PADE13}};

void expm_work(int n, const double *M, double *E, double *work)
{
    const int nn = n * n;
    double *A = work, *power[5], *U = work + 6 * nn, *V = work + 7 * nn, *T = work + 8 * nn; /* A^0, A^2, ... A^8 */
    double norm = norm1(n, M);
    int choice = 0, squarings = 0, top, i, k;
    const double *b;
    for (k = 0; k < 5; k++) power[k] = work + (1 + k) * nn;
    while (choice < 4 && norm > PADE[choice].theta) choice++;
    if (choice == 4 && norm > PADE[4].theta) squarings = (int)ceil(log2(norm / PADE[4].theta));
    for (i = 0; i < nn; i++) A[i] = ldexp(M[i], -squarings);
    b = PADE[choice].b;
    for (i = 0; i < nn; i++) power[0][i] = i % (n + 1) == 0 ? 1.0 : 0.0;
    multiply(n, A, A, power[1]);
    top = PADE[choice].degree == 13 ? 3 : (PADE[choice].degree - 1) / 2; /* the even powers needed */
    for (k = 2; k <= top; k++) multiply(n, power[k - 1], power[1], power[k]);
    for (i = 0; i < nn; i++) U[i] = V[i] = 0.0;
    if (PADE[choice].degree < 13) {
        /* U = A sum b_{2k+1} A^2k, V = sum b_2k A^2k */
        for (k = 0; k <= top; k++)
            for (i = 0; i < nn; i++) {
                U[i] += b[2 * k + 1] * power[k][i];
                V[i] += b[2 * k] * power[k][i];
            }
        memcpy(T, U, sizeof(double) * nn);
        multiply(n, A, T, U);
    } else {
        /* degree 13 from A^2, A^4, A^6 (Higham 2005, eq. 2.7):
         * U = A (A^6 (b13 A^6 + b11 A^4 + b9 A^2) + b7 A^6 + b5 A^4 + b3 A^2 + b1 I),
         * V = A^6 (b12 A^6 + b10 A^4 + b8 A^2) + b6 A^6 + b4 A^4 + b2 A^2 + b0 I */
        double *W = work + 9 * nn, *Z = work + 10 * nn;
        for (i = 0; i < nn; i++) {
            W[i] = b[13] * power[3][i] + b[11] * power[2][i] + b[9] * power[1][i];
            Z[i] = b[12] * power[3][i] + b[10] * power[2][i] + b[8] * power[1][i];
        }
        multiply(n, power[3], W, T);
        for (i = 0; i < nn; i++)
            W[i] = T[i] + b[7] * power[3][i] + b[5] * power[2][i] + b[3] * power[1][i] + b[1] * power[0][i];
        multiply(n, A, W, U);
        multiply(n, power[3], Z, T);
        for (i = 0; i < nn; i++)
            V[i] = T[i] + b[6] * power[3][i] + b[4] * power[2][i] + b[2] * power[1][i] + b[0] * power[0][i];
    }
    /* (V - U) E = (V + U) */
    for (i = 0; i < nn; i++) {
        T[i] = V[i] - U[i];
        E[i] = V[i] + U[i];
    }
    solve(n, T, n, E);
    for (k = 0; k < squarings; k++) {
        memcpy(T, E, sizeof(double) * nn);
        multiply(n, T, T, E);
    }
}

void zero_order_hold(int n, int m, const double *A, const double *B, double h, double *Ad, double *Bd, double *work)
{
    const int s = n + m;
    double *M = work, *E = work + s * s;
    int i, j;
    for (i = 0; i < s * s; i++) M[i] = 0.0;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) M[i * s + j] = h * A[i * n + j];
        for (j = 0; j < m; j++) M[i * s + n + j] = h * B[i * m + j];
    }
    expm_work(s, M, E, work + 2 * s * s);
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) Ad[i * n + j] = E[i * s + j];
        for (j = 0; j < m; j++) Bd[i * m + j] = E[i * s + n + j];
    }
}
