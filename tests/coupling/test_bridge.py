"""A double-break bridge (circuit.template = "bridge"): a free steel bar on two rivets over two
fixed contacts "a" and "b", the circuit's two contacts in series in one loop.

Checks: the loop current flows only while both points touch (against the mechanics' own
contact intervals) and the run counts the bridge closed exactly then; at a break the two
arcs in series follow the closed form with twice the arc voltage and go out at a smaller
gap than one contact of the same gap in the same circuit; a netlist naming each contact is
the same bridge; a scene whose circuit and fixed contacts do not match is refused in one
line. SI units.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from coupling import run
from coupling.core.diagnostics import pairs_warning
from coupling.core.metrics import merge_intervals
from coupling.core.scene import scene_from_dict

V_S, R_S, R_L = 36.0, 0.05, 12.0
U_MIN, I_MIN, R_ARC, E_COL = 12.0, 0.4, 0.05, 5e3  # the arc model (E_COL: 5 V/mm, illustrative)
ARC = dict(min_voltage=U_MIN, min_current=I_MIN, resistance=R_ARC, column_gradient=E_COL)


def bridge_doc(**circuit) -> dict:
    """The bar (30 x 4 x 1 mm steel) rests on both contacts, is pressed onto them by 2 N at its
    middle, then pulled off by 3 N at 2 ms (both contacts part together and fly apart)."""
    doc = {
        "bar": dict(length=0.03, width=0.004, thickness=0.001, tip_radius=0.0021, youngs_modulus=210e9,
                    poisson_ratio=0.3, density=7850.0, modes={"axial": 1, "bending": 4}, modal_damping=0.05),
        "rivet": [dict(position=0.003, offset=-0.0005, radius=0.001, name="left"),
                  dict(position=0.027, offset=-0.0005, radius=0.001, name="right")],
        "fixed": [dict(point="left", name="a", gap=0.0), dict(point="right", name="b", gap=0.0)],
        "force": [dict(position=0.015, direction=[0.0, 0.0, -1.0], time=[0.0, 2e-4, 2e-3, 2.05e-3],
                       value=[0.0, 2.0, 2.0, -3.0])],
        "initial": dict(height=0.0, angle_deg=0.0, velocity=[0.0, 0.0, 0.0]),
        "contact": dict(reference_speed=0.1, restitution=0.5),
        "friction": dict(model="regularized"),
        "solver": dict(t_end=5e-3),
        # mu held at mu(0): the mechanics are the same whatever the circuit (the arc test
        # compares two circuits on one motion)
        "tribology": dict(source="illustrative", feedback=False),
        "circuit": dict(template="bridge", voltage=V_S, source_resistance=R_S, wiring_resistance=0.0,
                        wiring_inductance=1e-6, load_resistance=R_L, contact_capacitance=100e-12, arc=ARC),
        "coupling": dict(macro_step=5e-6, max_macro_step=1e-3),
    }
    doc["circuit"].update(circuit)
    return doc


def dropped_doc() -> dict:
    """The bar dropped tilted (0.3 deg) from 0.2 mm onto the contacts at 0.3 m/s: the two
    points make at different instants and bounce apart from each other. No arc, no stray
    capacitance and no wiring inductance: the loop carries nothing but the metallic current
    and the 1e-12 S leakage of the open contacts."""
    doc = bridge_doc(arc=False, contact_capacitance=0.0, wiring_inductance=0.0)
    doc["fixed"] = [dict(point="left", name="a", height=0.0), dict(point="right", name="b", height=0.0)]
    doc["initial"] = dict(height=2e-4, angle_deg=0.3, velocity=[0.0, 0.0, -0.3])
    doc["force"][0].update(time=[0.0, 1e-3], value=[0.0, 1.0])
    doc["solver"]["t_end"] = 3e-3
    return doc


def touching(res, tip: int) -> list[tuple[float, float]]:
    """The mechanics' own contact intervals of contact pair ``tip`` (s)."""
    c = res.mechanics.contact_columns
    mine = c["tip"] == tip
    return merge_intervals(zip(c["t_start"][mine], c["t_end"][mine]))


def inside(t: np.ndarray, intervals, margin: float) -> np.ndarray:
    """Samples at least ``margin`` (s) inside one of ``intervals``."""
    out = np.zeros(len(t), dtype=bool)
    for a, b in intervals:
        out |= (t > a + margin) & (t < b - margin)
    return out


@pytest.fixture(scope="module")
def dropped():
    return run(scene_from_dict(dropped_doc()))


def test_the_loop_current_flows_only_while_both_points_touch(dropped):
    """Where one point touches and the other does not, the loop is open: its current is the
    open contact's leakage (36 V x 1e-12 S = 3.6e-11 A), taken < 1e-9 A. Where both touch it is
    Ohm's law of the loop, V_s / (R_s + R_L + R_a + R_b) with each contact's own resistance:
    to 2e-4 (ngspice's RELTOL 1e-4 on the branch current and on each contact's effective
    conductance node, measured 9.3e-5), and 0 to the leakage where a point touches without
    force (a contact's last instants, its damping force spent: no conductance). The run
    counts the bridge closed exactly while both touch (the two points' intervals
    intersected)."""
    res = dropped
    w = res.waveform_columns
    t, i = w["time"], w["load_current"]
    a, b = touching(res, 0), touching(res, 1)
    both = [(max(p[0], q[0]), min(p[1], q[1])) for p in a for q in b if max(p[0], q[0]) < min(p[1], q[1])]
    in_a, in_b = inside(t, a, 1e-9), inside(t, b, 1e-9)
    one = (in_a ^ in_b) & ~(inside(t, a, -1e-9) & inside(t, b, -1e-9))
    assert one.sum() > 20 and len(a) > 1 and len(b) > 1  # (bounces: one point on while the other is off)
    assert np.max(np.abs(i[one])) < 1e-9
    closed = inside(t, both, 1e-9)
    assert closed.sum() > 20
    ohm = V_S / (R_S + R_L + w["contact_resistance_a"][closed] + w["contact_resistance_b"][closed])
    np.testing.assert_allclose(i[closed], ohm, rtol=2e-4, atol=1e-9)
    assert res.closed_intervals == sorted(both)
    assert res.summary["bounce"]["bounces"] == len(both) - 1


def test_the_whole_bridge_columns_are_its_contacts_in_series(dropped):
    """contact_voltage is the voltage across the whole bridge: open, the supply less the
    leakage current's drop stands across it (to 1e-6 V, ngspice's VNTOL on the node
    potentials; measured 2e-9 V); closed, the loop current through both contacts'
    resistances, I (R_a + R_b), to 2e-4 (RELTOL on the current and on each conductance node)."""
    w = dropped.waveform_columns
    v, i = w["contact_voltage"], w["load_current"]
    opened = w["contact_conductance_a"] == 0.0
    assert opened.sum() > 20
    np.testing.assert_allclose(v[opened], V_S - (R_S + R_L) * i[opened], rtol=0, atol=1e-6)
    # (conducting: both above circuit.probes.CLOSED_CONDUCTANCE, where a contact's voltage is
    # its own current over its conductance; the loop's one current runs through both: KCL)
    closed = (w["contact_conductance_a"] > 1e-6) & (w["contact_conductance_b"] > 1e-6)
    assert closed.sum() > 20
    np.testing.assert_allclose(v[closed], i[closed] * (w["contact_resistance_a"] + w["contact_resistance_b"])[closed],
                               rtol=2e-4)
    np.testing.assert_allclose(v[closed], i[closed] * w["contact_resistance"][closed], rtol=2e-4)  # (the bridge's)
    assert np.all(w["contact_conductance"][opened] == 0.0)


@pytest.fixture(scope="module")
def breaks():
    """The same motion switching the same circuit through the bridge (two arcs in series) and
    through one contact (the resistive template: one arc, the nearer point's gap)."""
    bridge = run(scene_from_dict(bridge_doc()))
    one = run(scene_from_dict(bridge_doc(template="resistive")))
    return bridge, one


def burning(w, names) -> np.ndarray:
    """Samples where every named contact's arc burns across an open gap (a parting contact's
    last instants, touching without force, carry an arc at zero gap: the molten bridge)."""
    return np.all([(np.abs(w[f"arc_current{n}"]) > 1.02 * I_MIN) & (w[f"gap{n}"] > 0.0) for n in names], axis=0)


def test_two_arcs_in_series_burn_at_twice_the_arc_voltage(breaks):
    """While both arcs burn, the loop is V_s = (R_s + R_L + 2 R_arc) I + 2 U_min + E_col (d_a +
    d_b): the current follows it with each contact's own gap from the mechanics, and one
    contact's arc in the same circuit follows V_s = (R_s + R_L + R_arc) I + U_min + E_col d.
    Tolerance 2e-4 A: ngspice's RELTOL 1e-4 on a current of about 1 A (measured 1.5e-4 A on
    the bridge, 1.7e-4 A on one contact; the 100 pF across each gap takes only C E_col dd/dt,
    ~1e-6 A). The bridge's voltage is both arcs' to 2e-3 V (measured 1.1e-7 V)."""
    bridge, one = breaks
    w = bridge.waveform_columns
    on = burning(w, ("_a", "_b")) & (w["time"] > 2e-3)
    assert on.sum() > 10
    expected = (V_S - 2 * U_MIN - E_COL * (w["gap_a"][on] + w["gap_b"][on])) / (R_S + R_L + 2 * R_ARC)
    np.testing.assert_allclose(w["load_current"][on], expected, rtol=0, atol=2e-4)
    # across the bridge: both arcs' voltages
    arc_v = 2 * U_MIN + E_COL * (w["gap_a"][on] + w["gap_b"][on]) + 2 * R_ARC * np.abs(w["load_current"][on])
    np.testing.assert_allclose(w["contact_voltage"][on], arc_v, rtol=0, atol=2e-3)
    u = one.waveform_columns
    on1 = burning(u, ("",)) & (u["time"] > 2e-3)
    assert on1.sum() > 10
    expected1 = (V_S - U_MIN - E_COL * u["gap"][on1]) / (R_S + R_L + R_ARC)
    np.testing.assert_allclose(u["load_current"][on1], expected1, rtol=0, atol=2e-4)


def test_two_arcs_go_out_where_the_closed_form_says_and_sooner_than_one(breaks):
    """The arcs go out where the loop current falls to I_min: for the bridge at a summed gap
    d_a + d_b = (V_s - 2 U_min - I_min (R_s + R_L + 2 R_arc)) / E_col, for one contact at
    d = (V_s - U_min - I_min (R_s + R_L + R_arc)) / E_col; the same motion, so the bridge's
    arcs burn a shorter time (0.61 ms against 1.49 ms). Located to 1e-3 of the gap (ArcState
    resolves I_min to 1e-5, the current's RELTOL 1e-4 moves the crossing by ~1e-4 A over its
    slope; measured 2.6e-4 for the bridge, 1.1e-4 for one contact)."""
    bridge, one = breaks
    w, u = bridge.waveform_columns, one.waveform_columns

    def last_burning(w, names):
        on = np.any([np.abs(w[f"arc_current{n}"]) > 1e-3 for n in names], axis=0) & (w["time"] > 2e-3)
        return int(np.flatnonzero(on)[-1])

    k = last_burning(w, ("_a", "_b"))
    gap_sum = w["gap_a"][k] + w["gap_b"][k]
    assert gap_sum == pytest.approx((V_S - 2 * U_MIN - I_MIN * (R_S + R_L + 2 * R_ARC)) / E_COL, rel=1e-3)
    k1 = last_burning(u, ("",))
    assert u["gap"][k1] == pytest.approx((V_S - U_MIN - I_MIN * (R_S + R_L + R_ARC)) / E_COL, rel=1e-3)
    brk, brk1 = bridge.operations[-1]["break"], one.operations[-1]["break"]
    # the same motion (mu held), integrated over macro steps that each circuit's current sets:
    # the same break to the mechanics' own tolerance
    assert brk["time"] == pytest.approx(brk1["time"], rel=1e-6)
    assert brk["arc_duration"] < 0.5 * brk1["arc_duration"]
    assert brk["complete"] and brk1["complete"]


def test_a_netlist_naming_each_contact_is_the_same_bridge(breaks, tmp_path):
    """XCONTACT_A and XCONTACT_B in series in the user's netlist, fed by the fixed contacts of
    those names (case ignored): the same circuit as the template, so the same break within
    ngspice's tolerance (the two decks order their elements differently)."""
    (tmp_path / "bridge.cir").write_text(
        "bridge\nVsource src 0 36\nRsource src n1 0.05\nLwire n1 wire 1e-6\n"
        "XCONTACT_A wire mid\nCA wire mid 1e-10\nXCONTACT_B mid out\nCB mid out 1e-10\n"
        "VLOAD out load 0\nRload load 0 12\n")
    doc = bridge_doc()
    doc["circuit"] = dict(template="netlist", netlist="bridge.cir", arc=ARC)
    res = run(scene_from_dict(doc, base_dir=tmp_path))
    assert not any(line.startswith("[[fixed]]") for line in res.warnings)
    brk, ref = res.operations[-1]["break"], breaks[0].operations[-1]["break"]
    np.testing.assert_allclose(np.array(res.closed_intervals), np.array(breaks[0].closed_intervals), rtol=1e-6)
    assert brk["arc_duration"] == pytest.approx(ref["arc_duration"], rel=1e-3)
    assert brk["arc_energy"] == pytest.approx(ref["arc_energy"], rel=1e-3)


def test_a_matched_bridge_has_no_pairs_line_and_one_contact_keeps_it(breaks):
    bridge, one = breaks
    assert pairs_warning(bridge.scene) is None
    assert not any(line.startswith("[[fixed]]") for line in bridge.warnings)
    assert pairs_warning(one.scene) is not None  # (one circuit contact for two fixed ones: said)


@pytest.mark.parametrize("patch, words", [
    (dict(fixed=[dict(point="left", name="a", gap=0.0), dict(point="right", name="b", gap=0.0, electrical=False)]),
     "needs two electrical [[fixed]] contacts"),
    (dict(fixed=[dict(point="left", name="a", gap=0.0), dict(point="right", name="b_2", gap=0.0)]),
     "fixed[1].name = 'b_2'"),
])
def test_a_bridge_template_without_its_two_fixed_contacts_is_refused(patch, words):
    doc = bridge_doc()
    doc.update(copy.deepcopy(patch))
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_netlist_whose_contacts_are_not_the_fixed_ones_is_refused(tmp_path):
    (tmp_path / "n.cir").write_text("n\nV1 src 0 36\nXCONTACT_A src m\nXCONTACT_C m out\nVLOAD out l 0\nR1 l 0 12\n")
    doc = bridge_doc()
    doc["circuit"] = dict(template="netlist", netlist="n.cir")
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, base_dir=tmp_path)
    line = str(err.value)
    assert "\n" not in line
    assert "the circuit's contacts (a, c) and the electrical [[fixed]] contacts (a, b) do not match" in line
    assert "no electrical [[fixed]] contact named 'c'" in line and "no circuit contact named 'b'" in line


def test_a_netlist_whose_contacts_are_not_in_series_is_read_as_independent_contacts(tmp_path):
    """Two named contacts side by side (a bridge wired in parallel, like a changeover's NO and
    NC): not a series chain, so independent contacts, each closed while its own rivet touches
    (tests/coupling/test_changeover.py checks a changeover's; here only the reading)."""
    from coupling.core.arrangement import is_independent, is_series

    (tmp_path / "p.cir").write_text("p\nV1 src 0 36\nXCONTACT_A src out\nXCONTACT_B src out\nVLOAD out l 0\nR1 l 0 12\n")
    doc = bridge_doc()
    doc["circuit"] = dict(template="netlist", netlist="p.cir")
    circuit = scene_from_dict(doc, base_dir=tmp_path).circuit.circuit
    assert is_independent(circuit) and not is_series(circuit)


# --- an inductive load: the contactor's duty (AC-3/DC-3: motors, coils) -------------------------

L_LOAD = 20e-3  # H: tau = L / (R_s + R_L) = 1.7 ms, the loop still rising when the bar is pulled off at 2 ms


@pytest.fixture(scope="module")
def inductive():
    """The same motion breaking the bridge with the load's inductance, without and with a
    flyback diode."""
    return (run(scene_from_dict(bridge_doc(load_inductance=L_LOAD))),
            run(scene_from_dict(bridge_doc(load_inductance=L_LOAD, flyback=True))))


def trapezoid(y, t) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def test_the_inductors_energy_goes_into_the_two_arcs_in_series(inductive):
    """Over the arcs' time: the supply's energy plus what the inductors give up, 1/2 L (I0^2 -
    I1^2) (L the load's and the wiring's), is both arcs' energy (each contact's voltage times
    the loop current) plus R's losses; to 5e-3 of the arcs' energy (trapezoidal sums over the
    waveform's ~40 samples, up to 100 us apart, of a current curving over the 1.6 ms arc:
    measured 2.1e-3; the 100 pF across each gap holds ~1e-7 J against 0.08 J). The run's
    arc_energy is the same integral (to 1e-3), and the arcs carry the larger part."""
    w, brk = inductive[0].waveform_columns, inductive[0].operations[-1]["break"]
    assert brk["complete"]
    t, i = w["time"], w["load_current"]
    on = (t >= brk["time"]) & (t <= brk["time"] + brk["arc_duration"])
    t, i = t[on], i[on]
    arcs = trapezoid((w["contact_voltage_a"][on] + w["contact_voltage_b"][on]) * i, t)
    supplied = trapezoid(V_S * i, t) + 0.5 * (L_LOAD + 1e-6) * (i[0] ** 2 - i[-1] ** 2)
    assert supplied - trapezoid((R_S + R_L) * i ** 2, t) == pytest.approx(arcs, rel=5e-3)
    assert brk["arc_energy"] == pytest.approx(arcs, rel=1e-3)
    assert 0.5 * L_LOAD * i[0] ** 2 > 0.5 * arcs  # (the inductor's energy: more than half the arcs')


def test_an_inductive_bridge_break_burns_past_the_resistive_extinction_gap(breaks, inductive):
    """With R only the arcs go out at the summed gap where V_s holds 2 U_min + E_col d at
    I_min (test above); the inductor drives them on past it, so on the same motion they burn
    longer (1.62 ms against 0.61 ms) although the current at the break is the same order. A
    flyback diode takes the inductor's current: the arcs see the supply alone behind R_s
    and go out sooner than without it."""
    resistive = breaks[0].operations[-1]["break"]
    (ind, diode) = (r.operations[-1]["break"] for r in inductive)
    w = inductive[0].waveform_columns
    d_out = (V_S - 2 * U_MIN - I_MIN * (R_S + R_L + 2 * R_ARC)) / E_COL
    burning_past = burning(w, ("_a", "_b")) & (w["gap_a"] + w["gap_b"] > 1.2 * d_out)
    assert burning_past.sum() > 3
    assert ind["arc_duration"] > 2.0 * resistive["arc_duration"]
    assert resistive["arc_duration"] < diode["arc_duration"] < 0.7 * ind["arc_duration"]


@pytest.mark.parametrize("circuit, words", [
    (dict(load_inductance="20 mH"), "circuit.load_inductance"),
    (dict(load_inductance=-1.0), "circuit.load_inductance"),
    (dict(flyback=True), "circuit.flyback is set but the bridge's load is resistive"),
])
def test_bad_inductive_bridge_keys_are_refused_in_one_line(circuit, words):
    with pytest.raises(ValueError) as err:
        scene_from_dict(bridge_doc(**circuit))
    assert words in str(err.value) and "\n" not in str(err.value)
