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

What crosses the seam, both ways, is owned by the links of coupling.core.exchange (a
circuit contact fed by the mechanics' contact points: conductance and gap into the
circuit's input channels, mu(I) into the mechanics' drives); the step rules are
coupling.core.policy's.

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

import numpy as np

from mech import ImpactSolver

from coupling.core.arrangement import LEGACY_POINTS, contact_feeds, is_series, switch_columns
from coupling.core.exchange import CONTACT_EVENTS, FLUX_FLOOR, CoilLink, ContactLink
from coupling.core.policy import StepPolicy
from coupling.core.results import CoupledResult, RunStatus
from coupling.core.scene import Scene

# the coil's flux extrapolated over at most this fraction of its time scale: its error, ~x^2/2
# of the change over x time scales, is then ~0.5 %, and the armature's force follows the
# flux squared (measured on the default relay: operate time within 0.3 % of a 10x finer run)
COIL_TIME_SCALE_FRACTION = 0.1
# rows of the mechanics' dense output before the contact is sampled at the circuit's points
# and the dense output released (4096 rows of a 45-state blade: 7 MB); each sampling costs
# ~60 us of calls, so sampling every macro step cost the default relay 4 % of its run
DENSE_FLUSH_ROWS = 4096

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


def _unseat_time(seg) -> float | None:
    """s: where the segment's armature first leaves a stop (a seated one: its unseat), or None."""
    return next((e["time"] for e in seg.events if e["kind"] == "armature_stop_end"), None)


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

    def __init__(self, scene: Scene, *, progress: bool = False, watch=None):
        """watch: None, or a callable given the mechanics solver (mech.ImpactSolver) after every
        macro step, when every record it holds is final (no later step returns before them):
        for a caller that consumes the history as the run goes on (``switchsim run`` writes
        history.csv's rows then). It must not raise or change the solver."""
        if scene.kind != "coupled":
            raise ValueError(f"CoSimulation needs a coupled scene (mechanics, [tribology] and [circuit]); "
                             f"this one is {scene.kind!r}: use coupling.run")
        self.scene = scene
        self.laws = scene.tribology.laws if scene.tribology is not None else None
        self.feedback = scene.tribology.feedback if scene.tribology is not None else False
        self.progress_enabled = progress
        self.watch = watch
        # (a make/break a sliver from a step's end or start counts as there)
        self.policy = StepPolicy.from_options(scene.coupling, scene.circuit.options.sliver(scene.t_end))
        self._links_unused = False
        self._reset()
        self._links_unused = True  # the first run takes these links (see _reset)
        # the coil's flux linkage is watched by the same rules, with a floor in Wb
        coil = self.coil
        self.coil_policy = self.policy.for_coil(scene.coupling, coil.floor) if coil is not None else None

    def _links(self) -> list:
        """The links between the scene's mechanics and circuit blocks: each circuit contact fed
        by its contact pairs (coupling.core.arrangement: one contact by the first two, which
        touch the same fixed contact; each of several by the [[fixed]] contact of its name),
        and the relay's coil driving its armature through the magnet."""
        circuit = self.scene.circuit.circuit
        links: list = []
        contacts = circuit.contacts
        if contacts and self.scene.mech.bar is not None:
            for block, points in zip(contacts, contact_feeds(self.scene.mech, contacts)):
                links.append(ContactLink(block.label, points, self.laws, self.scene.coupling.onset_penetration,
                                         self.feedback, load_column=None if block.load_probe is None
                                         else "load_current" + block.suffix))
        coils = getattr(circuit, "coils", ())
        if coils:
            from coupling.core.device import device

            from circuit.coil_drive import CoilDrive

            spec = device(self.scene.raw)
            drive = circuit if isinstance(circuit, CoilDrive) else getattr(circuit, "coil", None)
            switches = [t for t, _ in drive.switch_vertices()] if isinstance(drive, CoilDrive) else ()
            rated = float(spec.coil.get("voltage", 0.0)) / spec.resistance  # A (a netlist's coil: no voltage known)
            link = CoilLink(coils[0].label, spec.magnet, spec.rest_gap, spec.lever, switches)
            rated_psi = float(spec.magnet.flux_linkage(rated, spec.rest_gap)) if rated > 0 else 1e-6
            link.floor = FLUX_FLOOR * float(link.signal(rated_psi))
            # (a thousandth of the rated current: the unsaturated inductance; 1 mA for a netlist's coil)
            probe = 1e-3 * rated if rated > 0 else 1e-3
            link.time_constant = float(spec.magnet.flux_linkage(probe, spec.rest_gap)) / probe / spec.resistance
            link.flux_floor = FLUX_FLOOR * abs(rated_psi)
            links.append(link)
        return links

    @property
    def contact(self) -> ContactLink | None:
        """The first contact link: its loop current sets the step rules (contacts in series
        carry one loop current)."""
        return next((link for link in self.links if isinstance(link, ContactLink)), None)

    @property
    def contacts(self) -> list[ContactLink]:
        """Every contact link, in the circuit's order of its contacts."""
        return [link for link in self.links if isinstance(link, ContactLink)]

    @property
    def coil(self) -> CoilLink | None:
        return next((link for link in self.links if isinstance(link, CoilLink)), None)

    def _reset(self) -> None:
        """Fresh per-run state: ``run`` starts from it each time, so one CoSimulation (and one
        worker process) can run many times with the same results."""
        self.progress = Progress(self.scene.t_end, self.progress_enabled)
        # (the links __init__ built, no run having used them yet, are those a new build
        # gives: not built again for the first run, ~0.4 ms of reading the device and
        # inverting the magnet)
        if not self._links_unused:
            self.links = self._links()
        self._links_unused = False
        # the links' roles, read at every macro step
        self._contact_links = [link for link in self.links if isinstance(link, ContactLink)]
        self._coil_link = next((link for link in self.links if isinstance(link, CoilLink)), None)
        self._makes = self.scene.mech.bar is not None  # (contact points that can make and break)
        self.stats = dict(macro_steps=0, aligned_steps=0, contact_steps=0, mech_seconds=0.0,
                          circuit_seconds=0.0)
        if self._coil_link is not None:
            self.stats["approach_steps"] = 0  # macro steps redone to approach an armature's unseat
        self._contact_times: list[np.ndarray] = []  # the circuit's points sampled so far ...
        self._contacts: list[np.ndarray] = []  # ... and the mechanics' contact there (_sample_contact)
        self._pending: list[float] = []  # s: the circuit's points not sampled yet
        self._started = False

    @property
    def mu_log(self) -> list[tuple[float, float, float, float]]:
        """(t_start, t_end, mu at the start, mu at the end) of every macro step (N^gamma)."""
        return self.contact.mu_log

    def _mu(self, current: float) -> float:
        return self.contact.mu(current)

    def run(self) -> CoupledResult:
        from circuit import Stepper

        self._reset()
        sc = self.scene
        opts = sc.coupling
        policy = self.policy
        t_end = sc.t_end
        tick = time.perf_counter()
        mech = ImpactSolver(sc.mech, keep_dense=True, input_work=sc.duty is not None and sc.duty.repulsion)
        try:
            stepper = Stepper(sc.circuit.circuit, t_end, sc.circuit.options)
        except ValueError:  # the netlist is bad input (ngspice refused it): an input error, exit 2
            raise
        except Exception as err:  # ngspice failed to start the circuit: a failed run at t = 0
            partial = None
            try:
                partial = CoupledResult(scene=sc, mechanics=mech.result(), waveform_columns=None,
                                        stats=dict(self.stats), status=RunStatus.FAILED,
                                        message=f"{type(err).__name__}: {err}", stopped_at=0.0)
            except Exception:  # noqa: BLE001 - best effort
                pass
            raise CoupledRunError(f"coupled run failed at t = 0.0 s: {type(err).__name__}: {err}", partial) from err
        self.mech, self.stepper = mech, stepper
        contact, coil = self.contact, self._coil_link
        t = 0.0
        i_now = 0.0
        # a contact closed at t = 0 (a resting start): the circuit's operating point carries
        # a current not known yet, so the first step is a short one, as after a make
        jump_since_prev = contact is not None and bool(np.any(mech.contact_now()[:, 0] > 0.0))
        rate, scale = 0.0, math.inf  # dI/dt of the loop current at t (A/s) and its time scale (s)
        coil_switched = False  # the last step ended at a switching of the coil's drive
        quiet = 0.0  # s: the last step's length if the contact stayed closed and the current steady
        # (looked up once a run, not at each macro step: the same doubles)
        coil_policy = self.coil_policy
        coil_probe = coil_policy.probe if coil is not None else 0.0
        progress = self.progress
        last = t_end * (1.0 - 1e-14)
        try:
            with stepper, _deferred_interrupt() as interrupted:
                while t < last:
                    if interrupted():  # Ctrl-C, taken here between macro steps
                        raise KeyboardInterrupt
                    # a bar held at rest (mech: loads constant, contacts quiet) changes nothing
                    # the circuit sees until the hold ends: the long step, up to that end
                    resting = mech.at_rest and not jump_since_prev
                    touching = contact is not None and not resting and (
                        jump_since_prev or bool(np.any(mech.friction_engaged())) or bool(
                            np.any(mech.contact_now()[:, 0] > 0.0)))
                    t_next = policy.base_end(t, t_end, touching, previous=quiet)
                    if resting and mech.hold_until < t_next:
                        t_next = mech.hold_until
                    if opts.scheme == "jacobi":
                        i_now, t = self._jacobi_step(mech, stepper, t, t_next, i_now)
                    else:
                        slope = 0.0
                        if contact is not None:
                            # (no curvature, unlike the coil's: a touching contact's steps stay
                            # within 4 macro steps at the current's peaks, and the curvature of
                            # its last points spans each make's rise, stopping the growth for
                            # no accuracy: docs/coupling.md, "The contact current at its peaks")
                            t_next, slope = policy.plan(t, t_next, t_end, touching=touching,
                                                        jumped=jump_since_prev, current=i_now, rate=rate,
                                                        scale=scale)
                        if coil is not None:  # the flux linkage: its time-scale rule, always watched
                            # (right after the drive switched, the short step of a jump)
                            switched = coil_switched
                            t_coil, coil.slope = coil_policy.plan(t, t_next, t_end, touching=True, jumped=switched,
                                                                  current=coil.value, rate=coil.rate,
                                                                  scale=coil.scale, curvature=coil.curvature)
                            # the gap rule itself holds while the armature moves, steady flux
                            # or not: a released armature's return flight under a flux below
                            # the change rule's floor (6e-4 of the rated psi^2 on the default
                            # relay) took one 1 ms step, the drive held, and the coil-armature
                            # interface missed 7.5e-4 of the energy into the coil (2.1e-4 with the rule)
                            t_coil = min(t_coil, t + max(coil_probe, coil.gap_scale))
                            # and since the armature left a seat, steps no longer than that
                            # time (_approach_unseat)
                            t_coil = min(t_coil, t + max(coil_policy.macro_step, t - coil.left_seat))
                            switch = coil.next_switch(t)
                            t_next = min(t_next, t_coil, switch)
                            coil_switched = t_next == switch
                        t_new, current, jumped, (rate, scale) = self._mechanics_first_step(
                            mech, stepper, t, t_next, i_now, slope, scale)
                        quiet = t_new - t if (touching and not jumped and not jump_since_prev and policy.steady(
                            current, rate, 2.0 * (t_new - t))) else 0.0
                        i_now, t = current, t_new
                        jump_since_prev = jumped
                    self.stats["macro_steps"] += 1
                    self.stats["contact_steps"] += int(touching)
                    if progress.enabled:  # (no call a macro step for a run without progress reports)
                        progress(t)
                    if self.watch is not None:
                        self.watch(mech)
                self.stats["wall_time"] = time.perf_counter() - tick
                return self._result(mech, stepper)
        except KeyboardInterrupt as err:  # Ctrl-C: keep what was computed
            self.stats["wall_time"] = time.perf_counter() - tick
            t_stop = min(_reached(mech), t_end)
            partial = self._partial(mech, stepper, RunStatus.INTERRUPTED, "Ctrl-C", t_stop)
            raise RunInterrupted(f"interrupted at t = {t_stop!r} s", partial) from err
        except Exception as err:  # a failure keeps what was computed and says why
            self.stats["wall_time"] = time.perf_counter() - tick
            t_fail = _failure_time(err, t)
            partial = self._partial(mech, stepper, RunStatus.FAILED, f"{type(err).__name__}: {err}", t_fail)
            raise CoupledRunError(f"coupled run failed at t = {t_fail!r} s: {type(err).__name__}: {err}",
                                  partial) from err

    def _partial(self, mech, stepper, status: RunStatus, message: str, stopped_at: float) -> CoupledResult | None:
        """The result up to a failure or interruption (best effort: None if even that fails)."""
        try:
            return self._result(mech, stepper, status=status, message=message, stopped_at=stopped_at)
        except Exception:  # noqa: BLE001
            return None

    # --- schemes -----------------------------------------------------------------------

    def _mechanics_first_step(self, mech, stepper, t, t_next, i_now, slope, horizon=math.inf):
        policy = self.policy
        links, coil = self._contact_links, self._coil_link
        contact = links[0] if links else None

        def current_at(s):
            return policy.extrapolate(i_now, slope, s - t, horizon)

        mu0 = [link.mu(link.own(current_at(t))) for link in links] if links else ()
        arm = mech.armature_now() if coil is not None else None

        def drives(end: float) -> dict:
            """The mechanics' drives over [t, end]: each link's, extrapolated to the step's end."""
            out = {}
            for link, mu in zip(links, mu0):
                out.update(link.drives(mech, mu, link.mu(link.own(current_at(end))))
                           | link.repulsion(mech, self.scene.duty, lambda s, link=link: link.own(current_at(s)),
                                            t, end))
            if coil is not None:
                out.update(coil.drives(t, end, arm, self.coil_policy))
            return out

        touching = mech.friction_engaged()
        align = self.scene.coupling.align_events
        # (mechanics without a bar make and break nothing: no step is redone, none returned to)
        cp = mech.checkpoint() if align and self._makes else None
        tick = time.perf_counter()
        # In free flight no friction acts, so a step may end where it meets a make without
        # being redone there with the current extrapolated to that end: the mechanics stop
        # at it (instead of integrating the bounces beyond and returning to it).
        # (any() of the few rows as Python bools: ndarray.any's wrapper cost ~1 us a step)
        in_flight = align and not any(touching.tolist())
        seated = coil is not None and mech.armature_seated
        start = cp if cp is not None or not seated else mech.checkpoint()
        seg = mech.advance(t_next, drives(t_next), stop_at_switch=in_flight)
        if seated:
            t_next, seg = self._approach_unseat(mech, start, t, t_next, seg, drives, in_flight)
        # (most segments have no events: no list comprehension run for none)
        switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS] if seg.events else []
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
                seg = mech.advance(t_next, drives(t_next))
                self.stats["aligned_steps"] += int(end is not None)
                switching = [e["time"] for e in seg.events if e["kind"] in CONTACT_EVENTS]
                aligned = end is not None
        self.stats["mech_seconds"] += time.perf_counter() - tick
        for link, mu in zip(links, mu0):
            link.mu_log.append((t, t_next, mu, link.mu(link.own(current_at(t_next)))))
        # (a make/break within the policy's guard after the step's start is at the start, where
        # ngspice restarts: the mechanics find one a few femtoseconds after the step cut at
        # it, and a sliver step towards it failed against an inductive load)
        restart, breakpoints = False, []
        if switching:  # (most steps make or break nothing: no generator, set and sort for none)
            guard = policy.guard
            restart = any(t < s <= t + guard for s in switching)
            breakpoints = sorted({s for s in switching if t + guard < s <= t_next})
        inputs = {}
        for link in links:
            inputs.update(link.inputs(seg, touching, stepper.uses_gap))
        if coil is not None:
            inputs.update(coil.inputs(seg))
        # (ngspice's points inside a macro step of a coil: the coil's step rules)
        cap = math.inf if coil is None else self.coil_policy.circuit_step(
            t, t_next, coil.time_constant if coil.flux_changing(self.coil_policy.change_fraction) else math.inf)
        tick = time.perf_counter()
        step = stepper.advance(t_next, inputs=inputs, breakpoints=breakpoints, max_step=cap, restart=restart)
        self.stats["circuit_seconds"] += time.perf_counter() - tick
        self._sample_contact(mech, step)
        jumped = bool(switching) or aligned
        if coil is not None:
            coil.observe(step, seg, self.coil_policy)
            coil.receive(seg, mech)
        if contact is None:
            return t_next, 0.0, jumped, (0.0, math.inf)
        for link in links:
            link.observe(step, jumped)
        # a step cut at a make/break ends at a current jump even when the re-run mechanics
        # stops a round-off short of the event (it is then found at the next step's start)
        return t_next, contact.current(step), jumped, contact.tail.rate(policy.macro_step)

    def _approach_unseat(self, mech, start, t, t_next, seg, drives, in_flight):
        """(t_next, seg): a step that began with the armature seated, redone from the checkpoint
        ``start`` where the mechanics found it leaving its stop inside the step. Where the
        drive (psi^2, extrapolated linearly over the step) reaches the stop's press decides
        the unseat, and after it the armature's net force is a small difference of two large
        ones: a step of hundreds of us over it let the extrapolation, not the circuit's flux,
        decide both (the default relay's unseat 6.6 us early, the card's touch 3.8 us, against
        a run at a quarter of every step rule). So the steps approach the unseat by halves
        (``StepPolicy.approach_end``), end a macro step past it, and then grow no faster than
        the time since (``CoilLink.left_seat``, the rule in ``run``)."""
        leave = _unseat_time(seg)
        end = None if leave is None else self.coil_policy.approach_end(t, t_next, leave)
        if end is not None:
            t_next = end
            mech.restore(start)
            seg = mech.advance(t_next, drives(t_next), stop_at_switch=in_flight)
            self.stats["approach_steps"] += 1
            leave = _unseat_time(seg)
        if leave is not None:
            self._coil_link.left_seat = leave
        return t_next, seg

    def _jacobi_step(self, mech, stepper, t, t_next, i_now):
        if self.coil is not None or self.contact is None:
            raise ValueError("coupling.scheme = \"jacobi\" couples a contact alone; a scene with a coil runs "
                             "\"mechanics_first\"")
        inputs, drives = {}, {}
        state = mech.contact_now()
        for link in self.contacts:
            mu = link.mu(link.own(i_now))
            inputs.update(link.held_inputs(state, stepper.uses_gap))
            drives.update(link.drives(mech, mu, mu) | link.repulsion(mech, self.scene.duty,
                                                                     lambda s, link=link: link.own(i_now), t, t_next))
            link.mu_log.append((t, t_next, mu, mu))
        tick = time.perf_counter()
        mech.advance(t_next, drives)
        self.stats["mech_seconds"] += time.perf_counter() - tick
        tick = time.perf_counter()
        step = stepper.advance(t_next, inputs=inputs)
        self.stats["circuit_seconds"] += time.perf_counter() - tick
        self._sample_contact(mech, step)
        return self.contact.current(step), t_next

    def _sample_contact(self, mech, step) -> None:
        """Note the circuit's new points of a macro step (a step's reader starts at the
        previous step's last point); once the mechanics hold DENSE_FLUSH_ROWS rows of dense
        output, sample their contact (penetration, rate, normal force per tip) at the points
        noted, from that dense output, and release it: the mechanics keep a few macro steps'
        dense output, not the run's (docs/mechanics.md, "Memory")."""
        if not self._contact_links:
            # an armature alone: no contact is sampled, so no point is noted (a read of the
            # step's times and a slice a macro step); the coil link samples the armature
            # step by step, and the dense output is released all the same
            if mech.dense_rows >= DENSE_FLUSH_ROWS:
                mech.release_dense()
            return
        # (as floats: a step's few points appended to a list, an array made at the flush)
        times = step.floats("time")
        self._pending.extend(times[1:] if self._started else times)
        self._started = True
        if mech.dense_rows >= DENSE_FLUSH_ROWS:
            pending = np.array(self._pending, dtype=np.float64)
            # a point beyond the last record (ngspice may land a hair past the step's end)
            # lies in the next step's first record: sampled later, from that record
            k = int(np.searchsorted(pending, mech.last_record_time, side="right"))
            self._contact_times.append(pending[:k])
            self._contacts.append(mech.contact_series(pending[:k]))
            self._pending = pending[k:].tolist()
            mech.release_dense()


    # --- results -------------------------------------------------------------------------

    def _result(self, mech, stepper, status: RunStatus = RunStatus.OK, message: str = "",
                stopped_at: float | None = None) -> CoupledResult:
        waves = stepper.result_columns(probes=self.scene.circuit.probes)
        kept = waves["time"] <= mech.t + 1e-15
        waves = {name: values[kept] for name, values in waves.items()}
        circuit = self.scene.circuit.circuit
        # the whole bridge's, or a changeover's first contact's, beside each contact's own
        waves.update(switch_columns(waves, circuit))
        if self.contact is not None:
            self._contact_columns(mech, waves)
        if self.coil is not None:
            waves.update(self.coil.columns(waves))
        return CoupledResult(scene=self.scene, mechanics=mech.result(), waveform_columns=waves,
                             stats=dict(self.stats, circuit=stepper.stats), status=status, message=message,
                             stopped_at=stopped_at,
                             armature_received=self.coil.received if self.coil is not None else None)

    def _contact_columns(self, mech, waves: dict) -> None:
        """The contact's mechanics at the circuit's points: normal force and penetration per
        contact point, their sum, the gap the arc sees, mu."""
        # sampled as the run went (_sample_contact); the points since are sampled now
        done = np.concatenate(self._contact_times) if self._contact_times else np.zeros(0)
        if not np.array_equal(waves["time"][:len(done)], done):
            raise RuntimeError("the circuit's points differ from those sampled step by step")
        contact = np.concatenate(self._contacts + [mech.contact_series(waves["time"][len(done):])])
        for i in range(2):
            waves[f"normal_force_{i}"] = contact[:, i, 2]
            waves[f"penetration_{i}"] = np.maximum(contact[:, i, 0], 0.0)
        waves["normal_force"] = contact[:, 0, 2] + contact[:, 1, 2]
        # the arc's length as given to ngspice: the nearer tip's height, 0 while a tip touches
        waves["gap"] = np.where(waves["normal_force"] > 0.0, 0.0,
                                np.maximum(0.0, -np.max(contact[:, :, 0], axis=1)))
        waves["mu"] = self.contact.mu_series(waves["time"])
        own = len(self.contacts) > 1 or self.contacts[0].points != LEGACY_POINTS
        if own:  # each contact's own: its arc's gap, its points' mu and force
            for link in self.contacts:
                suffix = link.label[len("contact"):]
                points = list(link.points)
                touching = np.any(contact[:, points, 0] > 0.0, axis=1)
                waves["gap" + suffix] = np.where(touching, 0.0, np.maximum(0.0, -np.max(contact[:, points, 0], axis=1)))
                waves["mu" + suffix] = link.mu_series(waves["time"])
                waves["normal_force" + suffix] = np.sum(contact[:, points, 2], axis=1)
            if not is_series(self.scene.circuit.circuit):  # the unsuffixed ones: the first contact's
                suffix = self.contacts[0].label[len("contact"):]
                for name in ("gap", "mu", "normal_force"):
                    waves[name] = waves[name + suffix]


def run(scene: Scene, *, progress: bool = False, check: bool = False, watch=None) -> CoupledResult:
    """Run any scene: mechanics only, circuit only (prescribed schedule) or coupled, and judge
    the result (``CoupledResult.judge``: ok or unsound). check: also rerun it refined and
    write summary.accuracy (coupling/app/accuracy.py). A failed or interrupted run raises
    CoupledRunError or RunInterrupted with what it computed (status failed or interrupted).
    watch: a coupled run's ``CoSimulation`` watcher (its docstring); a run again with refined
    modes gives it the new run's solver. Not with check."""
    if not isinstance(scene, Scene):
        hint = f"load_scene({str(scene)!r})" if isinstance(scene, str) or hasattr(scene, "__fspath__") else \
            "load_scene('scene.toml'), default_scene() or scene_from_dict(document)"
        raise TypeError(f"run() takes a Scene, got {type(scene).__name__} {scene!r:.60}: {hint} first")
    for name, value in (("progress", progress), ("check", check)):
        if not isinstance(value, bool):
            raise TypeError(f"run({name}={value!r:.60}): pass True or False")
    if watch is not None and (check or not callable(watch)):
        raise ValueError(f"run(watch={watch!r:.60}): a callable, and only without check (the checked "
                         "route runs the scene several times)")
    if check:
        from coupling.app.accuracy import run_checked

        return run_checked(scene, progress=progress)
    if scene.kind == "circuit":
        return _run_schedule(scene).judge()
    result = _run_once(scene, progress, watch)
    refined = _refined_modes(scene, result)
    if refined is not None:
        # the run's own impacts were faster (shorter) than the estimate its "auto" count
        # was chosen for: run again with the count they ask for (once: a faster impact still
        # would only move the cutoff by v^(1/5))
        first = result.mechanics.model.mode_count
        modes = {"axial": refined.axial, "bending": refined.bending}
        result = _run_once(scene.set("bar.modes", modes), progress, watch)
        result.stats["modes_refined"] = {"first": first.reason, "rule": refined.reason, "modes": modes}
    return result.judge()


def _run_once(scene: Scene, progress: bool, watch=None) -> CoupledResult:
    if scene.kind == "coupled":
        return CoSimulation(scene, progress=progress, watch=watch).run()
    return _run_mechanics(scene)


def _refined_modes(scene: Scene, result: CoupledResult):
    """The mode count the finished run's own impacts ask for where "auto" chose fewer
    (mech.model.refined_mode_count), else None."""
    from mech.model import refined_mode_count

    mech = result.mechanics
    if mech is None or getattr(mech.model, "mode_count", None) is None or not len(mech.contact_columns["t_start"]):
        return None
    return refined_mode_count(scene.mech, mech.model.mode_count, mech.contact_columns["normal_speed_in"])


def _run_mechanics(scene: Scene) -> CoupledResult:
    from mech.solver import MechSolverError

    tick = time.perf_counter()
    solver = ImpactSolver(scene.mech)
    try:
        result = solver.run()
    except MechSolverError as err:
        partial = None
        if err.partial_result is not None:
            partial = CoupledResult(scene=scene, mechanics=err.partial_result, waveform_columns=None, stats={},
                                    status=RunStatus.FAILED, message=str(err), stopped_at=float(err.t))
        raise CoupledRunError(str(err), partial) from err
    except KeyboardInterrupt as err:
        try:
            partial = CoupledResult(scene=scene, mechanics=solver.result(), waveform_columns=None,
                                    stats=dict(wall_time=time.perf_counter() - tick), status=RunStatus.INTERRUPTED,
                                    message="Ctrl-C", stopped_at=_reached(solver))
        except Exception:  # noqa: BLE001 - best effort
            partial = None
        raise RunInterrupted(f"interrupted at t = {_reached(solver)!r} s", partial) from err
    return CoupledResult(scene=scene, mechanics=result, waveform_columns=None,
                         stats=dict(wall_time=time.perf_counter() - tick))


def _reached(solver) -> float:
    """s: how far an interrupted mechanics run got: its time, or its history's last row where
    the interrupt came between the recorder keeping a segment's rows and the solver taking
    its time (the kept history then reaches further; a fresh clone's Ctrl-C test met it)."""
    return max(float(solver.t), solver.last_record_time)


def _run_schedule(scene: Scene) -> CoupledResult:
    from circuit import run_transient

    tick = time.perf_counter()
    spec = scene.circuit
    try:
        waves = run_transient(spec.circuit, spec.schedule, scene.t_end, options=spec.options,
                              probes=spec.probes)
    except KeyboardInterrupt as err:  # the one-shot transient has no partial waveforms
        raise RunInterrupted("interrupted", CoupledResult(scene=scene, mechanics=None, waveform_columns=None, stats={},
                                                          status=RunStatus.INTERRUPTED, message="Ctrl-C")) from err
    except Exception as err:  # noqa: BLE001 - a failed circuit run still leaves its summary
        raise CoupledRunError(f"circuit run failed: {type(err).__name__}: {err}",
                              CoupledResult(scene=scene, mechanics=None, waveform_columns=None, stats={},
                                            status=RunStatus.FAILED, message=f"{type(err).__name__}: {err}")) from err
    return CoupledResult(scene=scene, mechanics=None, waveform_columns={k: waves[k].to_numpy() for k in waves.columns},
                         stats=dict(wall_time=time.perf_counter() - tick))
