#ifndef WINDER_EVENTS_H
#define WINDER_EVENTS_H

/* What winder's C integrators share (dopri5.c, dop853.c, rk4.c, ros2.c, rosenbrock.c): the
 * locked modes of a generated machine, their located switches, the penetration guard, the
 * status codes and the call of the generated functions. A line-by-line port of
 * src/winder/solve/integrators.py (read its docstrings for the contract): the same
 * floating-point operations in the same order (compiled with -ffp-contract=off), so the
 * accepted steps, event times and states agree with the numba kernels bit for bit. Static
 * functions: each integrator's translation unit includes this header.
 *
 * The machine's functions: fns (int64 addresses) [F_RHS, F_JAC, F_OUT, F_SW], each
 * int f(const double* t, const double* x, const double* p, const double* m, double* out).
 * The mode table: nslots rows of 5 int64 (kind, g1, g2, state, param) -- see
 * integrators.py. Output: Y_out is (n, n_out) row-major, Y_out[i * n_out + k].
 * stats (int64): nfev, accepted, rejected, events, stiff steps (nstats of them). */

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef int (*wfn)(const double*, const double*, const double*, const double*, double*);

enum { DONE = 0, PAUSED = 1, STEP_UNDERFLOW = 2, NON_FINITE = 3, EXHAUSTED = 4,
       PENETRATED = 5, NO_MEMORY = 6 };
enum { K_CONTACT = 0, K_CORE = 1, K_END = 2 };
enum { F_RHS = 0, F_JAC = 1, F_OUT = 2, F_SW = 3 };
#define AUTO (-1.0)
#define FREE 0.0
#define IN_CONTACT 1.0
#define WINDING 0.0
#define AT_CORE 1.0
#define END 9.0
#define GUARD (-2)
#define TIME_RESOLUTION 1e-14

/* Python's max(a, b) and min(a, b) (the first argument unless the second is beyond it) */
static inline double pmax(double a, double b) { return b > a ? b : a; }
static inline double pmin(double a, double b) { return b < a ? b : a; }

/* Everything a run needs besides the state: the machine, the table, work buffers. */
typedef struct {
    wfn fns[4];
    const int64_t* table;
    int64_t nslots;
    int64_t n;
    const double* p;
    double* m;
    double tb[1];
    double* g;
    double* g0;
    double* yt;
    double* ye;  /* guard_step's end of a cut step */
    double* rl;  /* _chord's straight path as a dense output (rows x n) */
    /* The dense output's form: rows of rc (dense()): 5 (the 4th-order polynomial of DOPRI5,
     * and the cubic Hermite of ROS2, RODAS, RK4; the default) or 8 (DOP853's 7th-order
     * one; no other). Where lazy_rc is set, the rows of that rc are written on first use by
     * complete(lazy_arg) (DOP853: its 3 extra stages only on steps that need them). */
    int64_t rows;
    const double* lazy_rc;
    void (*complete)(void*);
    void* lazy_arg;
    int64_t ns;  /* the switch buffers' length */
    /* the switches at an accepted step's end (next_event's, before any probe), kept as the
     * next step's switches at its start: g_end written by this step, g_start the last
     * step's, valid where start_ok (set by the integrator: the step began at that end) */
    double* g_end;
    double* g_start;
    int start_ok;
    int64_t n_sw;        /* switch evaluations: all of them */
    int64_t n_sw_locate; /* of which in locate (the event's root finding) */
    int64_t n_locate;    /* locate calls (candidate switches in accepted steps) */
    int legacy_probe;    /* guard_step probes after a chord that found nothing (RK4) */
} Ctx;

#define TAB(s, c) (cx->table[(s) * 5 + (c)])

static inline void evaluate(Ctx* cx, int which, double t, const double* y, double* out) {
    cx->tb[0] = t;
    cx->fns[which](cx->tb, y, cx->p, cx->m, out);
}

static inline void switches(Ctx* cx, double t, const double* y, double* g) {
    cx->n_sw++;
    evaluate(cx, F_SW, t, y, g);
}

/* After an accepted step with no event that ends where the next one starts (t = t + hh
 * exactly, y = y1): its end's switches are the next step's start's (the same function of
 * the same t, y and modes: the same bits), so guard_step does not evaluate them again. */
static inline void step_continues(Ctx* cx, int continues) {
    double* g = cx->g_start;
    cx->g_start = cx->g_end;
    cx->g_end = g;
    cx->start_ok = continues;
}

static inline void modes_of(Ctx* cx, double t, const double* y, int contact_auto) {
    double* g = cx->g;
    switches(cx, t, y, g);
    for (int64_t s = 0; s < cx->nslots; s++) {
        if (TAB(s, 0) == K_CONTACT) {
            if (contact_auto)
                cx->m[s] = AUTO;
            else
                cx->m[s] = g[TAB(s, 1)] > 0.0 ? IN_CONTACT : FREE;
        } else if (TAB(s, 0) == K_END) {
            cx->m[s] = 0.0;
        } else {
            cx->m[s] = (g[TAB(s, 1)] >= 0.0 && g[TAB(s, 2)] <= 0.0) ? AT_CORE : WINDING;
        }
    }
}

#define MAX_ROWS 8

/* The dense output at theta in [0, 1] of a step: rc[0] + theta (rc[1] + (1 - theta)
 * (rc[2] + theta (rc[3] + ...))), rows alternating theta and 1 - theta (scipy's
 * Dop853DenseOutput's form; DOPRI5's with 5 rows, its arithmetic unchanged). */
static inline void dense(Ctx* cx, const double* rc, double theta, double* out) {
    int64_t n = cx->n;
    double th1 = 1.0 - theta;
    if (rc == cx->lazy_rc) {
        cx->lazy_rc = NULL;
        cx->complete(cx->lazy_arg);
    }
    if (cx->rows == 5) {
        for (int64_t i = 0; i < n; i++)
            out[i] = rc[i] + theta * (rc[n + i] + th1 * (rc[2 * n + i] + theta
                                      * (rc[3 * n + i] + th1 * rc[4 * n + i])));
        return;
    }
    for (int64_t i = 0; i < n; i++)  /* rows == 8 */
        out[i] = rc[i] + theta * (rc[n + i] + th1 * (rc[2 * n + i] + theta
                 * (rc[3 * n + i] + th1 * (rc[4 * n + i] + theta * (rc[5 * n + i] + th1
                 * (rc[6 * n + i] + theta * rc[7 * n + i]))))));
}

static inline double switch_at(Ctx* cx, int64_t gi, double t, const double* y, double* g) {
    switches(cx, t, y, g);
    return g[gi];
}

/* First theta in (0, 1] of an accepted step where switching function gi is on its new
 * side; Illinois method to ~1e-12 s. */
static inline double locate(Ctx* cx, int64_t gi, int new_pos, const double* rc, double t,
                     double hh) {
    double* yt = cx->yt;
    double* g = cx->g;
    int64_t before = cx->n_sw;
    cx->n_locate++;
    dense(cx, rc, 1.0, yt);
    double gb = switch_at(cx, gi, t + hh, yt, g);
    dense(cx, rc, 0.0, yt);
    double ga = switch_at(cx, gi, t, yt, g);
    if (new_pos && ga > 0.0)
        ga = -1e-300;
    else if (!new_pos && ga <= 0.0)
        ga = 1e-300;
    double ta = 0.0, tb_ = 1.0;
    int side = 0;
    double tol = 1e-12 * pmax(1.0, fabs(t)) / hh;
    for (int it = 0; it < 100; it++) {
        if (tb_ - ta <= tol)
            break;
        double th = (ta * gb - tb_ * ga) / (gb - ga);
        if (!(ta < th && th < tb_))
            th = 0.5 * (ta + tb_);
        dense(cx, rc, th, yt);
        double gv = switch_at(cx, gi, t + th * hh, yt, g);
        if ((gv > 0.0) == (new_pos != 0)) {
            tb_ = th;
            gb = gv;
            if (side == -1)
                ga *= 0.5;
            side = -1;
        } else {
            ta = th;
            ga = gv;
            if (side == 1)
                gb *= 0.5;
            side = 1;
        }
    }
    cx->n_sw_locate += cx->n_sw - before;
    return tb_;
}

static inline int64_t sliver(int64_t n, double t, double t1, double* y, const double* f,
                      const double* t_out, int64_t n_out, double* Y_out, int64_t k) {
    for (int64_t i = 0; i < n; i++)
        y[i] += (t1 - t) * f[i];
    while (k < n_out && t_out[k] <= t1 + 1e-13 * pmax(1.0, fabs(t1))) {
        for (int64_t i = 0; i < n; i++)
            Y_out[i * n_out + k] = y[i];
        k++;
    }
    return k;
}

/* The first mode switch inside the step to y1: theta (2 for none), slot, new mode. */
static inline double next_event(Ctx* cx, const double* rc, double t, double hh, const double* y1,
                         int located, int64_t* slot_out, double* new_out) {
    double* g = cx->g;
    switches(cx, t + hh, y1, g);
    memcpy(cx->g_end, g, sizeof(double) * (size_t)cx->ns);
    double best = 2.0, newm = 0.0;
    int64_t slot = -1;
    for (int64_t s = 0; s < cx->nslots; s++) {
        int64_t gi = -1;
        int pos = 1;
        double nm = 0.0;
        double ms = cx->m[s];
        if (TAB(s, 0) == K_CONTACT) {
            if (ms == IN_CONTACT && g[TAB(s, 1)] <= 0.0) {
                gi = TAB(s, 1); pos = 0; nm = FREE;
            } else if (ms == FREE && g[TAB(s, 1)] > 0.0) {
                gi = TAB(s, 1); pos = 1; nm = IN_CONTACT;
            }
        } else if (TAB(s, 0) == K_END) {
            if (g[TAB(s, 1)] > 0.0) {
                gi = TAB(s, 1); pos = 1; nm = END;
            }
        } else {
            if (ms == WINDING && g[TAB(s, 1)] > 0.0) {
                gi = TAB(s, 1); pos = 1; nm = AT_CORE;
            } else if (ms == AT_CORE && g[TAB(s, 2)] > 0.0) {
                gi = TAB(s, 2); pos = 1; nm = WINDING;
            }
        }
        if (gi >= 0) {
            /* as the numba kernel: locate() probes into g, and the later slots of this
             * loop read those probes, not g at y1 (kept for bit-equality; see NOTES) */
            double th = located ? locate(cx, gi, pos, rc, t, hh) : 1.0;
            if (th < best) {
                best = th; slot = s; newm = nm;
            }
        }
    }
    *slot_out = slot;
    *new_out = newm;
    return best;
}

/* The first contact slot whose guard function is beyond its bound (> 0 or NaN); -1. */
static inline int64_t beyond_bound(const Ctx* cx, const double* g) {
    for (int64_t s = 0; s < cx->nslots; s++)
        if (TAB(s, 0) == K_CONTACT && !(g[TAB(s, 2)] <= 0.0))
            return s;
    return -1;
}

static inline int beyond_at(Ctx* cx, double t, const double* y, double* g) {
    switches(cx, t, y, g);
    return beyond_bound(cx, g) >= 0;
}

/* Where the nips beyond their bound at th_hi cross it: bisection on the dense output. */
static inline double first_beyond(Ctx* cx, const double* rc, double t, double hh, double th_hi,
                           double* g) {
    double* yt = cx->yt;
    double best = th_hi;
    for (int64_t s = 0; s < cx->nslots; s++) {
        if (TAB(s, 0) != K_CONTACT)
            continue;
        int64_t gi = TAB(s, 2);
        dense(cx, rc, th_hi, yt);
        if (!(switch_at(cx, gi, t + th_hi * hh, yt, g) > 0.0))
            continue;
        double ta = 0.0, tb_ = th_hi;
        for (int it = 0; it < 60; it++) {
            double th = 0.5 * (ta + tb_);
            dense(cx, rc, th, yt);
            if (switch_at(cx, gi, t + th * hh, yt, g) > 0.0)
                tb_ = th;
            else
                ta = th;
        }
        best = pmin(best, tb_);
    }
    return best;
}

/* theta where the straight path from y0 to y1 first takes a nip beyond its bound; 2. */
static inline double chord(Ctx* cx, double t, double hh, const double* y0, const double* y1,
                    const double* g0, double* g) {
    int64_t n = cx->n;
    double* yt = cx->yt;
    double best = 2.0;
    for (int64_t s = 0; s < cx->nslots; s++) {
        if (TAB(s, 0) != K_CONTACT)
            continue;
        double x0 = g0[TAB(s, 3)], z0 = g0[TAB(s, 4)];
        double x1 = g[TAB(s, 3)], z1 = g[TAB(s, 4)];
        double dx = x1 - x0, dz = z1 - z0;
        double d2 = dx * dx + dz * dz;
        double bound = g[TAB(s, 2)] + sqrt(x1 * x1 + z1 * z1);
        if (!(d2 > 0.0))
            continue;
        double th = pmin(1.0, pmax(0.0, -(x0 * dx + z0 * dz) / d2));
        double ccx = x0 + th * dx, ccz = z0 + th * dz;
        if (!(ccx * ccx + ccz * ccz < bound * bound))
            continue;
        double b2 = x0 * dx + z0 * dz;
        double disc = b2 * b2 - d2 * (x0 * x0 + z0 * z0 - bound * bound);
        th = 0.5 * (th + pmax(0.0, (-b2 - sqrt(pmax(disc, 0.0))) / d2));
        for (int64_t i = 0; i < n; i++)
            yt[i] = y0[i] + th * (y1[i] - y0[i]);
        if (switch_at(cx, TAB(s, 2), t + th * hh, yt, g) > 0.0) {
            double* rl = cx->rl;
            memset(rl, 0, sizeof(double) * (size_t)(cx->rows * n));
            for (int64_t i = 0; i < n; i++) {
                rl[i] = y0[i];
                rl[n + i] = y1[i] - y0[i];
            }
            best = pmin(best, first_beyond(cx, rl, t, hh, th, g));
        }
        switches(cx, t + hh, y1, g);
    }
    return best;
}

/* The guard of the kept part [0, th_end] of an accepted step (see integrators.py). */
static inline double guard_step(Ctx* cx, const double* rc, double t, double hh, double th_end,
                         double* y0, const double* y1, const double* t_out, int64_t n_out,
                         int64_t k, int fresh) {
    int64_t n = cx->n;
    double* yt = cx->yt;
    double* g = cx->g;
    double* g0 = cx->g0;
    const double* ye = y1;
    if (th_end < 1.0) {
        dense(cx, rc, th_end, cx->ye);
        ye = cx->ye;
    }
    double best = 2.0;
    int straight = 0;
    if (cx->start_ok)
        memcpy(g0, cx->g_start, sizeof(double) * (size_t)cx->ns);
    else
        switches(cx, t, y0, g0);
    if (!(fresh && th_end >= 1.0))
        switches(cx, t + th_end * hh, ye, g);
    if (beyond_bound(cx, g) >= 0) {
        best = first_beyond(cx, rc, t, hh, th_end, g);
        switches(cx, t + th_end * hh, ye, g);
    }
    double th = chord(cx, t, th_end * hh, y0, ye, g0, g);
    /* only where the chord crosses (th <= 1; 2 is none): with th = 2 and a step cut at an
     * event (th_end < 1) the test 2 th_end < best held, and every located event probed the
     * dense output at 64 points for nothing (DOPRI5, ROS2: the results then discarded, y0
     * is moved to the event and the guard's 2 th_end lies past it). RK4 keeps the old test
     * (legacy_probe): its core events interpolate from the y0 this moves (see
     * docs/c-integrators.md, pitfalls), recorded in its traces. */
    if ((th <= 1.0 || cx->legacy_probe) && th * th_end < best) {
        best = th * th_end;
        straight = 1;
        for (int j = 1; j < 65; j++) {
            double tj = th_end * j / 64.0;
            dense(cx, rc, tj, yt);
            if (beyond_at(cx, t + tj * hh, yt, g)) {
                best = first_beyond(cx, rc, t, hh, tj, g);
                straight = 0;
                break;
            }
        }
    }
    while (k < n_out && t_out[k] <= t + pmin(best, th_end) * hh) {
        th = pmax(0.0, (t_out[k] - t) / hh);
        dense(cx, rc, th, yt);
        if (beyond_at(cx, t + th * hh, yt, g)) {
            th = first_beyond(cx, rc, t, hh, th, g);
            if (th < best) {
                best = th;
                straight = 0;
            }
            break;
        }
        k++;
    }
    if (best <= 1.0) {
        if (straight) {
            for (int64_t i = 0; i < n; i++)
                y0[i] += best / th_end * (ye[i] - y0[i]);
        } else {
            dense(cx, rc, best, y0);
        }
    }
    return best;
}

static inline int64_t switch_size(const int64_t* table, int64_t nslots) {
    int64_t size = 1;
    for (int64_t s = 0; s < nslots; s++) {
        int last = table[s * 5] == K_CONTACT ? 5 : 3;
        for (int c = 1; c < last; c++)
            if (table[s * 5 + c] + 1 > size)
                size = table[s * 5 + c] + 1;
    }
    return size;
}

static inline double first_step(int64_t n, const double* y, const double* f, double rtol,
                         double atol) {
    double d0 = 0.0, d1 = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double sk = atol + rtol * fabs(y[i]);
        double a = y[i] / sk, b = f[i] / sk;
        d0 += a * a;
        d1 += b * b;
    }
    d0 = sqrt(d0 / (double)n);
    d1 = sqrt(d1 / (double)n);
    return (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
}

/* After an accepted step: the first switch, the samples up to it, y moved there. */
static inline int64_t sample_and_switch(Ctx* cx, const double* rc, double t, double hh, double t1,
                                 double* y, const double* y1, const double* t_out,
                                 int64_t n_out, double* Y_out, int64_t* k_io,
                                 double* new_out, double* t_end_out) {
    int64_t n = cx->n;
    double* yt = cx->yt;
    int64_t slot;
    double new_mode;
    int64_t k = *k_io;
    double theta_end = next_event(cx, rc, t, hh, y1, 1, &slot, &new_mode);
    if (theta_end > 1.0)
        theta_end = 1.0;
    double theta_guard = guard_step(cx, rc, t, hh, theta_end, y, y1, t_out, n_out, k,
                                    slot < 0);
    if (theta_guard <= theta_end) {
        theta_end = theta_guard;
        slot = GUARD;
    }
    double t_end = t + theta_end * hh;
    while (k < n_out && t_out[k] <= t_end + 1e-13 * pmax(1.0, fabs(t_end))) {
        if (t_out[k] > t1 + 1e-13 * pmax(1.0, fabs(t1)))
            break;
        if (slot == GUARD && t_out[k] >= t_end)
            break;
        dense(cx, rc, pmin(theta_end, pmax(0.0, (t_out[k] - t) / hh)), yt);
        for (int64_t i = 0; i < n; i++)
            Y_out[i * n_out + k] = yt[i];
        k++;
    }
    if (slot >= 0) {
        dense(cx, rc, theta_end, y);
        if (new_mode == END || (TAB(slot, 0) == K_CORE && new_mode == AT_CORE))
            y[TAB(slot, 3)] = cx->p[TAB(slot, 4)];
    }
    *k_io = k;
    *new_out = new_mode;
    *t_end_out = t_end;
    return slot;
}

/* What an accepted step's event (sample_and_switch's slot) does to the run: PENETRATED at
 * the guard, EXHAUSTED at an unwinding roll's run-out (t moved there), or DONE where the
 * integration goes on; a mode switch sets the slot's mode, moves t to the event, evaluates
 * f there (the next step's first stage) and sets *switched. Shared by DOPRI5 and ROS2. */
static inline int end_of_step(Ctx* cx, int64_t slot, double new_mode, double t_end,
                              const double* y, double* f, double* t, int64_t* nfev,
                              int64_t* stats, int* switched) {
    *switched = 0;
    if (slot == GUARD) {
        *t = t_end;
        return PENETRATED;
    }
    if (slot >= 0) {
        *t = t_end;
        if (new_mode == END)
            return EXHAUSTED;
        cx->m[slot] = new_mode;
        evaluate(cx, F_RHS, *t, y, f);
        *nfev += 1;
        stats[3] += 1;
        *switched = 1;
    }
    return DONE;
}

/* Work buffers: g, g0 (switches), yt, ye (n), rl (MAX_ROWS n), g_end, g_start, then n_extra
 * vectors of n. */
static inline int ctx_init(Ctx* cx, const int64_t* fns, const int64_t* table, int64_t nslots,
                    int64_t n_switches, int64_t n, const double* p, double* m, double** extra,
                    int64_t n_extra) {
    /* the switch buffers: every switch the generated sw writes (n_switches), and at least
     * those the table refers to (the numba kernels size them from the table alone) */
    int64_t ns = switch_size(table, nslots);
    if (n_switches > ns)
        ns = n_switches;
    for (int j = 0; j < 4; j++)
        cx->fns[j] = (wfn)(intptr_t)fns[j];
    cx->table = table; cx->nslots = nslots; cx->n = n; cx->p = p; cx->m = m;
    double* buf = malloc(sizeof(double) * (size_t)(4 * ns + (2 + MAX_ROWS) * n
                                                  + n_extra * n));
    if (!buf)
        return 0;
    cx->g = buf; cx->g0 = buf + ns; cx->yt = buf + 2 * ns; cx->ye = cx->yt + n;
    cx->rl = cx->ye + n;
    cx->ns = ns; cx->g_end = cx->rl + MAX_ROWS * n; cx->g_start = cx->g_end + ns; cx->start_ok = 0;
    cx->n_sw = 0; cx->n_sw_locate = 0; cx->n_locate = 0; cx->legacy_probe = 0;
    cx->rows = 5; cx->lazy_rc = NULL; cx->complete = NULL; cx->lazy_arg = NULL;
    double* e = cx->g_start + ns;
    for (int64_t j = 0; j < n_extra; j++)
        extra[j] = e + j * n;
    return 1;
}

#endif
