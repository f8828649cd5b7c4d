"""A changeover (form C): circuit template "changeover" and netlists whose contacts are not in series.

Physics: the template's two throws each carry their own load (Kirchhoff against the closed
form with each contact's own resistance); the preloaded blade rests on its NC contact with
the spring's preload (the cantilever's closed form with the Hertz compression's share);
the transfer time (NC break to NO make) read from the mechanics' contact intervals agrees
with the instants the circuit's own conduction changes (each contact's conductance
channel: an independent route through the links and ngspice); a changeover whose NC is
never reached makes and breaks NO exactly as the single-contact run of the same scene; a
netlist written by hand with the template's topology gives the template's results.
Also the break-before-make verdict and the arc joining the throws (a pure function, on
intervals built to overlap), and bad input (one line naming the key).
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mech.contact_laws import hertz_stiffness

from coupling import load_scene, run
from coupling.core.arrangement import changeover_metrics, changeover_warnings
from coupling.core.scene import scene_from_dict

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "changeover_relay.toml"
RAW = tomllib.loads(EXAMPLE.read_text())


def _doc(**changes) -> dict:
    doc = copy.deepcopy(RAW)
    doc.update(changes)
    return doc


@pytest.fixture(scope="module")
def relay():
    """The example's relay."""
    return run(load_scene(EXAMPLE))


def test_the_run_is_sound_and_reports_a_form_c_switching(relay):
    assert relay.status == "ok", relay.message
    co = relay.summary["changeover"]
    assert co["normally_open"] == "NO" and co["normally_closed"] == "NC"
    assert co["break_before_make"] is True and co["overlaps"] == []
    assert len(co["operate"]) == 1 and len(co["release"]) == 1
    assert co["transfer_time"] == co["operate"][0]["transfer_time"] > 0.0
    assert set(relay.summary["per_contact"]) == {"NO", "NC"}
    # the unsuffixed results are NO's (the first contact): its instants, its columns (the
    # currents they read differ: the common's load current there, NO's own here)
    def instants(ops):
        return [(kind, op[kind]["time"]) for op in ops for kind in ("make", "break") if kind in op]

    assert instants(relay.operations) == instants(relay.contact_results["NO"]["operations"])
    assert instants(relay.operations) == [("make", co["operate"][0]["no_make"]), ("break", co["release"][0]["no_break"])]
    w = relay.waveform_columns
    assert np.array_equal(w["contact_voltage"], w["contact_voltage_NO"])


def test_each_throw_carries_its_own_load(relay):
    """Kirchhoff through each throw: at rest on NC (before the coil is switched on) the
    supply's current is V / (R_s + R_c,NC + R_NC) and NO carries no current; held on
    NO (1 ms before the coil is switched off) V / (R_s + R_c,NO + R_NO) with NC open. The
    contact resistances are the run's own columns; ngspice meets its RELTOL of 1e-4 on the
    branch currents, so 1e-3."""
    c = RAW["circuit"]
    w = relay.waveform_columns
    t = w["time"]
    for at, closed, load, other in ((RAW["coil"]["on_time"] - 0.1e-3, "NC", c["nc_load_resistance"], "NO"),
                                    (RAW["coil"]["off_time"] - 1e-3, "NO", c["load_resistance"], "NC")):
        k = int(np.searchsorted(t, at))
        loop = c["source_resistance"] + w[f"contact_resistance_{closed}"][k] + load
        assert w["load_current"][k] == pytest.approx(c["voltage"] / loop, rel=1e-3)
        assert w[f"contact_current_{closed}"][k] == pytest.approx(c["voltage"] / loop, rel=1e-3)
        assert abs(w[f"contact_current_{other}"][k]) < 1e-6 and w[f"contact_conductance_{other}"][k] == 0.0


def pressed_force(press: float, stiffness: float, k_hertz: float) -> float:
    """N: the NC contact's force at rest under a press ``press`` (N) up at the rivet, the
    blade lifted by the Hertz compression (R / k_hertz)^(2/3) against ``stiffness`` (N/m):
    R = press - stiffness (R / k_hertz)^(2/3), by fixed-point iteration (a contraction)."""
    r = press
    for _ in range(60):
        r = press - stiffness * (r / k_hertz) ** (2.0 / 3.0)
    return r


def test_the_preloaded_blade_rests_on_nc_with_the_spring_preload():
    """The example's relay before its coil is switched on, without gravity and friction (the
    closed form leaves out the blade's weight, and a friction force stuck at the contact
    point, 1.65 mm above the blade's axis, is statically indeterminate: with mu = 0.3 it took
    1.2 % of the preload; mu = 1e-9 bounds it to 1e-9 of the normal force): at rest NC
    carries the spring's preload less what the lift of the Hertz compression takes off,
    against the cantilever's 3 E I / a^3 at the rivet plus the spring's rate (the two silver
    rivet heads: their effective radius R1 R2 / (R1 + R2)). The correction is 1.5e-3 of the
    preload, the spring rate's share 1.4e-5. The preload, applied at the start, sets the
    blade ringing on NC with its 2 % modal damping: from 10 to 13 ms it still swings by
    1.2e-4 of the force (peak to peak; measured) about its equilibrium, so the force is
    averaged over that window (a dozen periods of the blade propped on NC, ~4 kHz: what a
    partial period leaves is below 2e-6); the modal basis's flexibility enters only through
    the correction (docs/mechanics.md section 11). Measured 7e-7; 3e-6 sees the spring."""
    bar, rivet, nc = RAW["bar"], RAW["rivet"][1], RAW["fixed"][1]
    spring = RAW["spring"][0]
    arm = RAW["mount"]["position"] - rivet["position"]
    k_blade = 3.0 * bar["youngs_modulus"] * bar["width"] * bar["thickness"] ** 3 / 12.0 / arm**3
    radius = rivet["radius"] * nc["radius"] / (rivet["radius"] + nc["radius"])
    k_hertz = hertz_stiffness(radius, rivet["youngs_modulus"], rivet["poisson_ratio"], nc["youngs_modulus"],
                              nc["poisson_ratio"])
    expected = pressed_force(spring["preload"], k_blade + spring["stiffness"], k_hertz)
    assert spring["preload"] - expected > 1e-3 * spring["preload"]  # (the correction is seen)
    doc = _doc(environment=dict(gravity=0.0))
    doc["tribology"]["mu"] = 1e-9
    doc["coil"].update(on_time=0.02, off_time=0.03)
    doc["solver"]["t_end"] = 0.013
    res = run(scene_from_dict(doc, base_dir=EXAMPLE.parent))
    assert res.status == "ok"
    w = res.waveform_columns
    t, force = w["time"], w["normal_force_NC"]
    sel = t >= 0.010
    mean = np.trapezoid(force[sel], t[sel]) / (t[sel][-1] - t[sel][0])
    assert mean == pytest.approx(expected, rel=3e-6)
    assert np.all(w["normal_force_NO"] == 0.0)
    assert res.changeover["operate"] == [] and res.contact_closed["NC"][1]


# s: how far apart two integrations of one macro step may locate the same make or break
RELOCATION = 1e-9
# S: a contact's conductance channel below this is open. At a break the channel gives its left
# limit (circuit.contact.left_limited), the Hertz-Holm conductance a femtosecond before the
# break, which is 0 or, where the penetration there is a round-off above 0, ~1e-19 S
# (measured); the circuit holds 1 nS across an open contact anyway
OPEN_BELOW = 1e-12


def _switching(t, g):
    """(s, s, closed after) of each change of a conductance column: the last point of one
    state, the first of the other, and whether the other is conducting."""
    on = g > OPEN_BELOW
    k = np.flatnonzero(on[1:] != on[:-1])
    return [(t[i], t[i + 1], bool(on[i + 1])) for i in k]


def test_the_transfer_time_is_where_the_circuits_conduction_changes(relay):
    """The summary's transfer times come from the mechanics' contact intervals; the circuit's
    own conductance channels (each contact fed by its own fixed contact's pair, through the
    links and ngspice) change state at the same instants. The macro steps end at each
    event and ngspice lands on it: at a break the first open point of the circuit is the
    mechanics' break, at a make the last open point is the make (G = 0 at zero
    penetration), each within the metrics' make guard (1e-9 of the run, 19 ps); so the
    transfer times agree to twice that, up to where the mechanics locate a switch: a step
    redone to end at a switch ends where the first run located it, and the redone run, on
    other steps, can locate it a little earlier (77 ps on the release, once the coil's gap
    rule changed the steps), so ngspice switches the contact at the step's end, that much
    after the reported break. The bound below allows 1 ns for that (the switch's location
    between two integrations of the same step; ending the redone step where it locates the
    switch instead moves every aligned scene's results at the integration tolerance)."""
    w = relay.waveform_columns
    t = w["time"]
    guard = 1e-9 * RAW["solver"]["t_end"]
    co = relay.changeover
    op, rel = co["operate"][0], co["release"][0]
    nc_changes = _switching(t, w["contact_conductance_NC"])
    no_changes = _switching(t, w["contact_conductance_NO"])
    nc_break = next(c for c in nc_changes if not c[2])
    no_make = next(c for c in no_changes if c[2])
    assert nc_break[1] == pytest.approx(op["nc_break"], abs=guard + RELOCATION)
    assert no_make[0] == pytest.approx(op["no_make"], abs=guard + RELOCATION)
    assert co["transfer_time"] == pytest.approx(no_make[0] - nc_break[1], abs=2 * guard + RELOCATION)
    no_break = next(c for c in no_changes if not c[2] and c[1] > rel["no_break"] - guard)
    nc_make = next(c for c in nc_changes if c[2] and c[0] > no_break[0])
    assert rel["transfer_time"] == pytest.approx(nc_make[0] - no_break[1], abs=2 * guard + RELOCATION)
    # the NC make's bounces: NC's own closures in its make episode, as the circuit sees them
    closures = [c for c in nc_changes if c[2] and c[0] >= nc_make[0]]
    assert rel["nc_bounces"] == len(closures) - 1


def test_a_changeover_whose_nc_is_never_reached_switches_no_as_one_contact():
    """NC 5 mm above the blade and no preload: the blade never reaches it, so the changeover
    (NO its own block, NC another) and the one-contact circuit of the same scene (template
    "resistive": one circuit contact fed by both pairs, NC's never touching) switch NO alike.
    Before the first make no current flows in either, so the mechanics is the same to the
    bit; after it the two circuits differ only by NC's open branch (its 100 pF stray
    capacitance in series with its load), which changes the circuit's points and so the
    macro steps at which the mechanics restarts its integration (mu is a constant here): the
    break, 3.6 ms after the make, agrees to the mechanics' rtol (1e-6) of its instant; the
    make agrees to 1e-12 s and the bounce counts exactly."""
    doc = _doc()
    del doc["spring"]
    doc["fixed"][1]["gap"] = 5e-3
    doc["solver"]["t_end"] = 0.011
    change = run(scene_from_dict(copy.deepcopy(doc), base_dir=EXAMPLE.parent))
    doc["circuit"]["template"] = "resistive"
    del doc["circuit"]["nc_load_resistance"]
    one = run(scene_from_dict(doc, base_dir=EXAMPLE.parent))
    assert change.status == one.status == "ok"
    assert change.changeover["operate"] == [] and change.contact_closed["NC"][0] == []
    a, b = change.contact_results["NO"]["operations"], one.operations
    assert len(a) == len(b) == 1
    assert a[0]["make"]["time"] == pytest.approx(b[0]["make"]["time"], abs=1e-12)
    assert a[0]["make"]["bounces"] == b[0]["make"]["bounces"] > 0
    assert a[0]["break"]["time"] == pytest.approx(b[0]["break"]["time"], rel=RAW["solver"]["rtol"])


NETLIST = """form C by hand
Vsource src 0 24
Rsource src common 0.05
Vload common contact_a 0
XCONTACT_NO contact_a throw_no
Ccontact_no contact_a throw_no 100p
Vload_no throw_no load_no 0
Rload_no load_no 0 10
XCONTACT_NC contact_a throw_nc
Ccontact_nc contact_a throw_nc 100p
Vload_nc throw_nc load_nc 0
Rload_nc load_nc 0 20
"""


def forced(circuit: dict) -> dict:
    """The example's blade driven by a force at the card's place instead of the coil (the
    arrangements work with a force-driven contact too): 1.5 N down from 1 ms to 4 ms (the
    blade leaves NC, crosses to NO and is held there), then released; no wiring inductance."""
    doc = _doc()
    for section in ("coil", "magnet", "armature"):
        del doc[section]
    doc["force"] = [dict(position=RAW["armature"]["card_position"], direction=[0.0, 0.0, -1.0],
                         time=[0.0, 1e-3, 1.2e-3, 4e-3, 4.2e-3], value=[0.0, 0.0, 1.5, 1.5, 0.0])]
    doc["solver"]["t_end"] = 7e-3
    doc["circuit"] = circuit
    return doc


def test_a_netlist_with_the_templates_topology_gives_its_results(tmp_path):
    """The template's circuit written by hand (XCONTACT_NO and XCONTACT_NC, each in its own
    branch from the common: not a chain, so independent contacts) against the template on
    the same force-driven blade: the same NC break, NO make, NO break and NC make, and the
    same bounces. The netlist lists its elements in another order, so ngspice's points may
    differ: the instants agree to the events' location (1e-9 s), the bounce counts exactly."""
    (tmp_path / "formc.cir").write_text(NETLIST)
    c = RAW["circuit"]
    arc = c["arc"]
    template = dict(template="changeover", voltage=24.0, source_resistance=0.05, wiring_resistance=0.0,
                    wiring_inductance=0.0, load_resistance=10.0, nc_load_resistance=20.0, arc=arc)
    results = [run(scene_from_dict(forced(circuit), base_dir=tmp_path)) for circuit in
               (template, dict(template="netlist", netlist="formc.cir", arc=arc))]
    for res in results:
        assert res.status == "ok", res.message
    a, b = (r.changeover for r in results)
    assert a["break_before_make"] and b["break_before_make"]
    for key in ("nc_break", "no_make", "no_bounces"):
        assert a["operate"][0][key] == pytest.approx(b["operate"][0][key], abs=1e-9), key
    for key in ("no_break", "nc_make", "nc_bounces"):
        assert a["release"][0][key] == pytest.approx(b["release"][0][key], abs=1e-9), key
    assert a["operate"][0]["no_bounces"] > 0 and a["release"][0]["nc_bounces"] > 0


# --- the verdicts, on intervals built to overlap ------------------------------------------

def _ops(breaks=(), makes=()):
    return [{"break": dict(time=t, arc_duration=0.0, arc_energy=0.0)} for t in breaks] + [
        {"make": dict(time=t, bounces=0, bounce_time=0.0, settled=True)} for t in makes]


def test_both_throws_closed_at_once_is_a_warning_naming_them():
    """NO makes at 2 ms while NC breaks only at 2.5 ms: 0.5 ms of both closed (make before
    break): break_before_make False, the overlap's interval and time, one warning line. Apart
    by 0.1 ms: break before make, transfer 0.1 ms, no warning."""
    no = dict(intervals=[(2e-3, 8e-3)], operations=_ops(makes=[2e-3]))
    nc = dict(intervals=[(0.0, 2.5e-3)], operations=_ops(breaks=[2.5e-3]))
    m = changeover_metrics(no, nc)
    assert m["break_before_make"] is False and m["overlaps"] == [[2e-3, 2.5e-3]]
    assert m["overlap_time"] == pytest.approx(0.5e-3, rel=1e-12)
    lines = changeover_warnings(m, ("NO", "NC"))
    assert len(lines) == 1 and "NO and NC are closed at once for 500 us" in lines[0] and "\n" not in lines[0]
    nc = dict(intervals=[(0.0, 1.9e-3)], operations=_ops(breaks=[1.9e-3]))
    m = changeover_metrics(no, nc)
    assert m["break_before_make"] is True and m["transfer_time"] == pytest.approx(0.1e-3, rel=1e-9)
    assert changeover_warnings(m, ("NO", "NC")) == []


def test_an_arc_still_burning_at_the_other_throws_make_is_a_warning():
    """NC breaks at 1.9 ms and its arc burns until 2.05 ms, past NO's make at 2 ms: the
    operate row says so and the warning names the arc; an arc out at 1.95 ms does not."""
    t = np.linspace(0.0, 4e-3, 4001)
    no = dict(intervals=[(2e-3, 4e-3)], operations=_ops(makes=[2e-3]), time=t, arc_current=np.zeros_like(t))
    for out, burning in ((2.05e-3, True), (1.95e-3, False)):
        arc = np.where((t >= 1.9e-3) & (t < out), 0.5, 0.0)
        nc = dict(intervals=[(0.0, 1.9e-3)], operations=_ops(breaks=[1.9e-3]), time=t, arc_current=arc)
        m = changeover_metrics(no, nc)
        assert m["operate"][0]["arc_at_make"] is burning and m["break_before_make"] is True
        lines = changeover_warnings(m, ("NO", "NC"))
        assert (len(lines) == 1 and "NC's arc still burns when NO makes at 2 ms" in lines[0]) is burning


def _make_before_break(**circuit) -> dict:
    """The bridge contactor's motion (examples/bridge_contactor.toml: both rivets closed at
    once, then pulled off together) wired as a changeover, NO and NC."""
    bridge = tomllib.loads((EXAMPLE.parent / "bridge_contactor.toml").read_text())
    names = iter(("NO", "NC"))
    for fixed in bridge["fixed"]:
        fixed["name"] = next(names)
    bridge["circuit"]["template"] = "changeover"
    bridge["circuit"].update(circuit)
    return bridge


def test_while_both_throws_are_closed_each_ones_mu_follows_its_own_current():
    """Make before break with NC's load three times NO's (12 and 36 ohm on 36 V): while both
    throws are closed NO carries ~3 A and NC ~1 A, the supply ~4 A. The friction coefficient
    each throw's contact points get must be mu(I) of that throw's own current (its load
    probe's), not of the supply's (the illustrative law: mu(4 A) is 0.335, mu(1 A) 0.273).
    The mechanics gets mu linear over each macro step from the extrapolated current, hence
    the 1e-4."""
    result = run(scene_from_dict(_make_before_break(nc_load_resistance=36.0), base_dir=EXAMPLE.parent))
    assert result.status == "ok", result.message
    w, mu = result.waveform_columns, result.scene.tribology.laws.mu
    overlaps = result.summary["changeover"]["overlaps"]
    assert overlaps
    for a, b in overlaps:
        inner = (w["time"] > a + 0.1 * (b - a)) & (w["time"] < b - 0.1 * (b - a))
        assert np.count_nonzero(inner) > 10
        shares = {}
        for name in ("NO", "NC"):
            own = np.array([mu(i) for i in w[f"load_current_{name}"][inner]])
            assert np.max(np.abs(w[f"mu_{name}"][inner] - own)) < 1e-4, name
            shares[name] = np.median(w[f"load_current_{name}"][inner] / w["load_current"][inner])
        # Kirchhoff: the throws' own currents are the supply's, shared as their loads say
        assert shares["NO"] + shares["NC"] == pytest.approx(1.0, abs=1e-3)
        assert shares["NO"] / shares["NC"] == pytest.approx(3.0, rel=0.02)
        supply = np.array([mu(i) for i in w["load_current"][inner]])
        assert np.min(np.abs(w["mu_NC"][inner] - supply)) > 0.05  # (what the supply's current gave)


def test_a_make_before_break_changeover_opening_both_throws_burns_both_arcs():
    """The bridge contactor's motion (``_make_before_break``) wired as a changeover: both
    throws open on the wiring's current and both arcs burn at once. The run goes to its end (it had aborted, "timestep
    too small" at the common: not the two arcs, but a 1e-19 s step where an arc's landing
    fell an ulp before a macro step's end), and wherever both burn each holds at least its
    burning voltage U_min (the arc model's dead zone: |v| = U_min + E_col d + R_arc |i|)."""
    bridge = _make_before_break()
    result = run(scene_from_dict(bridge, base_dir=EXAMPLE.parent))
    assert result.status == "ok", result.message
    assert result.summary["changeover"]["break_before_make"] is False
    w = result.waveform_columns
    u_min, i_min = bridge["circuit"]["arc"]["min_voltage"], bridge["circuit"]["arc"]["min_current"]
    both = (np.abs(w["arc_current_NO"]) >= i_min) & (np.abs(w["arc_current_NC"]) >= i_min)
    assert np.count_nonzero(both) > 10
    for name in ("NO", "NC"):
        assert np.all(np.abs(w[f"contact_voltage_{name}"][both]) >= u_min)


def test_an_inductive_throw_rings_the_open_contact_unless_a_diode_clamps_it():
    """NO's load made inductive (10 mH behind its 10 ohm), released: NO breaks with its arc,
    which carries the load's current while it burns. Without a flyback diode the arc takes
    at least the energy the inductor held at the break (1/2 L I^2; the supply feeds it too),
    and when it goes out (below I_min) the inductor's current rings the contact's 100 pF:
    the open contact sees I sqrt(L / C) = 4 kV at I_min (the ring's damping, zeta = R/2
    sqrt(C/L) = 5e-4, and the arc's current a little above I_min at its end: within 20 %).
    With the diode across the load the throw's inductor no longer drives the open contact:
    what it sees stays within the supply and the wiring's own ringing (1 uH with the
    contacts' capacitance at NC's bounces: ~36 V), a fiftieth of the ring. The coupled run's own route (the template's elements, ngspice, the arc
    model) against the closed forms of the throw's L-C ring."""
    inductance, capacitance = 10e-3, float(RAW["circuit"]["contact_capacitance"])
    i_min = 0.4  # A: the arc model's default I_min
    for flyback in (False, True):
        doc = _doc()
        doc["circuit"] = dict(doc["circuit"], load_inductance=inductance, nc_load_inductance=0.0, flyback=flyback)
        result = run(scene_from_dict(doc, base_dir=EXAMPLE.parent))
        assert result.status == "ok", result.message
        (brk,) = [op["break"] for op in result.contact_results["NO"]["operations"] if "break" in op]
        w = result.waveform_columns
        after = np.asarray(w["time"]) > brk["time"]
        peak = float(np.max(np.abs(w["contact_voltage_NO"][after])))
        ring = i_min * math.sqrt(inductance / capacitance)
        if flyback:
            assert peak < 0.02 * ring
        else:
            assert brk["arc_energy"] >= 0.5 * inductance * brk["current_at_break"] ** 2
            assert peak == pytest.approx(ring, rel=0.2)


def test_both_throws_inductive_with_flyback_diodes_run_through_makes_at_a_steps_edge():
    """The make-before-break changeover (``_make_before_break``) with a 10 mH load behind each
    throw and a flyback diode across each. Its makes fell a few femtoseconds from a macro
    step's edge: at 6 ms one 3e-15 s before a step's end (at 1.1 ms), at 1.5 ms the first
    make found again 5e-15 s after the step cut at it (0.43 ms); ngspice, left a sliver
    step after its restart there, failed its Newton iterations against the inductor's L/h
    and aborted ("timestep too small"). A make within a sliver of a step's edge now counts
    as at it (1000 times ngspice's smallest step). Both runs go to their ends, and with the
    diodes no open contact sees its throw's L-C ring: I_min sqrt(L / C) = 4 kV, of which
    the contacts see at most the supply, the arcs and the wiring's ringing (~75 V)."""
    inductance, capacitance = 10e-3, float(RAW["circuit"]["contact_capacitance"])
    ring = 0.4 * math.sqrt(inductance / capacitance)  # (I_min, the arc model's default)
    for t_end in (1.5e-3, None):
        doc = _make_before_break(nc_load_resistance=24.0, load_inductance=inductance, flyback=True)
        if t_end is not None:
            doc["solver"]["t_end"] = t_end
        result = run(scene_from_dict(doc, base_dir=EXAMPLE.parent))
        assert result.status == "ok", result.message
        assert result.operations and "make" in result.operations[0]
        w = result.waveform_columns
        for name in ("NO", "NC"):
            assert np.max(np.abs(w[f"contact_voltage_{name}"])) < 0.02 * ring, (t_end, name)


# --- bad input ------------------------------------------------------------------------------

@pytest.mark.parametrize("change, words", [
    (lambda d: d["fixed"][1].update(name="top"), 'circuit.template = "changeover" needs two electrical [[fixed]] '
                                                 'contacts named "NO"'),
    (lambda d: d["fixed"][1].update(electrical=False), "this scene's electrical fixed contacts: NO"),
    (lambda d: d["circuit"].update(nc_load_resistance=-1.0), "circuit.nc_load_resistance"),
    (lambda d: d["circuit"].update(flyback=True), "circuit.flyback is set but both throws are resistive"),
    (lambda d: d["circuit"].update(load_inductance=-1e-3), "circuit.load_inductance"),
    (lambda d: d["circuit"].update(nc_load_inductance="10 mH"), "circuit.nc_load_inductance"),
])
def test_bad_changeover_input_is_one_line_naming_the_key(change, words):
    doc = _doc()
    change(doc)
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, base_dir=EXAMPLE.parent)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_netlist_that_does_not_place_a_declared_contact_is_one_line(tmp_path):
    (tmp_path / "no_only.cir").write_text("n\nV1 src 0 24\nXCONTACT_NO src out\nR1 out 0 10\n")
    doc = forced(dict(template="netlist", netlist="no_only.cir"))
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, base_dir=tmp_path)
    line = str(err.value)
    assert "\n" not in line and "no circuit contact named 'NC'" in line


def test_the_example_scene_loads_as_a_changeover():
    scene = load_scene(EXAMPLE)
    c = scene.circuit.circuit
    assert scene.circuit.template == "changeover" and [b.name for b in c.contacts] == ["NO", "NC"]
    assert c.load_resistances == (RAW["circuit"]["load_resistance"], RAW["circuit"]["nc_load_resistance"])
    assert math.isfinite(scene.t_end)


def test_a_breaks_arc_ends_before_the_contacts_next_make():
    """NC's operations in a changeover: it breaks at 1 ms (its arc burns 0.2 ms) and makes
    again at 5 ms with a bounce whose opening arcs for 0.1 ms. The break's arc is the 0.2 ms
    after the break alone: the later make's bounce arcs are that operation's (they used to
    be counted into the break's arc, which looked to the end of the run). Samples every
    1 us, so the durations are exact sums of sample intervals."""
    from coupling.core.metrics import operations

    t = np.round(np.arange(0.0, 8e-3 + 5e-7, 1e-6), 12)
    arc = np.where(((t >= 1e-3) & (t < 1.2e-3)) | ((t >= 5.1e-3) & (t < 5.2e-3)), 0.5, 0.0)
    v = np.where(arc > 0.0, 12.0, 0.0)
    intervals = [(0.0, 1e-3), (5e-3, 5.1e-3), (5.2e-3, 8e-3)]
    ops = operations(intervals, 8e-3, t, v, arc, np.zeros_like(t), arc)
    assert [list(op) for op in ops] == [["break"], ["make"]]
    assert ops[0]["break"]["arc_duration"] == pytest.approx(0.2e-3, rel=1e-9)
    assert ops[0]["break"]["arc_energy"] == pytest.approx(12.0 * 0.5 * 0.2e-3, rel=1e-2)
    assert ops[1]["make"]["bounces"] == 1
