"""The co-simulation master: mechanics and ngspice advanced in macro steps.

Exchange per macro step [t_n, t_n+1] (scheme "mechanics_first", the default):
1. The loop current is extrapolated linearly from the last two step ends (a zero-order
   hold right after a make or break, where it jumps) and gives mu(I) at both ends of
   the step; the mechanics integrates the step with mu linear in time.
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
        i_now, i_prev, t_prev = 0.0, None, None
        jump_since_prev = False
        t_jump = 0.0
        try:
            with stepper:
                while t < t_end * (1.0 - 1e-14):
                    touching = (jump_since_prev and t > 0.0) or bool(np.any(mech.regime != FREE)) or bool(
                        np.any(mech.contact_now()[:, 0] > 0.0))
                    h = opts.macro_step if touching else opts.free_step
                    if jump_since_prev and t > 0.0 and opts.scheme == "mechanics_first":
                        # Right after a make/break the current has jumped and is known only
                        # at the jump: a short step (H^2 / H_free) fetches it, so the
                        # zero-order hold costs O(H^2), not O(H), and the scheme stays second order.
                        h = min(h, opts.macro_step ** 2 / opts.free_step)
                    t_next = min(t + h, t_end)
                    if t_end - t_next < 1e-3 * opts.macro_step:
                        t_next = t_end  # no sliver step at the end
                    if opts.scheme == "jacobi":
                        i_prev, t_prev, i_now, t = self._jacobi_step(mech, stepper, rl, t, t_next, i_now)
                    else:
                        # linear extrapolation needs two samples after the last current jump
                        # (the sample at a make/break instant is still the value before it)
                        slope = 0.0
                        if t_prev is not None and t_prev > t_jump and t > t_prev:
                            slope = (i_now - i_prev) / (t - t_prev)
                        t_new, current, jumped = self._mechanics_first_step(mech, stepper, rl, t, t_next,
                                                                            i_now, slope)
                        i_prev, t_prev, i_now, t = i_now, t, current, t_new
                        jump_since_prev = jumped
                        if jumped:
                            t_jump = t
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

    def _mechanics_first_step(self, mech, stepper, rl, t, t_next, i_now, slope):
        def current_at(s):
            return i_now + slope * (s - t)

        mu0 = self._mu(current_at(t))
        touching = mech.regime != FREE
        cp = mech.checkpoint() if self.scene.coupling.align_events else None
        tick = time.perf_counter()
        seg = mech.advance(t_next, mu=(mu0, self._mu(current_at(t_next))))
        switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
        opts = self.scene.coupling
        guard = 1e-9 * opts.macro_step
        probe = opts.macro_step ** 2 / opts.free_step
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
        # a step cut at a make/break ends at a current jump even when the re-run mechanics
        # stops a round-off short of the event (it is then found at the next step's start)
        return t_next, _coupling_current(step), bool(switching) or aligned

    def _jacobi_step(self, mech, stepper, rl, t, t_next, i_now):
        mu = self._mu(i_now)
        contact = mech.contact_now()
        g = float(np.sum(rl.force_conductance(contact[:, 2])))
        gap = float(max(0.0, -np.max(contact[:, 0])))
        tick = time.perf_counter()
        mech.advance(t_next, mu=mu)
        self.stats["mech_seconds"] += time.perf_counter() - tick
        self.mu_log.append((t, t_next, mu, mu))
        tick = time.perf_counter()
        step = stepper.advance(t_next, g, gap=gap if stepper.uses_gap else None)
        self.stats["circuit_seconds"] += time.perf_counter() - tick
        return i_now, t, _coupling_current(step), t_next

    @staticmethod
    def _conductance(seg, rl, touching_at_start):
        """G_F(F_n(t)) summed over both tips (they touch the same block), S, from the dense output.

        Each tip conducts only inside its contact intervals as the mechanics' events
        delimit them, the same instants ngspice gets as breakpoints: the interpolant may
        show a round-off penetration just before a located make.
        """
        intervals = _contact_intervals(seg, touching_at_start)
        force = rl.scalar_force_conductance
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
                    total += force(forces[i])
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


def _coupling_current(step) -> float:
    """A: the current that sets mu(I): the loop (load) current, a smooth state of the
    circuit (the metallic contact current also carries the parasitic capacitance's
    discharge spikes at each make); the contact current when the netlist has no load probe."""
    current = float(step.load_current)
    return current if np.isfinite(current) else float(step.contact_current)


def run(scene: Scene, *, progress: bool = False) -> CoupledResult:
    """Run any scene: mechanics only, circuit only (prescribed schedule) or coupled."""
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


