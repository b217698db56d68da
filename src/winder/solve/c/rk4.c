/* Classical fixed-step RK4 in C: solve/rk4.py line by line (for real-time stepping): the
 * clamped nip law without contact event location; the core events of spec 2 located on
 * the step's cubic Hermite interpolant; the penetration guard (events.h). */

#include "events.h"

/* Cubic Hermite interpolant of a step of length h at s in [0, 1]. */
static void hermite(int64_t n, const double* y0, const double* f0, const double* y1,
                    const double* f1, double h, double s, double* out) {
    double s2 = s * s, s3 = s * s2;  /* numba's s ** 2 and s ** 3 */
    double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s;
    double h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
    for (int64_t i = 0; i < n; i++)
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
}

/* RK4 with steps of at most h evenly dividing [t0, t1] (solve/rk4.py: the same
 * arguments, statuses and results). Returns the status; *t_res, *h_res, *k_res: the
 * time reached, the step taken, the samples written. */
int winder_rk4(const int64_t* fns, const int64_t* table, int64_t nslots,
               int64_t n_switches, double t0, double t1, double* y, int64_t n,
               const double* p, double* m, double h, const double* t_out, int64_t n_out,
               double* Y_out, int64_t k, int64_t* stats, double* t_res, double* h_res,
               int64_t* k_res) {
    Ctx ctx, *cx = &ctx;
    double* v[10];
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 10))
        return NO_MEMORY;
    cx->legacy_probe = 1; /* bit-equal to its recorded traces (events.h, guard_step) */
    double *k1 = v[0], *k2 = v[1], *k3 = v[2], *k4 = v[3], *y1 = v[4], *rc = v[5];
    double* yt = cx->yt;
    modes_of(cx, t0, y, 1);
    evaluate(cx, F_RHS, t0, y, k1);
    int64_t nfev = 1;
    double t = t0;
    double hh = h;
    int status = DONE;
    while (t < t1 && status == DONE) {
        if (t1 - t < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
            k = sliver(n, t, t1, y, k1, t_out, n_out, Y_out, k);
            t = t1;
            break;
        }
        int64_t steps = (int64_t)ceil((t1 - t) / h - 1e-9);
        if (steps < 1)
            steps = 1;
        double ts = t;
        hh = (t1 - ts) / (double)steps;
        for (int64_t j = 0; j < steps; j++) {
            double tn = j == steps - 1 ? t1 : ts + (double)(j + 1) * hh;
            double hs = tn - t;
            for (int64_t i = 0; i < n; i++)
                yt[i] = y[i] + 0.5 * hs * k1[i];
            evaluate(cx, F_RHS, t + 0.5 * hs, yt, k2);
            for (int64_t i = 0; i < n; i++)
                yt[i] = y[i] + 0.5 * hs * k2[i];
            evaluate(cx, F_RHS, t + 0.5 * hs, yt, k3);
            for (int64_t i = 0; i < n; i++)
                yt[i] = y[i] + hs * k3[i];
            evaluate(cx, F_RHS, t + hs, yt, k4);
            for (int64_t i = 0; i < n; i++)
                y1[i] = y[i] + hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            evaluate(cx, F_RHS, tn, y1, k2); /* f at the step end (next k1) */
            nfev += 4;
            stats[1] += 1;
            int ok = 1;
            for (int64_t i = 0; i < n; i++)
                if (!isfinite(y1[i]))
                    ok = 0;
            if (!ok) {
                status = NON_FINITE;
                break;
            }
            /* core events (spec 2): first point of the interpolant on the new side */
            int64_t slot;
            double new_mode;
            next_event(cx, rc, t, hs, y1, 0, &slot, &new_mode);
            double theta = 1.0;
            if (slot >= 0) {
                int64_t gi = (new_mode == AT_CORE || new_mode == END) ? TAB(slot, 1)
                                                                      : TAB(slot, 2);
                double ta = 0.0, tb_ = 1.0;
                for (int it = 0; it < 60; it++) {
                    double th = 0.5 * (ta + tb_);
                    hermite(n, y, k1, y1, k2, hs, th, yt);
                    if (switch_at(cx, gi, t + th * hs, yt, cx->g) > 0.0)
                        tb_ = th;
                    else
                        ta = th;
                }
                theta = tb_;
            }
            for (int64_t i = 0; i < n; i++) { /* the step's cubic Hermite, DOPRI5's form */
                rc[i] = y[i];
                rc[n + i] = y1[i] - y[i];
                rc[2 * n + i] = hs * k1[i] - rc[n + i];
                rc[3 * n + i] = rc[n + i] - hs * k2[i] - rc[2 * n + i];
                rc[4 * n + i] = 0.0;
            }
            double theta_guard = guard_step(cx, rc, t, hs, theta, y, y1, t_out, n_out, k,
                                            slot < 0);
            if (theta_guard <= theta) {
                t = t + theta_guard * hs;
                status = PENETRATED;
                break;
            }
            double t_end = t + theta * hs;
            while (k < n_out && t_out[k] <= t_end + 1e-13 * pmax(1.0, fabs(t_end))) {
                hermite(n, y, k1, y1, k2, hs, pmin(theta, pmax(0.0, (t_out[k] - t) / hs)),
                        yt);
                for (int64_t i = 0; i < n; i++)
                    Y_out[i * n_out + k] = yt[i];
                k++;
            }
            if (slot < 0) {
                for (int64_t i = 0; i < n; i++) {
                    y[i] = y1[i];
                    k1[i] = k2[i];
                }
                t = tn;
                continue;
            }
            hermite(n, y, k1, y1, k2, hs, theta, yt);
            for (int64_t i = 0; i < n; i++)
                y[i] = yt[i];
            if (new_mode == AT_CORE || new_mode == END)
                y[TAB(slot, 3)] = p[TAB(slot, 4)]; /* land exactly on the core */
            t = theta < 1.0 ? t_end : tn;
            if (new_mode == END) {
                status = EXHAUSTED;
                break;
            }
            m[slot] = new_mode;
            evaluate(cx, F_RHS, t, y, k1);
            nfev += 1;
            stats[3] += 1;
            break; /* divide the rest of the interval again */
        }
    }
    stats[0] += nfev;
    free(cx->g);
    *t_res = t;
    *h_res = hh;
    *k_res = k;
    return status;
}
