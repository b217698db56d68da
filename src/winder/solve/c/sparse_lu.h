#ifndef WINDER_SPARSE_LU_H
#define WINDER_SPARSE_LU_H

/* LU of W = diag/(h gamma) - J on the Jacobian's sparsity (rodas3.c).
 *
 * The pattern: the union of the nonzeros of every Jacobian seen in a run (plus the
 * diagonal); it only grows (a contact that closes adds its terms), and each growth
 * recomputes the ordering and the symbolic factorisation (rare: a few times per run).
 * The ordering: by degree (row + column nonzeros), ascending, ties by index: the states
 * that couple to everything (a drum's angle, the set's radius) come last and the chains
 * of segments first, so the fill stays small (flexible two-drum winder, 309 states: 3.9k
 * nonzeros, 8.1k after fill, 72k multiply-adds against 9.8M for the dense LU; scipy's
 * MMD/COLAMD orderings gave 25k-36k). No pivoting on this static pattern: a pivot below
 * 1e-12 of its row's largest entry (or not finite) falls back to the dense LU with
 * partial pivoting for that factorisation (counted in slu->dense_factors).
 *
 * Storage: compressed rows in the permuted order, L (below the diagonal) and U (above
 * it) each as column indices and values, the pivots' inverses apart; a row is factored
 * in a dense work row of n values (the updates of its L entries scatter there, in L1),
 * then gathered back. */

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dense_lu.h"

typedef struct {
    int64_t n;
    unsigned char* pat;  /* n x n, pat[r + n * c]: J[r, c] may be nonzero (original order,
                          * column-major as the generated Jacobian) */
    int64_t* perm;       /* position -> original index */
    int64_t* lptr;       /* n + 1: row i's L columns lidx[lptr[i] .. lptr[i+1]) ascending */
    int32_t* lidx;       /* (32-bit: half the index traffic of the solves) */
    int64_t* uptr;       /* row i's U columns (> i) */
    int32_t* uidx;
    double* W;           /* n x n: the dense fallback's matrix */
    double* lval;        /* L's values, as lidx */
    double* uval;        /* U's values, as uidx */
    double* dinv;        /* 1 / the pivots */
    double* x;           /* work vector */
    int64_t* piv;        /* the dense fallback's pivots */
    int dense;           /* the current factorisation is the dense fallback */
    int dirty;           /* the pattern grew: ordering and symbolic factorisation anew */
    int64_t fill;        /* nonzeros of L + U (diagonal included) */
    int64_t dense_factors, symbolic;
} Slu;

static void slu_free(Slu* s) {
    free(s->pat); free(s->perm); free(s->lptr); free(s->lidx); free(s->uptr);
    free(s->uidx); free(s->W); free(s->lval); free(s->uval); free(s->dinv); free(s->x); free(s->piv);
    memset(s, 0, sizeof(*s));
}

static int slu_init(Slu* s, int64_t n) {
    memset(s, 0, sizeof(*s));
    s->n = n;
    size_t nn = (size_t)n * (size_t)n;
    s->pat = calloc(nn, 1);
    s->perm = malloc(sizeof(int64_t) * (size_t)n);
    s->lptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
    s->uptr = malloc(sizeof(int64_t) * (size_t)(n + 1));
    s->W = malloc(sizeof(double) * nn);
    s->dinv = malloc(sizeof(double) * (size_t)n);
    s->x = calloc((size_t)n, sizeof(double));
    s->piv = malloc(sizeof(int64_t) * (size_t)n);
    if (!s->pat || !s->perm || !s->lptr || !s->uptr || !s->W || !s->dinv || !s->x
        || !s->piv) {
        slu_free(s);
        return 0;
    }
    for (int64_t i = 0; i < n; i++)
        s->pat[i * n + i] = 1;
    s->dirty = 1;
    return 1;
}

/* Add the nonzeros of the column-major Jacobian to the pattern (one pass in memory
 * order; branch-free). */
static void slu_observe(Slu* s, const double* jac) {
    int64_t nn = s->n * s->n;
    unsigned char* pat = s->pat;
    unsigned char grew = 0;
    for (int64_t q = 0; q < nn; q++) {
        unsigned char nz = jac[q] != 0.0;
        grew |= nz & (unsigned char)!pat[q];
        pat[q] |= nz;
    }
    if (grew)
        s->dirty = 1;
}

/* The ordering and the symbolic factorisation of the current pattern; 0: no memory. */
static int slu_symbolic(Slu* s) {
    int64_t n = s->n;
    int64_t* deg = malloc(sizeof(int64_t) * (size_t)(3 * n + 2));
    unsigned char* F = malloc((size_t)n * (size_t)n);  /* the filled pattern, permuted */
    if (!deg || !F) {
        free(deg);
        free(F);
        return 0;
    }
    for (int64_t i = 0; i < n; i++) {
        deg[i] = 0;
        for (int64_t j = 0; j < n; j++)
            deg[i] += s->pat[i + n * j] + s->pat[j + n * i];
    }
    int64_t* start = deg + n;  /* a counting sort by degree (<= 2n), stable: reentrant */
    memset(start, 0, sizeof(int64_t) * (size_t)(2 * n + 2));
    for (int64_t i = 0; i < n; i++)
        start[deg[i] + 1]++;
    for (int64_t d = 1; d <= 2 * n + 1; d++)
        start[d] += start[d - 1];
    for (int64_t i = 0; i < n; i++)
        s->perm[start[deg[i]]++] = i;
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < n; j++)
            F[i * n + j] = s->pat[s->perm[i] + n * s->perm[j]];
    int64_t nl = 0, nu = 0;
    for (int64_t i = 0; i < n; i++) {  /* row i takes the U pattern of every k in its L */
        for (int64_t k = 0; k < i; k++) {
            if (!F[i * n + k])
                continue;
            nl++;
            for (int64_t j = k + 1; j < n; j++)
                F[i * n + j] |= F[k * n + j];
        }
        for (int64_t j = i + 1; j < n; j++)
            nu += F[i * n + j];
    }
    free(s->lidx);
    free(s->uidx);
    free(s->lval);
    free(s->uval);
    s->lidx = malloc(sizeof(int32_t) * (size_t)(nl + 1));
    s->uidx = malloc(sizeof(int32_t) * (size_t)(nu + 1));
    s->lval = malloc(sizeof(double) * (size_t)(nl + 1));
    s->uval = malloc(sizeof(double) * (size_t)(nu + 1));
    if (!s->lidx || !s->uidx || !s->lval || !s->uval) {
        free(deg);
        free(F);
        return 0;
    }
    nl = nu = 0;
    for (int64_t i = 0; i < n; i++) {
        s->lptr[i] = nl;
        s->uptr[i] = nu;
        for (int64_t k = 0; k < i; k++)
            if (F[i * n + k])
                s->lidx[nl++] = (int32_t)k;
        for (int64_t j = i + 1; j < n; j++)
            if (F[i * n + j])
                s->uidx[nu++] = (int32_t)j;
    }
    s->lptr[n] = nl;
    s->uptr[n] = nu;
    s->fill = nl + nu + n;
    s->dirty = 0;
    s->symbolic++;
    free(deg);
    free(F);
    return 1;
}

/* Factor W = d I - J (jac column-major); 0 if singular (or no memory: *nomem). */
static int slu_factor(Slu* s, const double* jac, double d, int* nomem) {
    int64_t n = s->n;
    const int64_t* P = s->perm;
    double* W = s->W;
    *nomem = 0;
    if (s->dirty && !slu_symbolic(s)) {
        *nomem = 1;
        return 0;
    }
    s->dense = 0;
    double* x = s->x;  /* the dense work row: zero outside a row's factorisation */
    const int64_t *lp = s->lptr, *up = s->uptr;
    const int32_t *li = s->lidx, *ui = s->uidx;
    double *lv = s->lval, *uv = s->uval;
    for (int64_t i = 0; i < n; i++) {
        const double* Jr = jac + P[i];  /* row P[i] of the column-major Jacobian */
        double big = fabs(d - Jr[n * P[i]]);
        x[i] = d - Jr[n * P[i]];
        for (int64_t q = lp[i]; q < lp[i + 1]; q++)
            x[li[q]] = -Jr[n * P[li[q]]];
        for (int64_t q = up[i]; q < up[i + 1]; q++)
            x[ui[q]] = -Jr[n * P[ui[q]]];
        for (int64_t q = lp[i]; q < lp[i + 1]; q++) {  /* ascending k */
            int64_t kk = li[q];
            double l = x[kk] * s->dinv[kk];
            x[kk] = 0.0;
            lv[q] = l;
            if (fabs(l) > big)
                big = fabs(l);
            if (l != 0.0)
                for (int64_t u = up[kk]; u < up[kk + 1]; u++)
                    x[ui[u]] -= l * uv[u];
        }
        for (int64_t q = up[i]; q < up[i + 1]; q++) {
            uv[q] = x[ui[q]];
            x[ui[q]] = 0.0;
        }
        double piv = x[i];
        x[i] = 0.0;
        if (!isfinite(piv) || !(fabs(piv) > 1e-12 * big))
            goto dense;
        s->dinv[i] = 1.0 / piv;
    }
    return 1;
dense:  /* a small pivot on the static pattern: the dense LU with partial pivoting */
    memset(x, 0, sizeof(double) * (size_t)n);
    s->dense = 1;
    s->dense_factors++;
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < n; j++)
            W[i * n + j] = (i == j ? d : 0.0) - jac[i + n * j];
    return lu(n, W, s->piv);
}

/* b := W^-1 b. */
static void slu_solve(const Slu* s, double* b) {
    int64_t n = s->n;
    const double* W = s->W;
    if (s->dense) {
        lu_solve(n, W, s->piv, b);
        return;
    }
    double* x = s->x;
    const int64_t* P = s->perm;
    const int64_t *lp = s->lptr, *up = s->uptr;
    const int32_t *li = s->lidx, *ui = s->uidx;
    const double *lv = s->lval, *uv = s->uval;
    for (int64_t i = 0; i < n; i++) {
        double v = b[P[i]];
        for (int64_t q = lp[i]; q < lp[i + 1]; q++)
            v -= lv[q] * x[li[q]];
        x[i] = v;
    }
    for (int64_t i = n - 1; i >= 0; i--) {
        double v = x[i];
        for (int64_t q = up[i]; q < up[i + 1]; q++)
            v -= uv[q] * x[ui[q]];
        x[i] = v * s->dinv[i];
    }
    for (int64_t i = 0; i < n; i++) {
        b[P[i]] = x[i];
        x[i] = 0.0;  /* the work row stays zero for the next factorisation */
    }
}

#endif
