/* Dense LU with partial pivoting and its solve: ros2.c's factorisation, and the fallback of
 * sparse_lu.h's (RODAS) where a pivot on the static pattern is too small. */
#ifndef WINDER_DENSE_LU_H
#define WINDER_DENSE_LU_H

#include <math.h>
#include <stdint.h>

/* In-place LU with partial pivoting of the row-major n x n A; 0 if singular. */
static int lu(int64_t n, double* A, int64_t* piv) {
    for (int64_t k = 0; k < n; k++) {
        int64_t p = k;
        double big = fabs(A[k * n + k]);
        for (int64_t i = k + 1; i < n; i++) {
            if (fabs(A[i * n + k]) > big) {
                big = fabs(A[i * n + k]);
                p = i;
            }
        }
        if (big == 0.0 || !isfinite(big))
            return 0;
        piv[k] = p;
        if (p != k) {
            for (int64_t j = 0; j < n; j++) {
                double a = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = a;
            }
        }
        double inv = 1.0 / A[k * n + k];
        for (int64_t i = k + 1; i < n; i++) {
            A[i * n + k] *= inv;
            double f = A[i * n + k];
            if (f != 0.0)
                for (int64_t j = k + 1; j < n; j++)
                    A[i * n + j] -= f * A[k * n + j];
        }
    }
    return 1;
}

static void lu_solve(int64_t n, const double* LU, const int64_t* piv, double* b) {
    for (int64_t k = 0; k < n; k++) {
        int64_t p = piv[k];
        if (p != k) {
            double a = b[k];
            b[k] = b[p];
            b[p] = a;
        }
    }
    for (int64_t i = 0; i < n; i++) {
        double s = b[i];
        for (int64_t j = 0; j < i; j++)
            s -= LU[i * n + j] * b[j];
        b[i] = s;
    }
    for (int64_t i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int64_t j = i + 1; j < n; j++)
            s -= LU[i * n + j] * b[j];
        b[i] = s / LU[i * n + i];
    }
}

#endif
