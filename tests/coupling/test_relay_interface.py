"""The coil-armature interface's energy audit (coupling.core.relay, relay.energy): the work the
mechanics received from the drive "armature.force" (coupling.core.exchange.received_work,
GainIntegral) against independent routes, the audit's whole chain, and the interface
residual (the magnet's work as the circuit sees it less the work the mechanics received)
falling under macro-step refinement at the coupling's order."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from coupling import builtin_scene, load_scene, run
from coupling.app.accuracy import refined_steps
from coupling.core.exchange import GAUSS_NODES, GAUSS_WEIGHTS, RECEIVED_NODES, CoilLink, GainIntegral, received_work
from coupling.laws.magnet import FluxTubeMagnet
from mech.armature import gain_at, gain_table

PLUNGER = Path(__file__).parents[2] / "examples" / "plunger_solenoid.toml"


def plunger_table() -> np.ndarray:
    """The plunger solenoid's gain table as the mechanics holds it (3, count): positions (m),
    gains lever h(g(q)) (N/Wb^2) and the PCHIP slopes mech computes."""
    from coupling.core.device import device

    scene = load_scene(PLUNGER)
    spec = device(scene.raw)
    assert isinstance(spec.magnet, FluxTubeMagnet)
    q, gain = CoilLink("coil", spec.magnet, spec.rest_gap, spec.lever).gain_table(scene.mech.armature.travel)
    return gain_table(q, gain)


def test_the_gain_integral_is_the_antiderivative_of_the_mechanics_gain_table():
    """G(q) against an adaptive quadrature of mech.armature.gain_at itself (the kernel's law),
    inside the table, between knots and on the tangent lines beyond its ends (a stop's
    penetration); quad meets 1e-10 of the integral, and the closed form is exact."""
    table = plunger_table()
    count = table.shape[1]
    G = GainIntegral(table)
    x0, x1 = table[0, 0], table[0, -1]
    knots = table[0].tolist()
    for q in (x0 - 2e-6, x0 + 1e-5, 0.37 * x1, 0.5 * (knots[-3] + knots[-2]), x1, x1 + 3e-6):
        lo, hi = min(x0, q), max(x0, q)
        inside = [k for k in knots if lo < k < hi]
        ref, err = quad(lambda s: gain_at(s, table, count), lo, hi, points=inside or None, limit=500,
                        epsabs=0.0, epsrel=1e-12)
        ref = ref if q >= x0 else -ref
        assert G(q) == pytest.approx(ref, rel=1e-10, abs=1e-12 * abs(G(x1))), q
    assert GainIntegral(np.zeros((3, 0)))(0.3) == 0.3  # no table: gain 1


def test_the_gain_integral_of_many_is_the_gain_integral_of_each_to_the_bit():
    """GainIntegral.many (a batch of samples at once) against __call__ one by one: the same
    doubles, before, inside, at the knots of and beyond the table, and without one."""
    table = plunger_table()
    G = GainIntegral(table)
    x = table[0]
    rng = np.random.default_rng(7)
    q = np.concatenate([x, rng.uniform(x[0] - 1e-4, x[-1] + 1e-4, 500), [x[0] - 1e-9, x[-1] + 1e-9]])
    assert G.many(q).tobytes() == np.array([G(float(v)) for v in q]).tobytes()
    assert GainIntegral(np.zeros((3, 0))).many(q).tobytes() == q.tobytes()
    one = GainIntegral(table[:, :1])
    assert one.many(q).tobytes() == np.array([one(float(v)) for v in q]).tobytes()


@pytest.mark.parametrize("batch, pieces", [(1, 1 << 16), (7, 1 << 16), (256, 5)])
def test_the_batched_samples_and_received_work_are_those_of_each_step(batch, pieces, monkeypatch):
    """CoilLink evaluates the armature's travel at the circuit's points and the received work
    for BATCH_STEPS macro steps at once (or fewer, once they hold BATCH_PIECES dense steps);
    against the same run sampled step by step (Segment.travel and received_work on each
    segment, the route of a segment ``inputs`` did not see): the same travel column and
    received work, to the bit."""
    from coupling.core import exchange

    scene = load_scene(PLUNGER).set("solver.t_end", 0.014)  # (the first arrival and bounces at the pole)
    monkeypatch.setattr(exchange, "BATCH_STEPS", batch)
    monkeypatch.setattr(exchange, "BATCH_PIECES", pieces)
    batched = run(scene)
    monkeypatch.setattr(CoilLink, "_segment_index", lambda self, seg: None)
    stepwise = run(scene)
    assert batched.armature_received == stepwise.armature_received != 0.0
    a, b = batched.waveform_columns["armature_position"], stepwise.waveform_columns["armature_position"]
    assert a.tobytes() == b.tobytes() and np.ptp(a) > 4e-3


def test_the_received_works_gauss_rule_is_exact_on_the_unit_interval_to_degree_seven():
    """received_work's 4-point rule on [0, 1] (mech.gauss's, mapped): the integral of t^k is
    1 / (k + 1) for k <= 2 RECEIVED_NODES - 1 to round-off, and not for the degree above."""
    assert len(GAUSS_NODES) == len(GAUSS_WEIGHTS) == RECEIVED_NODES and all(0.0 < t < 1.0 for t in GAUSS_NODES)
    for k in range(2 * RECEIVED_NODES):
        assert sum(w * t**k for t, w in zip(GAUSS_NODES, GAUSS_WEIGHTS)) == pytest.approx(1.0 / (k + 1), rel=0,
                                                                                          abs=1e-15)
    k = 2 * RECEIVED_NODES
    assert abs(sum(w * t**k for t, w in zip(GAUSS_NODES, GAUSS_WEIGHTS)) - 1.0 / (k + 1)) > 1e-6


def test_received_work_meets_the_direct_quadrature_of_force_times_speed():
    """By parts, received_work never multiplies by dq/dt; here against the direct integral of
    drive(t) gain(q(t)) dq/dt (quad, 1e-12) along a motion with a fast vibration on its
    travel (what the bar passes through the card: 40 kHz, 2 um) and a kink at a cut (a
    stop), the drive ramping down through the step. Cut into pieces of 10 us (2.5 per
    vibration period) the 4 Gauss points per piece meet it to 1e-9 (measured 2e-12); in
    pieces of 40 us, longer than the period, still to 1 % (measured 0.6 %) where the same
    points on F dq/dt itself are 36 % off (the vibration's speed, not its travel)."""
    table = plunger_table()
    count = table.shape[1]
    G = GainIntegral(table)
    x1 = table[0, -1]
    t0, t1, cut = 0.0, 2e-4, 1.3e-4
    w, amp = 2 * np.pi * 4e4, 2e-6

    def armature(t):
        base, speed = (0.2 * x1 + 1e4 * x1 * t * t, 2e4 * x1 * t) if t <= cut else (
            0.2 * x1 + 1e4 * x1 * cut * cut + 2e4 * x1 * cut * (t - cut) * 0.3, 2e4 * x1 * cut * 0.3)
        return base + amp * np.sin(w * t), speed + amp * w * np.cos(w * t)

    d0, d1 = 3e-3, 1e-3  # Wb^2

    def power(t):
        q, v = armature(t)
        return (d0 + (d1 - d0) * (t - t0) / (t1 - t0)) * gain_at(q, table, count) * v

    ref = sum(quad(power, a, b, limit=400, epsabs=0.0, epsrel=1e-12)[0] for a, b in ((t0, cut), (cut, t1)))

    def pieces(length):
        return sorted([cut, *np.arange(length, t1 - 1e-12, length).tolist()])

    assert received_work(armature, t0, t1, d0, d1, G, pieces(1e-5)) == pytest.approx(ref, rel=1e-9)
    coarse = pieces(4e-5)
    assert received_work(armature, t0, t1, d0, d1, G, coarse) == pytest.approx(ref, rel=1e-2)
    edges = [t0, *coarse, t1]
    direct = sum((b - a) * sum(wt * power(a + x * (b - a)) for x, wt in zip(GAUSS_NODES, GAUSS_WEIGHTS))
                 for a, b in zip(edges[:-1], edges[1:]))
    assert abs(direct - ref) > 0.1 * abs(ref)
    # a constant drive: exact along any path, d x (G(q1) - G(q0))
    exact = 2e-3 * (G(armature(t1)[0]) - G(armature(t0)[0]))
    assert received_work(armature, t0, t1, 2e-3, 2e-3, G) == pytest.approx(exact, rel=1e-14)


@pytest.fixture(scope="module")
def plunger():
    """The plunger solenoid run to its end (it arrives at 12.3 ms and bounces on the pole)."""
    return run(load_scene(PLUNGER))


def test_the_received_work_is_the_mechanics_own_input_work(plunger):
    """An armature alone has no input work but its drive's: the mechanics' work_in, its
    quadrature of F_drive v integrated by DOPRI5 with the state, is an independent route to
    the received work (which follows the dense position q). They differ by the mechanics'
    integration error (dq/dt against v inside its steps, at its rtol 1e-6) and by each seat's
    snap to the stop's surface (F times a penetration of at most 2 F / k): 1e-6 allowed,
    1.7e-8 measured."""
    e = plunger.relay["energy"]
    work_in = float(plunger.mechanics.energy_columns["work_in"][-1])
    assert e["armature_received"] == pytest.approx(work_in, rel=1e-6)


@pytest.mark.parametrize("name", ["plunger", "default"])
def test_the_chain_from_the_coil_to_the_mechanics_balance(name, plunger):
    """into_coil = copper + magnetic_change + armature_received + interface_residual + residual
    (the bookkeeping, to round-off), and armature_received = what the mechanics' own audit
    puts the drive's work into: kinetic, elastic, contact- and spring-stored energy changes,
    gravity's and every dissipation (the armature's stops, the bar's contact, friction,
    modes), within the mechanics' audit tolerance (solver.energy_tolerance x its energy
    scale). The default relay's drive works through the card on the bar."""
    res = plunger if name == "plunger" else run(builtin_scene("default"))
    e = res.relay["energy"]
    chain = e["copper"] + e["magnetic_change"] + e["armature_received"] + e["interface_residual"] + e["residual"]
    assert e["into_coil"] == pytest.approx(chain, rel=1e-12)
    assert e["interface_relative_residual"] == pytest.approx(abs(e["interface_residual"]) / e["into_coil"])
    en = res.mechanics.energy_columns
    stored = sum(float(en[k][-1] - en[k][0]) for k in ("kinetic", "elastic", "contact_stored", "spring_stored"))
    spent = sum(float(en[k][-1]) for k in ("potential", "normal_dissipation", "friction_dissipation",
                                           "modal_dissipation", "load_dissipation"))
    mech = res.mechanics
    allowed = mech.model.scene.solver.energy_tolerance * mech.energy_scale
    assert abs(e["armature_received"] - (stored + spent)) <= allowed
    assert e["armature_received"] > 100 * allowed  # (a work far above what the tolerance allows)


def test_the_interface_residual_falls_at_the_coupling_order():
    """The plunger's pull-in (t_end 12 ms, before its arrival at the pole), every step rule
    halved twice (run --check's refinement, coupling.app.accuracy.refined_steps): the
    interface residual comes from the drive's psi^2, extrapolated linearly over each macro
    step with the circuit's backward slope, against the circuit's psi^2: an error ~ psi^2''
    h^2 in the force, h^3 in a step's work, h^2 over the run: second order (measured 2.9
    and 3.3 per halving: 7.3e-6, 1.0e-6, 1.0e-7 J). Further halvings meet a floor of ~2e-8 J
    (docs/coupling.md, "The relay"), which these three levels stay 5x above; 1.7 allows for
    it."""
    scene = load_scene(PLUNGER).set("solver.t_end", 0.012)
    residuals = []
    for _ in range(3):
        residuals.append(abs(run(scene).relay["energy"]["interface_residual"]))
        scene = refined_steps(scene)[1]
    orders = np.log2(np.array(residuals[:-1]) / np.array(residuals[1:]))
    assert np.all(orders > 1.7), (residuals, orders)


def interface_warnings(result) -> list[str]:
    return [w for w in result.warnings if w.startswith("coil-armature interface")]


def test_a_coupling_too_coarse_for_the_coil_is_warned_the_default_is_not():
    """The default relay at its own steps: the interface residual 1.4e-5 of the energy into
    the coil, no line. At 10 times its coil's time-scale fraction (1.0, the largest allowed:
    psi^2 extrapolated over a whole time scale, an error ~x^2/2 of its change) the drive the
    mechanics got is off by 6.0e-3 of that energy (its operate time 10 us late, measured
    against a run at a quarter of every step rule; benchmarks/bench_relay_interface.py),
    above solver.energy_tolerance (1e-3): warned, and only warned."""
    scene = builtin_scene("default")
    assert not interface_warnings(run(scene))
    coarse = run(scene.set("coupling.coil_time_scale_fraction", 10 * scene.coupling.coil_time_scale_fraction))
    rel = coarse.relay["energy"]["interface_relative_residual"]
    assert rel > 3 * coarse.mechanics.model.scene.solver.energy_tolerance  # (measured 6.0 times it)
    lines = interface_warnings(coarse)
    assert len(lines) == 1 and f"{rel:.3g}" in lines[0] and "coil_time_scale_fraction" in lines[0]
    assert not any("interface" in p for p in coarse.problems)


def test_the_released_armatures_return_flight_keeps_the_gap_rule():
    """The default relay released without suppression: its flux collapses below the change
    rule's floor (psi^2 at 6e-4 of its rated value), so the flux's own rules let the steps
    grow to max_macro_step (1 ms), and the armature's whole return flight once fell into one
    step with its drive held at the step's start: the interface residual 7.5e-4 of the energy
    into the coil. The gap rule (the working gap changes by at most gap_change_fraction of
    itself in a step) holds while the armature moves whatever the flux does: every step of
    the flight is short of that, and the residual 1.4e-5 (measured; 2.1e-4 before psi^2's curvature entered the
    change rule, 2.3e-5 before its time scale's floor)."""
    scene = builtin_scene("default")
    steps = []
    observe = CoilLink.observe

    def watched(self, step, seg, policy):
        observe(self, step, seg, policy)
        q0, q1 = seg.armature(seg.t_start)[0], seg.armature(seg.t_end)[0]
        steps.append((seg.t_start, self.gap(q0), self.gap(q1)))

    CoilLink.observe = watched
    try:
        res = run(scene)
    finally:
        CoilLink.observe = observe
    off, rest_gap = scene.raw["coil"]["off_time"], scene.raw["magnet"]["rest_gap"]
    flight = [(g0, g1) for t, g0, g1 in steps if t > off and g0 < 0.99 * rest_gap and g1 > g0]
    assert len(flight) > 3
    # (a step's gap change against the gap at its start: the rule's time takes the speed and
    # acceleration over the step before, so the factor 2 leaves room for the flight's speed-up)
    assert all(g1 - g0 <= 2.0 * scene.coupling.gap_change_fraction * g0 for g0, g1 in flight), flight
    assert res.relay["energy"]["interface_relative_residual"] < 5e-4


def test_a_ringing_coils_stationary_points_keep_the_interface_within_tolerance():
    """The default relay released through its RC suppression: the coil's current rings with the
    capacitor, and at each extremum or zero of psi the slope of psi^2 vanishes. The change rule
    on the slope alone then let ~0.5 ms steps pass with the drive held while the ringing went
    on, and the interface missed 6.5e-2 of the energy into the coil (warned). With psi^2's
    curvature in the change rule the residual is 1.5e-4 (measured), below
    solver.energy_tolerance, and no line is printed."""
    scene = builtin_scene("default").set("coil.suppression", "rc")
    res = run(scene)
    assert res.relay["energy"]["interface_relative_residual"] < res.mechanics.model.scene.solver.energy_tolerance
    assert not interface_warnings(res)


def test_the_armatures_unseat_and_flight_converge_with_the_step_rules():
    """The default relay's pull-in: the armature leaves its rest stop where the drive (psi^2,
    extrapolated linearly over the macro step) reaches the spring's press, and flies until the
    card meets the blade. A long step over the unseat let the extrapolated drive, not the
    circuit's flux, decide it (6.4 us early against a run at a quarter of every step rule), and
    steps of hundreds of us after it drove the armature's slow start, where the net force is a
    small difference of two large ones, with that extrapolation (the card 3.7 us early). The
    steps now approach the unseat by halves, end a macro step past it and grow no faster than
    the time since (measured: unseat 0.06 us, card 0.07 us from the quarter-rule run)."""
    scene = builtin_scene("default").set("solver.t_end", 0.0042)
    quarter = refined_steps(refined_steps(scene)[1])[1]

    def times(result):
        ev = result.mechanics.events
        unseat = next(e["time"] for e in ev if e["kind"] == "armature_stop_end")
        card = next(e["time"] for e in ev if e["kind"] == "card_start")
        return unseat, card

    (u0, c0), (u2, c2) = times(run(scene)), times(run(quarter))
    assert abs(u0 - u2) < 1e-6 and abs(c0 - c2) < 1e-6, (u0 - u2, c0 - c2)


def test_a_table_magnet_drives_with_its_force_and_the_received_work_is_the_mechanics():
    """A table magnet (coupling.laws.magnet.table: F(psi, g) given, not separable) drives the
    mechanics with F itself, linear over each step, with no gain table (G(q) = q): the
    plunger's magnet tabulated, pulled in for 12 ms (no seat on the way). The received work
    meets the mechanics' own quadrature of F v (its work_in, the only input work) to 1e-9
    (measured 1e-15), and the interface residual stays small (3.1e-5 of the energy into the
    coil at the scene's own steps, against 6.5e-5 for the flux-tube magnet)."""
    import tomllib

    from coupling import scene_from_dict
    from coupling.laws.magnet.solenoid import plunger_solenoid
    from coupling.laws.magnet.table import tabulate

    with open(PLUNGER, "rb") as f:
        doc = tomllib.load(f)
    currents, gaps = np.linspace(0.0, 1.4, 29), np.geomspace(0.2e-3, 5.2e-3, 41)
    psi, force = tabulate(plunger_solenoid().magnet, currents, gaps)
    doc["magnet"] = {"model": "table", "rest_gap": 5e-3, "currents": currents.tolist(), "gaps": gaps.tolist(),
                     "flux_linkages": psi.tolist(), "forces": force.tolist(), "force_tolerance": 0.3}
    doc["coil"].pop("turns")
    doc["solver"]["t_end"] = 0.012
    res = run(scene_from_dict(doc))
    e = res.relay["energy"]
    assert res.mechanics.model.again.shape[1] == 0  # (no gain table: the drive is the force)
    assert e["armature_received"] == pytest.approx(float(res.mechanics.energy_columns["work_in"][-1]), rel=1e-9)
    assert e["interface_relative_residual"] < 1e-4
