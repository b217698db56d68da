"""Purpose: a small MPC of the span tension through the unwind torque, on winder.casadi_model.

The plant is the full nonlinear small winder line with its parent torque-driven
(``models/winder_line_fmu.toml``: input ``parent_torque``), advanced by a
:class:`winder.Stepper` (the compiled machine, every nip and roll) while the drums ramp at
2 m/s². Every ``--dt`` the MPC reads the state and solves, with CasADi's own SQP method
and QP solver (``sqpmethod``, ``qrqp``), over a horizon of ``--horizon`` steps::

    min  Σ_k ((T_k − T*) / 1 N)² + ((τ_k − τ_{k−1}) / s_τ)²     (s_τ = --move-scale, 300 N·m)
    s.t. (ω_k+1, T_k+1) = RK4 of f(x, τ_k, p) + d on (parent.theta_dot, span.tension)

where ``f`` is :func:`winder.casadi_model`'s right-hand side of the same machine: the two
predicted states enter the measured state vector, the other states (the set, the rider,
the nips) are held at their measured values over the horizon, but the other bodies'
speeds and the radii, which go on at their measured rates; the drums' speed profile comes
in through the time, the last parameter. What the held states would
add (the set's bounce under its imbalance moves the span) is the rate bias ``d``,
estimated from each step's one-step prediction error (offset-free MPC). The first torque
is applied over the step (state feedback).

The built-in controller (``winder.forces.tension_control``: PI with the inertia
feed-forward and the tension rate, poles at −10 rad/s) runs on the same line
(``models/winder_line_small.toml``) through :func:`winder.simulate`; the tension errors of
both over the ramp are printed and drawn.

Writes ``tension_mpc.png`` to ``--out``.

    python examples/tension_mpc.py [--t-end 23] [--dt 0.01] [--horizon 20]
                                   [--move-scale 300] [--out out] [--quick]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PLANT = ROOT / "models" / "winder_line_fmu.toml"
BUILT_IN = ROOT / "models" / "winder_line_small.toml"
PREDICTED = ("parent.theta_dot", "span.tension")


class TensionMPC:
    """The MPC of the module text on ``model`` (:func:`winder.casadi_model` with the input
    ``parent_torque``), set-point ``tension`` [N], step ``dt`` [s], ``horizon`` steps,
    torque moves weighed against ``move_scale`` [N·m] per 1 N of tension error."""

    def __init__(self, model, tension: float, dt: float, horizon: int,
                 move_scale: float = 300.0) -> None:
        import casadi as ca

        self.model, self.dt, self.N = model, dt, horizon
        idx = [model.state_names.index(n) for n in PREDICTED]
        n = model.n_states
        z, u = ca.SX.sym("z", 2), ca.SX.sym("u", 1)
        xm, p = ca.SX.sym("xm", n), ca.SX.sym("p", len(model.p0))
        # the other bodies' speeds and the radii go on at their measured rates; the rest
        # (positions, bounce velocities, friction: fast, oscillating) is held
        self.moving = np.array([name.endswith(("theta_dot", ".radius")) and i not in idx
                                for i, name in enumerate(model.state_names)], dtype=float)
        xr, s = ca.SX.sym("xr", n), ca.SX.sym("s")
        x = ca.vertcat(*[z[idx.index(i)] if i in idx else xm[i] + s * xr[i]
                         for i in range(n)])
        rate = model.f(x, u, p)
        F = ca.Function("F", [z, u, xm, xr, s, p], [ca.vertcat(rate[idx[0]], rate[idx[1]])])
        opti = ca.Opti()
        Z = opti.variable(2, horizon + 1)
        U = opti.variable(1, horizon)
        self.x_meas, self.p0 = opti.parameter(n), opti.parameter(len(model.p0))
        self.x_rate = opti.parameter(n)
        self.u_prev = opti.parameter()
        self.bias = opti.parameter(2)  # the rates the frozen states add: estimated
        opti.subject_to(Z[:, 0] == ca.vertcat(*[self.x_meas[i] for i in idx]))
        cost = 0
        for k in range(horizon):
            t = self.p0[-1] + k * dt
            pk = ca.vertcat(self.p0[:-1], t)
            ph = ca.vertcat(self.p0[:-1], t + dt / 2)
            p1 = ca.vertcat(self.p0[:-1], t + dt)
            zk, uk = Z[:, k], U[:, k]
            xm_, xr_ = self.x_meas, self.x_rate
            k1 = F(zk, uk, xm_, xr_, k * dt, pk) + self.bias
            k2 = F(zk + dt / 2 * k1, uk, xm_, xr_, (k + 0.5) * dt, ph) + self.bias
            k3 = F(zk + dt / 2 * k2, uk, xm_, xr_, (k + 0.5) * dt, ph) + self.bias
            k4 = F(zk + dt * k3, uk, xm_, xr_, (k + 1) * dt, p1) + self.bias
            opti.subject_to(Z[:, k + 1] == zk + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
            before = self.u_prev if k == 0 else U[:, k - 1]
            cost += (Z[1, k + 1] - tension) ** 2 + ((uk - before) / move_scale) ** 2
        opti.minimize(cost)
        opti.solver("sqpmethod", {"qpsol": "qrqp", "print_header": False,
                                  "print_iteration": False, "print_time": False,
                                  "print_status": False,
                                  "qpsol_options": {"print_iter": False,
                                                    "print_header": False,
                                                    "error_on_fail": False},
                                  "max_iter": 20})
        self.opti, self.Z, self.U = opti, Z, U
        self.idx = idx
        self.solves = 0
        self.d = np.zeros(2)
        self.predicted: np.ndarray | None = None

    def __call__(self, t: float, x: np.ndarray, u_prev: float) -> float:
        """The torque [N·m] at time ``t`` [s] from the measured state ``x``."""
        o = self.opti
        z = x[self.idx]
        if self.predicted is not None:  # offset-free: the one-step prediction's error
            self.d += 0.5 * (z - self.predicted[:, 1]) / self.dt
        o.set_value(self.bias, self.d)
        o.set_value(self.x_meas, x)
        rates = np.array(self.model.f(x, u_prev, self.model.parameters(t))).ravel()
        o.set_value(self.x_rate, self.moving * rates)
        o.set_value(self.p0, self.model.parameters(t))
        o.set_value(self.u_prev, u_prev)
        if self.solves == 0:
            o.set_initial(self.U, u_prev)
            o.set_initial(self.Z[0, :], z[0])
            o.set_initial(self.Z[1, :], z[1])
        sol = o.solve_limited()
        self.solves += 1
        self.stats = o.stats()
        self.predicted = np.array(sol.value(self.Z))
        o.set_initial(sol.value_variables())  # warm start the next step
        return float(np.ravel(sol.value(self.U))[0])


RAMP_END = 41.7 / 2.0  #: [s] the drums reach 41.7 m/s at 2 m/s²


def windows(ts: np.ndarray, t_end: float) -> dict[str, np.ndarray]:
    """The two windows of the comparison: over the ramp (0.5 s ≤ t < 20.8 s) and at its
    end (20.8 s ≤ t ≤ ``t_end``)."""
    return {"over the ramp (0.5 s <= t < 20.8 s)": (ts >= 0.5) & (ts < RAMP_END - 0.05),
            f"at the ramp's end (20.8 s <= t <= {t_end:g} s)": ts >= RAMP_END - 0.05}


def run(t_end: float = 23.0, dt: float = 0.01, horizon: int = 20,
        move_scale: float = 300.0) -> dict:
    """The MPC in closed loop with the nonlinear line (Stepper) and the built-in
    controller's run: the sample times ``t`` [s], the tension errors ``err_mpc`` and
    ``err_ref`` [N] at them, the MPC's ``torque`` [N·m], the built-in run ``ref``, the
    wall times [s] of building ``casadi_model`` (``t_model``), the MPC (``t_build``) and
    the loop (``t_loop``, the line's steps included; its CPU time ``cpu_loop``) and its
    ``steps``. Also the source
    of docs/control.md's numbers (benchmarks/guide_numbers.py)."""
    import winder

    tension = 1000.0  # [N], the built-in controller's set-point in winder_line_small.toml
    t0 = time.perf_counter()
    model = winder.casadi_model(PLANT, inputs=["parent_torque"], outputs=["span_tension"])
    t_model = time.perf_counter() - t0
    mpc = TensionMPC(model, tension, dt, horizon, move_scale)
    t_build = time.perf_counter() - t0 - t_model
    sim = winder.Stepper(PLANT)
    u = 0.0
    for _ in range(10):  # the torque the MPC settles on at t = 0 (a bumpless start)
        u = mpc(0.0, sim.y, u)
        mpc.predicted, mpc.d[:] = None, 0.0
    ts, Ts, us = [0.0], [sim.output("span_tension")], [u]
    t1, c1 = time.perf_counter(), time.process_time()
    steps = int(round(t_end / dt))
    for _ in range(steps):
        u = mpc(sim.t, sim.y, u)
        sim.set_input("parent_torque", u)
        sim.step(dt)
        ts.append(sim.t)
        Ts.append(sim.output("span_tension"))
        us.append(u)
    t_loop, c_loop = time.perf_counter() - t1, time.process_time() - c1
    ts = np.array(ts)
    ref = winder.simulate(BUILT_IN, t_end=t_end)
    return {"t": ts, "err_mpc": tension - np.array(Ts),
            "err_ref": np.interp(ts, ref.t, ref["tension_error"]), "torque": np.array(us),
            "ref": ref, "t_model": t_model, "t_build": t_build, "t_loop": t_loop,
            "steps": steps, "cpu_loop": c_loop}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=23.0,
                    help="end time [s] (default 23: the drums' ramp to 41.7 m/s, 20.85 s, "
                    "and 2 s at full speed after it)")
    ap.add_argument("--dt", type=float, default=0.01, help="MPC step [s] (default 0.01)")
    ap.add_argument("--horizon", type=int, default=20, help="steps (default 20)")
    ap.add_argument("--move-scale", type=float, default=300.0,
                    help="torque move [N·m] that costs as much as 1 N of tension error "
                    "(default 300; smaller: a smoother torque, a larger error where the "
                    "ramp ends)")
    ap.add_argument("--out", default="out", help="output directory (default out)")
    ap.add_argument("--quick", action="store_true", help="the first 2 s (for the tests)")
    args = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t_end = 2.0 if args.quick else args.t_end
    r = run(t_end, args.dt, args.horizon, args.move_scale)
    ts, err_mpc, err_ref, us, ref = r["t"], r["err_mpc"], r["err_ref"], r["torque"], r["ref"]
    ramp_end = RAMP_END
    print(f"casadi_model {r['t_model']:.2f} s, MPC built {r['t_build']:.2f} s, "
          f"{r['steps']} MPC steps in {r['t_loop']:.1f} s "
          f"({1e3 * r['t_loop'] / r['steps']:.1f} ms each, the line's step included)")
    for what, w in windows(ts, t_end).items():
        if not w.any():
            continue
        for name, e in (("MPC", err_mpc), ("built-in controller", err_ref)):
            print(f"{name}: tension error {what}: max {np.max(np.abs(e[w])):.4g} N, "
                  f"rms {np.sqrt(np.mean(e[w] ** 2)):.4g} N")
    ref_t, ref_u = ref.t[ref.t <= t_end], ref["parent_torque"][ref.t <= t_end]
    # left: the whole run; right: the event, the ramp's end, framed (from 0.5 s before it
    # to 1.5 s after it, or the run's end)
    lo, hi = max(0.0, ramp_end - 0.5), min(t_end, ramp_end + 1.5)
    fig, ax = plt.subplots(2, 2, figsize=(13, 7.5), sharex="col",
                           gridspec_kw={"width_ratios": (3, 2)}, layout="constrained")
    for col, (a, b) in enumerate(((0.0, t_end), (lo, hi))):
        w, wr = (ts >= a) & (ts <= b), (ref_t >= a) & (ref_t <= b)
        ax_e, ax_u = ax[0, col], ax[1, col]
        ax_e.plot(ts[w], err_mpc[w], label="MPC on casadi_model")
        ax_e.plot(ts[w], err_ref[w], label="built-in controller (simulate)")
        ax_u.plot(ts[w], np.array(us)[w], label="MPC unwind torque")
        ax_u.plot(ref_t[wr], ref_u[wr], label="built-in controller's torque")
        for a_ in (ax_e, ax_u):
            a_.grid(True, alpha=0.3)
            if ramp_end <= t_end:
                a_.axvline(ramp_end, color="k", lw=0.8, ls=":")
        ax_u.set_xlabel("t [s]")
    ax[0, 0].set_yscale("symlog", linthresh=1e-3)
    ax[0, 0].set(ylabel="tension error T* − T [N]", title="the whole run")
    fig.suptitle("Span tension of the small winder line over the drums' ramp")
    ax[1, 0].set(ylabel="parent torque [N·m]")
    ax[0, 0].legend(loc="lower left")
    ax[1, 0].legend(loc="lower left")
    if hi > lo:
        for a_ in ax[:, 0]:  # where the right column looks
            a_.axvspan(lo, hi, color="0.85", zorder=0)
        after = f"{hi - ramp_end:.2g} s after it" + (" (the run's end)" if hi >= t_end
                                                      else "")
        ax[0, 1].set_title(f"the event: the ramp's end at t = {ramp_end:.2f} s (dotted),\n"
                           f"from 0.5 s before it to {after}", fontsize=10)
        ax[0, 1].set_ylabel("tension error T* − T [N]")
        ax[1, 1].set_ylabel("parent torque [N·m]")
        ax[0, 1].set_xlim(lo, hi)
    else:
        for a_ in ax[:, 1]:
            a_.set_visible(False)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "tension_mpc.png", dpi=100)
    print(f"figure written to {out / 'tension_mpc.png'}")


if __name__ == "__main__":
    main()
