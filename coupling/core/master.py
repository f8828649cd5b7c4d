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

import contextlib
import math
import signal
import sys
import threading
import time
from dataclasses import dataclass

import numpy as np

from mech import ImpactSolver

from coupling.core.results import CoupledResult
from coupling.core.scene import Scene

CONTACT_EVENTS = ("contact_start", "contact_end")


class CoupledRunError(RuntimeError):
    """A coupled run failed; ``partial`` holds the CoupledResult up to the failure."""

    def __init__(self, message: str, partial: CoupledResult | None):
        super().__init__(message)
        self.partial = partial


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) stopped a run; ``partial`` holds the CoupledResult up to then (status
    "interrupted at t = ... s") or None. A KeyboardInterrupt, so scripts stop as before."""

    def __init__(self, message: str, partial: CoupledResult | None):
        super().__init__(message)
        self.partial = partial


@contextlib.contextmanager
def _deferred_interrupt():
    """While ngspice drives callbacks into Python, a KeyboardInterrupt raised inside one is
    printed and swallowed by cffi, and the run goes on to "ok" (seen: Ctrl-C during a
    coupled run exited 0). Here SIGINT only sets a flag, which the run loop checks between
    macro steps and turns into a KeyboardInterrupt there. Yields the check. Outside the
    main thread (a Dask worker) signals cannot be handled: the check is always False."""
    if threading.current_thread() is not threading.main_thread() or (
            signal.getsignal(signal.SIGINT) is signal.SIG_IGN):  # (or SIGINT is ignored, as asked)
        yield lambda: False
        return
    hit = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: hit.append(signum))
    try:
        yield lambda: bool(hit)
    finally:
        signal.signal(signal.SIGINT, previous)


def _failure_time(err: BaseException, t_step: float) -> float:
    """s: where a run failed: the mechanics' own failure time if it failed (inside a macro
    step, later than the step's start), else the start of the macro step."""
    from mech.solver import MechSolverError

    return float(err.t) if isinstance(err, MechSolverError) else t_step


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
        self.progress_enabled = progress
        self.policy = StepPolicy.from_options(scene.coupling)
        self._reset()

    def _reset(self) -> None:
        """Fresh per-run state: ``run`` starts from it each time, so one CoSimulation (and one
        worker process) can run many times with the same results."""
        self.progress = Progress(self.scene.t_end, self.progress_enabled)
        self.mu_log: list[tuple[float, float, float, float]] = []
        self.stats = dict(macro_steps=0, aligned_steps=0, contact_steps=0, mech_seconds=0.0,
                          circuit_seconds=0.0)
        self._tail_t = np.zeros(0)
        self._tail_i = np.zeros(0)

    def _mu(self, current: float) -> float:
        return float(self.laws.mu(current)) if self.feedback else float(self.laws.mu(0.0))

    def run(self) -> CoupledResult:
        from circuit import Stepper

        self._reset()
        sc = self.scene
        opts = sc.coupling
        policy = self.policy
        t_end = sc.t_end
        rl = self.laws.resistance_law
        tick = time.perf_counter()
        mech = ImpactSolver(sc.mech, keep_dense=True)
        try:
            stepper = Stepper(sc.circuit.circuit, t_end, sc.circuit.options)
        except ValueError:  # the netlist is bad input (ngspice refused it): an input error, exit 2
            raise
        except Exception as err:  # ngspice failed to start the circuit: a failed run at t = 0
            partial = None
            try:
                partial = CoupledResult(scene=sc, mechanics=mech.result(), waveform_columns=None,
                                        stats=dict(self.stats), status=f"failed at t = 0.0 s: {err}")
            except Exception:  # noqa: BLE001 - best effort
                pass
            raise CoupledRunError(f"coupled run failed at t = 0.0 s: {type(err).__name__}: {err}", partial) from err
        self.mech, self.stepper = mech, stepper
        t = 0.0
        i_now = 0.0
        # a contact closed at t = 0 (a resting start): the circuit's operating point carries
        # a current not known yet, so the first step is a short one, as after a make
        jump_since_prev = bool(np.any(mech.contact_now()[:, 0] > 0.0))
        rate, scale = 0.0, math.inf  # dI/dt of the loop current at t (A/s) and its time scale (s)
        quiet = 0.0  # s: the last step's length if the contact stayed closed and the current steady
        try:
            with stepper, _deferred_interrupt() as interrupted:
                while t < t_end * (1.0 - 1e-14):
                    if interrupted():  # Ctrl-C, taken here between macro steps
                        raise KeyboardInterrupt
                    # a bar held at rest (mech: loads constant, contacts quiet) changes nothing
                    # the circuit sees until the hold ends: the long step, up to that end
                    resting = mech.at_rest and not jump_since_prev
                    touching = not resting and (jump_since_prev or bool(np.any(mech.friction_engaged())) or bool(
                        np.any(mech.contact_now()[:, 0] > 0.0)))
                    t_next = policy.base_end(t, t_end, touching, previous=quiet)
                    if resting and mech.hold_until < t_next:
                        t_next = mech.hold_until
                    if opts.scheme == "jacobi":
                        i_now, t = self._jacobi_step(mech, stepper, rl, t, t_next, i_now)
                    else:
                        t_next, slope = policy.plan(t, t_next, t_end, touching=touching, jumped=jump_since_prev,
                                                    current=i_now, rate=rate, scale=scale)
                        t_new, current, jumped, (rate, scale) = self._mechanics_first_step(
                            mech, stepper, rl, t, t_next, i_now, slope, scale)
                        quiet = t_new - t if (touching and not jumped and not jump_since_prev and policy.steady(
                            current, rate, 2.0 * (t_new - t))) else 0.0
                        i_now, t = current, t_new
                        jump_since_prev = jumped
                    self.stats["macro_steps"] += 1
                    self.stats["contact_steps"] += int(touching)
                    self.progress(t)
                self.stats["wall_time"] = time.perf_counter() - tick
                return self._result(mech, stepper, status="ok")
        except KeyboardInterrupt as err:  # Ctrl-C: keep what was computed
            self.stats["wall_time"] = time.perf_counter() - tick
            t_stop = min(float(mech.t), t_end)
            partial = self._partial(mech, stepper, f"interrupted at t = {t_stop!r} s")
            raise RunInterrupted(f"interrupted at t = {t_stop!r} s", partial) from err
        except Exception as err:  # a failure keeps what was computed and says why
            self.stats["wall_time"] = time.perf_counter() - tick
            t_fail = _failure_time(err, t)
            partial = self._partial(mech, stepper, f"failed at t = {t_fail!r} s: {err}")
            raise CoupledRunError(f"coupled run failed at t = {t_fail!r} s: {type(err).__name__}: {err}",
                                  partial) from err

    def _partial(self, mech, stepper, status: str) -> CoupledResult | None:
        """The result up to a failure or interruption (best effort: None if even that fails)."""
        try:
            return self._result(mech, stepper, status=status)
        except Exception:  # noqa: BLE001
            return None

    # --- schemes -----------------------------------------------------------------------

    def _mechanics_first_step(self, mech, stepper, rl, t, t_next, i_now, slope, horizon=math.inf):
        policy = self.policy

        def current_at(s):
            return policy.extrapolate(i_now, slope, s - t, horizon)

        mu0 = self._mu(current_at(t))
        touching = mech.friction_engaged()
        cp = mech.checkpoint() if self.scene.coupling.align_events else None
        tick = time.perf_counter()
        # In free flight no friction acts, so a step may end where it meets a make without
        # being redone there with the current extrapolated to that end: the mechanics stop
        # at it (instead of integrating the bounces beyond and returning to it).
        in_flight = cp is not None and not np.any(touching)
        seg = mech.advance(t_next, mu=(mu0, self._mu(current_at(t_next))), stop_at_switch=in_flight)
        switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
        aligned = False
        if cp is not None and switching:
            end = policy.aligned_end(t, t_next, switching[0])
            if end is not None and seg.t_end == end:  # stopped there already
                t_next = end
                self.stats["aligned_steps"] += 1
                aligned = True
            elif end is not None or seg.t_end < t_next:
                # (a switch the policy keeps inside a step, at its very start or end: the
                # stopped flight step is redone in full)
                t_next = t_next if end is None else end
                mech.restore(cp)
                seg = mech.advance(t_next, mu=(mu0, self._mu(current_at(t_next))))
                self.stats["aligned_steps"] += int(end is not None)
                switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
                aligned = end is not None
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
        return t_next, _coupling_current(step), jumped, end_rate(self._tail_t, self._tail_i, policy.macro_step)

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
        waves = stepper.result_columns(probes=self.scene.circuit.probes)
        kept = waves["time"] <= mech.t + 1e-15
        waves = {name: values[kept] for name, values in waves.items()}
        contact = mech.contact_series(waves["time"])
        for i in range(2):
            waves[f"normal_force_{i}"] = contact[:, i, 2]
            waves[f"penetration_{i}"] = np.maximum(contact[:, i, 0], 0.0)
        waves["normal_force"] = contact[:, 0, 2] + contact[:, 1, 2]
        # the arc's length as given to ngspice: the nearer tip's height, 0 while a tip touches
        waves["gap"] = np.where(waves["normal_force"] > 0.0, 0.0,
                                np.maximum(0.0, -np.max(contact[:, :, 0], axis=1)))
        waves["mu"] = self._mu_series(waves["time"])
        return CoupledResult(scene=self.scene, mechanics=mech.result(), waveform_columns=waves,
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
GROWTH_CAP = 4.0  # macro steps: the longest step in a closed contact with a steady current
TAIL_POINTS = 8  # circuit points kept across macro steps for the slope and its curvature


@dataclass(frozen=True)
class StepPolicy:
    """The co-simulation's step rules, pure (no solver, no ngspice): where a macro step ends
    and how the loop current is extrapolated over it. Times in s, currents in A.

    - ``base_end``: a macro step while a tip touches (or right after a jump), the longer
      ``free_step`` while both are free; no sliver step (< 1e-3 H) left before t_end. While
      a contact stays closed and the current steady (``previous``: the last step's length
      when it made or broke nothing and the current moved less than the change rule of
      ``plan`` allows), the step doubles per step up to ``growth_cap`` macro steps: the
      mechanics find a make or break inside a long step and the step is cut there
      (``aligned_end``), ngspice reads the mechanics' conductance at its own points, and
      every step stays proportional to H, so the coupling keeps its order. A settled
      contact under a slow force (the default relay after its bounces) then takes a
      quarter of the macro steps.
    - ``plan`` (scheme mechanics_first): right after a make/break the current has jumped
      and is known only at the jump, so a short probe step H^2 / probe_time with the current
      held (zero-order hold: O(H^2) error, still second order); otherwise a Taylor step
      with the circuit's own slope, no longer than time_scale_fraction of the current's
      time scale where the step would change it by more than change_fraction of
      (|I| + current_floor).
    - ``extrapolate``: I(t + s) = I + slope min(s, horizon): linear, but not beyond the
      current's time scale (an exponential approach extrapolated over its time constant
      lands on its asymptote).
    - ``aligned_end``: where a step that saw a make/break at t_e is cut: at t_e inside it,
      at t + probe when t_e is at its start, else not cut (None).
    """

    macro_step: float
    free_step: float
    probe_time: float = PROBE_TIME
    time_scale_fraction: float = TIME_SCALE_FRACTION
    change_fraction: float = CHANGE_FRACTION
    current_floor: float = CURRENT_FLOOR
    growth_cap: float = GROWTH_CAP

    def __post_init__(self):
        for name in ("macro_step", "free_step", "probe_time", "time_scale_fraction", "current_floor", "growth_cap"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"StepPolicy.{name} = {value!r}: must be a finite number > 0")
        if self.free_step < self.macro_step:
            raise ValueError(f"StepPolicy.free_step = {self.free_step!r}: must be >= macro_step = {self.macro_step!r}")
        if not (math.isfinite(self.change_fraction) and self.change_fraction >= 0):
            raise ValueError(f"StepPolicy.change_fraction = {self.change_fraction!r}: must be a finite number >= 0")

    @classmethod
    def from_options(cls, options) -> "StepPolicy":
        """From a scene's CouplingOptions (macro_step, free_step)."""
        return cls(macro_step=float(options.macro_step), free_step=float(options.free_step))

    @property
    def probe(self) -> float:
        """s: the short step that fetches the current right after a make/break (H^2 / probe_time)."""
        return self.macro_step ** 2 / self.probe_time

    def base_end(self, t: float, t_end: float, touching: bool, previous: float = 0.0) -> float:
        """s: the end of the next step before the current is looked at; ``previous``: the
        length (s) of the step before when the contact stayed closed over it with a steady
        current (0: it did not, see ``steady``)."""
        step = self.free_step
        if touching:
            step = self.macro_step
            if previous > 0.0:
                step = min(self.free_step, self.growth_cap * self.macro_step, max(self.macro_step, 2.0 * previous))
        t_next = min(t + step, t_end)
        if t_end - t_next < 1e-3 * self.macro_step:
            t_next = t_end  # no sliver step at the end
        return t_next

    def plan(self, t: float, t_next: float, t_end: float, *, touching: bool, jumped: bool, current: float,
             rate: float, scale: float) -> tuple[float, float]:
        """(end of the step in s, slope in A/s to extrapolate the current with) for a step from t
        proposed to end at t_next, given the current (A), its rate dI/dt (A/s) and time scale (s)."""
        if jumped:
            return min(t + self.probe, t_end), 0.0
        if touching and not self.steady(current, rate, t_next - t):
            t_next = min(t_next, t + max(self.probe, self.time_scale_fraction * scale))
        return t_next, rate

    def steady(self, current: float, rate: float, span: float) -> bool:
        """True if the current (A) at rate dI/dt (A/s) moves by no more than the change rule
        of ``plan`` allows over ``span`` (s)."""
        return abs(rate) * span <= self.change_fraction * (abs(current) + self.current_floor)

    @staticmethod
    def extrapolate(current: float, slope: float, elapsed: float, horizon: float = math.inf) -> float:
        """A: the current ``elapsed`` s after a point where it is ``current`` with ``slope``."""
        return current + slope * min(elapsed, horizon)

    def aligned_end(self, t: float, t_next: float, event: float) -> float | None:
        """s: where to end a step [t, t_next] in which the first make/break is at ``event``; None: keep it."""
        guard = 1e-9 * self.macro_step
        if t + guard < event < t_next - guard:
            return event
        if event <= t + guard and t_next - t > self.probe * (1.0 + 1e-9):
            return t + self.probe  # it happened at the step start: only a short step past it
        return None


def end_rate(t: np.ndarray, i: np.ndarray, span: float) -> tuple[float, float]:
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
    check: also rerun it refined and write summary.accuracy (coupling/app/accuracy.py)."""
    if not isinstance(scene, Scene):
        hint = f"load_scene({str(scene)!r})" if isinstance(scene, str) or hasattr(scene, "__fspath__") else \
            "load_scene('scene.toml'), default_scene() or scene_from_dict(document)"
        raise TypeError(f"run() takes a Scene, got {type(scene).__name__} {scene!r:.60}: {hint} first")
    for name, value in (("progress", progress), ("check", check)):
        if not isinstance(value, bool):
            raise TypeError(f"run({name}={value!r:.60}): pass True or False")
    if check:
        from coupling.app.accuracy import run_checked

        return run_checked(scene, progress=progress)
    if scene.kind == "coupled":
        return CoSimulation(scene, progress=progress).run()
    if scene.kind == "mechanics":
        from mech.solver import MechSolverError

        tick = time.perf_counter()
        solver = ImpactSolver(scene.mech)
        try:
            result = solver.run()
        except MechSolverError as err:
            partial = None
            if err.partial_result is not None:
                partial = CoupledResult(scene=scene, mechanics=err.partial_result, waveform_columns=None,
                                        stats={}, status=f"failed at t = {float(err.t)!r} s: {err}")
            raise CoupledRunError(str(err), partial) from err
        except KeyboardInterrupt as err:
            status = f"interrupted at t = {float(solver.t)!r} s"
            try:
                partial = CoupledResult(scene=scene, mechanics=solver.result(), waveform_columns=None,
                                        stats=dict(wall_time=time.perf_counter() - tick), status=status)
            except Exception:  # noqa: BLE001 - best effort
                partial = None
            raise RunInterrupted(status, partial) from err
        return CoupledResult(scene=scene, mechanics=result, waveform_columns=None,
                             stats=dict(wall_time=time.perf_counter() - tick), status="ok")
    from circuit import run_transient

    tick = time.perf_counter()
    spec = scene.circuit
    try:
        waves = run_transient(spec.circuit, spec.schedule, scene.t_end, options=spec.options,
                              probes=spec.probes)
    except KeyboardInterrupt as err:  # the one-shot transient has no partial waveforms
        raise RunInterrupted("interrupted", CoupledResult(scene=scene, mechanics=None, waveform_columns=None,
                                                          stats={}, status="interrupted")) from err
    except Exception as err:  # noqa: BLE001 - a failed circuit run still leaves its summary
        raise CoupledRunError(f"circuit run failed: {type(err).__name__}: {err}",
                              CoupledResult(scene=scene, mechanics=None, waveform_columns=None, stats={},
                                            status=f"failed: {err}")) from err
    return CoupledResult(scene=scene, mechanics=None, waveform_columns={k: waves[k].to_numpy() for k in waves.columns},
                         stats=dict(wall_time=time.perf_counter() - tick), status="ok")


