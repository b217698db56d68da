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
 * (h |f(y1) - f(Y12)| / |y1 - Y12| > 6.1, Y12 the last stage's argument, at c = 1). */

#include "events.h"

/* One linear combination of the stages: m terms a[q] K[j[q]]. */
typedef struct {
    int m;
    int j[12];
    double a[12];
} Row;

enum { R_E5 = 15, R_E3 = 16, R_D = 17, N_ROWS = 21 };

/* The tableau as scipy's dop853_coefficients (the same doubles): rows 0..14 the stages
 * 1..15 (row 11, stage 12, is B: y1), then E5, E3, D0..D3. */
static const double C_[16] = {
    0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274,
    0.2816496580927726, 0.3333333333333333, 0.25, 0.3076923076923077,
    0.6512820512820513, 0.6, 0.8571428571428571, 1.0, 1.0, 0.1, 0.2, 0.7777777777777778};
static const Row ROWS[N_ROWS] = {
    /* stage 1 */
    {1, {0},
     {
      0.05260015195876773}},
    /* stage 2 */
    {2, {0, 1},
     {
      0.0197250569845379, 0.0591751709536137}},
    /* stage 3 */
    {2, {0, 2},
     {
      0.02958758547680685, 0.08876275643042054}},
    /* stage 4 */
    {3, {0, 2, 3},
     {
      0.2413651341592667, -0.8845494793282861, 0.924834003261792}},
    /* stage 5 */
    {3, {0, 3, 4},
     {
      0.037037037037037035, 0.17082860872947386, 0.12546768756682242}},
    /* stage 6 */
    {4, {0, 3, 4, 5},
     {
      0.037109375, 0.17025221101954405, 0.06021653898045596, -0.017578125}},
    /* stage 7 */
    {5, {0, 3, 4, 5, 6},
     {
      0.03709200011850479, 0.17038392571223998, 0.10726203044637328,
      -0.015319437748624402, 0.008273789163814023}},
    /* stage 8 */
    {6, {0, 3, 4, 5, 6, 7},
     {
      0.6241109587160757, -3.3608926294469414, -0.868219346841726, 27.59209969944671,
      20.154067550477894, -43.48988418106996}},
    /* stage 9 */
    {7, {0, 3, 4, 5, 6, 7, 8},
     {
      0.47766253643826434, -2.4881146199716677, -0.590290826836843, 21.230051448181193,
      15.279233632882423, -33.28821096898486, -0.020331201708508627}},
    /* stage 10 */
    {8, {0, 3, 4, 5, 6, 7, 8, 9},
     {
      -0.9371424300859873, 5.186372428844064, 1.0914373489967295, -8.149787010746927,
      -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196}},
    /* stage 11 */
    {9, {0, 3, 4, 5, 6, 7, 8, 9, 10},
     {
      2.273310147516538, -10.53449546673725, -2.0008720582248625, -17.9589318631188,
      27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303,
      0.6433927460157636}},
    /* stage 12: y1 (B) */
    {8, {0, 5, 6, 7, 8, 9, 10, 11},
     {
      0.054293734116568765, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
      0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259}},
    /* stage 13, dense output */
    {8, {0, 6, 7, 8, 9, 10, 11, 12},
     {
      0.056167502283047954, 0.25350021021662483, -0.2462390374708025,
      -0.12419142326381637, 0.15329179827876568, 0.00820105229563469,
      0.007567897660545699, -0.008298}},
    /* stage 14, dense output */
    {8, {0, 5, 6, 7, 10, 11, 12, 13},
     {
      0.03183464816350214, 0.028300909672366776, 0.053541988307438566,
      -0.05492374857139099, -0.00010834732869724932, 0.0003825710908356584,
      -0.00034046500868740456, 0.1413124436746325}},
    /* stage 15, dense output */
    {8, {0, 5, 6, 7, 8, 12, 13, 14},
     {
      -0.42889630158379194, -4.697621415361164, 7.683421196062599, 4.06898981839711,
      0.3567271874552811, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987}},
    /* E5: the 5th-order error estimator */
    {8, {0, 5, 6, 7, 8, 9, 10, 11},
     {
      0.01312004499419488, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864,
      -0.35032884874997366, 0.3341791187130175, 0.08192320648511571,
      -0.022355307863886294}},
    /* E3: the 3rd-order one */
    {8, {0, 5, 6, 7, 8, 9, 10, 11},
     {
      -0.18980075407240762, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
      -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082}},
    /* D0: the dense output's row 4 */
    {12, {0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
     {
      -8.428938276109013, 0.5667149535193777, -3.0689499459498917, 2.38466765651207,
      2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688,
      -0.08899033645133331, 18.148505520854727, -9.194632392478356, -4.436036387594894}},
    /* D1: the dense output's row 5 */
    {12, {0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
     {
      10.427508642579134, 242.28349177525817, 165.20045171727028, -374.5467547226902,
      -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229,
      15.697238121770845, -31.139403219565178, -9.35292435884448, 35.81684148639408}},
    /* D2: the dense output's row 6 */
    {12, {0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
     {
      19.985053242002433, -387.0373087493518, -189.17813819516758, 527.8081592054236,
      -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443,
      -2.778205752353508, -60.19669523126412, 84.32040550667716, 11.99229113618279}},
    /* D3: the dense output's row 7 */
    {12, {0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
     {
      -25.69393346270375, -154.18974869023643, -231.5293791760455, 357.6391179106141,
      93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605,
      -43.53345659001114, 96.32455395918828, -39.17726167561544, -149.72683625798564}},
};

/* out = y + h sum_q a[q] K[j[q]] (y NULL: h sum ...) */
static void combine(int64_t n, const Row* r, double* const* K, const double* y, double h,
                    double* out) {
    const double* k0 = K[r->j[0]];
    double a0 = r->a[0];
    for (int64_t i = 0; i < n; i++)
        out[i] = a0 * k0[i];
    for (int q = 1; q < r->m; q++) {
        const double* kq = K[r->j[q]];
        double aq = r->a[q];
        for (int64_t i = 0; i < n; i++)
            out[i] += aq * kq[i];
    }
    if (y) {
        for (int64_t i = 0; i < n; i++)
            out[i] = y[i] + h * out[i];
    } else {
        for (int64_t i = 0; i < n; i++)
            out[i] *= h;
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
        combine(n, &ROWS[st - 1], K, rc, h, s->ys);
        evaluate(cx, F_RHS, s->t + C_[st] * h, s->ys, K[st]);
    }
    s->nfev += 3;
    for (int64_t i = 0; i < n; i++) {
        double dy = s->y1[i] - rc[i];
        rc[n + i] = dy;
        rc[2 * n + i] = h * K[0][i] - dy;
        rc[3 * n + i] = 2.0 * dy - h * (K[12][i] + K[0][i]);
    }
    for (int r = 0; r < 4; r++)
        combine(n, &ROWS[R_D + r], K, NULL, h, rc + (4 + r) * n);
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
    double* v[28];
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 28))
        return NO_MEMORY;
    cx->rows = 8;
    double** K = v;  /* v[0..15] the stages */
    double *y1 = v[16], *rc = v[17], *ys = v[25], *e5 = v[26], *e3 = v[27];
    double* yt = cx->yt;
    Step step = {cx, 0.0, 0.0, y1, K, rc, ys, 0};
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
            combine(n, &ROWS[s - 1], K, y, hh, yt);
            evaluate(cx, F_RHS, t + C_[s] * hh, yt, K[s]);
        }
        combine(n, &ROWS[11], K, y, hh, y1);
        evaluate(cx, F_RHS, t + hh, y1, K[12]);
        nfev += 12;
        combine(n, &ROWS[R_E5], K, NULL, 1.0, e5);
        combine(n, &ROWS[R_E3], K, NULL, 1.0, e3);
        double n5 = 0.0, n3 = 0.0;
        for (int64_t i = 0; i < n; i++) {
            double sk = atol + rtol * pmax(fabs(y[i]), fabs(y1[i]));
            double a = e5[i] / sk, b = e3[i] / sk;
            n5 += a * a;
            n3 += b * b;
        }
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
