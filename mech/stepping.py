"""The stepping protocol: how the solver asks a stepper to integrate one segment.

A segment runs from the solver's current state towards a goal time and ends there, at
the first event (a contact made or broken, a slip, a stick, ...), when the history buffer
is full, or on a failure. Every stepper implements ``Stepper.segment`` on the same
integration state (the public attributes of mech.solver.ImpactSolver listed below) and
the same right-hand side, events and history rows; only how the steps are taken differs:
- ``CompiledStepper``: the compiled DOPRI5 loop (mech.integrator.integrate), the default;
- ``mech.scipy_backend.ScipyStepper``: scipy.integrate.solve_ivp (RK45, DOP853, Radau, BDF,
  LSODA), the independent routes of the tests and the accuracy study.

The integration state a stepper reads: ``t`` (s), ``h`` (s, the step in use; 0 to choose),
``regime``, ``eref``, ``model``, ``arrays`` (``model.kernel_arrays(drive)``), ``arm``
(``model.kernel_armature(armature_closed)``: None without an armature), ``drive``,
``coupled`` (None or mech.solver.CoupledStates), ``work`` (kernel scratch), ``scene``; what
it writes: ``y`` (and ``z``, the coupled extra states) in place to the state at the end,
``ev_sign``, ``stats`` (accumulated), the rows from ``recorder.n`` on (not committed: the
solver commits them with the regimes), and ``drive`` (its mu rows) when a coupled model sets mu.
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

from .compiled import integrate


class Outcome(NamedTuple):
    """What one segment ended with: status (kernel_layout DONE, EVENT, ...), the time
    reached (s), the step to go on with (s), the rows written and the event index (-1: none)."""

    status: int
    t: float
    h: float
    records: int
    event: int


class Stepper(Protocol):
    def segment(self, state, t_goal: float) -> Outcome:
        """Integrate ``state`` (see the module docstring) from ``state.t`` towards ``t_goal`` (s)."""
        ...


class CompiledStepper:
    """The compiled DOPRI5 loop with event location (mech.integrator)."""

    def __init__(self):
        # (model, solver settings, their tolerance tuple): both frozen, so one tuple serves
        # every segment, and the compiled call's argument check (mech.aot) passes it by
        # identity instead of checking a new tuple's arrays each time
        self._tolerances = (None, None, None)

    def segment(self, state, t_goal: float) -> Outcome:
        m = state.model
        solver = state.scene.solver
        rec = state.recorder
        # (the free rows as the buffers and where they start, not as new views: see free_window)
        rows, dense, first, dense_first, room = rec.free_window()
        model, settings, tolerances = self._tolerances
        if model is not m or settings is not solver:
            tolerances = (m.max_step, solver.rtol, m.atol, m.relmask)
            self._tolerances = (m, solver, tolerances)
        return Outcome(*integrate(
            state.t, state.y, t_goal, state.h, tolerances, state.arrays,
            state.regime, state.eref, state.ev_sign, rows, dense, first, dense_first, room, rec.keep_dense,
            solver.max_steps,
            state.work, state.stats, state.arm,
        ))
