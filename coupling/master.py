"""The co-simulation master: mechanics and ngspice advanced in macro steps.

Exchange per macro step [t_n, t_n+1] (scheme "mechanics_first", the default):
1. The loop current is extrapolated linearly with the circuit's own slope at the step
   start (a short zero-order-hold step right after a make or break, where it jumps; steps
   no longer than half the current's time scale |dI/dt|/|d2I/dt2|) and gives mu(I) at both
   ends of the step; the mechanics integrates the step with mu linear in time.
2. If a tip makes or breaks inside the step, the mechanics returns to the step start
   and integrates only up to that instant: the step ends there (``align_events``).
3. ngspice integrates the same step with the contact conductance G_F(F_n(t)) taken from
   the mechanics' dense output at whatever times it asks, with a breakpoint at each
   make/break. The current factor of R_c(F_n, I) is solved inside ngspice, so the only
   lagged quantity is mu(I).
While both tips are free nothing needs exchanging but the next onset, which the
mechanics locates exactly, so the macro step grows to ``max_macro_step``.

Scheme "jacobi" (for comparison): both advance over the step on the other's values at
t_n, held: mu(I_n) and the conductance G(F_n(t_n)).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from mech import ImpactSolver
from mech.kernel import FREE

from .results import CoupledResult
from .scene import Scene

CONTACT_EVENTS = ("contact_start", "contact_end")


class CoupledRunError(RuntimeError):
    """A coupled run failed; ``partial`` holds the CoupledResult up to the failure."""

    def __init__(self, message: str, partial: CoupledResult | None):
        super().__init__(message)
        self.partial = partial


class Progress:
    """Prints the simulated time now and then, for runs longer than a few seconds."""

    def __init__(self, t_end: float, enabled: bool, stream=sys.stderr, first_after: float = 3.0,
                 every: float = 2.0):
        self.t_end, self.enabled, self.stream = t_end, enabled, stream
        self.start = time.perf_counter()
        self.next_report = self.start + first_after
        self.every = every

    def __call__(self, t: float) -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if now >= self.next_report:
            self.next_report = now + self.every
            print(f"switchsim: t = {t * 1e3:.3f} of {self.t_end * 1e3:.3f} ms "
                  f"({100.0 * t / self.t_end:.0f} %), {now - self.start:.1f} s", file=self.stream, flush=True)


class CoSimulation:
    """Runs a coupled scene (mechanics + tribology + circuit)."""

    def __init__(self, scene: Scene, *, progress: bool = False):
        if scene.kind != "coupled":
            raise ValueError(f"CoSimulation needs a coupled scene (mechanics, [tribology] and [circuit]); "
                             f"this one is {scene.kind!r}: use coupling.run")
        self.scene = scene
        self.laws = scene.tribology.laws
        self.feedback = scene.tribology.feedback
        self.progress = Progress(scene.t_end, progress)
        self.mu_log: list[tuple[float, float, float, float]] = []
        self.stats = dict(macro_steps=0, aligned_steps=0, contact_steps=0, mech_seconds=0.0,
                          circuit_seconds=0.0)
        self._tail_t = np.zeros(0)
        self._tail_i = np.zeros(0)

    def _mu(self, current: float) -> float:
        return float(self.laws.mu(current)) if self.feedback else float(self.laws.mu(0.0))

    def run(self) -> CoupledResult:
        from circuit import Stepper

        sc = self.scene
        opts = sc.coupling
        t_end = sc.t_end
        rl = self.laws.resistance_law
        tick = time.perf_counter()
        mech = ImpactSolver(sc.mech, keep_dense=True)
        stepper = Stepper(sc.circuit.circuit, t_end, sc.circuit.options)
        self.mech, self.stepper = mech, stepper
        t = 0.0
        i_now = 0.0
        # a contact closed at t = 0 (a resting start): the circuit's operating point carries
        # a current not known yet, so the first step is a short one, as after a make
        jump_since_prev = bool(np.any(mech.contact_now()[:, 0] > 0.0))
        rate, scale = 0.0, math.inf  # dI/dt of the loop current at t (A/s) and its time scale (s)
        try:
            with stepper:
                while t < t_end * (1.0 - 1e-14):
                    touching = jump_since_prev or bool(np.any(mech.regime != FREE)) or bool(
                        np.any(mech.contact_now()[:, 0] > 0.0))
                    t_next = min(t + (opts.macro_step if touching else opts.free_step), t_end)
                    if t_end - t_next < 1e-3 * opts.macro_step:
                        t_next = t_end  # no sliver step at the end
                    if opts.scheme == "jacobi":
                        i_now, t = self._jacobi_step(mech, stepper, rl, t, t_next, i_now)
                    else:
                        probe = _probe_step(opts.macro_step)
                        if jump_since_prev:
                            # Right after a make/break the current has jumped and is known only
                            # at the jump: a short step (H^2 / PROBE_TIME) fetches it, so the
                            # zero-order hold costs O(H^2), not O(H): still second order.
                            t_next = min(t + probe, t_end)
                            slope = 0.0
                        else:
                            # Taylor step with the circuit's own slope at t. While the current
                            # moves on a time scale shorter than the step (an L/R rise after a
                            # make is ~100 ns) no slope extrapolates over it: the step shrinks
                            # to half that time scale, at least the probe length.
                            slope = rate
                            if touching and abs(rate) * (t_next - t) > CHANGE_FRACTION * (abs(i_now) + CURRENT_FLOOR):
                                t_next = min(t_next, t + max(probe, TIME_SCALE_FRACTION * scale))
                        t_new, current, jumped, (rate, scale) = self._mechanics_first_step(
                            mech, stepper, rl, t, t_next, i_now, slope, scale)
                        i_now, t = current, t_new
                        jump_since_prev = jumped
                    self.stats["macro_steps"] += 1
                    self.stats["contact_steps"] += int(touching)
                    self.progress(t)
                self.stats["wall_time"] = time.perf_counter() - tick
                return self._result(mech, stepper, status="ok")
        except Exception as err:  # a failure keeps what was computed and says why
            self.stats["wall_time"] = time.perf_counter() - tick
            partial = None
            try:
                partial = self._result(mech, stepper, status=f"failed at t = {t!r} s: {err}")
            except Exception:  # noqa: BLE001 - the partial result is best effort
                partial = None
            raise CoupledRunError(f"coupled run failed at t = {t!r} s: {type(err).__name__}: {err}", partial) from err

    # --- schemes -----------------------------------------------------------------------

    def _mechanics_first_step(self, mech, stepper, rl, t, t_next, i_now, slope, horizon=math.inf):
        def current_at(s):
            # linear, but not beyond the current's time scale: an exponential approach
            # extrapolated over its time constant lands on its asymptote
            return i_now + slope * min(s - t, horizon)

        mu0 = self._mu(current_at(t))
        touching = mech.regime != FREE
        cp = mech.checkpoint() if self.scene.coupling.align_events else None
        tick = time.perf_counter()
        seg = mech.advance(t_next, mu=(mu0, self._mu(current_at(t_next))))
        switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
        opts = self.scene.coupling
        guard = 1e-9 * opts.macro_step
        probe = _probe_step(opts.macro_step)
        aligned = False
        if cp is not None and switching:
            if t + guard < switching[0] < t_next - guard:
                end = switching[0]  # end the step at the make/break
            elif switching[0] <= t + guard and t_next - t > probe * (1.0 + 1e-9):
                end = t + probe  # it happened at the step start: only a short step past it
            else:
                end = None
            if end is not None:
                t_next = end
                mech.restore(cp)
                seg = mech.advance(t_next, mu=(mu0, self._mu(current_at(t_next))))
                self.stats["aligned_steps"] += 1
                switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
                aligned = True
        self.stats["mech_seconds"] += time.perf_counter() - tick
        self.mu_log.append((t, t_next, mu0, self._mu(current_at(t_next))))
        breakpoints = sorted({s for s in switching if t < s <= t_next})
        conductance, gap = self._conductance(seg, rl, touching)
        tick = time.perf_counter()
        step = stepper.advance(t_next, conductance, breakpoints=breakpoints,
                               gap=gap if stepper.uses_gap else None)
        self.stats["circuit_seconds"] += time.perf_counter() - tick
        # the circuit's last points, kept across steps for the slope and its time scale
        self._tail_t = np.concatenate([self._tail_t, step.reader("time")])[-TAIL_POINTS:]
        self._tail_i = np.concatenate([self._tail_i, step.reader("load_current")])[-TAIL_POINTS:]
        keep = np.concatenate([[True], np.diff(self._tail_t) > 0])
        self._tail_t, self._tail_i = self._tail_t[keep], self._tail_i[keep]
        jumped = bool(switching) or aligned
        if jumped:  # points before a jump say nothing of the current after it
            self._tail_t, self._tail_i = self._tail_t[-1:], self._tail_i[-1:]
        # a step cut at a make/break ends at a current jump even when the re-run mechanics
        # stops a round-off short of the event (it is then found at the next step's start)
        return t_next, _coupling_current(step), jumped, _end_rate(self._tail_t, self._tail_i,
                                                                  self.scene.coupling.macro_step)

    def _jacobi_step(self, mech, stepper, rl, t, t_next, i_now):
        mu = self._mu(i_now)
        contact = mech.contact_now()
        onset = self.scene.coupling.onset_penetration
        g = sum(rl.scalar_force_conductance(contact[i, 2]) * conduction_onset(contact[i, 0], onset) for i in range(2))
        gap = float(max(0.0, -np.max(contact[:, 0])))
        tick = time.perf_counter()
        mech.advance(t_next, mu=mu)
        self.stats["mech_seconds"] += time.perf_counter() - tick
        self.mu_log.append((t, t_next, mu, mu))
        tick = time.perf_counter()
        step = stepper.advance(t_next, g, gap=gap if stepper.uses_gap else None)
        self.stats["circuit_seconds"] += time.perf_counter() - tick
        return _coupling_current(step), t_next

    def _conductance(self, seg, rl, touching_at_start):
        """G_F(F_n(t)) summed over both tips (they touch the same block), S, from the dense output.

        Each tip conducts only inside its contact intervals as the mechanics' events
        delimit them, the same instants ngspice gets as breakpoints: the interpolant may
        show a round-off penetration just before a located make.
        """
        intervals = _contact_intervals(seg, touching_at_start)
        force = rl.scalar_force_conductance
        onset = self.scene.coupling.onset_penetration
        lo, hi = seg.t_start, seg.t_end

        def gap(s: float) -> float:
            """m: the arc's length, the smaller tip height; 0 while a tip touches."""
            s = lo if s < lo else (hi if s > hi else s)
            if any(a <= s <= b for spans in intervals for a, b in spans):
                return 0.0
            return seg.tip_forces(s)[2]

        if not intervals[0] and not intervals[1]:
            return 0.0, gap  # open throughout: no conductance callback needed

        def g(s: float) -> float:
            s = lo if s < lo else (hi if s > hi else s)
            total = 0.0
            forces = None
            for i in range(2):
                if any(a <= s <= b for a, b in intervals[i]):
                    if forces is None:
                        forces = seg.tip_forces(s)
                    total += force(forces[i]) * conduction_onset(forces[3 + i], onset)
            return total

        return g, gap


    # --- results -------------------------------------------------------------------------

    def _result(self, mech, stepper, status: str) -> CoupledResult:
        waves = stepper.results()
        waves = waves[waves.time <= mech.t + 1e-15].reset_index(drop=True)
        contact = mech.contact_series(waves.time.to_numpy())
        for i in range(2):
            waves[f"normal_force_{i}"] = contact[:, i, 2]
            waves[f"penetration_{i}"] = np.maximum(contact[:, i, 0], 0.0)
        waves["normal_force"] = contact[:, 0, 2] + contact[:, 1, 2]
        # the arc's length as given to ngspice: the nearer tip's height, 0 while a tip touches
        waves["gap"] = np.where(waves["normal_force"] > 0.0, 0.0,
                                np.maximum(0.0, -np.max(contact[:, :, 0], axis=1)))
        waves["mu"] = self._mu_series(waves.time.to_numpy())
        return CoupledResult(scene=self.scene, mechanics=mech.result(), waveforms=waves,
                             stats=dict(self.stats, circuit=stepper.stats), status=status)

    def _mu_series(self, times: np.ndarray) -> np.ndarray:
        """The friction coefficient the mechanics used (N^gamma), linear within each macro step."""
        if not self.mu_log:
            return np.full(len(times), self._mu(0.0))
        log = np.array(self.mu_log)
        k = np.clip(np.searchsorted(log[:, 1], times), 0, len(log) - 1)
        t0, t1, m0, m1 = log[k].T
        frac = np.where(t1 > t0, (times - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0)
        return m0 + (m1 - m0) * np.clip(frac, 0.0, 1.0)


def conduction_onset(penetration: float, onset: float) -> float:
    """Fraction (0..1) of the law's conductance a tip carries at penetration y (m).

    s = 3 x^2 - 2 x^3, x = y / onset, for 0 <= y < onset; 1 beyond; 0 out of contact. Over
    the first `onset` metres (default 10 nm, a surface-roughness scale: 10 ns at 1 m/s) the
    continuum Hertz and Holm laws do not hold, and G_F ~ y^0.4 has an unbounded derivative
    at y = 0 that ngspice's truncation-error control chases below its minimum step at tight
    RELTOL (measured: a relay with a snubber aborted at the first make at RELTOL 1e-6).
    With the ramp G ~ y^2.4 near touchdown: twice differentiable.
    """
    if penetration <= 0.0:
        return 0.0
    if onset <= 0.0 or penetration >= onset:
        return 1.0
    x = penetration / onset
    return x * x * (3.0 - 2.0 * x)


def _contact_intervals(seg, touching_at_start) -> list[list[tuple[float, float]]]:
    """Per tip, the contact intervals inside the segment as its events delimit them."""
    intervals = []
    for i in range(2):
        start = seg.t_start if touching_at_start[i] else None
        spans = []
        for e in seg.events:
            if e["tip"] != i:
                continue
            if e["kind"] == "contact_start":
                start = e["time"]
            elif e["kind"] == "contact_end" and start is not None:
                spans.append((start, e["time"]))
                start = None
        if start is not None:
            spans.append((start, seg.t_end))
        intervals.append(spans)
    return intervals


PROBE_TIME = 1e-4  # s: the step right after a current jump is H^2 / PROBE_TIME (O(H^2): second order)
# A step extrapolates the current over at most this fraction of its local time scale
# |dI/dt|/|d2I/dt2|: an exponential overshoots by ~(1 - e^-x - x)... ~x^2/2 of its remaining
# change over x time constants, ~12 % at 0.5.
TIME_SCALE_FRACTION = 0.5
CHANGE_FRACTION = 1e-3  # the time-scale rule applies only where a step would change the current by more
CURRENT_FLOOR = 1e-3  # A: floor of |I| in the cautious time scale |I|/|dI/dt|
TAIL_POINTS = 8  # circuit points kept across macro steps for the slope and its curvature


def _probe_step(macro_step: float) -> float:
    """s, the short step that fetches the current right after a make/break (H^2 / PROBE_TIME).
    The run loop takes it and the event alignment must recognise it: both call this."""
    return macro_step ** 2 / PROBE_TIME


def _end_rate(t: np.ndarray, i: np.ndarray, span: float) -> tuple[float, float]:
    """(dI/dt in A/s, its time scale |dI/dt| / |d2I/dt2| in s) of the loop current at the last
    of the circuit points (t, i) (several steps' worth: a short step may hold only one or
    two), with differences over at least 1e-3 of ``span`` (s) so a sliver landing step does
    not dominate; (0, inf) without enough points. For an exponential approach the time
    scale is its time constant wherever the current is on it; for a ramp it is infinite."""
    if len(t) < 2 or not np.all(np.isfinite(i[-3:])):
        return 0.0, math.inf
    k = len(t) - 2
    while k > 0 and t[-1] - t[k] < 1e-3 * span:
        k -= 1
    dt = t[-1] - t[k]
    if dt <= 0:
        return 0.0, math.inf
    rate = float((i[-1] - i[k]) / dt)
    j = k - 1
    while j > 0 and t[k] - t[j] < 1e-3 * span:
        j -= 1
    if j < 0 or t[k] <= t[j]:
        # too few points for a curvature: the cautious scale |I|/|dI/dt|
        return rate, (abs(float(i[-1])) + CURRENT_FLOOR) / abs(rate) if rate != 0.0 else math.inf
    previous = (i[k] - i[j]) / (t[k] - t[j])
    curvature = 2.0 * (rate - previous) / (t[-1] - t[j])
    if curvature == 0.0:
        return rate, math.inf
    return rate, float(abs(rate / curvature))


def _coupling_current(step) -> float:
    """A: the current that sets mu(I): the loop (load) current, a smooth state of the
    circuit (the metallic contact current also carries the parasitic capacitance's
    discharge spikes at each make); the contact current when the netlist has no load probe."""
    current = float(step.load_current)
    return current if np.isfinite(current) else float(step.contact_current)


def run(scene: Scene, *, progress: bool = False, check: bool = False) -> CoupledResult:
    """Run any scene: mechanics only, circuit only (prescribed schedule) or coupled.
    check: also rerun it refined and write summary.accuracy (coupling/accuracy.py)."""
    if check:
        from .accuracy import run_checked

        return run_checked(scene, progress=progress)
    if scene.kind == "coupled":
        return CoSimulation(scene, progress=progress).run()
    if scene.kind == "mechanics":
        from mech.solver import MechSolverError

        tick = time.perf_counter()
        try:
            result = ImpactSolver(scene.mech).run()
        except MechSolverError as err:
            partial = None
            if err.partial_result is not None:
                partial = CoupledResult(scene=scene, mechanics=err.partial_result, waveforms=None,
                                        stats={}, status=f"failed: {err}")
            raise CoupledRunError(str(err), partial) from err
        return CoupledResult(scene=scene, mechanics=result, waveforms=None,
                             stats=dict(wall_time=time.perf_counter() - tick), status="ok")
    from circuit import run_transient

    tick = time.perf_counter()
    spec = scene.circuit
    waves = run_transient(spec.circuit, spec.schedule, scene.t_end, options=spec.options)
    return CoupledResult(scene=scene, mechanics=None, waveforms=waves,
                         stats=dict(wall_time=time.perf_counter() - tick), status="ok")


