/* Rosenbrock methods in C on the generated exact Jacobian fns[F_JAC] factored on its
 * sparsity (sparse_lu.h), with the machine's locked modes and their located switches
 * (events.h), for machines whose fast modes are damped (flexible bodies: their upper
 * chain modes hold an explicit method's step at its stability limit). Two stiffly
 * accurate, L-stable schemes, written as Hairer & Wanner's (and KPP's) form
 *
 *   W = I/(h gamma) - J,   Y_i = y + sum_j a_ij K_j,
 *   W K_i = f(t + alpha_i h, Y_i) + sum_j c_ij K_j / h + h gamma_i f_t,
 *   y1 = y + sum_i m_i K_i,   error estimate sum_i e_i K_i:
 *
 * scheme 3: RODAS3 (Sandu et al. 1997, order 3 (2), 4 stages, 3 new evaluations);
 * scheme 4: RODAS4 (Hairer & Wanner 1996, order 4 (3), 6 stages, 5 new evaluations);
 * scheme 34: ROS34PW2 (Rang & Angermann 2005, a W-method of order 3 (2), 4 stages, 3 new
 * evaluations: its order holds with a Jacobian kept over several steps).
 * f_t by a forward difference (one evaluation per Jacobian). Dense output: the cubic
 * Hermite interpolant of y, y1, f(y), f(y1) (f(y1) is the next step's first stage: one
 * more evaluation per accepted step).
 *
 * Jacobian reuse (`reuse` >= 1: the most accepted steps one Jacobian serves): a Jacobian
 * is kept over accepted steps and evaluated anew after `reuse` steps, after a rejected
 * step and after a mode switch; W is factored again only where h changes, and where the
 * Jacobian is kept a step that would grow by less than 20 % is held (no new
 * factorisation). reuse = 1 is the plain Rosenbrock method (a new Jacobian every step).
 *
 * Arguments and results as winder_ros2, plus `scheme` and `reuse`; stats (needs 8): [4]
 * Jacobians, [5] factorisations, [6] dense fallbacks, [7] L + U nonzeros of the last
 * factorisation. */

#include "events.h"
#include "sparse_lu.h"

#define OBSERVE 16
/* a kept Jacobian holds a step that would grow by less than this factor (1.5 and 2 were
 * no faster on the flexible two-drum winder: the step shrinks as often as it grows) */
#define HOLD 1.2

typedef struct {
    int s;            /* stages */
    double gamma;     /* the diagonal */
    double elo;       /* the error estimate's order + 1 */
    double a[6][6], c[6][6], m[6], e[6], alpha[6], gam[6];
    int newf[6];
} Scheme;

static const Scheme RODAS3 = {
    4, 0.5, 3.0,
    {{0}, {0}, {2.0, 0.0}, {2.0, 0.0, 1.0}},
    {{0}, {4.0}, {1.0, -1.0}, {1.0, -1.0, -8.0 / 3.0}},
    {2.0, 0.0, 1.0, 1.0}, {0.0, 0.0, 0.0, 1.0}, {0.0, 0.0, 1.0, 1.0},
    {0.5, 1.5, 0.0, 0.0}, {1, 0, 1, 1}};

static const Scheme RODAS4 = {
    6, 0.25, 4.0,
    {{0}, {1.544},
     {0.9466785280815826, 0.2557011698983284},
     {3.314825187068521, 2.896124015972201, 0.9986419139977817},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950},
     {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0}},
    {{0}, {-5.6688},
     {-2.430093356833875, -0.2063599157091915},
     {-0.1073529058151375, -9.594562251023355, -20.47028614809616},
     {7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160},
     {8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136,
      -6.058818238834054}},
    {1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0,
     1.0},
    {0.0, 0.0, 0.0, 0.0, 0.0, 1.0},
    {0.0, 0.386, 0.210, 0.630, 1.0, 1.0},
    {0.25, -0.1043, 0.1035, -0.3620000000000023e-01, 0.0, 0.0},
    {1, 1, 1, 1, 1, 1}};

/* ROS34PW2 (Rang & Angermann 2005): a W-method (order 3 with any W, so a Jacobian kept
 * over several steps keeps the order), L-stable, stiffly accurate; its (alpha, Gamma, b,
 * b^) turned into this form (a = alpha Gamma^-1, c = diag(1/gamma) - Gamma^-1,
 * m = b Gamma^-1, e = (b - b^) Gamma^-1). */
static const Scheme ROS34PW2 = {
    4, 0.435866521508459, 3.0,
    {{0}, {2.0000000000000004},
     {1.4192173174557652, -0.25923221167296978},
     {4.1847604823191613, -0.28519201735549599, 2.2942803602790423}},
    {{0}, {-4.5885607205580836},
     {-4.1847604823191613, 0.28519201735549599},
     {-6.3681792001283597, -6.7956209444668367, 2.8700986043310550}},
    {4.184760482319163, -0.28519201735549543, 2.2942803602790423, 1.0},
    {0.2777499476479686, -1.4032398951759992, 1.772630127667551, 0.5},
    {0.0, 0.871733043016918, 0.7315799577888524, 1.0},
    {0.435866521508459, -0.435866521508459, -0.4133333762338865, 0.0},
    {1, 1, 1, 1}};

int winder_rodas(const int64_t* fns, const int64_t* table, int64_t nslots,
                  int64_t n_switches, double t0, double t1, double* y, int64_t n,
                  const double* p, double* m, double rtol, double atol, double h,
                  double max_step, const double* t_out, int64_t n_out, double* Y_out,
                  int64_t k, int64_t budget, int64_t scheme, int64_t reuse, int64_t* stats, double* t_res,
                  double* h_res, int64_t* k_res) {
    const Scheme* S = scheme == 4 ? &RODAS4 : scheme == 34 ? &ROS34PW2 : &RODAS3;
    Ctx ctx, *cx = &ctx;
    Slu lu;
    double* v[17];
    double* jac = malloc(sizeof(double) * (size_t)n * (size_t)n);
    if (!jac || !slu_init(&lu, n)) {
        free(jac);
        return NO_MEMORY;
    }
    if (!ctx_init(cx, fns, table, nslots, n_switches, n, p, m, v, 17)) {
        free(jac);
        slu_free(&lu);
        return NO_MEMORY;
    }
    double *f0 = v[0], *f1 = v[1], *ft = v[2], *dfdt = v[3], *y1 = v[4], *err_v = v[5];
    double* K[6] = {v[6], v[7], v[8], v[9], v[10], v[11]};
    double* rc = v[12]; /* the dense output: 5 n (v[12] .. v[16]) */
    double* yt = cx->yt;
    memset(rc, 0, sizeof(double) * 5 * (size_t)n);
    if (reuse < 1)
        reuse = 1;
    double t = t0;
    modes_of(cx, t, y, 0);
    evaluate(cx, F_RHS, t, y, f0);
    int64_t nfev = 1;
    if (h <= 0.0)
        h = first_step(n, y, f0, rtol, atol);
    int status = DONE;
    int64_t age = reuse;    /* steps the Jacobian has served; >= reuse: a new one */
    double h_lu = -1.0;     /* the step W is factored for (< 0: none) */
    int rejected_last = 0;
    /* the pattern: first what a state of NaN reaches (every entry that depends on the
     * state, and the constant ones), then the nonzeros of every OBSERVE-th Jacobian and
     * of every one after a rejected step or a mode switch */
    for (int64_t i = 0; i < n; i++)
        yt[i] = NAN;
    evaluate(cx, F_JAC, t, yt, jac);
    slu_observe(&lu, jac);
    int64_t n_jac = 0;
    int observe = 1;
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
                k = sliver(n, t, t1, y, f0, t_out, n_out, Y_out, k);
                t = t1;
                break;
            }
            status = STEP_UNDERFLOW;
            break;
        }
        if (age >= reuse) {
            evaluate(cx, F_JAC, t, y, jac);
            if (observe || n_jac % OBSERVE == 0)
                slu_observe(&lu, jac);
            observe = 0;
            n_jac++;
            double dt = 1e-7 * pmax(1.0, fabs(t));
            evaluate(cx, F_RHS, t + dt, y, ft);
            for (int64_t i = 0; i < n; i++)
                dfdt[i] = (ft[i] - f0[i]) / dt;
            nfev += 1;
            stats[4] += 1;
            age = 0;
            h_lu = -1.0;
        }
        if (hh != h_lu) {
            int nomem;
            int ok = slu_factor(&lu, jac, 1.0 / (hh * S->gamma), &nomem);
            stats[5] += 1;
            if (nomem) {
                status = NO_MEMORY;
                break;
            }
            if (!ok) {
                h = 0.5 * hh;
                h_lu = -1.0;
                stats[2] += 1;
                continue;
            }
            h_lu = hh;
        }
        double ih = 1.0 / hh;
        /* the stage's f; a stage without a new one reuses it (RODAS3's second stage: f0;
         * a stage's own f is overwritten by its K, so only f0 can be reused) */
        const double* F = f0;
        for (int st = 0; st < S->s; st++) {
            double* Ki = K[st];
            if (st > 0 && S->newf[st]) {
                for (int64_t i = 0; i < n; i++) {
                    double a = y[i];
                    for (int j = 0; j < st; j++)
                        a += S->a[st][j] * K[j][i];
                    yt[i] = a;
                }
                evaluate(cx, F_RHS, t + S->alpha[st] * hh, yt, Ki);
                nfev += 1;
                F = Ki;
            } else if (Ki != F) {
                memcpy(Ki, F, sizeof(double) * (size_t)n);
            }
            double hg = hh * S->gam[st];
            for (int64_t i = 0; i < n; i++) {
                double c = 0.0;
                for (int j = 0; j < st; j++)
                    c += S->c[st][j] * K[j][i];
                Ki[i] += ih * c + hg * dfdt[i];
            }
            slu_solve(&lu, Ki);
        }
        double err = 0.0;
        for (int64_t i = 0; i < n; i++) {
            double a = y[i], e = 0.0;
            for (int st = 0; st < S->s; st++) {
                a += S->m[st] * K[st][i];
                e += S->e[st] * K[st][i];
            }
            y1[i] = a;
            err_v[i] = e;
            double sk = atol + rtol * pmax(fabs(y[i]), fabs(a));
            double r = e / sk;
            err += r * r;
        }
        err = sqrt(err / (double)n);
        if (!isfinite(err) || err > 1.0) {
            stats[2] += 1;
            if (!isfinite(err)) {
                h = 0.1 * hh;
                if (h < 1e-14 * pmax(1.0, fabs(t))) {
                    status = NON_FINITE;
                    break;
                }
            } else {
                h = hh * pmax(0.2, 0.9 * pow(err, -1.0 / S->elo));
            }
            if (age > 0)  /* a kept Jacobian may be the cause: a new one */
                age = reuse;
            observe = 1;
            rejected_last = 1;
            continue;
        }
        evaluate(cx, F_RHS, t + hh, y1, f1);
        nfev += 1;
        for (int64_t i = 0; i < n; i++) { /* the cubic Hermite interpolant, dense() form */
            double dyi = y1[i] - y[i];
            double bspl = hh * f0[i] - dyi;
            rc[i] = y[i];
            rc[n + i] = dyi;
            rc[2 * n + i] = bspl;
            rc[3 * n + i] = dyi - hh * f1[i] - bspl;
        }
        double new_mode, t_end;
        int64_t slot = sample_and_switch(cx, rc, t, hh, t1, y, y1, t_out, n_out, Y_out, &k,
                                         &new_mode, &t_end);
        stats[1] += 1;
        age += 1;
        int switched;
        status = end_of_step(cx, slot, new_mode, t_end, y, f0, &t, &nfev, stats, &switched);
        if (status != DONE)
            break;
        if (switched) {  /* new modes: a new Jacobian */
            age = reuse;
            observe = 1;
            rejected_last = 0;
            continue;
        }
        for (int64_t i = 0; i < n; i++) {
            y[i] = y1[i];
            f0[i] = f1[i];
        }
        t = t + hh < t1 ? t + hh : t1;
        double fac = 0.9 * pow(pmax(err, 1e-10), -1.0 / S->elo);
        fac = rejected_last ? pmin(fac, 1.0) : pmin(fac, 6.0);
        if (age < reuse && fac >= 1.0 && fac < HOLD)
            fac = 1.0;  /* hold the step: W stays factored */
        h = hh * pmax(0.2, fac);
        rejected_last = 0;
    }
    stats[0] += nfev;
    stats[6] += lu.dense_factors;
    stats[7] = lu.fill;
    free(cx->g);
    free(jac);
    slu_free(&lu);
    *t_res = t;
    *h_res = h;
    *k_res = k;
    return status;
}
