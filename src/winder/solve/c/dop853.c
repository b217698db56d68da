/* DOP853 in C: Hairer's explicit Runge-Kutta method of order 8 (Dormand-Prince 8(5,3)),
 * with scipy's tableau, error estimator (the 5th- and 3rd-order estimates combined),
 * step control (safety 0.9, exponent -1/8, factors 0.2 to 10) and 7th-order dense output
 * (scipy/integrate/_ivp/rk.py, class DOP853, and dop853_coefficients.py), with the
 * machine's locked modes and their located switches (events.h), under the contract of
 * winder_dopri5 (dopri5.c: the same arguments, statuses, budget and counters).
 *
 * A step takes 12 evaluations (11 stages and f(y1), the next step's first). The dense
 * output needs 3 more stages: they are evaluated only on the steps whose dense output is
 * used (an output sample, a located switch, the guard's probes: events.h's dense() calls
 * complete() on first use), and counted in nfev. The stiffness test is Hairer's
 * (h |f(y1) - f(Y12)| / |y1 - Y12| > 6.1, Y12 the last stage's argument, at c = 1).
 * The first step is guessed as DOPRI5's (events.h's first_step), not by scipy's
 * select_initial_step. A non-finite extra stage ends the run with NON_FINITE (they lie
 * outside the error control: no NaN reaches the samples unannounced). */

#include "events.h"

/* The tableau: scipy's dop853_coefficients (the same doubles, printed by repr). */
static const double C_[16] = {
    0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726,
    0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6,
    0.8571428571428571, 1.0, 1.0, 0.1, 0.2, 0.7777777777777778};

/* The 16 stages by name (K0..K15). */
#define STAGES_OF(K) \
    const double *K0 = K[0], *K1 = K[1], *K2 = K[2], *K3 = K[3], *K4 = K[4], *K5 = K[5], \
                 *K6 = K[6], *K7 = K[7], *K8 = K[8], *K9 = K[9], *K10 = K[10], \
                 *K11 = K[11], *K12 = K[12], *K13 = K[13], *K14 = K[14], *K15 = K[15]; \
    (void)K1; (void)K2; (void)K3; (void)K4; (void)K12; (void)K13; (void)K14; (void)K15

/* out = y + h sum_j A[s][j] K[j]: the argument of stage s (1..15; s = 12: y1, B = A[12]) */
static void stage_arg(int s, int64_t n, double* const* K, const double* y, double h,
                      double* out) {
    STAGES_OF(K);
    switch (s) {
    case 1:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.05260015195876773 * K0[i]);
        break;
    case 2:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.0197250569845379 * K0[i] + 0.0591751709536137 * K1[i]);
        break;
    case 3:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.02958758547680685 * K0[i] + 0.08876275643042054 * K2[i]);
        break;
    case 4:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.2413651341592667 * K0[i] - 0.8845494793282861 * K2[i]
                                 + 0.924834003261792 * K3[i]);
        break;
    case 5:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.037037037037037035 * K0[i] + 0.17082860872947386 * K3[i]
                                 + 0.12546768756682242 * K4[i]);
        break;
    case 6:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.037109375 * K0[i] + 0.17025221101954405 * K3[i]
                                 + 0.06021653898045596 * K4[i] - 0.017578125 * K5[i]);
        break;
    case 7:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.03709200011850479 * K0[i] + 0.17038392571223998 * K3[i]
                                 + 0.10726203044637328 * K4[i]
                                 - 0.015319437748624402 * K5[i]
                                 + 0.008273789163814023 * K6[i]);
        break;
    case 8:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.6241109587160757 * K0[i] - 3.3608926294469414 * K3[i]
                                 - 0.868219346841726 * K4[i] + 27.59209969944671 * K5[i]
                                 + 20.154067550477894 * K6[i] - 43.48988418106996 * K7[i]);
        break;
    case 9:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.47766253643826434 * K0[i] - 2.4881146199716677 * K3[i]
                                 - 0.590290826836843 * K4[i] + 21.230051448181193 * K5[i]
                                 + 15.279233632882423 * K6[i] - 33.28821096898486 * K7[i]
                                 - 0.020331201708508627 * K8[i]);
        break;
    case 10:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (-0.9371424300859873 * K0[i] + 5.186372428844064 * K3[i]
                                 + 1.0914373489967295 * K4[i] - 8.149787010746927 * K5[i]
                                 - 18.52006565999696 * K6[i] + 22.739487099350505 * K7[i]
                                 + 2.4936055526796523 * K8[i] - 3.0467644718982196 * K9[i]);
        break;
    case 11:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (2.273310147516538 * K0[i] - 10.53449546673725 * K3[i]
                                 - 2.0008720582248625 * K4[i] - 17.9589318631188 * K5[i]
                                 + 27.94888452941996 * K6[i] - 2.8589982771350235 * K7[i]
                                 - 8.87285693353063 * K8[i] + 12.360567175794303 * K9[i]
                                 + 0.6433927460157636 * K10[i]);
        break;
    case 12:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.054293734116568765 * K0[i] + 4.450312892752409 * K5[i]
                                 + 1.8915178993145003 * K6[i] - 5.801203960010585 * K7[i]
                                 + 0.3111643669578199 * K8[i] - 0.1521609496625161 * K9[i]
                                 + 0.20136540080403034 * K10[i]
                                 + 0.04471061572777259 * K11[i]);
        break;
    case 13:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.056167502283047954 * K0[i] + 0.25350021021662483 * K6[i]
                                 - 0.2462390374708025 * K7[i] - 0.12419142326381637 * K8[i]
                                 + 0.15329179827876568 * K9[i]
                                 + 0.00820105229563469 * K10[i]
                                 + 0.007567897660545699 * K11[i] - 0.008298 * K12[i]);
        break;
    case 14:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (0.03183464816350214 * K0[i] + 0.028300909672366776 * K5[i]
                                 + 0.053541988307438566 * K6[i]
                                 - 0.05492374857139099 * K7[i]
                                 - 0.00010834732869724932 * K10[i]
                                 + 0.0003825710908356584 * K11[i]
                                 - 0.00034046500868740456 * K12[i]
                                 + 0.1413124436746325 * K13[i]);
        break;
    case 15:
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * (-0.42889630158379194 * K0[i] - 4.697621415361164 * K5[i]
                                 + 7.683421196062599 * K6[i] + 4.06898981839711 * K7[i]
                                 + 0.3567271874552811 * K8[i]
                                 - 0.0013990241651590145 * K12[i]
                                 + 2.9475147891527724 * K13[i] - 9.15095847217987 * K14[i]);
        break;
    }
}

/* The squared norms of the 5th-order (E5) and 3rd-order (E3) error estimates, each
 * component scaled by atol + rtol max(|y|, |y1|) (scipy's _estimate_error_norm). */
static void error_norms(int64_t n, double* const* K, const double* y, const double* y1,
                        double rtol, double atol, double* n5, double* n3) {
    STAGES_OF(K);
    double s5 = 0.0, s3 = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double sk = atol + rtol * pmax(fabs(y[i]), fabs(y1[i]));
        double e5 = (0.01312004499419488 * K0[i] - 1.2251564463762044 * K5[i]
                     - 0.4957589496572502 * K6[i] + 1.6643771824549864 * K7[i]
                     - 0.35032884874997366 * K8[i] + 0.3341791187130175 * K9[i]
                     + 0.08192320648511571 * K10[i] - 0.022355307863886294 * K11[i]) / sk;
        double e3 = (-0.18980075407240762 * K0[i] + 4.450312892752409 * K5[i]
                     + 1.8915178993145003 * K6[i] - 5.801203960010585 * K7[i]
                     - 0.4226823213237919 * K8[i] - 0.1521609496625161 * K9[i]
                     + 0.20136540080403034 * K10[i] + 0.02265179219836082 * K11[i]) / sk;
        s5 += e5 * e5;
        s3 += e3 * e3;
    }
    *n5 = s5;
    *n3 = s3;
}

/* The dense output's rows 4..7: h sum_j D[r][j] K[j] (r = 0..3). */
static void dense_rows(int64_t n, double* const* K, double h, double* rc) {
    STAGES_OF(K);
    for (int64_t i = 0; i < n; i++) {
        rc[4 * n + i] = h * (-8.428938276109013 * K0[i] + 0.5667149535193777 * K5[i]
                             - 3.0689499459498917 * K6[i] + 2.38466765651207 * K7[i]
                             + 2.117034582445028 * K8[i] - 0.871391583777973 * K9[i]
                             + 2.2404374302607883 * K10[i] + 0.6315787787694688 * K11[i]
                             - 0.08899033645133331 * K12[i] + 18.148505520854727 * K13[i]
                             - 9.194632392478356 * K14[i] - 4.436036387594894 * K15[i]);
        rc[5 * n + i] = h * (10.427508642579134 * K0[i] + 242.28349177525817 * K5[i]
                             + 165.20045171727028 * K6[i] - 374.5467547226902 * K7[i]
                             - 22.113666853125306 * K8[i] + 7.733432668472264 * K9[i]
                             - 30.674084731089398 * K10[i] - 9.332130526430229 * K11[i]
                             + 15.697238121770845 * K12[i] - 31.139403219565178 * K13[i]
                             - 9.35292435884448 * K14[i] + 35.81684148639408 * K15[i]);
        rc[6 * n + i] = h * (19.985053242002433 * K0[i] - 387.0373087493518 * K5[i]
                             - 189.17813819516758 * K6[i] + 527.8081592054236 * K7[i]
                             - 11.57390253995963 * K8[i] + 6.8812326946963 * K9[i]
                             - 1.0006050966910838 * K10[i] + 0.7777137798053443 * K11[i]
                             - 2.778205752353508 * K12[i] - 60.19669523126412 * K13[i]
                             + 84.32040550667716 * K14[i] + 11.99229113618279 * K15[i]);
        rc[7 * n + i] = h * (-25.69393346270375 * K0[i] - 154.18974869023643 * K5[i]
                             - 231.5293791760455 * K6[i] + 357.6391179106141 * K7[i]
                             + 93.40532418362432 * K8[i] - 37.45832313645163 * K9[i]
                             + 104.0996495089623 * K10[i] + 29.8402934266605 * K11[i]
                             - 43.53345659001114 * K12[i] + 96.32455395918828 * K13[i]
                             - 39.17726167561544 * K14[i] - 149.72683625798564 * K15[i]);
    }
}


/* What the dense output of the accepted step from (t, rc[0]) to (t + h, y1) needs. */
typedef struct {
    Ctx* cx;
    double t, h;
    const double* y1;
    double** K;  /* the 16 stages; K[12] = f(y1) */
    double* rc;  /* 8 rows: y0 (written with the step), then F0..F6 (by complete) */
    double* ys;  /* a stage's argument */
    int64_t nfev;
    int nonfinite;  /* an extra stage was not finite */
} Step;

/* The 3 extra stages and the 7 rows of the 7th-order interpolant (scipy's
 * DOP853._dense_output_impl). */
static void complete(void* arg) {
    Step* s = (Step*)arg;
    Ctx* cx = s->cx;
    int64_t n = cx->n;
    double h = s->h;
    double* rc = s->rc;
    double** K = s->K;
    for (int st = 13; st < 16; st++) {
        stage_arg(st, n, K, rc, h, s->ys);
        evaluate(cx, F_RHS, s->t + C_[st] * h, s->ys, K[st]);
        for (int64_t i = 0; i < n; i++)
            if (!isfinite(K[st][i]))
                s->nonfinite = 1;
    }
    s->nfev += 3;
    for (int64_t i = 0; i < n; i++) {
        double dy = s->y1[i] - rc[i];
        rc[n + i] = dy;
        rc[2 * n + i] = h * K[0][i] - dy;
        rc[3 * n + i] = 2.0 * dy - h * (K[12][i] + K[0][i]);
    }
    dense_rows(n, K, h, rc);
}

/* Integrate y from t0 to t1 (the arguments, statuses and results of winder_dopri5).
 * Returns the status; *t_res, *h_res, *k_res: the time reached, the next step, the
 * samples written. */
int winder_dop853(const int64_t* fns, const int64_t* table, int64_t nslots,
                  int64_t n_switches, double t0, double t1, double* y, int64_t n,
                  const double* p, double* m, double rtol, double atol, double h,
                  double max_step, const double* t_out, int64_t n_out, double* Y_out,
                  int64_t k, int64_t budget, int64_t* stats, int64_t nstats,
                  double* t_res, double* h_res, int64_t* k_res) {
    Ctx ctx, *cx = &ctx;
    double* v[26];
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 26))
        return NO_MEMORY;
    cx->rows = 8;
    double** K = v;  /* v[0..15] the stages */
    double *y1 = v[16], *rc = v[17], *ys = v[25];
    double* yt = cx->yt;
    Step step = {cx, 0.0, 0.0, y1, K, rc, ys, 0, 0};
    cx->complete = complete;
    cx->lazy_arg = &step;
    double t = t0;
    modes_of(cx, t, y, 0);
    evaluate(cx, F_RHS, t, y, K[0]);
    int64_t nfev = 1;
    if (h <= 0.0)
        h = first_step(n, y, K[0], rtol, atol);
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
                k = sliver(n, t, t1, y, K[0], t_out, n_out, Y_out, k);
                t = t1;
                break;
            }
        }
        if (hh < TIME_RESOLUTION * pmax(1.0, fabs(t))) {
            status = STEP_UNDERFLOW;
            break;
        }
        for (int s = 1; s < 12; s++) {
            stage_arg(s, n, K, y, hh, yt);
            evaluate(cx, F_RHS, t + C_[s] * hh, yt, K[s]);
        }
        stage_arg(12, n, K, y, hh, y1);
        evaluate(cx, F_RHS, t + hh, y1, K[12]);
        nfev += 12;
        double n5, n3;
        error_norms(n, K, y, y1, rtol, atol, &n5, &n3);
        double err = (n5 == 0.0 && n3 == 0.0) ? 0.0
                     : hh * n5 / sqrt((n5 + 0.01 * n3) * (double)n);
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
            h = hh * pmax(0.2, 0.9 * pow(err, -0.125));
            rejected_last = 1;
            continue;
        }
        if (nstats > 4) {  /* yt: the argument of stage 12 (c = 1) */
            double stnum = 0.0, stden = 0.0;
            for (int64_t i = 0; i < n; i++) {
                double a = K[12][i] - K[11][i], b = y1[i] - yt[i];
                stnum += a * a;
                stden += b * b;
            }
            if (stden > 0.0 && hh * hh * stnum > 6.1 * 6.1 * stden)
                stats[4] += 1;
        }
        memcpy(rc, y, sizeof(double) * (size_t)n);  /* the rest on first use */
        step.t = t;
        step.h = hh;
        step.nfev = 0;
        cx->lazy_rc = rc;
        double new_mode, t_end;
        int64_t slot = sample_and_switch(cx, rc, t, hh, t1, y, y1, t_out, n_out, Y_out, &k,
                                         &new_mode, &t_end);
        cx->lazy_rc = NULL;
        nfev += step.nfev;
        if (step.nonfinite) {
            status = NON_FINITE;
            break;
        }
        stats[1] += 1;
        int switched;
        status = end_of_step(cx, slot, new_mode, t_end, y, K[0], &t, &nfev, stats, &switched);
        if (status != DONE)
            break;
        if (switched) {
            cx->start_ok = 0;
            h = hh;
            rejected_last = 0;
            continue;
        }
        memcpy(y, y1, sizeof(double) * (size_t)n);
        memcpy(K[0], K[12], sizeof(double) * (size_t)n);
        step_continues(cx, t + hh < t1);
        t = t + hh < t1 ? t + hh : t1;
        double fac = 0.9 * pow(pmax(err, 1e-10), -0.125);
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
