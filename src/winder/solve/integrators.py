"""What the compiled integrators share, on the Python side: the status codes, the mode
table's kinds and the chunk size. The integrators are C, in every machine's library
(``solve/c/``: ``dopri5.c`` adaptive Dormand–Prince 5(4), ``rk4.c`` classical fixed-step
RK4, ``ros2.c`` the Rosenbrock ROS2 on the exact Jacobian, ``events.h`` what they share;
called through :class:`winder.solve.cint.Kernels`).

The *locked modes*: per nip the contact mode (touching or not) and per wound roll the core
mode of spec §2 stay fixed within a step. When an accepted step ends on the other side of
a switching function, the crossing is located on the step's dense output (Illinois
method, to ~1e-12 s; ``sample_and_switch`` in ``events.h``), the step is cut there and the
integration restarts in the new mode. The discontinuity of a damped normal force at
touch-down and the kink at lift-off never fall inside a step. A roll unwinding to its
core lands exactly on ``r_c``.

The machine's functions are called through their addresses: ``fns = [rhs, jac, out,
sw]``. Mode slots are described by ``table`` rows ``(kind, g1,
g2, state, param)``: kind :data:`K_CONTACT` (``g1`` its switching function, ``g2``
its guard ``NIP.overlap``, then the guard's ``NIP.dx`` and ``NIP.dz`` in place of state
and param),
:data:`K_CORE` (``g1`` = ``r_c − r``, ``g2`` = speed, ``state`` the radius, ``param``
``r_c``) or :data:`K_END` (an unwinding roll: ``g1`` = ``r_c − r``; where it crosses
zero the roll has run out of web, the radius lands on ``r_c`` and the integration stops
with :data:`EXHAUSTED`).

Every integrator integrates ``y`` in place, writes samples at output times into a
caller's array and keeps counters in ``stats = [nfev, accepted, rejected, events, stiff
steps]``. Status codes: :data:`DONE`, :data:`PAUSED` (the evaluation budget of this call
is spent; call again to resume), :data:`STEP_UNDERFLOW`, :data:`NON_FINITE`,
:data:`EXHAUSTED`, :data:`PENETRATED`.

The guard of every accepted step (``guard_step``: DOPRI5 and ROS2 in
``sample_and_switch``, RK4 after its non-finite check): where a nip's guard function
``NIP.overlap = δ − min(r_a, r_b)`` (the contact row's ``g2``) is positive or not a number
at the step's end or at an output sample inside it, or where the straight path of the
step (from its start to its end) takes it there (a step that jumps through the other
body), the first crossing of the bound is located, ``y`` moves there and the integration
stops with :data:`PENETRATED`: one body's axis inside the other means the integrator lost
the contact (a step or tolerance far too coarse for the nip), and every later number
would be wrong."""

from __future__ import annotations

from winder.model.locked_modes import ModeKind

__all__ = ["DONE", "PAUSED", "STEP_UNDERFLOW", "NON_FINITE", "EXHAUSTED", "PENETRATED",
           "CHUNK", "TIME_RESOLUTION", "K_CONTACT", "K_CORE", "K_END", "END",
           "F_RHS", "F_JAC", "F_OUT", "F_SW"]

DONE, PAUSED, STEP_UNDERFLOW, NON_FINITE, EXHAUSTED, PENETRATED = 0, 1, 2, 3, 4, 5
K_CONTACT, K_CORE, K_END = int(ModeKind.CONTACT), int(ModeKind.CORE), int(ModeKind.END)
#: The mode a :data:`K_END` slot switches to: the run ends (an unwinding roll at its core).
END = 9
#: The generated functions, in the order of ``fns`` (:data:`winder.model.codegen.FUNCTIONS`).
F_RHS, F_JAC, F_OUT, F_SW = 0, 1, 2, 3
#: Shortest step [s] relative to ``max(1 s, |t|)``; below it the time is not resolved.
TIME_RESOLUTION = 1e-14
#: Evaluations per call of a caller that checks its budgets between calls (20–40 ms).
CHUNK = 200_000
