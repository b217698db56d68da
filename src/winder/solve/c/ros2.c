/* The Rosenbrock ROS2 in C: solve/rosenbrock.py line by line (Shampine & Reichelt's ROS2,
 * MATLAB's ode23s, on the generated exact Jacobian fns[F_JAC], column-major), with the
 * machine's locked modes and their located switches (events.h). */

#include "events.h"

#include "dense_lu.h"

/* Integrate y from t0 to t1 (solve/rosenbrock.py: arguments and results as
 * winder_dopri5; stats[4] counts Jacobians). */
int winder_ros2(const int64_t* fns, const int64_t* table, int64_t nslots,
                int64_t n_switches, double t0, double t1, double* y, int64_t n,
                const double* p, double* m, double rtol, double atol, double h,
                double max_step, const double* t_out, int64_t n_out, double* Y_out,
                int64_t k, int64_t budget, int64_t* stats, double* t_res, double* h_res,
                int64_t* k_res) {
    const double D = 1.0 / (2.0 + sqrt(2.0));
    const double E32 = 6.0 + sqrt(2.0);
    Ctx ctx, *cx = &ctx;
    int64_t n_extra = 14 + 2 * n;
    double** v = malloc(sizeof(double*) * (size_t)n_extra);
    int64_t* piv = malloc(sizeof(int64_t) * (size_t)n);
    if (!v || !piv || !ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, n_extra)) {
        free(v);
        free(piv);
        return NO_MEMORY;
    }
    double *f0 = v[0], *f1 = v[1], *f2 = v[2], *k1 = v[3], *k2 = v[4], *k3 = v[5],
           *ft = v[6], *dfdt = v[7], *y1 = v[8], *rc = v[9], *jac = v[14],
           *W = v[14 + n];
    double* yt = cx->yt;
    memset(rc, 0, sizeof(double) * 5 * (size_t)n);
    double t = t0;
    modes_of(cx, t, y, 0);
    evaluate(cx, F_RHS, t, y, f0);
    int64_t nfev = 1;
    if (h <= 0.0)
        h = first_step(n, y, f0, rtol, atol);
    int status = DONE;
    int fresh = 0;
    while (t < t1) {
        if (nfev >= budget) {
            status = PAUSED;
            break;
        }
        double hh = pmin(h, max_step);
        if (t + 1.01 * hh >= t1)
            hh = t1 - t;
        if (hh < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
            if (t1 - t < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
                for (int64_t i = 0; i < n; i++)
                    y[i] += (t1 - t) * f0[i];
                t = t1;
                break;
            }
            status = STEP_UNDERFLOW;
            break;
        }
        if (!fresh) {
            evaluate(cx, F_JAC, t, y, jac);
            double dt = 1e-7 * pmax(1.0, fabs(t));
            evaluate(cx, F_RHS, t + dt, y, ft);
            for (int64_t i = 0; i < n; i++)
                dfdt[i] = (ft[i] - f0[i]) / dt;
            nfev += 1;
            stats[4] += 1;
            fresh = 1;
        }
        double hd = hh * D;
        for (int64_t i = 0; i < n; i++) {
            for (int64_t j = 0; j < n; j++)
                W[i * n + j] = -hd * jac[i + n * j]; /* column-major */
            W[i * n + i] += 1.0;
        }
        if (!lu(n, W, piv)) {
            h = 0.5 * hh;
            stats[2] += 1;
            continue;
        }
        for (int64_t i = 0; i < n; i++)
            k1[i] = f0[i] + hd * dfdt[i];
        lu_solve(n, W, piv, k1);
        for (int64_t i = 0; i < n; i++)
            yt[i] = y[i] + 0.5 * hh * k1[i];
        evaluate(cx, F_RHS, t + 0.5 * hh, yt, f1);
        for (int64_t i = 0; i < n; i++)
            k2[i] = f1[i] - k1[i];
        lu_solve(n, W, piv, k2);
        for (int64_t i = 0; i < n; i++) {
            k2[i] += k1[i];
            y1[i] = y[i] + hh * k2[i];
        }
        evaluate(cx, F_RHS, t + hh, y1, f2);
        for (int64_t i = 0; i < n; i++)
            k3[i] = f2[i] - E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]) + hd * dfdt[i];
        lu_solve(n, W, piv, k3);
        nfev += 2;
        double err = 0.0;
        for (int64_t i = 0; i < n; i++) {
            double sk = atol + rtol * pmax(fabs(y[i]), fabs(y1[i]));
            double r = hh / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]) / sk;
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
            continue;
        }
        if (err > 1.0) {
            stats[2] += 1;
            h = hh * pmax(0.2, 0.8 * pow(err, -1.0 / 3.0));
            continue;
        }
        for (int64_t i = 0; i < n; i++) { /* the interpolant in DOPRI5's dense form */
            rc[i] = y[i];
            rc[n + i] = hh * k2[i];
            rc[2 * n + i] = hh * (k1[i] - k2[i]) / (1.0 - 2.0 * D);
        }
        double new_mode, t_end;
        int64_t slot = sample_and_switch(cx, rc, t, hh, t1, y, y1, t_out, n_out, Y_out, &k,
                                         &new_mode, &t_end);
        stats[1] += 1;
        fresh = 0;
        int switched;
        status = end_of_step(cx, slot, new_mode, t_end, y, f0, &t, &nfev, stats, &switched);
        if (status != DONE)
            break;
        if (switched)
            continue;
        for (int64_t i = 0; i < n; i++) {
            y[i] = y1[i];
            f0[i] = f2[i];
        }
        t = t + hh < t1 ? t + hh : t1;
        h = hh * pmin(5.0, pmax(0.2, 0.8 * pow(pmax(err, 1e-10), -1.0 / 3.0)));
    }
    stats[0] += nfev;
    free(cx->g);
    free(v);
    free(piv);
    *t_res = t;
    *h_res = h;
    *k_res = k;
    return status;
}
