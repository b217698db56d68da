/* winder's native FMI 2.0 wrapper: the machine's generated functions and winder's C
 * integrators behind fmi2Functions.h. Co-simulation: DOPRI5 with located events and
 * switched modes, or fixed-step RK4, inside each communication step. Model exchange: the
 * states and their derivatives in locked modes, the switching functions of the mode
 * table as event indicators, the modes switched (from the state, as every integrator
 * call does) in fmi2NewDiscreteStates, the drums' ramp ends as time events. No Python: the machine's data (its parameters, initial
 * state, mode table, breakpoints, variables) is in winder_model.h, written by
 * winder.fmu.native for one scene.
 *
 * Value references (Real): outputs [0, W_NOUT), inputs, parameters, the solver settings
 * (rtol, atol, rk4_step), the states (locals) and their derivatives (locals); Boolean 0 is
 * `rk4` (fixed-step RK4 instead of DOPRI5). */

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "winder_model.h"

/* the integrators (src/winder/solve/c/, the same objects as winder.simulate's) */
int winder_dopri5(const int64_t* fns, const int64_t* table, int64_t nslots,
                  int64_t n_switches, double t0, double t1, double* y, int64_t n,
                  const double* p, double* m, double rtol, double atol, double h,
                  double max_step, const double* t_out, int64_t n_out, double* Y_out,
                  int64_t k, int64_t budget, int64_t* stats, int64_t nstats,
                  double* t_res, double* h_res, int64_t* k_res);
int winder_rk4(const int64_t* fns, const int64_t* table, int64_t nslots,
               int64_t n_switches, double t0, double t1, double* y, int64_t n,
               const double* p, double* m, double h, const double* t_out, int64_t n_out,
               double* Y_out, int64_t k, int64_t* stats, double* t_res, double* h_res,
               int64_t* k_res);
int winder_modes(const int64_t* fns, const int64_t* table, int64_t nslots,
                 int64_t n_switches, double t, const double* y, int64_t n, const double* p,
                 double* m, int64_t contact_auto);

enum { S_DONE = 0, S_PAUSED = 1, S_UNDERFLOW = 2, S_NON_FINITE = 3, S_EXHAUSTED = 4,
       S_PENETRATED = 5, S_NO_MEMORY = 6 };
#define CHUNK 200000       /* evaluations per integrator call (winder.solve.integrators) */
#define K_END 2
#define W_MAGIC 0x77696e6465723032LL /* "winder02" */

#include "layout.h"

enum { M_INSTANTIATED, M_INIT, M_STEP, M_TERMINATED, M_ERROR };

/* Everything a run is (copied by fmi2GetFMUstate, serialised as bytes). */
typedef struct {
    int64_t magic, size;
    double t, h;        /* time [s], the DOPRI5 step to try next [s] */
    double y[W_N + 1];  /* the state */
    double p[W_NP + 1]; /* the run-time parameters (the inputs among them) */
    double m[W_NSLOTS + 1];
    int64_t stats[5];
    double rtol, atol, hrk4;
    int32_t rk4, ended, mode, pad;
    double t_end;
    char why[240];
} Core;

typedef struct {
    Core c;
    int me; /* instantiated for model exchange */
    fmi2CallbackFunctions cb;
    char name[128];
    int logging;
    int64_t fns[4];
    int out_valid;
    double out[W_NCH + 1];
    double mw[W_NSLOTS + 1];
} Comp;

static void logf_(Comp* s, fmi2Status st, const char* cat, const char* fmt, ...) {
    char buf[512];
    va_list ap;
    if (!s->cb.logger)
        return;
    if (!s->logging && st == fmi2OK)
        return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    s->cb.logger(s->cb.componentEnvironment, s->name, st, cat, "%s", buf);
}

static fmi2Status fail(Comp* s, const char* fmt, const char* what) {
    logf_(s, fmi2Error, "logStatusError", fmt, what);
    return fmi2Error;
}

/* ---- the machine at the current point ----------------------------------------------- */

static void apply_ramps(Core* c) {
    for (int i = 0; i < W_NRAMP; i++) { /* a drum's ramp time v_w / a_w */
        double aw = c->p[W_RAMP[3 * i]], vw = c->p[W_RAMP[3 * i + 1]];
        c->p[W_RAMP[3 * i + 2]] = aw > 0.0 ? vw / aw : 0.0;
    }
}

static void channels(Comp* s) {
    if (s->out_valid)
        return;
    double tb[1] = {s->c.t};
    winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, s->c.t, s->c.y, W_N, s->c.p, s->mw, 1);
    W_OUT_FN(tb, s->c.y, s->c.p, s->mw, s->out);
    s->out_valid = 1;
}

/* dy/dt at (t, y) in the modes a DOPRI5 step from there runs in */
static void rates(Comp* s, const double* y, const double* p, double* dy) {
    double tb[1] = {s->c.t};
    if (s->me) { /* model exchange: the modes locked since the last event */
        W_RHS_FN(tb, y, p, s->c.m, dy);
        return;
    }
    winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, s->c.t, y, W_N, p, s->mw, 0);
    W_RHS_FN(tb, y, p, s->mw, dy);
}

/* a single-drum scene's web-speed profile min(a_w t, v_w) (a_w = 0: v_w from t = 0) */
static double profile_reference(const double* p, double t) {
    double a = W_REF_AP >= 0 ? p[W_REF_AP] : W_REF_A;
    double v = W_REF_VP >= 0 ? p[W_REF_VP] : W_REF_V;
    return a > 0.0 ? fmin(a * t, v) : v;
}

static double output_of(Comp* s, int i) {
    int ch = W_OUT_CH[i];
    if (ch == -2)
        return s->c.t;
    if (ch == -3)
        return profile_reference(s->c.p, s->c.t);
    if (ch < 0)
        return 0.0; /* a channel the machine lacks (an effect off) is zero */
    channels(s);
    return s->out[ch];
}

static void reset(Comp* s) {
    Core* c = &s->c;
    memset(c, 0, sizeof *c);
    c->magic = W_MAGIC;
    c->size = (int64_t)sizeof(Core);
    memcpy(c->y, W_X0, sizeof(double) * W_N);
    memcpy(c->p, W_P0, sizeof(double) * W_NP);
    c->rtol = 1e-8;
    c->atol = 1e-10;
    c->hrk4 = 1e-3;
    s->out_valid = 0;
}

/* ---- instance ------------------------------------------------------------------------ */

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String guid,
                              fmi2String resources, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)resources;
    (void)visible;
    if (!functions || !functions->logger)
        return NULL;
    if (!guid || strcmp(guid, W_GUID) != 0) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error,
                          "logStatusError", "wrong GUID %s (expected %s)",
                          guid ? guid : "(null)", W_GUID);
        return NULL;
    }
    Comp* s = calloc(1, sizeof(Comp));
    if (!s)
        return NULL;
    s->cb = *functions;
    snprintf(s->name, sizeof s->name, "%s", instanceName ? instanceName : "winder");
    s->logging = loggingOn;
    s->me = fmuType == fmi2ModelExchange;
    s->fns[0] = (int64_t)(intptr_t)&W_RHS_FN;
    s->fns[1] = (int64_t)(intptr_t)&W_JAC_FN;
    s->fns[2] = (int64_t)(intptr_t)&W_OUT_FN;
    s->fns[3] = (int64_t)(intptr_t)&W_SW_FN;
    reset(s);
    s->c.mode = M_INSTANTIATED;
    return s;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n,
                               const fmi2String cats[]) {
    (void)n;
    (void)cats;
    ((Comp*)c)->logging = on;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol,
                               fmi2Real start, fmi2Boolean stopDefined, fmi2Real stop) {
    Comp* s = c;
    (void)stopDefined;
    (void)stop;
    if (tolDefined && tol > 0.0 && tol <= 0.1)
        s->c.rtol = tol;
    s->c.t = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    ((Comp*)c)->c.mode = M_INIT;
    return fmi2OK;
}

/* The static balance of the parameters set by the host (machines.md §7): Newton on the
 * generated force residual and its exact Jacobian from the build-time balance, in its
 * locked modes (W_MB). Returns 0 where it does not converge. */
static int rebalance(Comp* s) {
    double out[W_NU + W_NU * W_NU + 1], J[W_NU * W_NU + 1], du[W_NU + 1];
    double tb[1] = {0.0};
    Core* k = &s->c;
    for (int it = 0; it < 50; it++) {
        W_BAL_FN(tb, k->y, k->p, W_MB, out);
        memcpy(J, out + W_NU, sizeof(double) * W_NU * W_NU);
        for (int i = 0; i < W_NU; i++)
            du[i] = -out[i];
        for (int col = 0; col < W_NU; col++) { /* LU with partial pivoting */
            int piv = col;
            for (int r = col + 1; r < W_NU; r++)
                if (fabs(J[col * W_NU + r]) > fabs(J[col * W_NU + piv]))
                    piv = r;
            if (!(fabs(J[col * W_NU + piv]) > 0.0))
                return 0;
            if (piv != col) {
                for (int cc = 0; cc < W_NU; cc++) {
                    double tmp = J[cc * W_NU + col];
                    J[cc * W_NU + col] = J[cc * W_NU + piv];
                    J[cc * W_NU + piv] = tmp;
                }
                double tmp = du[col];
                du[col] = du[piv];
                du[piv] = tmp;
            }
            for (int r = col + 1; r < W_NU; r++) {
                double f = J[col * W_NU + r] / J[col * W_NU + col];
                for (int cc = col; cc < W_NU; cc++)
                    J[cc * W_NU + r] -= f * J[cc * W_NU + col];
                du[r] -= f * du[col];
            }
        }
        for (int r = W_NU - 1; r >= 0; r--) {
            for (int cc = r + 1; cc < W_NU; cc++)
                du[r] -= J[cc * W_NU + r] * du[cc];
            du[r] /= J[r * W_NU + r];
        }
        int done = 1;
        for (int i = 0; i < W_NU; i++) {
            double u = k->y[W_U[i]];
            if (!isfinite(du[i]))
                return 0;
            k->y[W_U[i]] = u + du[i];
            if (fabs(du[i]) > 1e-15 * fmax(1.0, fabs(u)))
                done = 0;
        }
        if (done)
            return 1;
    }
    return 0;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Comp* s = c;
    if (!(s->c.rtol > 0.0 && s->c.rtol <= 0.1) || !(s->c.atol > 0.0 && s->c.atol <= 1e-3))
        return fail(s, "%s", "rtol must be in (0, 0.1] and atol in (0, 1e-3]");
    if (!(s->c.hrk4 > 0.0 && isfinite(s->c.hrk4)))
        return fail(s, "%s", "rk4_step must be finite and > 0 [s]");
    apply_ramps(&s->c);
    if (W_NU > 0 && memcmp(s->c.p, W_P0, sizeof(double) * W_NP) != 0) {
        memcpy(s->c.y, W_X0, sizeof(double) * W_N);
        if (!rebalance(s))
            return fail(s, "%s", "no static balance for the parameters set: Newton on the "
                        "force residual did not converge from the built balance (a nip "
                        "that would pull, or a change too large)");
    }
    if (s->me)
        winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, s->c.t, s->c.y, W_N, s->c.p, s->c.m, 0);
    s->out_valid = 0;
    s->c.mode = M_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    ((Comp*)c)->c.mode = M_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    Comp* s = c;
    reset(s);
    s->c.mode = M_INSTANTIATED;
    return fmi2OK;
}

/* ---- variables ----------------------------------------------------------------------- */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Comp* s = c;
    double dy[W_N + 1];
    int have_dy = 0;
    for (size_t i = 0; i < nvr; i++) {
        fmi2ValueReference r = vr[i];
        if (r < VR_IN)
            value[i] = output_of(s, (int)r);
        else if (r < VR_PAR)
            value[i] = s->c.p[W_IN_P[r - VR_IN]];
        else if (r < VR_RTOL)
            value[i] = s->c.p[W_PAR_P[r - VR_PAR]];
        else if (r == VR_RTOL)
            value[i] = s->c.rtol;
        else if (r == VR_ATOL)
            value[i] = s->c.atol;
        else if (r == VR_HRK4)
            value[i] = s->c.hrk4;
        else if (r < VR_DX)
            value[i] = s->c.y[r - VR_X];
        else if (r < VR_END) {
            if (!have_dy) {
                rates(s, s->c.y, s->c.p, dy);
                have_dy = 1;
            }
            value[i] = dy[r - VR_DX];
        } else {
            logf_(s, fmi2Error, "logStatusError", "unknown Real value reference %u", r);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Comp* s = c;
    for (size_t i = 0; i < nvr; i++) {
        fmi2ValueReference r = vr[i];
        double v = value[i];
        if (!isfinite(v)) {
            logf_(s, fmi2Error, "logStatusError", "value reference %u: %g is not finite",
                  r, v);
            return fmi2Error;
        }
        if (r >= VR_IN && r < VR_PAR)
            s->c.p[W_IN_P[r - VR_IN]] = v;
        else if (r >= VR_PAR && r < VR_X && s->c.mode == M_STEP) {
            logf_(s, fmi2Error, "logStatusError", "value reference %u is a fixed parameter: "
                  "set it before fmi2ExitInitializationMode", r);
            return fmi2Error;
        } else if (r >= VR_PAR && r < VR_RTOL)
            s->c.p[W_PAR_P[r - VR_PAR]] = v;
        else if (r == VR_RTOL)
            s->c.rtol = v;
        else if (r == VR_ATOL)
            s->c.atol = v;
        else if (r == VR_HRK4)
            s->c.hrk4 = v;
        else {
            logf_(s, fmi2Error, "logStatusError", "value reference %u cannot be set", r);
            return fmi2Error;
        }
    }
    s->out_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    (void)vr;
    (void)value;
    return nvr ? fail(c, "%s", "this FMU has no Integer variables") : fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr;
    (void)value;
    return nvr ? fail(c, "%s", "this FMU has no Integer variables") : fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    Comp* s = c;
    for (size_t i = 0; i < nvr; i++) {
        if (W_OWN && vr[i] == 1) { /* the single-drum switch, fixed at build time */
            value[i] = W_PROFILE ? fmi2True : fmi2False;
            continue;
        }
        if (vr[i] != 0)
            return fail(s, "%s", "unknown Boolean value reference");
        value[i] = s->c.rk4 ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    Comp* s = c;
    for (size_t i = 0; i < nvr; i++) {
        if (W_OWN && vr[i] == 1) { /* the single-drum switch: the machine it was built as */
            if ((value[i] ? 1 : 0) != W_PROFILE)
                return fail(s, "%s", W_PROFILE
                    ? "speed_profile = false needs the free-drum machine: build this FMU "
                      "with winder fmu --no-speed-profile"
                    : "speed_profile = true needs the profile-driven machine: build this "
                      "FMU with winder fmu --speed-profile");
            continue;
        }
        if (vr[i] != 0)
            return fail(s, "%s", "unknown Boolean value reference");
        if (s->c.mode == M_STEP)
            return fail(s, "%s", "rk4 is a fixed parameter: set it before "
                                 "fmi2ExitInitializationMode");
        s->c.rk4 = value[i] ? 1 : 0;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)vr;
    (void)value;
    return nvr ? fail(c, "%s", "this FMU has no String variables") : fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)vr;
    (void)value;
    return nvr ? fail(c, "%s", "this FMU has no String variables") : fmi2OK;
}

/* ---- FMU state ----------------------------------------------------------------------- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
    Comp* s = c;
    Core* copy = *state ? (Core*)*state : malloc(sizeof(Core));
    if (!copy)
        return fail(s, "%s", "out of memory");
    *copy = s->c;
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    Comp* s = c;
    const Core* copy = state;
    if (!copy || copy->magic != W_MAGIC || copy->size != (int64_t)sizeof(Core))
        return fail(s, "%s", "not an FMU state of this FMU");
    s->c = *copy;
    s->out_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
    (void)c;
    if (state) {
        free(*state);
        *state = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size) {
    (void)c;
    (void)state;
    *size = sizeof(Core) + sizeof(W_GUID);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                 size_t size) {
    if (size < sizeof(Core) + sizeof(W_GUID) || !state)
        return fail(c, "%s", "buffer too small for the serialized FMU state");
    memcpy(bytes, W_GUID, sizeof(W_GUID));
    memcpy(bytes + sizeof(W_GUID), state, sizeof(Core));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate* state) {
    Core tmp;
    if (size != sizeof(Core) + sizeof(W_GUID) || memcmp(bytes, W_GUID, sizeof(W_GUID)) != 0)
        return fail(c, "%s", "the bytes are no serialized state of this FMU (GUID or size)");
    memcpy(&tmp, bytes + sizeof(W_GUID), sizeof(Core));
    if (tmp.magic != W_MAGIC || tmp.size != (int64_t)sizeof(Core))
        return fail(c, "%s", "the bytes are no serialized state of this FMU");
    Core* copy = *state ? (Core*)*state : malloc(sizeof(Core));
    if (!copy)
        return fail(c, "%s", "out of memory");
    *copy = tmp;
    *state = copy;
    return fmi2OK;
}

/* ---- directional derivatives --------------------------------------------------------- */

/* the unknown vr at state y, parameters p (outputs: the channels; derivatives: rhs) */
static double unknown_at(Comp* s, fmi2ValueReference r, const double* y, const double* p) {
    double tb[1] = {s->c.t};
    if (r < VR_IN) {
        int ch = W_OUT_CH[r];
        if (ch == -2)
            return s->c.t;
        if (ch == -3)
            return profile_reference(p, s->c.t);
        if (ch < 0)
            return 0.0;
        winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, s->c.t, y, W_N, p, s->mw, 1);
        W_OUT_FN(tb, y, p, s->mw, s->out);
        s->out_valid = 0;
        return s->out[ch];
    }
    double dy[W_N + 1];
    rates(s, y, p, dy);
    return dy[r - VR_DX];
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vU[],
                                        size_t nU, const fmi2ValueReference vK[], size_t nK,
                                        const fmi2Real dvK[], fmi2Real dvU[]) {
    Comp* s = c;
    int exact = 1;
    for (size_t j = 0; j < nK; j++) {
        if (vK[j] >= VR_X && vK[j] < VR_DX)
            continue;
        if (vK[j] >= VR_IN && vK[j] < VR_PAR) {
            exact = 0;
            continue;
        }
        return fail(s, "%s", "directional derivatives are w.r.t. states and inputs only");
    }
    for (size_t i = 0; i < nU; i++) {
        if (vU[i] >= VR_DX && vU[i] < VR_END)
            continue;
        if (vU[i] < VR_IN) {
            exact = 0;
            continue;
        }
        return fail(s, "%s", "directional derivatives are of derivatives and outputs only");
    }
    if (exact) { /* the generated exact Jacobian, dense column-major */
        double* J = malloc(sizeof(double) * W_N * W_N);
        if (!J)
            return fail(s, "%s", "out of memory");
        double tb[1] = {s->c.t};
        if (s->me)
            memcpy(s->mw, s->c.m, sizeof(double) * W_NSLOTS);
        else
            winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, s->c.t, s->c.y, W_N, s->c.p, s->mw,
                         0);
        W_JAC_FN(tb, s->c.y, s->c.p, s->mw, J);
        for (size_t i = 0; i < nU; i++) {
            size_t row = vU[i] - VR_DX;
            double acc = 0.0;
            for (size_t j = 0; j < nK; j++)
                acc += J[(vK[j] - VR_X) * W_N + row] * dvK[j];
            dvU[i] = acc;
        }
        free(J);
        return fmi2OK;
    }
    /* central differences along dvK (outputs, or w.r.t. inputs) */
    double yp[W_N + 1], ym[W_N + 1], pp[W_NP + 1], pm[W_NP + 1];
    double norm = 0.0, scale = 0.0;
    for (size_t j = 0; j < nK; j++) {
        double x = vK[j] < VR_PAR ? s->c.p[W_IN_P[vK[j] - VR_IN]] : s->c.y[vK[j] - VR_X];
        norm += dvK[j] * dvK[j];
        scale += x * x;
    }
    if (norm == 0.0) {
        for (size_t i = 0; i < nU; i++)
            dvU[i] = 0.0;
        return fmi2OK;
    }
    double eps = 1e-6 * (1.0 + sqrt(scale)) / sqrt(norm);
    memcpy(yp, s->c.y, sizeof(double) * W_N);
    memcpy(ym, s->c.y, sizeof(double) * W_N);
    memcpy(pp, s->c.p, sizeof(double) * W_NP);
    memcpy(pm, s->c.p, sizeof(double) * W_NP);
    for (size_t j = 0; j < nK; j++) {
        if (vK[j] < VR_PAR) {
            pp[W_IN_P[vK[j] - VR_IN]] += eps * dvK[j];
            pm[W_IN_P[vK[j] - VR_IN]] -= eps * dvK[j];
        } else {
            yp[vK[j] - VR_X] += eps * dvK[j];
            ym[vK[j] - VR_X] -= eps * dvK[j];
        }
    }
    for (size_t i = 0; i < nU; i++)
        dvU[i] = (unknown_at(s, vU[i], yp, pp) - unknown_at(s, vU[i], ym, pm)) / (2.0 * eps);
    return fmi2OK;
}

/* ---- stepping ------------------------------------------------------------------------ */

static void ended(Comp* s, double t) {
    const char* roll = "?";
    for (int k = 0; k < W_NSLOTS; k++) {
        if (W_TABLE[5 * k] != K_END)
            continue;
        if (!strcmp(roll, "?"))
            roll = W_SLOT_OWNER[k];
        if (s->c.y[W_TABLE[5 * k + 3]] <= s->c.p[W_TABLE[5 * k + 4]] * (1.0 + 1e-9)) {
            roll = W_SLOT_OWNER[k];
            break;
        }
    }
    s->c.ended = 1;
    s->c.t_end = t;
    snprintf(s->c.why, sizeof s->c.why, "the unwinding roll '%s' ran out of web (its radius "
             "reached the core) at t = %.6g s: the run ends there", roll, t);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t0, fmi2Real dt, fmi2Boolean noSetPrior) {
    Comp* s = c;
    Core* k = &s->c;
    (void)noSetPrior;
    if (k->mode != M_STEP)
        return fail(s, "%s", "fmi2DoStep outside the stepping mode");
    if (k->ended) {
        logf_(s, fmi2Discard, "logStatusDiscard", "the run has ended: %s", k->why);
        return fmi2Discard;
    }
    if (fabs(t0 - k->t) > 1e-9 * fmax(1.0, fabs(t0))) {
        logf_(s, fmi2Error, "logStatusError", "fmi2DoStep at t = %.17g but the FMU is at "
              "t = %.17g (steps must be contiguous)", t0, k->t);
        return fmi2Error;
    }
    if (!(isfinite(dt) && dt >= 1e-14 * fmax(1.0, fabs(k->t)))) {
        logf_(s, fmi2Error, "logStatusError", "communication step %g s: must be finite and "
              ">= the time resolution 1e-14*max(1 s, |t|)", dt);
        return fmi2Error;
    }
    double t_end = k->t + dt;
    double dummy_t[1] = {0.0}, dummy_y[1] = {0.0};
    int64_t kr;
    double tr, hr;
    s->out_valid = 0;
    /* the stops: the drums' ramp ends v_w / a_w inside the step (sorted), then its end */
    double stops[W_NRAMP + 1];
    int nstops = 0;
    for (int i = 0; i < W_NRAMP; i++) {
        double tr_ = k->p[W_RAMP[3 * i + 2]];
        if (!(k->p[W_RAMP[3 * i]] > 0.0 && k->t < tr_ && tr_ < t_end))
            continue;
        int j = nstops++;
        while (j > 0 && stops[j - 1] > tr_) {
            stops[j] = stops[j - 1];
            j--;
        }
        stops[j] = tr_;
    }
    stops[nstops++] = t_end;
    for (int b = 0; b < nstops; b++) {
        double tb = stops[b];
        while (k->t < tb) {
            int status;
            if (k->rk4)
                status = winder_rk4(s->fns, W_TABLE, W_NSLOTS, W_NSW, k->t, tb, k->y, W_N,
                                    k->p, k->m, k->hrk4, dummy_t, 0, dummy_y, 0, k->stats,
                                    &tr, &hr, &kr);
            else
                status = winder_dopri5(s->fns, W_TABLE, W_NSLOTS, W_NSW, k->t, tb, k->y, W_N,
                                       k->p, k->m, k->rtol, k->atol, k->h, INFINITY, dummy_t,
                                       0, dummy_y, 0, CHUNK, k->stats, 5, &tr, &hr, &kr);
            int finite = 1;
            for (int i = 0; i < W_N; i++)
                finite = finite && isfinite(k->y[i]);
            if (status == S_NO_MEMORY)
                return fail(s, "%s", "the integrator could not allocate its work buffers");
            if (status == S_NON_FINITE || status == S_UNDERFLOW || !finite) {
                logf_(s, fmi2Error, "logStatusError", "integration failed at t = %.6g s: %s",
                      tr, status == S_UNDERFLOW ? "the step size underflowed (too stiff or "
                      "discontinuous)" : "the state went non-finite");
                k->mode = M_ERROR;
                return fmi2Error;
            }
            if (status == S_PENETRATED) {
                k->t = tr;
                k->h = hr;
                logf_(s, fmi2Error, "logStatusError", "the run stopped at t = %.6g s: a nip's "
                      "penetration reached the smaller radius (one body's axis inside the "
                      "other); try a smaller atol or rk4_step", tr);
                k->mode = M_ERROR;
                return fmi2Error;
            }
            if (status == S_EXHAUSTED) {
                k->t = tr;
                k->h = k->rk4 ? k->h : hr;
                ended(s, tr);
                logf_(s, fmi2Discard, "logStatusDiscard", "%s; the step from t = %.9g s by "
                      "%.6g s stopped at t = %.9g s (the outputs are those of that time); no "
                      "further steps", k->why, t0, dt, tr);
                return fmi2Discard;
            }
            k->t = status == S_DONE ? tb : tr;
            if (!k->rk4)
                k->h = hr;
        }
    }
    k->t = t_end;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    return fail(c, "%s", "fmi2CancelStep: steps run synchronously");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Status* value) {
    (void)kind;
    (void)c;
    *value = fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind kind, fmi2Real* value) {
    Comp* s = c;
    if (kind != fmi2LastSuccessfulTime)
        return fmi2Discard;
    *value = s->c.t;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind kind,
                                fmi2Integer* value) {
    (void)c;
    (void)kind;
    (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind kind,
                                fmi2Boolean* value) {
    Comp* s = c;
    if (kind != fmi2Terminated)
        return fmi2Discard;
    *value = s->c.ended ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind kind,
                               fmi2String* value) {
    Comp* s = c;
    if (kind != fmi2PendingStatus)
        return fmi2Discard;
    *value = s->c.ended ? s->c.why : "";
    return fmi2OK;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    return nvr ? fail(c, "%s", "input derivatives are not supported") : fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)vr;
    (void)order;
    (void)value;
    return nvr ? fail(c, "%s", "output derivatives are not supported") : fmi2OK;
}

/* ---- model exchange ------------------------------------------------------------------ */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

/* The modes from the state (the new side of a located crossing), the run-out of an
 * unwinding roll (terminateSimulation, the reason logged), the next ramp end. */
fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo* ev) {
    Comp* s = c;
    Core* k = &s->c;
    double g[W_NSW + 1];
    double tb[1] = {k->t};
    winder_modes(s->fns, W_TABLE, W_NSLOTS, W_NSW, k->t, k->y, W_N, k->p, k->m, 0);
    W_SW_FN(tb, k->y, k->p, k->m, g);
    s->out_valid = 0;
    ev->newDiscreteStatesNeeded = fmi2False;
    ev->terminateSimulation = fmi2False;
    ev->nominalsOfContinuousStatesChanged = fmi2False;
    ev->valuesOfContinuousStatesChanged = fmi2False;
    ev->nextEventTimeDefined = fmi2False;
    ev->nextEventTime = 0.0;
    for (int slot = 0; slot < W_NSLOTS; slot++)
        if (W_TABLE[5 * slot] == K_END && g[W_TABLE[5 * slot + 1]] >= 0.0 && !k->ended) {
            ended(s, k->t);
            logf_(s, fmi2Warning, "logStatusDiscard", "%s", k->why);
        }
    if (k->ended) {
        ev->terminateSimulation = fmi2True;
        return fmi2OK;
    }
    double next = INFINITY;
    for (int i = 0; i < W_NRAMP; i++) {
        double tr = k->p[W_RAMP[3 * i + 2]];
        if (k->p[W_RAMP[3 * i]] > 0.0 && tr > k->t + 1e-12 * fmax(1.0, fabs(k->t)) && tr < next)
            next = tr;
    }
    if (isfinite(next)) {
        ev->nextEventTimeDefined = fmi2True;
        ev->nextEventTime = next;
    }
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetPrior,
                                       fmi2Boolean* enterEventMode,
                                       fmi2Boolean* terminateSimulation) {
    (void)c;
    (void)noSetPrior;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    Comp* s = c;
    s->c.t = time;
    s->out_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    Comp* s = c;
    if (nx != W_N)
        return fail(s, "%s", "fmi2SetContinuousStates: wrong number of states");
    memcpy(s->c.y, x, sizeof(double) * W_N);
    s->out_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    Comp* s = c;
    if (nx != W_N)
        return fail(s, "%s", "fmi2GetDerivatives: wrong number of states");
    rates(s, s->c.y, s->c.p, dx);
    return fmi2OK;
}

/* the switching functions the mode table refers to, in the machine's locked modes; one
 * exactly at zero is reported on the side the mode rule puts zero (W_Z_ZERO: ±1e-300), so
 * that a host which starts on a boundary (a roll at rest on its core) sees a sign change
 * when the state leaves it */
fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t ni) {
    Comp* s = c;
    double g[W_NSW + 1];
    double tb[1] = {s->c.t};
    if (ni != W_NZ)
        return fail(s, "%s", "fmi2GetEventIndicators: wrong number of event indicators");
    W_SW_FN(tb, s->c.y, s->c.p, s->c.m, g);
    for (int i = 0; i < W_NZ; i++)
        z[i] = g[W_Z[i]] != 0.0 ? g[W_Z[i]] : W_Z_ZERO[i] * 1e-300;
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    Comp* s = c;
    if (nx != W_N)
        return fail(s, "%s", "fmi2GetContinuousStates: wrong number of states");
    memcpy(x, s->c.y, sizeof(double) * W_N);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    (void)c;
    for (size_t i = 0; i < nx; i++)
        x[i] = 1.0;
    return fmi2OK;
}
