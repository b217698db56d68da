/* The machine's locked modes and result channels over a whole trajectory, for the Python
 * side (what the numba helpers of solve/system.py did): the same modes_of and the same
 * generated `out` as the integrators (events.h). */

#include "events.h"

/* The modes a step starting at (t, y) runs in, into m (nslots). contact_auto: nips in
 * AUTO (the clamped law, RK4). Returns NO_MEMORY or DONE. */
int winder_modes(const int64_t* fns, const int64_t* table, int64_t nslots,
                 int64_t n_switches, double t, const double* y, int64_t n, const double* p,
                 double* m, int64_t contact_auto) {
    Ctx ctx, *cx = &ctx;
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, NULL, 0))
        return NO_MEMORY;
    modes_of(cx, t, y, contact_auto != 0);
    free(cx->g);
    return DONE;
}

/* The channels at every sample: out (n_channels, n_t) row-major from Y (n, n_t)
 * row-major, the modes of each sample from its state with nips in AUTO (the clamped
 * law) as the result's channels are defined. m: nslots of work space. */
int winder_channels(const int64_t* fns, const int64_t* table, int64_t nslots,
                    int64_t n_switches, const double* t, int64_t n_t, const double* Y,
                    int64_t n, const double* p, double* m, double* out,
                    int64_t n_channels) {
    Ctx ctx, *cx = &ctx;
    double* v[2];
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 2))
        return NO_MEMORY;
    double* y = v[0];
    double* col = malloc(sizeof(double) * (size_t)(n_channels > 0 ? n_channels : 1));
    if (!col) {
        free(cx->g);
        return NO_MEMORY;
    }
    for (int64_t i = 0; i < n_t; i++) {
        for (int64_t j = 0; j < n; j++)
            y[j] = Y[j * n_t + i];
        modes_of(cx, t[i], y, 1);
        evaluate(cx, F_OUT, t[i], y, col);
        for (int64_t j = 0; j < n_channels; j++)
            out[j * n_t + i] = col[j];
    }
    free(col);
    free(cx->g);
    return DONE;
}

/* count evaluations of the generated function fns[which] at one point, called as the
 * integrators call it (the benchmarks' cost per evaluation); returns the sum of out[0]
 * so that no call can be optimised away. */
double winder_repeat(const int64_t* fns, int64_t which, int64_t count, double t,
                     const double* y, const double* p, const double* m, double* out) {
    wfn f = (wfn)(intptr_t)fns[which];
    double tb[1] = {t};
    double acc = 0.0;
    for (int64_t i = 0; i < count; i++) {
        f(tb, y, p, m, out);
        acc += out[0];
    }
    return acc;
}
