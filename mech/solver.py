"""The impact solver: advances the compiled integrator, switches regimes at events.

``ImpactSolver(scene).run()`` integrates a whole scene. For co-simulation,
``advance(t, drives)`` integrates to ``t`` under the named drive channels given for the
step (each contact point's friction coefficient and repulsion, mech.drives) and returns a
``Segment`` whose dense output gives the state and contact forces at any time inside the
step; the solver then resumes from where it stopped, without starting over.

Regimes per tip: free, slip, stick. At every event the integration stops exactly at
the event (located on the dense output), the regimes are resolved for the new state,
and the integration restarts:
- contact start/end (penetration crosses zero) and force clip (F_n would go negative);
- slip: the slip velocity's component along the slip direction at the last restart
  crosses zero. If the slip speed is then below ``stick_velocity_tol`` the tip sticks
  when the friction needed to hold it is within the limit, otherwise it slips the other
  way (reversal); a larger speed means the slip direction turned, and slip goes on
  along the new direction;
- stick: the friction needed to hold the tip reaches the limit mu F_n^(1-gamma); slip
  starts along the direction that friction was resisting.
"""

from __future__ import annotations

import math
import time
from bisect import bisect_left
from dataclasses import dataclass, field

import numpy as np

from .compiled import (
    armature_force, armature_table, dense_contact, dense_eval, dense_force_arguments, dense_pair_forces,
    dense_tip_forces, dynamics, energies, energy_table, event_values, make_work, project_to_stick,
)
from .kernel_layout import (
    A_FN, A_FTX, A_FTY, A_MARGIN, A_VTX, A_VTY, A_Y, A_YDOT, BAR_HELD, BUFFER_FULL, C_N, C_ON, C_R, DONE, EV_CLIP,
    EV_COMPRESSION, D_SLOPE, D_VALUE, EA_CARD, EA_POLE, EA_REST, EA_SEAT, EA_TURN, EV_CONTACT, EV_SLIP, EV_STICK,
    EVENT, F_MASS, FREE, FRICTION_EXACT, I_FRICTION, I_MOUNT, MOUNT_CLAMP, MOUNT_PIVOT, N_ACLOSED, NAUX,
    NEV_TIP, Q_WIN, SLIP, STATUS_TEXT, STICK, state_sizes,
)
from .contact_laws import hertz_impact
from .drives import set_step, step_targets, values_at
from .friction import REVERSAL_DEADBAND
from .mechanism import base_velocity_jumps
from .model import BarModel, armature_scales, build_model
from .parameters import MechScene
from .recorder import MEMORY_LIMIT, Recorder, history_memory
from .results import ImpactResult, seat_credit
from .scipy_backend import METHODS as SCIPY_METHODS, ScipyStepper
from .stepping import CompiledStepper, Stepper
from .frozen import frozen

REGIME_NAMES = ("free", "slip", "stick")
_FLOAT64 = np.dtype(np.float64)
EVENT_KINDS = ("contact", "clip", "slip", "stick", "compression")
ARMATURE_EVENTS = {EA_REST: ("armature_stop", "rest"), EA_POLE: ("armature_stop", "pole"), EA_CARD: ("card", "")}
CHATTER_LIMIT = 200  # events at one instant (within round-off, or picoseconds apart) before the run is stopped
FLIGHT_RETRY = 0.125  # of the rest window: how soon a bar found not at rest in flight is looked at again


class MechSolverError(RuntimeError):
    """The integration failed; carries the time (s), the named state and the partial result."""

    def __init__(self, message: str, t: float, state: dict, partial=None):
        super().__init__(message)
        self.t = t
        self.state = state
        self.partial_result = partial


@frozen
class CoupledStates:
    """Extra states integrated in the same solve as the mechanics (scipy backends only).

    The mechanics gives them the contact quantities; they give back the friction
    coefficient. A monolithic co-simulation reference is built this way without the
    mechanics knowing what the states are.
    initial: (size,) initial values; atol: (size,) absolute tolerances.
    rhs(t, z, contact) -> dz/dt, with contact (rows, 3): per contact row penetration (m),
    penetration rate (m/s), normal force (N).
    friction_coefficient(t, z) -> mu (N^gamma).
    """

    initial: np.ndarray
    atol: np.ndarray
    rhs: object
    friction_coefficient: object

    @property
    def size(self) -> int:
        return len(self.initial)


@dataclass
class Segment:
    """Dense trajectory over one ``advance`` call: state and contact quantities at any t.

    events: the events inside the segment, as dicts with time (s), tip, kind, regimes.
    """

    t_start: float
    t_end: float
    events: list
    _model: BarModel
    _t0: np.ndarray
    _h: np.ndarray
    _t_valid: np.ndarray
    _coef: np.ndarray
    _start_state: np.ndarray
    _regime: np.ndarray
    _eref: np.ndarray
    _arrays: tuple = field(repr=False)  # the kernel's arguments with the drive of the segment
    _arm: tuple = field(repr=False, default=None)  # and its armature's (kernel.dynamics), or None
    _work: tuple = field(repr=False, default=None)
    # the dense force evaluations' arguments after t (mech.compiled.dense_force_arguments),
    # made at the first tip_forces or pair_forces call
    _out: tuple = field(repr=False, default=None)
    _last_t: float = field(repr=False, default=float("nan"))
    _last_forces: tuple = field(repr=False, default=(0.0, 0.0, 0.0, 0.0, 0.0))
    _pairs_t: float = field(repr=False, default=float("nan"))
    _pairs_last: np.ndarray = field(repr=False, default=None)
    _arm_t: float = field(repr=False, default=float("nan"))
    _arm_last: tuple = field(repr=False, default=(0.0, 0.0))
    _arm_index: int = field(repr=False, default=-2)  # the model's armature_index, once asked (-2: not yet)
    # the step ends as a list and, per dense step once asked, the armature's (t0, h, its two
    # components' coefficients): the coil asks at every new circuit time (thousands a run)
    _arm_steps: tuple = field(repr=False, default=None)

    def state(self, t: float) -> np.ndarray:
        """State vector at time t (s) in [t_start, t_end] (4th-order dense output)."""
        if not (self.t_start - 1e-15 <= t <= self.t_end + 1e-15):
            raise ValueError(f"t = {t!r}: outside the segment [{self.t_start!r}, {self.t_end!r}] s")
        if len(self._t_valid) == 0 or t <= self.t_start:
            return self._start_state.copy()
        k = int(np.searchsorted(self._t_valid, t))
        k = min(k, len(self._t_valid) - 1)
        out = np.empty(self._coef.shape[2])
        dense_eval(self._coef[k], (t - self._t0[k]) / self._h[k], out)
        return out

    def contact(self, t: float) -> np.ndarray:
        """(rows, 3) per contact row: penetration (m), penetration rate (m/s), normal force (N) at t."""
        y = self.state(t)
        if self._work is None:
            self._work = make_work(self._model.n)
        dy = np.empty_like(y)
        rows = self._model.rows
        aux = np.empty((rows, NAUX))
        k = int(np.searchsorted(self._t_valid, t)) if len(self._t_valid) else 0
        k = min(k, max(len(self._regime) - 1, 0))
        regime = self._regime[k] if len(self._regime) else np.zeros(rows, np.int64)
        dynamics(t, y, self._arrays, regime, self._eref, dy, aux, self._work, self._arm)
        return aux[:, [A_Y, A_YDOT, A_FN]].copy()

    def normal_force(self, t: float) -> float:
        """N: total normal force of every contact row at t."""
        return float(self.contact(t)[:, 2].sum())

    def armature(self, t: float) -> tuple[float, float]:
        """(q, dq/dt) of the armature at t (s) in [t_start, t_end] from the dense output (4th
        order): its travel from the rest stop, m and m/s (plunger) or rad and rad/s
        (clapper). Needs ``ImpactSolver(scene, keep_dense=True)`` unless t is the start.
        Repeated calls at the same t are cached."""
        if t == self._arm_t:
            return self._arm_last
        a = self._arm_index
        if a == -2:  # (a property: asked once, not at each of the coil's samples)
            a = self._arm_index = self._model.armature_index
        if a < 0:
            raise ValueError("Segment.armature: this model has no armature (the scene has no [armature])")
        if not (self.t_start - 1e-15 <= t <= self.t_end + 1e-15):
            raise ValueError(f"t = {t!r}: outside the segment [{self.t_start!r}, {self.t_end!r}] s")
        steps = self._arm_steps
        if steps is None:
            steps = self._arm_steps = (self._t_valid.tolist(), [None] * len(self._t_valid))
        ends, pieces = steps
        if not ends or t <= self.t_start:
            out = (float(self._start_state[a]), float(self._start_state[a + 1]))
        else:
            if not len(self._coef):
                raise ValueError("Segment.armature: the dense output is kept only with "
                                 "ImpactSolver(scene, keep_dense=True)")
            # (bisect_left on the list is np.searchsorted's side="left" without numpy's
            # per-call overhead; the arithmetic is the same double arithmetic)
            k = min(bisect_left(ends, t), len(ends) - 1)
            piece = pieces[k]
            if piece is None:
                piece = self._arm_piece(k, a)
            t0, h, c0, c1, c2, c3, c4, d0, d1, d2, d3, d4 = piece
            th = float((t - t0) / h)
            t1 = 1.0 - th
            # (mech.integrator.dense_eval on the armature's two components only)
            out = (c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4))),
                   d0 + th * (d1 + t1 * (d2 + th * (d3 + t1 * d4))))
        self._arm_t, self._arm_last = t, out
        return out

    def _arm_piece(self, k: int, a: int) -> tuple:
        """Dense step k's (t0, h, q's five coefficients, dq/dt's five), as floats, kept for the
        segment's later calls. (The two components' columns read in one slice: a slice and
        tolist per component, and a float per scalar, cost ~0.5 us more a step.)"""
        (c0, d0), (c1, d1), (c2, d2), (c3, d3), (c4, d4) = self._coef[k, :, a:a + 2].tolist()
        piece = self._arm_steps[1][k] = (float(self._t0[k]), float(self._h[k]), c0, c1, c2, c3, c4, d0, d1, d2, d3, d4)
        return piece

    def travel(self, times) -> list[float]:
        """q of the armature (m or rad) at each of ``times`` (s, each in [t_start, t_end]):
        ``armature(t)[0]`` for each, by the same operations, in one call and without the rate
        (a caller that samples the travel at several times of a segment: the coil's circuit
        points, the received work's Gauss points). ``armature``'s cache is left as it is."""
        a = self._arm_index
        if a == -2:
            a = self._arm_index = self._model.armature_index
        if a < 0:
            raise ValueError("Segment.travel: this model has no armature (the scene has no [armature])")
        steps = self._arm_steps
        if steps is None:
            steps = self._arm_steps = (self._t_valid.tolist(), [None] * len(self._t_valid))
        ends, pieces = steps
        lo, hi, last = self.t_start, self.t_end, len(ends) - 1
        dense = len(self._coef) > 0
        out = []
        for t in times:
            if not (lo - 1e-15 <= t <= hi + 1e-15):
                raise ValueError(f"t = {t!r}: outside the segment [{lo!r}, {hi!r}] s")
            if last < 0 or t <= lo:
                out.append(float(self._start_state[a]))
                continue
            if not dense:
                raise ValueError("Segment.travel: the dense output is kept only with "
                                 "ImpactSolver(scene, keep_dense=True)")
            k = min(bisect_left(ends, t), last)
            piece = pieces[k]
            if piece is None:
                piece = self._arm_piece(k, a)
            t0, h, c0, c1, c2, c3, c4 = piece[:7]
            th = float((t - t0) / h)
            t1 = 1.0 - th
            out.append(c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4))))
        return out

    def armature_pieces(self) -> tuple | None:
        """The armature's travel q over the segment as the dense output's pieces, for a caller
        that evaluates ``armature(t)[0]`` elsewhere with the same arithmetic: (q at t_start,
        ends, t0, h, coefficients), float64 C arrays, ends, t0 and h (n,), the coefficients
        (n, 5). For t in [t_start, t_end]: q at t_start if n = 0 or t <= t_start, else with
        k = min(bisect_left(ends, t), n - 1), th = (t - t0[k]) / h[k] and t1 = 1 - th,
        q = c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4))) with c = coefficients[k] (the
        operations of ``armature``, in its order). None without an armature, or when the
        dense output is not kept."""
        a = self._model.armature_index
        n = len(self._t_valid)
        if a < 0 or (n and not len(self._coef)):
            return None
        t0, h = self._t0, self._h
        if len(t0) != n or len(h) != n:  # (advance makes them n long: no views cut then)
            t0, h = t0[:n], h[:n]
        # (the dtype as a dtype object: np.float64, a type, is converted at each call, ~0.15 us)
        return (float(self._start_state[a]), np.ascontiguousarray(self._t_valid, dtype=_FLOAT64),
                np.ascontiguousarray(t0, dtype=_FLOAT64), np.ascontiguousarray(h, dtype=_FLOAT64),
                np.ascontiguousarray(self._coef[:n, :, a], dtype=_FLOAT64))

    def pair_forces(self, t: float) -> np.ndarray:
        """(rows, 3) at t (s): each contact row's (pair's, ImpactSolver.pairs) normal force
        (N), penetration (m) and gap to its fixed contact (m, 0 when touching), by a compiled
        evaluation of the dense output (as ``tip_forces``). A row without a pair (a single
        contact's switched-off second row): 0, -1e3, 1e3. The same read-only array is
        returned for repeated calls at the same t."""
        if t == self._pairs_t:
            return self._pairs_last
        if not (self.t_start - 1e-15 <= t <= self.t_end + 1e-15):
            raise ValueError(f"t = {t!r}: outside the segment [{self.t_start!r}, {self.t_end!r}] s")
        out = np.empty((self._model.rows, 3))
        if len(self._t_valid) == 0 or t <= self.t_start:
            c = self.contact(t)
            out[:, 0] = c[:, 2]
            out[:, 1] = c[:, 0]
        else:
            args = self._out
            if args is None:  # (as tip_forces': one tuple of arguments a segment, made once)
                args = self._out = dense_force_arguments(self._t_valid, self._t0, self._h, self._coef,
                                                         self._arrays)
            dense_pair_forces(t, args, out[:, :2])
        out[:, 2] = np.maximum(-out[:, 1], 0.0)
        out.flags.writeable = False
        self._pairs_t, self._pairs_last = t, out
        return out

    def pair_force(self, t: float, k: int) -> tuple[float, float, float]:
        """(normal force N, penetration m, gap m) of contact pair k at t (s): ``pair_forces``'s row k."""
        if not 0 <= k < len(self._model.pairs):
            raise ValueError(f"k = {k!r}: this model's contact pairs are 0 to {len(self._model.pairs) - 1}")
        row = self.pair_forces(t)[k]
        return float(row[0]), float(row[1]), float(row[2])

    def tip_forces(self, t: float) -> tuple[float, float, float, float, float]:
        """(F_0, F_1, gap, y_0, y_1) at t: the first two contact rows' normal force (N), the
        nearest row's gap to its fixed contact (m, 0 when touching) and the first two rows'
        penetration (m), by a compiled evaluation of the dense output (about 1/10 the cost
        of ``contact``); for a model of more pairs, ``pair_forces``. Repeated calls at the
        same t are cached."""
        if t == self._last_t:
            return self._last_forces
        if not (self.t_start - 1e-15 <= t <= self.t_end + 1e-15):
            raise ValueError(f"t = {t!r}: outside the segment [{self.t_start!r}, {self.t_end!r}] s")
        if len(self._t_valid) == 0 or t <= self.t_start:
            c = self.contact(t)
            forces = (float(c[0, 2]), float(c[1, 2]), float(max(0.0, -np.max(c[:, 0]))),
                      float(c[0, 0]), float(c[1, 0]))
        else:
            # the compiled call's arguments after t, one tuple made at the segment's first call
            # (not per segment: most segments' tip forces are never asked, a coil's): its dense
            # output, what the call reads of the model, its scratch (mech.compiled.
            # dense_force_arguments: the 15-array model tuple, converted and checked at every
            # call, and the arrays the call made cost ~1.1 us of its 2.2 us)
            args = self._out
            if args is None:
                args = self._out = dense_force_arguments(self._t_valid, self._t0, self._h, self._coef,
                                                         self._arrays)
            forces = dense_tip_forces(t, args)
        self._last_t, self._last_forces = t, forces
        return forces


class ImpactSolver:
    """Integrates one mechanics scene; see the module docstring for the regimes."""

    def __init__(self, scene: MechScene, *, keep_dense: bool = False, capacity: int = 4096,
                 backend: str = "dopri5", coupled: CoupledStates | None = None, input_work: bool = False,
                 hold_in_flight: bool = True):
        """backend: "dopri5" (the compiled loop) or "scipy:<method>" (solve_ivp with
        RK45, DOP853, Radau, BDF or LSODA on the same right-hand side and events).
        input_work: keep the input-work quadrature (the audit's ``work_in``) on a free bar
        without loads too, so that a driven force ("repulsion.<i>") may act on it (a held
        bar or one with loads always has it; without, a free bar's state is what it was).
        hold_in_flight: hold a clamped or pivoted bar at rest in flight (_watch_flight);
        False integrates it throughout (to compare with)."""
        if backend != "dopri5" and not (backend.startswith("scipy:") and backend[6:] in SCIPY_METHODS):
            raise ValueError(f"backend = {backend!r}: allowed values are 'dopri5' or 'scipy:<method>' with "
                             f"<method> one of {', '.join(SCIPY_METHODS)}")
        if keep_dense and backend != "dopri5":
            raise ValueError("keep_dense: dense output is provided by the 'dopri5' backend only")
        if coupled is not None and backend == "dopri5":
            raise ValueError("coupled: extra states need a stiff scipy backend, e.g. 'scipy:Radau'")
        self.backend = backend
        self.coupled = coupled
        self.z = np.array(coupled.initial, dtype=float) if coupled is not None else np.zeros(0)
        self.scene = scene
        self.model = build_model(scene, input_work=input_work)
        self.keep_dense = keep_dense
        m = self.model
        # (of the frozen model: read at every step's drives, where a numpy scalar's test cost ~0.2 us)
        self._friction_exact = bool(m.ipar[I_FRICTION] == FRICTION_EXACT)
        self.t = 0.0
        self.y = m.initial_state()
        self.h = 0.0
        rows = m.rows  # contact rows (the pairs', kernel_layout.CONTACT_ROWS at least)
        self.regime = np.zeros(rows, dtype=np.int64)
        self.eref = np.zeros((rows, 2))
        self.eref[:, 0] = 1.0
        self.ev_sign = np.zeros(m.event_count)
        self.stats = np.zeros(4, dtype=np.int64)
        self.events: list[dict] = []
        self._last_event_time = -1.0
        self._chatter = 0
        self.wall_time = 0.0
        self.projection_energy = 0.0
        self.work = make_work(m.n)  # the compiled kernel's scratch arrays
        self._aux = np.empty((rows, NAUX))
        self._dy = np.empty(m.state_size)
        # what changes during the run besides the state: the named drive channels over time
        # (one row each, kernel_layout D_*), passed to the kernel beside the model's arrays
        self.drive = m.initial_drive()
        self._step_end = 0.0  # s: the end of the step the drives were last set for
        if coupled is not None:
            self.drive[m.drive_rows("mu"), D_VALUE] = coupled.friction_coefficient(0.0, self.z)
        # which of the armature's stops and card are closed (kernel_layout EA_*): set at its
        # events from the watched sides (_armature_signs), read by the kernel
        self.armature_closed = np.zeros(N_ACLOSED)
        self.arrays = m.kernel_arrays(self.drive)
        self.arm = m.kernel_armature(self.armature_closed)  # (None without an armature)
        keep = scene.solver.history_rows
        memory = history_memory(m.state_size, keep, len(self.z), m.rows)
        if memory > MEMORY_LIMIT:
            raise ValueError(
                f"solver.history_rows = {keep}: with {m.state_size} states per row the history could take "
                f"{memory / 2**30:.3g} GiB, more than the "
                f"{MEMORY_LIMIT / 2**30:g} GiB a run may take; keep fewer rows (or fewer modes)")
        self.recorder = Recorder(m.state_size, len(self.z), capacity, keep_dense, row_limit=keep, contact_rows=rows)
        self.recorder.on_full = self._make_room
        # (a model without contact points has nothing to check: no call at every segment)
        self.recorder.on_commit = self._check_rows if m.pairs else None
        self._thin_mid_run = False  # thinning inside advance: only in run() (no index is held then)
        self.thinning = dict(resolution=0.0, until=0.0, rows_dropped=0, max_abs_residual=0.0, max_kinetic=0.0,
                             max_drive_work=-math.inf, max_speed=0.0, max_penetration=[-math.inf] * rows)
        self.stepper: Stepper = CompiledStepper() if backend == "dopri5" else ScipyStepper(backend[6:])
        self._jumps = base_velocity_jumps(scene)
        self._jump_index = 0
        self._hold_until = -math.inf
        self._hold_regime = self.regime.copy()
        self._rest_t0 = 0.0
        self._rest_ke = 0.0
        self._rest_e = np.empty(5)
        self.holds: list[list[float]] = []  # [start, end] of each hold at rest (s)
        # the bar held in flight while the armature moves (_watch_flight): until when (s),
        # the step before it (s), the next time to look for it (s), [start, end] of each
        self._flight_until = -math.inf
        self._flight_h = 0.0
        self._hold_in_flight = hold_in_flight
        self._flight_next = 0.0 if hold_in_flight else math.inf
        self.flight_holds: list[list[float]] = []
        if self._jumps and self._jumps[0][0] == 0.0:
            self._apply_base_jump(resolve=False)
        self._initial_state = self.y.copy()
        if m.has_bar:
            hz = hertz_impact(m.contact.reference_mass, m.contact.stiffness, m.contact.reference_speed)
            self._onset_step = hz.contact_time * scene.solver.rtol ** (2.0 / 7.0)
        else:
            self._onset_step = math.inf
        # the step after the armature's stop or card closes: a tenth of their shortest half
        # period (model.armature_scales), where its first step would otherwise be the free
        # flight's and be rejected down to it
        self._armature_onset = 0.1 * armature_scales(scene.armature).contact_time if m.has_armature else math.inf
        self._resolve(triggered=None)
        if m.has_armature:
            self._seat(start=True)  # at rest on a stop it is pressed onto: seated from the start
        self._settle_start()
        self._watch_flight()
        self._record_point()

    # --- public API -------------------------------------------------------------------

    @property
    def planar(self) -> bool:
        return self.model.planar

    @property
    def drive_names(self) -> tuple[str, ...]:
        """The drive channels of this model, which ``advance`` takes: "mu.<i>" and
        "repulsion.<i>" of each contact pair i, and "armature.force" with an armature
        (mech.drives)."""
        return self.model.drive_names

    @property
    def pairs(self) -> tuple:
        """The contact pairs, in the order of the contact rows (index i: ``drive_names``'
        "mu.<i>", ``Segment.pair_forces``' row i, the results' columns ``_<i>``): each a
        mech.mechanism.ContactPair with ``point.name`` (the contact point: a rivet's name,
        "tip0" or "tip1"), ``fixed`` (its fixed contact's name; "block" for [block]),
        ``electrical`` (False: a mechanical stop) and ``normal`` (+1 facing up, -1 down)."""
        return self.model.pairs

    def armature_now(self) -> tuple[float, float]:
        """(q, dq/dt) of the armature now: its travel from the rest stop, m and m/s (plunger)
        or rad and rad/s (clapper)."""
        a = self.model.armature_index
        if a < 0:
            raise ValueError("armature_now: this model has no armature (the scene has no [armature])")
        return float(self.y[a]), float(self.y[a + 1])

    def drives_now(self) -> dict[str, float]:
        """Each drive channel's value at the current time (mu as given, before the kernel
        clips it at zero)."""
        return dict(zip(self.model.drive_names, values_at(self.drive, self.t).tolist()))

    def set_friction_coefficient(self, mu_start: float, mu_end: float | None = None,
                                 t_end: float | None = None) -> None:
        """Every contact point's friction coefficient (N^gamma) from now on: constant, or
        linear to ``mu_end`` at ``t_end``; the other channels hold their values."""
        end = mu_start if mu_end is None or t_end is None else mu_end
        self._set_drives(step_targets(self.model.drive_names, None, (mu_start, end)),
                         self.t if t_end is None else t_end)

    def advance(self, t_target: float, drives=None, *, mu=None, stop_at_switch: bool = False) -> Segment:
        """Integrate to ``t_target`` (s) under the drives given for this step.

        drives: {channel: value} for channels of ``drive_names``, each value a number
        (constant over the step) or a (start, end) pair (linear in time from now to
        ``t_target``): "mu.<i>", contact point i's friction coefficient (N^gamma; below
        zero it acts as zero), and "repulsion.<i>" (N, >= 0), a force on contact point i
        along the block's normal, away from it, acting while the point touches -- Holm's
        electrodynamic repulsion of the constriction; its work counts as work put in
        (``work_in``); "armature.force", the armature's drive: its force along q is this
        value times the scene's gain table at q (N, or N m for a clapper, with no table;
        positive towards the pole; its work is work put in too). A channel not given holds
        the value it ended the previous step with. mu: a number or pair for every "mu.<i>"
        at once.

        A new mu that changes what can stick re-resolves the regimes; a hold at rest ends
        when a channel that moves the static equilibrium (a repulsion, the armature's
        drive) changes.

        stop_at_switch: return at the first contact start or end (make/break) after the
        current time instead, the segment ending there (a co-simulation step in free flight
        ends at the make it meets; integrating past it only to return there costs the whole
        bounce sequence beyond).
        """
        if not math.isfinite(t_target) or t_target < self.t:
            raise ValueError(f"t_target = {t_target!r}: must be a finite time >= the current {self.t!r} s")
        targets = step_targets(self.model.drive_names, drives, mu)
        self._set_drives(targets, t_target)
        rec = self.recorder
        n_first = rec.n
        ev_first = len(self.events)
        start_state = self.y.copy()
        t_start = self.t
        tick = time.perf_counter()
        m = self.model
        if self._hold_until > self.t and (self.regime != self._hold_regime).any():
            self._release_hold()  # the new mu no longer holds a contact at rest
        while self.t < t_target:
            rec.reserve(1)
            goal = t_target
            jump_due = self._jump_index < len(self._jumps) and self._jumps[self._jump_index][0] <= t_target
            if jump_due:
                goal = max(self._jumps[self._jump_index][0], self.t)
            if self.armature_closed[BAR_HELD]:  # held in flight: until the next load change
                if self._flight_until <= self.t:
                    self._release_flight()
                elif self._flight_until < goal:
                    goal, jump_due = self._flight_until, False
            if self._hold_until > self.t:
                # at rest: nothing changes until a load or the base does
                self.t = min(goal, self._hold_until)
                self._record_point()
                if self.t >= self._hold_until:
                    self._release_hold()
                if jump_due and self.t == goal:
                    self._apply_base_jump()
                continue
            # watched for rest in windows only while a contact is closed (a bar in flight
            # is never at rest, and its steps stay as they were)
            window_end = self._rest_t0 + self.model.rest_window
            # (the rows' penetrations as floats: the comparison and any() of numpy cost ~1.8 us a
            # segment, these ~0.5 us; a NaN is not > 0 in either)
            closed = any([y > 0.0 for y in rec.last_aux[:, A_Y].tolist()])
            if not closed:
                self._restart_rest_window()
            elif window_end < goal:
                goal = window_end
                jump_due = False
            try:
                n0 = rec.n
                status, t_new, h, n_rec, ev = self.stepper.segment(self, goal)
            except (np.linalg.LinAlgError, ArithmeticError) as err:
                # (ArithmeticError: a division by zero the compiled code raises; a failed run
                # with what it computed, not a crash)
                self.wall_time += time.perf_counter() - tick
                raise MechSolverError(f"mechanics integration failed at t = {self.t!r} s: {err}",
                                      self.t, self.named_state(), partial=self.result()) from err
            rec.commit(n_rec, self.regime)
            self.t = t_new
            self.h = h
            if status == DONE:
                self.t = goal
            if status in (DONE, BUFFER_FULL, EVENT):
                self._watch_rest(n0, n_rec)
            if status in (DONE, BUFFER_FULL) and not self.armature_closed[BAR_HELD] and self._hold_until <= self.t:
                self._watch_flight()
            if status == DONE:
                if jump_due and self._jumps[self._jump_index][0] == goal:
                    self._apply_base_jump()
                continue
            if status == BUFFER_FULL:
                continue
            if status == EVENT:
                n_events = len(self.events)
                self._handle_event(ev)
                if not self.armature_closed[BAR_HELD] and self._hold_until <= self.t:
                    self._watch_flight()  # (the card has left the bar, say)
                if ev % NEV_TIP == EV_CONTACT:  # a contact made or broken: not at rest
                    self._restart_rest_window()
                    if stop_at_switch and t_new > t_start and any(
                            e["kind"] in ("contact_start", "contact_end") for e in self.events[n_events:]):
                        break
                continue
            self.wall_time += time.perf_counter() - tick
            raise MechSolverError(
                f"mechanics integration failed at t = {self.t!r} s: {STATUS_TEXT[status]} "
                f"(step {self.h!r} s, regimes {[REGIME_NAMES[r] for r in self.regime]})",
                self.t, self.named_state(), partial=self.result(),
            )
        self.wall_time += time.perf_counter() - tick
        n_last = rec.n
        if self.keep_dense:
            t0, hh, coef = rec.dense(n_first, n_last)
        else:
            t0 = hh = np.empty(0)
            coef = np.empty((0, 5, m.state_size))
        return Segment(t_start, self.t, self.events[ev_first:], m, t0, hh,
                       rec.t[n_first:n_last].copy(), coef, start_state,
                       rec.regime[n_first:n_last].copy(), self.eref.copy(),
                       _arrays=m.kernel_arrays(self.drive.copy()),
                       _arm=m.kernel_armature(self.armature_closed.copy()))

    def run(self):
        """Integrate to ``solver.t_end`` and return the ``ImpactResult``.

        The history is thinned as it is made once it holds ``solver.history_rows`` rows
        (without ``keep_dense``; see ``_thin_history``). Running out of memory ends the run
        as any failure does: a MechSolverError with the partial result."""
        self._thin_mid_run = not self.keep_dense
        try:
            self.advance(self.scene.solver.t_end)
        except MemoryError as err:
            self._thin_mid_run = False
            raise MechSolverError(f"mechanics ran out of memory at t = {self.t!r} s ({_one_line(err)})",
                                  self.t, self.named_state(), partial=self._partial_after_memory_error()) from err
        finally:
            self._thin_mid_run = False
        return self.result()

    def _partial_after_memory_error(self):
        """The result so far, after a MemoryError: as it stands, or from a history thinned to
        a quarter of its rows (the result copies its rows), or None."""
        try:
            return self.result()
        except MemoryError:
            pass
        try:
            self._thin_history(self.recorder.n, rows=max(self.recorder.n // 4, 2))
            return self.result()
        except MemoryError:
            return None

    def result(self) -> ImpactResult:
        th = self.thinning
        return ImpactResult(
            model=self.model,
            **self.recorder.columns(),
            events=list(self.events),
            stats=dict(steps=int(self.stats[0]), rejected_steps=int(self.stats[1]),
                       rhs_evals=int(self.stats[2]), events=int(self.stats[3]),
                       wall_time=self.wall_time),
            projection_energy=self.projection_energy,
            thinning=dict(th, max_penetration=list(th["max_penetration"])) if th["rows_dropped"] else None,
        )

    def records(self, kept: np.ndarray) -> ImpactResult:
        """The history's records ``kept`` (indices into the records so far, ascending) as a
        result of their own, its energy audit measured from the run's first record and no
        stick-projection credit (that is the last record's, at the run's end): the rows the
        whole run's result gives them, for a caller that writes the history while the run
        goes on. Indices hold until a thinning (``thinning["rows_dropped"]`` grows) or a
        ``restore`` to a checkpoint taken before them."""
        rec = self.recorder
        kept = np.asarray(kept, dtype=np.int64)
        if len(kept) and not (0 <= kept[0] and kept[-1] < rec.n and np.all(np.diff(kept) > 0)):
            raise ValueError(f"records: indices must ascend within the {rec.n} records so far")
        return ImpactResult(model=self.model, t=rec.t[kept], states=rec.y[kept], aux=rec.aux[kept],
                            peak_force=rec.fmax[kept], regimes=rec.regime[kept], events=list(self.events),
                            stats={}, extra_states=rec.ext[kept], energy_origin=self._first_energies())

    def _first_energies(self) -> np.ndarray:
        """(5,) J: ``energies`` of the run's first record, the energy audit's origin."""
        m = self.model
        return energy_table(self.recorder.y[:1], m.arrays, m.armature_arrays)[0]

    # --- memory: the history in proportion to what is kept ------------------------------

    def release_dense(self) -> None:
        """Forget the dense output recorded so far (``keep_dense``), between two ``advance``
        calls, once what is needed of it has been sampled (a co-simulation samples each
        macro step's contact forces at the circuit's points, then releases them); the
        history is then thinned if it holds more than ``solver.history_rows`` rows.
        ``contact_series`` afterwards covers only the later steps."""
        rec = self.recorder
        rec.release_dense()
        if rec.n >= rec.row_limit:
            self._thin_history(self._protected_row())

    def _protected_row(self) -> int:
        """The first row a thinning must keep, with every row after it: the rows of the
        current rest window (``_watch_rest`` averages the state over them)."""
        rec = self.recorder
        return int(min(np.searchsorted(rec.t[:rec.n], self._rest_t0, side="left"), rec.n - 1))

    def _make_room(self) -> None:
        """Recorder.on_full: thin the history inside ``run`` (never while another caller of
        ``advance`` may hold row indices)."""
        if self._thin_mid_run:
            self._thin_history(self._protected_row())

    def _thin_history(self, floor: int, rows: int | None = None) -> None:
        """Thin the rows before ``floor`` to about ``rows`` (default: half of
        ``solver.history_rows``) on a uniform time grid anchored at the first row: of the
        rows in each interval of the grid the first is kept, and always the first and the
        last row, the rows on either side of every event and every change of a regime (so
        the contact intervals, their impulses and restitutions, and the phases are those of
        the unthinned run). The grid's interval only grows, so earlier rows are never finer
        than later ones. Of the rows dropped, what the result's checks read is kept as
        extremes: the largest energy residual, kinetic energy, input work, speed and
        penetration (mech.results.ImpactResult reads them with its own rows), and each
        kept row's peak force covers the rows dropped before it."""
        rec = self.recorder
        if floor < 3:
            return
        target = max((rec.row_limit if rows is None else rows) // 2, 1)
        t = rec.t[:floor]
        th = self.thinning
        span = float(t[-1] - t[0])
        th["resolution"] = max(th["resolution"], span / target if span > 0.0 else 0.0)
        keep = np.zeros(floor, bool)
        keep[[0, -1]] = True
        if th["resolution"] > 0.0:
            bins = np.floor((t - t[0]) / th["resolution"])
            keep[np.flatnonzero(np.diff(bins) > 0) + 1] = True
        change = np.flatnonzero(np.any(rec.regime[1:floor] != rec.regime[:floor - 1], axis=1))
        keep[change] = True
        keep[change + 1] = True
        if self.events:
            times = np.fromiter((e["time"] for e in self.events), float, len(self.events))
            k = np.searchsorted(t, times[times <= t[-1]])
            keep[np.minimum(k, floor - 1)] = True
            keep[np.maximum(k - 1, 0)] = True
        drop = ~keep
        if not drop.any():
            return
        self._record_dropped(drop)
        th["rows_dropped"] += rec.thin(keep)
        th["until"] = float(rec.t[int(np.count_nonzero(keep)) - 1])

    def _record_dropped(self, drop: np.ndarray) -> None:
        """The extremes of the rows ``drop`` (bool over the first rows) that the result's
        checks read (see _thin_history), folded into ``thinning``."""
        from .results import audit_residual, audit_terms

        rec = self.recorder
        th = self.thinning
        m = self.model
        Y = rec.y[:len(drop)][drop]
        # as the result computes its own rows' energies: the armature's included, and the
        # ringing its seats removed credited (seat_credit, as ImpactResult's residual)
        E = energy_table(Y, m.arrays, m.armature_arrays)
        first = self._first_energies()
        qd = Y[:, m.slices()["quad"]]
        terms = audit_terms(E, qd, first)
        residual = audit_residual(E, qd, first) + seat_credit(rec.t[:len(drop)][drop], self.events)
        th["max_abs_residual"] = max(th["max_abs_residual"], float(np.max(np.abs(residual))))
        th["max_kinetic"] = max(th["max_kinetic"], float(E[:, 0].max()))
        drive = terms["work_in"] - terms["potential"] - (terms["spring_stored"] - first[4])
        th["max_drive_work"] = max(th["max_drive_work"], float(np.max(drive)))
        th["max_speed"] = max(th["max_speed"], float(np.max(np.linalg.norm(Y[:, m.slices()["vel"]], axis=1))))
        pen = rec.aux[:len(drop)][drop][:, :, A_Y].max(axis=0)
        th["max_penetration"] = [max(a, float(b)) for a, b in zip(th["max_penetration"], pen)]

    def _check_rows(self, start: int, rows: int) -> None:
        """Recorder.on_commit: stop a run whose contact point has sunk deeper into its fixed
        contact than its cap's radius. The cap is then wholly inside it: no contact law
        describes that, nothing after it means anything, and such a run (the relay's blade
        under a 5.4 MN armature force) otherwise goes on at steps of 1e-9 s for hours."""
        if not self.model.pairs:  # (an armature alone: no contact point)
            return
        pen = self.recorder.aux[start:start + rows, :, A_Y].max(axis=0)
        cps = self.model.cpar
        for i, pair in enumerate(self.model.pairs):
            if cps[i, C_ON] != 0.0 and pen[i] > cps[i, C_R]:
                into = "the block" if pair.key == "block" else f"its fixed contact {pair.fixed!r}"
                raise MechSolverError(
                    f"contact point {i} went {pen[i]:.3g} m into {into} by t = {self.t!r} s, deeper than its "
                    f"cap's {cps[i, C_R]:.3g} m radius: no contact law describes that; the loads press the "
                    f"contact far beyond what it can carry (forces, springs, gravity)", self.t, self.named_state(),
                    partial=self.result())

    def set_modal_state(self, q=None, eta=None) -> None:
        """Start from given modal coordinates q (m) and speeds eta (m/s), before integrating.

        Order of the modes: ``self.model.basis.families``/``orders``. The run's first
        record and the regimes are redone for the new state.
        """
        self.start_from(**{name: value for name, value in (("q", q), ("eta", eta)) if value is not None})

    def start_from(self, **parts) -> None:
        """Overwrite named parts of the initial state before integrating: any key of
        ``model.slices()`` except "quad" (pos, angle or quat, q, vel, omega, eta, armature;
        SI, the solver's frame). For what a scene cannot say: a modal initial condition, a start
        already in contact. The run's first record and the regimes are redone."""
        if self.t != 0.0 or self.recorder.n != 1:
            raise ValueError("start_from: only before the first advance")
        sl = self.model.slices()
        for name, value in parts.items():
            if name not in sl or name == "quad":
                raise ValueError(f"start_from: unknown part {name!r}; allowed: "
                                 f"{', '.join(k for k in sl if k != 'quad')}")
            size = sl[name].stop - sl[name].start
            arr = np.asarray(value, dtype=float).reshape(-1)
            if arr.shape != (size,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"{name}: expected {size} finite number(s), got {value!r}")
            self.y[sl[name]] = arr
        self._initial_state = self.y.copy()
        self.recorder.truncate(0)
        self.armature_closed[:] = 0.0
        self._hold_until = -math.inf
        self.holds, self.flight_holds = [], []
        self._flight_until = -math.inf
        self._flight_next = 0.0 if self._hold_in_flight else math.inf
        self._resolve(triggered=None)
        if self.model.has_armature:
            self._seat(start=True)
        self._watch_flight()
        self._record_point()

    def checkpoint(self) -> dict:
        """Everything needed to return to this instant with ``restore`` (records after it are dropped)."""
        return dict(t=self.t, y=self.y.copy(), z=self.z.copy(), h=self.h, regime=self.regime.copy(),
                    eref=self.eref.copy(), ev_sign=self.ev_sign.copy(), stats=self.stats.copy(),
                    n=self.recorder.n, thinned=self.thinning["rows_dropped"],
                    n_events=len(self.events), projection_energy=self.projection_energy,
                    drive=self.drive.copy(), jump_index=self._jump_index, armature=self.armature_closed.copy(),
                    rest=(self._hold_until, self._hold_regime.copy(), self._rest_t0, self._rest_ke,
                          [list(h) for h in self.holds]),
                    flight=(self._flight_until, self._flight_h, self._flight_next,
                            [list(h) for h in self.flight_holds]))

    def restore(self, cp: dict) -> None:
        """Return to a ``checkpoint`` (e.g. to redo a coupling step so it ends at an event)."""
        if cp.get("thinned", 0) != self.thinning["rows_dropped"]:
            raise ValueError("restore: the history was thinned after this checkpoint (release_dense); "
                             "take a new checkpoint")
        self.t, self.h = cp["t"], cp["h"]
        self.y[:] = cp["y"]
        self.z[:] = cp["z"]
        self.regime[:] = cp["regime"]
        self.eref[:] = cp["eref"]
        self.ev_sign[:] = cp["ev_sign"]
        self.armature_closed[:] = cp["armature"]
        self.stats[:] = cp["stats"]
        self.recorder.truncate(cp["n"])
        del self.events[cp["n_events"]:]
        self.projection_energy = cp["projection_energy"]
        self.drive[:] = cp["drive"]
        self._jump_index = cp["jump_index"]
        self._hold_until, hold_regime, self._rest_t0, self._rest_ke, holds = cp["rest"]
        self._hold_regime = hold_regime.copy()
        self.holds = [list(h) for h in holds]
        self._flight_until, self._flight_h, self._flight_next, flights = cp["flight"]
        self.flight_holds = [list(h) for h in flights]

    def contact_series(self, times) -> np.ndarray:
        """(len(times), rows, 3): per contact row penetration (m), rate (m/s), normal force
        (N) at the given times (s, within the integrated span), from the dense output
        (keep_dense=True)."""
        if not self.keep_dense:
            raise ValueError("contact_series needs the dense output: build the solver with keep_dense=True")
        times = np.asarray(times, dtype=float)
        order = np.argsort(times, kind="stable")
        rec = self.recorder
        n = rec.n
        b = rec.dense_base  # (rows before it were released, release_dense)
        start = rec.dense_t0[0] if 0 < b < n else rec.t[min(b, n - 1)]  # the first kept step's start
        if len(times) and (times[order[0]] < start - 1e-15 or times[order[-1]] > self.t + 1e-15):
            raise ValueError(f"times must lie in [{start!r}, {self.t!r}] s"
                             + (" (the dense output before was released)" if b else ""))
        out = np.empty((len(times), self.model.rows, 3))
        dense_contact(times[order], rec.t[b:n], rec.dense_t0[:n - b], rec.dense_h[:n - b], rec.dense_coef[:n - b],
                      rec.regime[b:n], self.arrays, self.eref, self.work, out, self.arm)
        result = np.empty_like(out)
        result[order] = out
        return result

    @property
    def dense_rows(self) -> int:
        """Rows of dense output held (``keep_dense``): those recorded since the last
        ``release_dense``."""
        return self.recorder.n - self.recorder.dense_base if self.keep_dense else 0

    @property
    def last_record_time(self) -> float:
        """s: the time of the history's last row (the dense output reaches no further: a
        time beyond it lies in the next step)."""
        return float(self.recorder.t[self.recorder.n - 1])

    @property
    def at_rest(self) -> bool:
        """True while the bar is held at rest (see _watch_rest): nothing in it changes before
        ``hold_until`` unless mu changes enough to unstick a contact or a repulsion changes."""
        return self._hold_until > self.t

    @property
    def held_in_flight(self) -> bool:
        """True while the bar is held at its static equilibrium in flight while the armature
        moves (see _watch_flight): the bar's state stays as it is until the card meets it or
        a load changes; the armature is integrated as ever."""
        return bool(self.armature_closed[BAR_HELD])

    @property
    def armature_seated(self) -> bool:
        """True while the armature is seated on one of its stops (held there, see _seat)."""
        return bool(self.model.has_armature and self.armature_closed[EA_SEAT])

    @property
    def hold_until(self) -> float:
        """s: when the current hold at rest ends (the next load or base change; inf: none)."""
        return self._hold_until if self.at_rest else self.t

    def friction_engaged(self) -> np.ndarray:
        """(rows,) bool: each contact row is sliding or sticking (in a friction regime) now."""
        # (regime != FREE as a cast: FREE is 0, and the cast costs ~0.2 us where numpy's
        # comparison with a Python int cost ~0.5 us, once a macro step)
        return self.regime.astype(bool)

    def contact_now(self) -> np.ndarray:
        """(rows, 3) per contact row: penetration (m), rate (m/s), normal force (N) at the current time."""
        aux = self._evaluate()
        return aux[:, [A_Y, A_YDOT, A_FN]].copy()

    def named_state(self) -> dict:
        """The current state by name (SI), for error messages and inspection."""
        sl = self.model.slices()
        return {name: self.y[s].tolist() for name, s in sl.items() if name != "quad"}

    # --- internals ------------------------------------------------------------------

    def _set_drives(self, targets: dict, t_end: float) -> None:
        """The drive for a step from now to ``t_end`` (s): the channels of ``targets`` (row
        -> (start, end), checked by mech.drives.step_targets) linear over it, the others
        held. A driven force needs the input-work quadrature; a new mu re-resolves the
        regimes (it may change what can stick); a changed repulsion ends a hold at rest and
        restarts the watch for rest (its static equilibrium moved)."""
        m = self.model
        kinds = m.drive_kinds
        if m.nq <= Q_WIN:
            for row, (start, end) in targets.items():
                if kinds[row].force and (start != 0.0 or end != 0.0):
                    raise ValueError(
                        f"drives[{m.drive_names[row]!r}] = {(start, end)!r}: this free bar's model has no input-work "
                        f"quadrature to put a driven force's work in the energy audit; build the solver with "
                        f"ImpactSolver(scene, input_work=True)")
        changed = set_step(self.drive, kinds, targets, self.t, t_end)
        if not changed:
            return
        if self.armature_closed[EA_SEAT] and self._seat_state()[2] <= 0.0:
            self._unseat()  # the new drive no longer presses the seated armature on its stop
        if self._friction_exact and any(kinds[row].friction for row in changed):
            self._resolve(triggered=None)  # a new mu may change what can stick
        self._step_end = t_end
        for row in changed:  # (a loop, not any() over a generator: once a macro step)
            if kinds[row].moves_equilibrium and not self._seated_through(row):
                if self._hold_until > self.t:
                    self._release_hold()
                else:
                    self._restart_rest_window()
                break

    def _drives_ramping(self) -> bool:
        """True if a channel that moves the static equilibrium changes during this step."""
        return any(kind.moves_equilibrium and self.drive[row, D_SLOPE] != 0.0 and not self._seated_through(row)
                   for row, kind in enumerate(self.model.drive_kinds))

    def _seated_through(self, row: int) -> bool:
        """True if ``row`` is the armature's drive and the seated armature stays pressed on its
        stop to the step's end: its press (linear in the drive while it sits still) positive
        at both ends. Its drive then moves nothing the bar feels (the card and the bar see
        the armature's position, which the stop holds), so a hold of the bar at rest goes on
        while the coil's flux changes (the relay held closed while its coil current settles)."""
        if row != self.model.armature_drive_row or not self.armature_closed[EA_SEAT]:
            return False
        stop, _, press = self._seat_state()
        if press <= 0.0:
            return False
        end = float(armature_force(self._step_end, self.y, self.arrays, self.arm))
        return (end if stop == EA_POLE else -end) > 0.0

    def _evaluate(self) -> np.ndarray:
        dynamics(self.t, self.y, self.arrays, self.regime, self.eref, self._dy, self._aux, self.work, self.arm)
        return self._aux

    # --- contacts at rest ------------------------------------------------------------

    def _restart_rest_window(self) -> None:
        self._rest_t0 = self.t
        self._rest_ke = 0.0

    def _release_hold(self) -> None:
        self._hold_until = -math.inf
        self._restart_rest_window()

    def _watch_rest(self, n0: int, n_rec: int) -> None:
        """Hold a bar that has come to rest until its loads change.

        At rest means: for a whole window (model.rest_window, two periods of the slowest
        oscillation the contacts and modes allow) a contact stayed closed, no contact opened
        or closed, none slips, and the largest kinetic energy stayed within what the run
        resolves: rtol times the energy scale its error control holds the energy
        quadratures to (model.contact.energy_scale, the energy available to the scene; the
        integrator accepts an energy error of that size at every step, so whether a
        vibration that small decays, as the contact damping makes it, or grows is not
        decided by the physics but by the integration error: measured, a bar standing on
        its tip kept 8e-10 J of axial vibration fed by an energy drift of 1e-12 J a step,
        far inside its 6e-7 J per-step tolerance, at 155,000 steps per simulated second).
        The state about which that motion oscillates is resolved (positions are held to
        rtol x the Hertz penetration): the bar is held at the window's time-mean position
        with zero speeds, the static equilibrium to within the mean's residue of the
        oscillation, and the energy of the motion dropped (at most about that rtol x energy
        scale) is credited to the audit with the stick projections, so its residual still
        measures integration error only. The hold lasts until the next change of a load (a
        force table's breakpoint, a base breakpoint) or of mu that unsticks a contact.
        """
        if self.model.rest_window <= 0.0:
            return
        rec = self.recorder
        if n_rec and not (rec.last_aux[:, A_Y] > 0.0).any():
            # the segment ends in flight: the window restarts (as the next segment would
            # otherwise do first), so the kinetic energy of its records is not needed
            self._restart_rest_window()
            return
        if n_rec:  # the largest kinetic energy of the new records, in one compiled call
            kinetic = energy_table(rec.y[n0:n0 + n_rec], self.arrays, self.arm)[:, 0]
            self._rest_ke = max(self._rest_ke, float(kinetic.max()))
        if self.t - self._rest_t0 < self.model.rest_window * (1.0 - 1e-12):
            return
        # closed throughout: a window that began in flight (a segment ending at touchdown
        # is watched before its event is handled) says nothing about rest
        first = int(np.searchsorted(rec.t[:rec.n], self._rest_t0, side="right"))
        if not np.all(np.any(rec.aux[first:rec.n, :, A_Y] > 0.0, axis=1)):
            self._restart_rest_window()
            return
        tol = self.scene.solver.stick_velocity_tol
        quiet = self._rest_ke <= self.scene.solver.rtol * self.model.contact.energy_scale
        # micro-slip at a contact held near its friction limit may go on at slip speeds far
        # below the stick tolerance; it does not keep a quiet bar from being at rest
        aux = self._evaluate()
        slipping = any(self.regime[i] == SLIP and math.hypot(aux[i, A_VTX], aux[i, A_VTY]) > tol
                       for i in range(self.model.rows))
        # a force on a ramp is not a constant load, however slowly the bar follows it
        # (nor is a driven force on a ramp: a repulsion that grows within the step)
        # an armature between its stops with its card open is not held: it floats on its
        # return spring, whose slow swing the window is not made to see
        floating = self.model.has_armature and not np.any(self.armature_closed[[EA_REST, EA_POLE, EA_CARD]])
        if (quiet and not slipping and not floating and not self.model.loads_ramping(self.t)
                and not self._drives_ramping() and self._settle_at_mean()):
            later = [t for t in self.model.load_change_times if t > self.t]
            later += [t for t, _ in self._jumps[self._jump_index:] if t > self.t]
            self._hold_until = min(later) if later else math.inf
            self._hold_regime = self.regime.copy()
            self.holds.append([self.t, self._hold_until])
        else:
            self._restart_rest_window()

    def _settle_at_mean(self) -> bool:
        """Move the bar to its static equilibrium near the rest window's time-mean position,
        with zero speeds (see _watch_rest), crediting the energy this removes to the audit.
        Returns False, and leaves the state as it was, if no equilibrium is found or a
        contact would then change its regime."""
        rec = self.recorder
        n = rec.n
        first = int(np.searchsorted(rec.t[:n], self._rest_t0, side="left"))
        t = rec.t[first:n]
        if len(t) < 2 or t[-1] <= t[0]:
            return False
        pos, vel = self._rest_coordinates()
        saved = (self.y.copy(), self.regime.copy(), self.eref.copy(), self.ev_sign.copy(), self.projection_energy,
                 self.armature_closed.copy())
        e = self._rest_e
        energies(self.y, self.arrays, self.work, e, self.arm)
        before = float(e.sum())
        self.y[pos] = np.trapezoid(rec.y[first:n][:, pos], t, axis=0) / (t[-1] - t[0])
        self.y[vel] = 0.0
        self._normalize_attitude()
        regime = self.regime.copy()
        self._resolve(triggered=None)
        found = self._static_equilibrium(pos, vel)
        if found:
            self._resolve(triggered=None)
        # (a contact that stuck must still stick: at zero speed it would otherwise slide; and
        # the armature's stops and card keep their states)
        if (not found or np.any((regime == FREE) != (self.regime == FREE))
                or np.any((regime == STICK) & (self.regime == SLIP))
                or np.any(saved[5] != self.armature_closed)):
            (self.y[:], self.regime[:], self.eref[:], self.ev_sign[:], self.projection_energy,
             self.armature_closed[:]) = saved
            return False
        energies(self.y, self.arrays, self.work, e, self.arm)
        self.projection_energy += float(e.sum()) - before
        return True

    def _watch_flight(self) -> None:
        """Hold a bar that is at rest in flight (nothing touches it) until the card meets it
        or a load changes.

        At rest in flight means: a clamped or pivoted bar, its base still, no contact
        closed, the card open, no spring between it and the armature (whose moving end
        would change its loads), no hysteretic spring, no load on a ramp, and its mechanical
        energy above its static equilibrium under the loads acting (kinetic energy plus
        the strain, gravity and spring energy above the equilibrium's) within what the run
        resolves, rtol x the scene's energy scale (as a hold at rest: _watch_rest). Under
        constant loads and with nothing touching it, a bar's mechanical energy can only
        fall (its modal damping and dashpots dissipate, nothing does work on it), so one
        look suffices: the energy above the equilibrium stays below that tolerance for as
        long as the loads stay. The bar is moved to that equilibrium (found by
        _static_equilibrium, which checks its residual acceleration), its speeds zero, and
        the energy this removes is credited to the audit with the stick projections.

        Held, with an armature: the kernel gives the bar's positions and speeds zero rates
        (kernel_layout BAR_HELD) and the armature is integrated as ever, at the steps its own
        motion needs instead of the bar's highest mode's stability limit; the card's event
        (its gap to the bar's card point reaching zero) releases the bar there, at the
        state it was held in. Without an armature nothing moves: the whole state is held as
        at rest (``at_rest``, ``hold_until``). Either ends at the next load change (a force
        table's breakpoint, a base velocity jump). A bar found not at rest is looked at again
        FLIGHT_RETRY rest windows later.
        """
        m = self.model
        if self.t < self._flight_next or not m.has_bar or m.hysteresis_count:
            return
        # (the cheap tests first: this is asked after most segments, and a contact closed or
        # the card on the bar, the usual answers, need no look at the state)
        mount = m.ipar[I_MOUNT]
        if (mount not in (MOUNT_CLAMP, MOUNT_PIVOT) or (self.regime != FREE).any()
                or (m.has_armature and (self.armature_closed[EA_CARD] or m.armature_springs))):
            return
        sl = m.slices()
        base_still = (self.y[sl["vel"]] == 0.0).all() and (mount == MOUNT_PIVOT or (self.y[sl["omega"]] == 0.0).all())
        if not base_still or m.loads_ramping(self.t):
            return
        aux = self._evaluate()
        if np.any(aux[:, A_Y] > 0.0):
            return
        self._flight_next = self.t + FLIGHT_RETRY * m.rest_window
        tol = self.scene.solver.rtol * m.contact.energy_scale
        e = self._rest_e
        energies(self.y, self.arrays, self.work, e, self.arm)
        before = float(e.sum())
        npos, nvel = state_sizes(m.n, m.planar)
        pos, vel = slice(0, npos), slice(npos, npos + nvel)
        saved = (self.y.copy(), self.regime.copy(), self.eref.copy(), self.ev_sign.copy(),
                 self.armature_closed.copy())
        self.y[vel] = 0.0
        energies(self.y, self.arrays, self.work, e, self.arm)
        held = before - float(e.sum()) <= tol  # its kinetic energy alone (cheap: no equilibrium sought)
        if held:
            held = self._static_equilibrium(pos, vel, armature=False)
        if held:
            energies(self.y, self.arrays, self.work, e, self.arm)
            drop = before - float(e.sum())
            aux = self._evaluate()
            card_open = not m.has_armature or armature_table(self.y[None, :], self.arrays, self.arm)[0, 4] < 0.0
            # (a negative drop beyond the tolerance: an equilibrium above the state, not one it rests in)
            held = abs(drop) <= tol and card_open and not np.any(aux[:, A_Y] > 0.0)
        if held:
            self._resolve(triggered=None)
            held = not np.any(self.regime != FREE) and np.all(self.armature_closed == saved[4])
        if not held:
            self.y[:], self.regime[:], self.eref[:], self.ev_sign[:], self.armature_closed[:] = saved
            return
        if self.recorder.n:  # (a hold before the first record, at the start: the audit starts after it)
            self.projection_energy -= drop
        later = [t for t in m.load_change_times if t > self.t]
        later += [t for t, _ in self._jumps[self._jump_index:] if t > self.t]
        until = min(later) if later else math.inf
        if m.has_armature:
            self.armature_closed[BAR_HELD] = 1.0
            self._flight_until, self._flight_h = until, self.h
            self.flight_holds.append([self.t, until])
        else:
            self._hold_until = until
            self._hold_regime = self.regime.copy()
            self.holds.append([self.t, until])

    def _settle_start(self) -> None:
        """A relay's contact spring (a clamped or pivoted bar beside an armature) given at
        rest, touching nothing, starts at its static equilibrium under the loads acting at
        t = 0 (gravity: its sag), not undeformed: it has rested under its weight before its
        coil is switched on. Undeformed, it rang at the sag's amplitude (the default blade:
        0.43 um in its first bending mode, 2e-10 J, decaying over ~10 ms) as if gravity were
        switched on at t = 0, and that ringing, twice the energy the run resolves, kept the
        bar from being held in flight (_watch_flight). A bar without an armature starts as
        given: released straight, it is an experiment of its own (a blade swinging into its
        sag: tests/mech/test_energy_scale.py). Nothing else of the state changes; a bar
        given a speed, touching, or whose equilibrium would touch, starts as given."""
        m = self.model
        if (not m.has_bar or not m.has_armature or m.hysteresis_count
                or m.ipar[I_MOUNT] not in (MOUNT_CLAMP, MOUNT_PIVOT)):
            return
        npos, nvel = state_sizes(m.n, m.planar)
        if np.any(self.y[npos:npos + nvel] != 0.0) or np.any(self.regime != FREE) or m.loads_ramping(0.0):
            return
        if np.any(self._evaluate()[:, A_Y] > 0.0) or (m.has_armature and self.armature_closed[EA_CARD]):
            return
        saved = (self.y.copy(), self.regime.copy(), self.eref.copy(), self.ev_sign.copy(),
                 self.armature_closed.copy())
        found = self._static_equilibrium(slice(0, npos), slice(npos, npos + nvel), armature=False)
        card_open = not m.has_armature or armature_table(self.y[None, :], self.arrays, self.arm)[0, 4] < 0.0
        if found and card_open and not np.any(self._evaluate()[:, A_Y] > 0.0):
            self._resolve(triggered=None)
            if not np.any(self.regime != FREE) and np.all(self.armature_closed == saved[4]):
                self._initial_state = self.y.copy()
                return
        self.y[:], self.regime[:], self.eref[:], self.ev_sign[:], self.armature_closed[:] = saved

    def _release_flight(self) -> None:
        """End a hold in flight (_watch_flight): the bar moves again, from the step it took before."""
        self.armature_closed[BAR_HELD] = 0.0
        self.flight_holds[-1][1] = self.t
        if self._flight_h > 0.0:
            self.h = min(self.h, self._flight_h)
        self._flight_until = -math.inf
        self._flight_next = self.t

    def _normalize_attitude(self) -> None:
        if not self.model.planar:
            quat = self.model.slices()["quat"]
            self.y[quat] /= np.linalg.norm(self.y[quat])

    def _rest_coordinates(self) -> tuple:
        """Where in the state the positions and the speeds a hold at rest settles are: the
        bar's (two slices) and, with an armature, its q and rate too (two index arrays;
        one speed coordinate per position rate). (Slices without an armature: numpy sums a
        strided view in another order than a copy, and the held state stays the one
        the solver gave before the armature.)"""
        m = self.model
        npos, nvel = state_sizes(m.n, m.planar)
        a = m.armature_index
        if a < 0:
            return slice(0, npos), slice(npos, npos + nvel)
        return np.append(np.arange(npos), a), np.append(np.arange(npos, npos + nvel), a + 1)

    def _static_equilibrium(self, pos, vel, armature: bool | None = None) -> bool:
        """Newton's method on the accelerations at zero speed, in the speed coordinates (a
        displacement du moves the positions by the state's own rates for speeds du), with
        the regimes held: stuck contacts keep their points (their holding forces adjust) and
        the directions nothing restores (sliding along a frictionless block, turning about a
        stuck pair of points) get no displacement (minimum-norm steps). Converged when a
        step moves no coordinate by more than rtol x the Hertz penetration scale (angles:
        over the bar's length; an armature's q: rtol x its stops' penetration scale, its
        error control's). The finite-difference steps are 1e-6 of that scale. pos, vel: the
        state indices of the positions and speeds (_rest_coordinates, or the bar's alone
        with armature=False; default: the armature's too where the model has one).

        Converged is not yet at rest: the residual acceleration there must be one the bar
        does not feel within the rest window T (model.rest_window). Of the acceleration a
        left at the converged state, the part a displacement cancels (J du = -a) must ask
        for a displacement du within the convergence bound, and the rest (r = a + J du: in
        directions nothing restores, e.g. a free bar's fall, or a slide along a
        frictionless block) must move no coordinate by more than that bound in T:
        r T^2 / 2 <= rtol x its scale. Otherwise the state is left where Newton's method
        took it and False is returned (the caller restores it)."""
        m = self.model
        npos, nvel = state_sizes(m.n, m.planar)
        # each speed coordinate's length scale: penetration (m) or penetration / length (rad)
        atol_v = m.atol[npos:npos + nvel]
        scale = m.contact.penetration_scale * atol_v / np.max(atol_v)
        rtol = self.scene.solver.rtol
        if m.has_armature if armature is None else armature:  # the armature's q (its error scale is rtol x that length)
            scale = np.append(scale, m.atol[m.armature_index] / rtol)
            nvel += 1

        def displaced(du):
            self.y[vel] = du
            self._evaluate()
            rate = self._dy[pos].copy()
            self.y[vel] = 0.0
            return rate

        def accel():
            self._evaluate()
            return self._dy[vel].copy()

        J = np.empty((nvel, nvel))
        for _ in range(8):
            a0 = accel()
            base = self.y.copy()
            for j in range(nvel):
                du = np.zeros(nvel)
                du[j] = 1e-6 * scale[j]
                self.y[pos] += displaced(du)
                J[:, j] = (accel() - a0) / du[j]
                self.y[:] = base
            # columns in units of their scale: the least-squares cut-off then compares like with like
            step = np.linalg.lstsq(J * scale, -a0, rcond=1e-10)[0] * scale
            self.y[pos] += displaced(step)
            self._normalize_attitude()
            if np.all(np.abs(step) <= rtol * scale):
                a = accel()
                du = np.linalg.lstsq(J * scale, -a, rcond=1e-10)[0] * scale
                window = self.model.rest_window
                return bool(np.all(np.abs(du) <= rtol * scale)
                            and np.all(0.5 * np.abs(a + J @ du) * window * window <= rtol * scale))
        return False

    def _apply_base_jump(self, resolve: bool = True) -> None:
        """A breakpoint of a clamp's piecewise-linear travel: the base velocity jumps by dv
        (world). The clamp's impulse changes the frame velocity by dv and, the blade lagging
        its clamp, the modal speeds by -(L^T R^T dv)/m; the kinetic energy it puts in is
        credited to the input work, so the audit still closes."""
        _, dv = self._jumps[self._jump_index]
        self._jump_index += 1
        m = self.model
        sl = m.slices()
        n = m.n
        e = np.empty(5)
        energies(self.y, self.arrays, self.work, e, self.arm)
        ke_before = e[0]
        R = m.rotation(self.y)
        self.y[sl["vel"]] += (dv[0], dv[2]) if m.planar else dv
        L = m.first_moments[:, 1:n + 1]
        self.y[sl["eta"]] -= (L.T @ (R.T @ dv)) / m.fpar[F_MASS]
        energies(self.y, self.arrays, self.work, e, self.arm)
        if resolve:  # (a jump at t = 0 comes before the first record: the audit starts after it)
            self.y[sl["quad"].start + Q_WIN] += e[0] - ke_before
            self._resolve(triggered=None)

    def _record_point(self) -> None:
        """Record the current state as a history row (the start, a hold at rest)."""
        self.recorder.append(self.t, self.y, self._evaluate(), self.regime, self.z)

    def _handle_event(self, ev: int) -> None:
        tip, kind = divmod(ev, NEV_TIP)
        base = self.model.armature_event_base
        # one instant: within round-off, or within 1e-4 of the contact onset's first step (a
        # few ps): switching that creeps on by 0.1 ps per event (a slip reversing over and
        # over) is no more progress than switching at one instant, and ran without end
        onset = self._onset_step if math.isfinite(self._onset_step) else 0.0
        spacing = max(1e-12 * max(abs(self.t), 1e-6), 1e-4 * onset)
        same_instant = abs(self.t - self._last_event_time) <= spacing
        self._chatter = self._chatter + 1 if same_instant else 0
        self._last_event_time = self.t
        if self._chatter > CHATTER_LIMIT:
            last = (f"armature {ARMATURE_EVENTS[ev - base]}" if ev >= base
                    else f"tip {tip} {EVENT_KINDS[kind]}")
            raise MechSolverError(
                f"regime switching does not settle at t = {self.t!r} s: {self._chatter} events at one "
                f"instant (last: {last}, regimes "
                f"{[REGIME_NAMES[r] for r in self.regime]})", self.t, self.named_state(), partial=self.result())
        if ev >= base:
            self._armature_event(ev - base)
            return
        if kind == EV_COMPRESSION:
            # a restart for the work split only (the time of maximum compression is in the
            # history): no regime changes, the watched sign turns; a contact chattering at
            # rest makes many of these, so they skip the full regime resolution
            self.ev_sign[ev] = -self.ev_sign[ev]
            return
        old = self.regime.copy()
        old_sign = self.ev_sign[ev]
        self._resolve(triggered=ev)
        aux = self._aux
        name = None
        if kind == EV_CONTACT:
            # (None: a round-off crossing at the surface that changed nothing, see _resolve)
            if (old[tip] == FREE) != (self.regime[tip] == FREE):
                name = "contact_start" if old_sign < 0 else "contact_end"
            if name == "contact_start":
                self._check_cap(tip)
                # F_n ~ y^1.5 is not smooth at y = 0: the first step's local error goes as
                # (h/t_c)^3.5, which the embedded estimate underrates; start small.
                self.h = min(self.h, self._onset_step)
        elif kind == EV_CLIP:
            name = "force_clip_start" if old_sign > 0 else "force_clip_end"
        elif kind == EV_SLIP:
            if self.regime[tip] == STICK:
                name = "stick_start"
            elif self.regime[tip] != SLIP:
                name = "slip_end"
            elif math.hypot(aux[tip, A_VTX], aux[tip, A_VTY]) > self.scene.solver.stick_velocity_tol:
                name = "slip_turn"  # the slip direction swept past 90 deg of the reference
            else:
                name = "slip_reversal"
        else:
            name = "stick_end"
        if name is not None:
            self._log(tip, name, old[tip], aux)
        # Another contact row may have crossed at the same instant (a symmetric landing): its
        # regime changed at this restart without an event of its own.
        for other in range(self.model.rows):
            if other == tip or (old[other] == FREE) == (self.regime[other] == FREE):
                continue
            if self.regime[other] != FREE:
                self._check_cap(other)
                self.h = min(self.h, self._onset_step)
            self._log(other, "contact_start" if old[other] == FREE else "contact_end", old[other], aux)

    def _armature_signs(self, g: np.ndarray, triggered: int | None) -> None:
        """The watched side of each of the armature's events (g: every event function at the
        current state): the triggered one is now on its new side, the others on the side
        their value says (at a stop, not pressed: open); and so which of its stops and card
        are closed (the seat is set by _seat and _unseat alone). The turn and the seat are
        watched by which stops are closed: their values are taken again once that is set."""
        base = self.model.armature_event_base
        for k in range(base, self.model.event_count):
            if triggered == k:
                self.ev_sign[k] = -self.ev_sign[k]
            else:
                self.ev_sign[k] = 1.0 if g[k] >= 0.0 else -1.0
        closed = self.armature_closed.copy()
        for k in (EA_REST, EA_POLE, EA_CARD):
            self.armature_closed[k] = 1.0 if self.ev_sign[base + k] < 0.0 else 0.0
        if closed.tolist() != self.armature_closed.tolist():  # (a few floats: np.any(!=) cost ~2.6 us)
            event_values(self.y, self._evaluate(), self.work[22], self.eref, self.arrays, g, self.arm)
            for k in (base + EA_TURN, base + EA_SEAT):
                if triggered != k:
                    self.ev_sign[k] = 1.0 if g[k] >= 0.0 else -1.0

    def _armature_resolve(self, triggered: int | None = None) -> None:
        """The armature's event signs and contact states for the current state."""
        if not self.model.has_armature:
            return
        g = np.empty(self.model.event_count)
        event_values(self.y, self._evaluate(), self.work[22], self.eref, self.arrays, g, self.arm)
        self._armature_signs(g, triggered)

    def _armature_event(self, k: int) -> None:
        """The armature's event k (kernel_layout EA_*): a stop or the card closed or opened
        (logged; a closing one starts with a step of its own time scale), a turn on a stop
        (where it may be seated), or a seated armature's press vanishing (it leaves the
        stop). The regimes of the contact points do not change: the card's force on the
        bar is a load like the others."""
        ev = self.model.armature_event_base + k
        if k == EA_CARD and self.armature_closed[BAR_HELD]:
            self._release_flight()  # the card meets the held bar: it moves again from here
        if k == EA_TURN:
            self.ev_sign[ev] = -self.ev_sign[ev]
            self._seat()
            return
        if k == EA_SEAT:
            self._unseat()
            return
        opened = self.ev_sign[ev] < 0.0  # it was closed (g < 0)
        self._armature_resolve(ev)
        if not opened:
            self.h = min(self.h, self._armature_onset)
        self._log_armature(k, "end" if opened else "start")
        self._restart_rest_window()

    def _seat_state(self) -> tuple[int, float, float]:
        """(the closed stop EA_REST or EA_POLE, or -1; its penetration m or rad; the force
        pressing the armature onto it, N or N m)."""
        a = self.model.armature_index
        arm = self.scene.armature
        force = float(armature_force(self.t, self.y, self.arrays, self.arm))
        if self.armature_closed[EA_POLE]:
            return EA_POLE, float(self.y[a]) - arm.travel, force
        if self.armature_closed[EA_REST]:
            return EA_REST, -float(self.y[a]), -force
        return -1, 0.0, 0.0

    def _seat(self, start: bool = False) -> None:
        """Seat the armature on its closed stop if it will stay there: at a turn (its speed
        zero) with a force pressing it on, its stop's spring within that force of the
        press, |k pen - R| <= R (its ringing then never lifts it off while R holds). Seated,
        it is held at the stop's surface with zero speed, the stop's force the reaction R,
        until R vanishes (the event EA_SEAT); the stop's stiffness then costs no steps (an
        explicit method on a stop of 1e11 N/m kept ringing at ~100 times its tolerance and
        lifted a pressed armature off spuriously: 5929 contact events in 10 ms of the
        solenoid pressed with 5 N at rtol 1e-6). The energy this removes (the ringing's,
        at most R^2 / (2 k)) is credited to the audit at that time: the event
        "armature_seat" carries it (``energy``, J; mech.results).
        start: at the start of the run, at the stop's surface and at rest (no ringing)."""
        a = self.model.armature_index
        arm = self.scene.armature
        if start:
            q, v = float(self.y[a]), float(self.y[a + 1])
            at = EA_REST if q == 0.0 else EA_POLE if q == arm.travel else -1
            if at < 0 or v != 0.0:
                return
            self.armature_closed[at] = 1.0
            stop, pen, press = self._seat_state()
            if press <= 0.0:
                self.armature_closed[at] = 0.0
                return
        else:
            stop, pen, press = self._seat_state()
            k_stop = arm.stop_stiffness
            if stop < 0 or press <= 0.0 or abs(k_stop * pen - press) > press:
                return
        e = self._rest_e
        energies(self.y, self.arrays, self.work, e, self.arm)
        before = float(e.sum())
        self.y[a] = 0.0 if stop == EA_REST else arm.travel
        self.y[a + 1] = 0.0
        self.armature_closed[EA_SEAT] = 1.0
        energies(self.y, self.arrays, self.work, e, self.arm)
        self._armature_resolve()
        self._log_armature(stop, "seat", energy=float(e.sum()) - before, press=press)

    def _unseat(self) -> None:
        """The press of the seated armature has vanished: it leaves its stop (at the surface,
        at rest: the stop opens at once)."""
        stop = EA_POLE if self.armature_closed[EA_POLE] else EA_REST
        self.armature_closed[EA_SEAT] = 0.0
        self._armature_resolve()
        self._log_armature(stop, "end")
        self._restart_rest_window()

    def _log_armature(self, k: int, edge: str, **extra) -> None:
        """Log the armature's stop or card event k (EA_*) as "<name>_<edge>" (start, end), or its
        seat on stop k ("armature_seat", with the energy credited to the audit, J, and the
        press, N or N m); ``extra``: more fields of the event."""
        name, stop = ARMATURE_EVENTS[k]
        if edge == "seat":
            name, edge = "armature", "seat"
        q, v, card, _, pen_card, pen_card_rate = armature_table(self.y[None, :], self.arrays, self.arm)[0]
        travel = self.scene.armature.travel
        if k == EA_CARD:
            pen, rate, force = pen_card, pen_card_rate, card
        elif k == EA_REST:
            pen, rate, force = -q, -v, self.scene.armature.stop_stiffness * max(0.0, -q)
        else:
            pen, rate, force = q - travel, v, self.scene.armature.stop_stiffness * max(0.0, q - travel)
        self.events.append(dict(
            time=self.t, tip=-1, kind=f"{name}_{edge}", stop=stop,
            regime_before="", regime_after="", penetration=float(pen), penetration_rate=float(rate),
            normal_force=float(force), slip_speed=0.0, armature_position=float(q), armature_velocity=float(v),
            **extra,
        ))

    def _log(self, tip: int, kind: str, before: int, aux: np.ndarray) -> None:
        self.events.append(dict(
            time=self.t, tip=tip, kind=kind,
            regime_before=REGIME_NAMES[before], regime_after=REGIME_NAMES[self.regime[tip]],
            penetration=float(aux[tip, A_Y]), penetration_rate=float(aux[tip, A_YDOT]),
            normal_force=float(aux[tip, A_FN]),
            slip_speed=float(math.hypot(aux[tip, A_VTX], aux[tip, A_VTY])),
        ))

    def _check_cap(self, tip: int) -> None:
        """Flag contacts whose normal leaves the spherical cap (the model then does not hold),
        and contacts too far from the top of a spherical block for its tangent plane."""
        self._check_sphere_block(tip)
        axis, half_angle = self.model.cap_axes[tip]
        if axis is None:
            return
        R = self.model.rotation(self.y)
        inward_z = -float(self.model.cpar[tip, C_N] * (R[2] @ axis))  # the cap's outward axis along the fixed contact's inward normal
        angle = math.acos(max(-1.0, min(1.0, inward_z)))  # between the outward axis and that normal
        if angle > half_angle + 1e-9:
            self.events.append(dict(
                time=self.t, tip=tip, kind="invalid_contact_geometry", regime_before="", regime_after="",
                penetration=0.0, penetration_rate=0.0, normal_force=0.0, slip_speed=0.0,
                note=f"contact normal {math.degrees(angle):.1f} deg from the cap's axis, beyond the cap's "
                     f"{math.degrees(half_angle):.1f} deg: the bar's side would touch",
            ))

    def _check_sphere_block(self, tip: int) -> None:
        """A spherical fixed contact is treated by its tangent plane at the top: a contact a
        horizontal distance d from the top sees the sphere d^2 / (2 R) beyond that plane. Flag a contact where that exceeds a tenth of the Hertz penetration scale."""
        if tip >= len(self.model.pairs) or self.model.pairs[tip].shape != "sphere":
            return
        pair = self.model.pairs[tip]
        x = self.model.contact_point_x(self.y, tip)
        d = x - self.model.sphere_tops[tip]
        drop = d * d / (2.0 * pair.radius)
        if drop > 0.1 * self.model.contact.penetration_scale:
            what = "block" if pair.key == "block" else f"fixed contact {pair.fixed!r}"
            self.events.append(dict(
                time=self.t, tip=tip, kind="invalid_contact_geometry", regime_before="", regime_after="",
                penetration=0.0, penetration_rate=0.0, normal_force=0.0, slip_speed=0.0,
                note=f"contact {d * 1e3:.3g} mm from the top of the spherical {what} (radius {pair.radius * 1e3:.3g} "
                     f"mm): the sphere lies {drop:.2g} m {'below' if pair.normal > 0.0 else 'above'} its tangent "
                     "plane there, more than a tenth of the "
                     f"contact's penetration scale; the tangent-plane treatment does not hold ({pair.key}.offset?)",
            ))

    def _start_from_rest(self, new: np.ndarray, tol: float) -> None:
        """Bring every touching tip that slips slower than ``tol`` (stick_velocity_tol) to
        zero slip speed, before the holding forces decide between stick and slip.

        Below the tolerance a slip speed is rest (the event that stopped it resolves it no
        better), so a tip that then slips starts from rest along the unbalanced holding
        force, exactly as one that sticks does. Without this, a tip that could not stick
        kept its sub-tolerance speed, possibly against the slip direction the holding force
        gives, and the slip event fired again at the same instant (measured: 201 events at
        one instant for a bar coming to rest). The speeds change by the smallest change in
        the kinetic-energy metric (project_to_stick); the energy removed, at most
        1/2 m_eff tol^2 per tip, enters the audit as projection energy.
        """
        aux = self._aux  # evaluated by the caller for this state
        rest = new.copy()
        any_rest = False
        for i in range(len(new)):
            if new[i] != FREE and aux[i, A_FN] > 0.0 and math.hypot(aux[i, A_VTX], aux[i, A_VTY]) <= tol:
                rest[i] = STICK
                any_rest = True
            elif rest[i] == STICK:
                rest[i] = SLIP  # (not at rest: left out of the projection)
        if any_rest:
            self.projection_energy += project_to_stick(
                self.t, self.y, self.arrays, rest, self.eref, self._aux, self.work, self.arm)

    def _slip_reference(self, i: int, aux: np.ndarray, resisted: np.ndarray) -> np.ndarray:
        """Reference direction of a slip that starts at tip i from (near) rest: the direction
        the holding force resisted, or the tip's own slip velocity where the bar keeps one
        that _start_from_rest could not remove (a rigid bar on two contacts: their slip
        speeds differ by its rotation rate times their height difference) and that reaches
        half the slip event's dead band: a slip referenced against its own velocity fires
        that event again at once if its speed is at the band, as a slip that has just
        reversed is (measured: 201 reversals at one instant at 0.99999 of the band), and
        one slower than half the band cannot reach it that way."""
        v = np.array([aux[i, A_VTX], aux[i, A_VTY]])
        speed = float(np.hypot(*v))
        if speed > 0.5 * REVERSAL_DEADBAND * self.scene.solver.stick_velocity_tol:
            return v / speed
        return resisted

    def _resolve(self, triggered: int | None) -> None:
        """Set each tip's regime for the current state and the event signs to watch."""
        fexact = self.model.ipar[I_FRICTION] == FRICTION_EXACT
        tol = self.scene.solver.stick_velocity_tol
        aux = self._evaluate()
        new = self.regime.copy()
        # A triggered event's state can sit a round-off away from the root on either side
        # (solve_ivp does not say which); its crossing direction decides there.
        tiny = 1e-9 * self.model.contact.penetration_scale
        rows = self.model.rows
        for i in range(rows):
            pen = aux[i, A_Y]
            if triggered == NEV_TIP * i + EV_CONTACT and abs(pen) <= tiny:
                # at the surface the tip's normal speed says where it goes; only where that
                # is a round-off too does the crossing direction decide. (A tip leaving the
                # block at 1 cm/s re-crossed its surface by round-off 5e-16 s after its
                # contact end: taken as a contact start, it left at once, and the steps
                # shrank to nothing: 'step size too small'.)
                rate = aux[i, A_YDOT]
                if abs(rate) > 1e-9 * self.model.contact.reference_speed:
                    in_contact = rate > 0.0
                else:
                    in_contact = self.ev_sign[triggered] < 0.0  # crossing upwards: contact starts
            else:
                in_contact = pen > 0.0
            if not in_contact:
                new[i] = FREE
                continue
            vt = np.array([aux[i, A_VTX], aux[i, A_VTY]])
            speed = float(np.hypot(*vt))
            if not fexact or aux[i, A_FN] <= 0.0:
                new[i] = SLIP
                if speed > 0.0:
                    self.eref[i] = vt / speed
                continue
            if new[i] == STICK:
                continue
            if speed > tol:
                new[i] = SLIP
                self.eref[i] = vt / speed
            else:
                new[i] = STICK  # provisional: kept if the holding force is within the limit
        if fexact:
            self._start_from_rest(new, tol)
        # Stick needs the holding force within the limit; the tips are coupled through the bar.
        # A tip whose own stick-limit event fired slips: the located state can sit a
        # round-off inside the limit, and keeping the tip stuck would re-fire the event.
        for i in range(rows):
            if triggered == NEV_TIP * i + EV_STICK and new[i] == STICK:
                aux = self._evaluate()
                ft = np.array([aux[i, A_FTX], aux[i, A_FTY]])
                fmag = float(np.hypot(*ft))
                if fmag > 0.0:
                    new[i] = SLIP
                    self.eref[i] = self._slip_reference(i, aux, -ft / fmag)
        for _ in range(3):
            self.regime[:] = new
            aux = self._evaluate()
            changed = False
            for i in range(rows):
                if new[i] != STICK:
                    continue
                ft = np.array([aux[i, A_FTX], aux[i, A_FTY]])
                fmag = float(np.hypot(*ft))
                limit = aux[i, A_MARGIN] + fmag
                if aux[i, A_MARGIN] < -1e-9 * max(limit, 1e-12):
                    new[i] = SLIP
                    self.eref[i] = self._slip_reference(i, aux, -ft / fmag)
                    changed = True
            if not changed:
                break
        self.regime[:] = new
        aux = self._evaluate()
        g = np.empty(self.model.event_count)
        event_values(self.y, aux, self.work[22], self.eref, self.arrays, g, self.arm)
        self._armature_signs(g, triggered)
        for i in range(rows):
            b = NEV_TIP * i
            self.ev_sign[b + EV_CONTACT] = -1.0 if new[i] == FREE else 1.0
            gc = g[b + EV_CLIP]
            if triggered == b + EV_CLIP:
                self.ev_sign[b + EV_CLIP] = -self.ev_sign[b + EV_CLIP]  # now on the new side
            else:
                self.ev_sign[b + EV_CLIP] = 1.0 if gc >= 0.0 else -1.0
            self.ev_sign[b + EV_SLIP] = 1.0
            self.ev_sign[b + EV_STICK] = 1.0
            gd = g[b + EV_COMPRESSION]
            if triggered == b + EV_COMPRESSION:
                self.ev_sign[b + EV_COMPRESSION] = -self.ev_sign[b + EV_COMPRESSION]
            else:
                self.ev_sign[b + EV_COMPRESSION] = 1.0 if gd >= 0.0 else -1.0


def _one_line(err: BaseException) -> str:
    """An exception as one line: its type and first line of text."""
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0]}" if text else type(err).__name__
