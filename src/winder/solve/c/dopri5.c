/* DOPRI5 in C: solve/dopri5.py line by line (Hairer's DOPRI5: tableau, error estimate,
 * 4th-order dense output and step control of scipy's RK45) with the machine's locked
 * modes and their located switches (events.h). */

#include "events.h"

/* Dormand-Prince 5(4) tableau */
#define C2 (1.0 / 5.0)
#define C3 (3.0 / 10.0)
#define C4 (4.0 / 5.0)
#define C5 (8.0 / 9.0)
#define A21 (1.0 / 5.0)
#define A31 (3.0 / 40.0)
#define A32 (9.0 / 40.0)
#define A41 (44.0 / 45.0)
#define A42 (-56.0 / 15.0)
#define A43 (32.0 / 9.0)
#define A51 (19372.0 / 6561.0)
#define A52 (-25360.0 / 2187.0)
#define A53 (64448.0 / 6561.0)
#define A54 (-212.0 / 729.0)
#define A61 (9017.0 / 3168.0)
#define A62 (-355.0 / 33.0)
#define A63 (46732.0 / 5247.0)
#define A64 (49.0 / 176.0)
#define A65 (-5103.0 / 18656.0)
#define A71 (35.0 / 384.0)
#define A73 (500.0 / 1113.0)
#define A74 (125.0 / 192.0)
#define A75 (-2187.0 / 6784.0)
#define A76 (11.0 / 84.0)
#define E1 (71.0 / 57600.0)
#define E3 (-71.0 / 16695.0)
#define E4 (71.0 / 1920.0)
#define E5 (-17253.0 / 339200.0)
#define E6 (22.0 / 525.0)
#define E7 (-1.0 / 40.0)
#define D1 (-12715105075.0 / 11282082432.0)
#define D3 (87487479700.0 / 32700410799.0)
#define D4 (-10690763975.0 / 1880347072.0)
#define D5 (701980252875.0 / 199316789632.0)
#define D6 (-1453857185.0 / 822651844.0)
#define D7 (69997945.0 / 29380423.0)

/* Integrate y from t0 to t1 (solve/dopri5.py: the same arguments, statuses and
 * results). Returns the status; *t_out_, *h_out, *k_out: the time reached, the next
 * step, the samples written. */
int winder_dopri5(const int64_t* fns, const int64_t* table, int64_t nslots,
                  int64_t n_switches, double t0, double t1, double* y, int64_t n,
                  const double* p, double* m, double rtol, double atol, double h,
                  double max_step, const double* t_out, int64_t n_out, double* Y_out,
                  int64_t k, int64_t budget, int64_t* stats, int64_t nstats,
                  double* t_res, double* h_res, int64_t* k_res) {
    Ctx ctx, *cx = &ctx;
    double* v[13];
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 13))
        return NO_MEMORY;
    double *k1 = v[0], *k2 = v[1], *k3 = v[2], *k4 = v[3], *k5 = v[4], *k6 = v[5],
           *k7 = v[6], *y1 = v[7], *rc = v[8];
    double* yt = cx->yt;
    double t = t0;
    modes_of(cx, t, y, 0);
    evaluate(cx, F_RHS, t, y, k1);
    int64_t nfev = 1;
    if (h <= 0.0)
        h = first_step(n, y, k1, rtol, atol);
    int rejected_last = 0;
    int status = DONE;
    while (t < t1) {
        if (nfev >= budget) {
            status = PAUSED;
            break;
        }
        double hh = pmin(h, max_step);
        if (t + 1.01 * hh >= t1) {
            hh = t1 - t;
            if (hh < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
                k = sliver(n, t, t1, y, k1, t_out, n_out, Y_out, k);
                t = t1;
                break;
            }
        }
        if (hh < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
            status = STEP_UNDERFLOW;
            break;
        }
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + hh * A21 * k1[i];
        evaluate(cx, F_RHS, t + C2 * hh, yt, k2);
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + hh * (A31 * k1[i] + A32 * k2[i]);
        evaluate(cx, F_RHS, t + C3 * hh, yt, k3);
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + hh * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        evaluate(cx, F_RHS, t + C4 * hh, yt, k4);
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + hh * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        evaluate(cx, F_RHS, t + C5 * hh, yt, k5);
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + hh * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i]
                                 + A65 * k5[i]);
        evaluate(cx, F_RHS, t + hh, yt, k6);
        for (int64_t i = 0; i < n; i++)
            y1[i] = y[i] + hh * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i]
                                 + A76 * k6[i]);
        evaluate(cx, F_RHS, t + hh, y1, k7);
        nfev += 6;
        double err = 0.0;
        for (int64_t i = 0; i < n; i++) {
            double sk = atol + rtol * pmax(fabs(y[i]), fabs(y1[i]));
            double ei = hh * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i]
                              + E6 * k6[i] + E7 * k7[i]);
            double r = ei / sk;
            err += r * r;
        }
        err = sqrt(err / (double)n);
        if (!isfinite(err)) {
            stats[2] += 1;
            h = 0.1 * hh;
            if (h < 1e-14 * pmax(1.0, fabs(t))) {
                status = NON_FINITE;
                break;
            }
            rejected_last = 1;
            continue;
        }
        if (err > 1.0) {
            stats[2] += 1;
            h = hh * pmax(0.2, 0.9 * pow(err, -0.2));
            rejected_last = 1;
            continue;
        }
        if (nstats > 4) {
            double stnum = 0.0, stden = 0.0;
            for (int64_t i = 0; i < n; i++) {
                double a = k7[i] - k6[i], b = y1[i] - yt[i];
                stnum += a * a;
                stden += b * b;
            }
            if (stden > 0.0 && hh * hh * stnum > 3.25 * 3.25 * stden)
                stats[4] += 1;
        }
        for (int64_t i = 0; i < n; i++) {
            double dyi = y1[i] - y[i];
            double bspl = hh * k1[i] - dyi;
            rc[i] = y[i];
            rc[n + i] = dyi;
            rc[2 * n + i] = bspl;
            rc[3 * n + i] = dyi - hh * k7[i] - bspl;
            rc[4 * n + i] = hh * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i]
                                  + D6 * k6[i] + D7 * k7[i]);
        }
        double new_mode, t_end;
        int64_t slot = sample_and_switch(cx, rc, t, hh, t1, y, y1, t_out, n_out, Y_out, &k,
                                         &new_mode, &t_end);
        stats[1] += 1;
        int switched;
        status = end_of_step(cx, slot, new_mode, t_end, y, k1, &t, &nfev, stats, &switched);
        if (status != DONE)
            break;
        if (switched) {
            cx->start_ok = 0;
            h = hh;
            rejected_last = 0;
            continue;
        }
        for (int64_t i = 0; i < n; i++) {
            y[i] = y1[i];
            k1[i] = k7[i];
        }
        step_continues(cx, t + hh < t1);
        t = t + hh < t1 ? t + hh : t1;
        double fac = 0.9 * pow(pmax(err, 1e-10), -0.2);
        fac = rejected_last ? pmin(fac, 1.0) : pmin(fac, 10.0);
        h = hh * pmax(0.2, fac);
        rejected_last = 0;
    }
    stats[0] += nfev;
    if (nstats > 7) {  /* where asked for: the switches' cost (events.h, Ctx) */
        stats[5] += cx->n_sw;
        stats[6] += cx->n_sw_locate;
        stats[7] += cx->n_locate;
    }
    free(cx->g);
    *t_res = t;
    *h_res = h;
    *k_res = k;
    return status;
}
