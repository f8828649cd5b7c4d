"""The arc voltage growing with the gap distance (ArcModel.column_gradient, breakdown_gradient).

U_arc = U_min + E_col d(t) + R_arc |i|, with the gap d(t) >= 0 (m) supplied from Python like
G(t) (``gap=``), or by a ContactSchedule with an opening speed; V_bd(d) = V_bd0 + E_bd d.
Closed forms on a resistive circuit, the default reproducing the constant-U_min model,
stepped runs against the one-shot PWL reference, error paths. SI units.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySpice.Spice.Netlist import Circuit

from circuit import (
    ArcModel,
    ContactSchedule,
    DCSource,
    GapError,
    InductiveLoad,
    NetlistCircuit,
    ResistiveLoad,
    SimulationOptions,
    Stepper,
    SwitchCircuit,
    Wiring,
    add_arc,
    add_contact,
    run_pwl_reference,
    run_transient,
)
from circuit.arc import ArcState
from test_circuit_arc_stepping import BOUNCES, OPTIONS, R_CLOSED, burning_edges, scene, stepped

# -- (a) closed form: a DC arc put out by the lengthening gap --------------------------
#
# 24 V, 0.05 ohm source, no wiring, 12 ohm load, 100 pF across the contact; the contact
# breaks at T_BREAK and the gap opens at SPEED: d = v (t - t_break). While the arc burns,
# V_s = (R_s + R_L) i + U_min + E_col d + R_arc i, so
#     i(t) = (V_s - U_min - E_col v (t - t_break)) / R_total,   R_total = R_s + R_L + R_arc,
# falling linearly (less the 0.4 uA, C E_col v, into the 100 pF), until i = I_min at
#     d* = (V_s - U_min - I_min R_total) / E_col,   t* = t_break + d* / v.
# Arc energy: the arc voltage is V_s - (R_s + R_L) i, and dt = -R_total / (E_col v) di:
#     W = R_total / (E_col v) [V_s (i0^2 - I_min^2) / 2 - (R_s + R_L) (i0^3 - I_min^3) / 3].

V_S, R_S, R_L = 24.0, 0.05, 12.0
E_COL, SPEED = 2e3, 2.0  # 2 V/mm (illustrative), a bar flying off at 2 m/s
ARC = ArcModel(min_voltage=12.0, min_current=0.4, resistance=0.05, column_gradient=E_COL)
T_BREAK, T_END = 0.1e-3, 2.5e-3
R_TOTAL = R_S + R_L + ARC.resistance
I0 = (V_S - ARC.min_voltage) / R_TOTAL  # 0.99174 A
D_STAR = (V_S - ARC.min_voltage - ARC.min_current * R_TOTAL) / E_COL  # 3.58 mm
T_STAR = T_BREAK + D_STAR / SPEED  # 1.89 ms
W_CLOSED = R_TOTAL / (E_COL * SPEED) * (
    V_S * (I0**2 - ARC.min_current**2) / 2 - (R_S + R_L) * (I0**3 - ARC.min_current**3) / 3
)  # 18.82 mJ


def resistive(arc: ArcModel | None = ARC) -> SwitchCircuit:
    return SwitchCircuit(DCSource(V_S, R_S), ResistiveLoad(R_L), wiring=Wiring(0.0, 0.0),
                         contact_capacitance=100e-12, arc=arc)


def linear_gap(t: float) -> float:
    """What a coupling would pass: the separation, 0 while in contact."""
    return max(0.0, SPEED * (t - T_BREAK))


BREAK = ContactSchedule(((0.0, T_BREAK),), closed_resistance=0.01)
BREAK_WITH_GAP = ContactSchedule(((0.0, T_BREAK),), closed_resistance=0.01, opening_speed=SPEED)


def run_stepped(circuit, schedule, t_end, macro_step, gap, options):
    with Stepper(circuit, t_end, options) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + macro_step, t_end)
            stepper.advance(t_next, schedule, schedule.breakpoints(t, t_next), gap=gap)
            t = t_next
        return stepper.results()


def extinction_index(df, after=T_BREAK + 1e-6):
    """First point after ``after`` with the arc out (its 1 GOhm off path leaks uA)."""
    t, i_arc = df.time.to_numpy(), np.abs(df.arc_current.to_numpy())
    return int(np.argmax((t > after) & (i_arc < 1e-4)))


CASES = {
    "one-shot, schedule gap, max step 1 us": lambda: run_transient(
        resistive(), BREAK_WITH_GAP, T_END, options=SimulationOptions(max_step=1e-6)),
    "one-shot, schedule gap, max step 10 us": lambda: run_transient(
        resistive(), BREAK_WITH_GAP, T_END, options=SimulationOptions(max_step=10e-6)),
    "PWL reference, max step 1 us": lambda: run_pwl_reference(
        resistive(), BREAK_WITH_GAP, T_END, options=SimulationOptions(max_step=1e-6)),
    "stepped 10 us, gap function, max step 1 us": lambda: run_stepped(
        resistive(), BREAK, T_END, 10e-6, linear_gap, SimulationOptions(max_step=1e-6)),
    "stepped 100 us, gap function, max step 10 us": lambda: run_stepped(
        resistive(), BREAK, T_END, 100e-6, linear_gap, SimulationOptions(max_step=10e-6)),
}


@pytest.fixture(scope="module", params=list(CASES))
def opening(request):
    return CASES[request.param]()


def test_closed_form_numbers():
    assert I0 == pytest.approx(0.991736, rel=1e-6)
    assert D_STAR == pytest.approx(3.58e-3, rel=1e-12)
    assert T_STAR == pytest.approx(1.89e-3, rel=1e-12)
    assert W_CLOSED == pytest.approx(0.0188205, rel=1e-5)


def test_arc_current_falls_with_the_gap_closed_form(opening):
    df = opening
    t, i_arc, v = df.time.to_numpy(), df.arc_current.to_numpy(), df.contact_voltage.to_numpy()
    k = extinction_index(df)
    burning = (t > T_BREAK + 2e-6) & (t < t[k - 1])
    assert burning.sum() > 20
    expected = (V_S - ARC.min_voltage - E_COL * SPEED * (t[burning] - T_BREAK)) / R_TOTAL
    # Measured 4.0e-7 A: C E_col v, the current the 100 pF takes as the gap voltage ramps.
    np.testing.assert_allclose(i_arc[burning], expected, rtol=0, atol=1e-6)
    # The gap voltage is the arc voltage U_min + E_col d + R_arc i (measured 1e-9 V).
    gap_voltage = ARC.min_voltage + E_COL * SPEED * (t[burning] - T_BREAK) + ARC.resistance * i_arc[burning]
    np.testing.assert_allclose(v[burning], gap_voltage, rtol=0, atol=1e-6)


def test_arc_extinguishes_where_the_gap_reaches_d_star(opening):
    df = opening
    t, i_arc = df.time.to_numpy(), np.abs(df.arc_current.to_numpy())
    k = extinction_index(df)
    # The last burning point: the state goes out there, |i| within 1e-5 I_min below I_min
    # (ArcState's resolution; the current falls at 330 A/s, so 1e-5 I_min is 12 ns).
    assert i_arc[k - 1] == pytest.approx(ARC.min_current, rel=2e-5)  # measured <= 7.9e-6
    assert i_arc[k - 1] <= ARC.min_current
    assert t[k - 1] == pytest.approx(T_STAR, rel=1e-5)  # measured <= 4.4e-6 (8 ns)
    # Then the gap is open for good: no re-ignition without a breakdown voltage.
    assert np.all(i_arc[k:] < 1e-5)
    assert t[-1] == pytest.approx(T_END, rel=1e-9)


def test_arc_energy_closed_form(opening):
    df = opening
    t, i_arc, v = df.time.to_numpy(), df.arc_current.to_numpy(), df.contact_voltage.to_numpy()
    k = extinction_index(df)
    # From the break (the arc forms within the 10 ns ramp) to the extinction point.
    window = t >= T_BREAK - 20e-9
    energy = np.trapezoid((v * i_arc)[window][: int(np.sum(window[:k]))], t[window][: int(np.sum(window[:k]))])
    assert energy == pytest.approx(W_CLOSED, rel=1e-5)  # measured -1.3e-6 to 2.3e-6
    # Without the gap dependence the same arc burns at I0 to the end of the run (28.7 mJ
    # here, and growing with the run's length).
    constant = (ARC.min_voltage + ARC.resistance * I0) * I0 * (T_END - T_BREAK)
    assert energy < 0.7 * constant


def test_gap_node_is_the_gap_given():
    df = run_transient(resistive(), BREAK_WITH_GAP, T_END, options=SimulationOptions(max_step=10e-6),
                       extra=("arc_gap",))
    t = df.time.to_numpy()
    np.testing.assert_allclose(df.arc_gap.to_numpy(), [BREAK_WITH_GAP.gap(s) for s in t], rtol=1e-12, atol=1e-15)
    assert df.arc_gap.iloc[-1] == pytest.approx(SPEED * (T_END - T_BREAK), rel=1e-9)


def test_steeper_gradient_puts_the_arc_out_sooner():
    """t* - t_break = d*/v scales as 1/E_col: 2 V/mm -> 1.79 ms (above), 5 V/mm -> 0.716 ms,
    20 V/mm -> 0.179 ms."""
    options = SimulationOptions(max_step=1e-6)
    for gradient in (5e3, 20e3):
        arc = ArcModel(min_voltage=12.0, min_current=0.4, resistance=0.05, column_gradient=gradient)
        df = run_transient(resistive(arc), BREAK_WITH_GAP, T_END, options=options)
        k = extinction_index(df)
        d_star = (V_S - arc.min_voltage - arc.min_current * R_TOTAL) / gradient
        assert df.time.iloc[k - 1] == pytest.approx(T_BREAK + d_star / SPEED, rel=2e-5)  # measured <= 4.5e-6


# -- (b) the default (no gap dependence) is the constant-U_min model ------------------

# The bounce scene of test_circuit_arc_stepping: 24 V / 0.05 ohm, 1 uH, 12 ohm, 100 pF.
BOUNCE_END = 3e-3


@pytest.mark.parametrize("macro_step", [None, 2e-6, 1e-4], ids=["one-shot", "H=2e-06", "H=0.0001"])
def test_zero_gradient_is_bit_identical_to_the_constant_model(macro_step):
    """column_gradient = 0 (the default) writes the same netlist as before, and a gap
    given anyway is ignored: the run is bit-identical."""
    schedule = ContactSchedule(BOUNCES, closed_resistance=R_CLOSED)
    assert str(scene().build()) == str(scene(arc=ArcModel(column_gradient=0.0, breakdown_gradient=0.0)).build())
    before = stepped(scene(), schedule, BOUNCE_END, macro_step)
    if macro_step is None:
        after = run_transient(scene(arc=ArcModel(column_gradient=0.0)), schedule, BOUNCE_END, options=OPTIONS,
                              gap=lambda t: 1.0)
    else:
        after = run_stepped(scene(arc=ArcModel(column_gradient=0.0)), schedule, BOUNCE_END, macro_step,
                            lambda t: 1.0, OPTIONS)
    assert list(after.columns) == list(before.columns)
    for column in before.columns:
        assert np.array_equal(before[column].to_numpy(), after[column].to_numpy(), equal_nan=True), column


@pytest.mark.parametrize("macro_step", [None, 2e-6, 1e-4], ids=["one-shot", "H=2e-06", "H=0.0001"])
def test_zero_gap_with_a_gradient_matches_the_constant_model_to_round_off(macro_step):
    """With column_gradient > 0 and d = 0 the netlist gains the gap source (one more
    matrix row), so the run is not bit-identical. Measured: the same points and the same
    arc switching instants (to 1e-16 s); point times within 7.3e-9 s: the short first step
    after each arc switch (circuit.arc.RESTART) lets round-off move ngspice's step choice
    in the 6th digit, and the step doubling of a closed contact carries that along to the
    next breakpoint. At equal times the waveforms agree to round-off: each value within
    1e-5 of the other run's plus its slope times the shift of the point."""
    schedule = ContactSchedule(BOUNCES, closed_resistance=R_CLOSED)
    before = stepped(scene(), schedule, BOUNCE_END, macro_step)
    arc = ArcModel(column_gradient=E_COL)
    if macro_step is None:
        after = run_transient(scene(arc=arc), schedule, BOUNCE_END, options=OPTIONS, gap=0.0)
    else:
        after = run_stepped(scene(arc=arc), schedule, BOUNCE_END, macro_step, 0.0, OPTIONS)
    assert len(after) == len(before)
    t_a, t_b = after.time.to_numpy(), before.time.to_numpy()
    np.testing.assert_allclose(t_a, t_b, rtol=0, atol=1e-8)
    for column in ("contact_voltage", "contact_current", "load_current", "arc_current"):
        a, b = after[column].to_numpy(), before[column].to_numpy()
        left, right = np.gradient(b, t_b, edge_order=1), np.r_[np.diff(b) / np.diff(t_b), 0.0]
        slope = np.maximum(np.abs(left), np.abs(right))
        assert np.all(np.abs(a - b) <= 1e-5 + 1.01 * slope * np.abs(t_a - t_b)), column
    np.testing.assert_allclose(burning_edges(after), burning_edges(before), rtol=0, atol=1e-10)


# -- (c) stepped == one-shot == PWL reference, bounces then flying off ------------------

FLY_ARC = ArcModel(column_gradient=5e3)  # 5 V/mm: the arc dies 0.716 ms after the last break
FLY = ContactSchedule(BOUNCES, closed_resistance=R_CLOSED, opening_speed=SPEED)
FLY_R_TOTAL = 0.05 + 12.0 + FLY_ARC.resistance
FLY_LAG = 1e-6 / FLY_R_TOTAL  # the 1 uH wiring: the current follows a ramp L/R_total = 83 ns late
FLY_OPTIONS = SimulationOptions(max_step=1e-6, wall_timeout=60.0)  # the ramps of d resolved
FLY_EXTINCTION = BOUNCES[-1][1] + (24.0 - 12.0 - 0.4 * FLY_R_TOTAL) / 5e3 / SPEED + FLY_LAG


def arc_edges(df):
    """Times where the arc turns on or off (|i| crosses 1e-4 A)."""
    on = (np.abs(df.arc_current.to_numpy()) > 1e-4).astype(int)
    return df.time.to_numpy()[1:][np.diff(on) != 0]


def coupled_like_with_gap(circuit, schedule, t_end, contact_step=2e-6, free_step=1e-4, tail=20e-6):
    """As test_circuit_arc_stepping.coupled_like, with the gap passed at every step."""
    events = sorted({t for pair in schedule.intervals for t in pair})
    with Stepper(circuit, t_end, FLY_OPTIONS) as stepper:
        t = 0.0
        while not stepper.finished:
            touching = any(make - 1e-15 <= t < brk + tail for make, brk in schedule.intervals)
            t_next = min(t + (contact_step if touching else free_step), t_end)
            inside = [e for e in events if t + 1e-15 < e < t_next - 1e-15]
            if inside:
                t_next = inside[0]
            stepper.advance(t_next, schedule, schedule.breakpoints(t, t_next), gap=schedule.gap)
            t = t_next
        return stepper.results()


@pytest.fixture(scope="module")
def fly_reference():
    return run_pwl_reference(scene(arc=FLY_ARC), FLY, BOUNCE_END, options=FLY_OPTIONS)


FLY_RUNS = [None, 1e-6, 1e-5, 1e-4, "coupled"]


@pytest.mark.parametrize("macro_step", FLY_RUNS, ids=["one-shot", "H=1e-06", "H=1e-05", "H=0.0001", "coupling-like"])
def test_stepped_gap_run_matches_the_pwl_reference(fly_reference, macro_step):
    circuit = scene(arc=FLY_ARC)
    if macro_step is None:
        df = run_transient(circuit, FLY, BOUNCE_END, options=FLY_OPTIONS)
    elif macro_step == "coupled":
        df = coupled_like_with_gap(circuit, FLY, BOUNCE_END)
    else:
        df = run_stepped(circuit, FLY, BOUNCE_END, macro_step, FLY.gap, FLY_OPTIONS)
    reference = fly_reference
    edges, edges_ref = arc_edges(df), arc_edges(reference)
    # Formed at each break, out at each make, and finally put out by the gap.
    assert len(edges_ref) == 2 * len(BOUNCES)
    assert len(edges) == len(edges_ref)
    # Closed form, with the 1 uH lag (measured 5.2 ns late: the 1e-5 I_min resolution).
    assert edges_ref[-1] == pytest.approx(FLY_EXTINCTION, abs=1e-8)
    # Make/break edges lie in the 10 ns ramps (measured <= 0.3 ns apart); the extinction
    # is located to 1e-5 I_min of a current falling at 826 A/s, i.e. within ~5 ns
    # (measured <= 0.6 ns).
    np.testing.assert_allclose(edges[:-1], edges_ref[:-1], rtol=0, atol=1e-9)
    assert abs(edges[-1] - edges_ref[-1]) < 5e-9
    # Away from the 5 us after each corner (ramps, the gap's apexes) and from the ringing
    # after the final extinction (its phase follows the ns-located event): the same
    # waveform (measured <= 2.0e-7 A, 1e-8 V).
    grid = np.arange(0.0, BOUNCE_END, 1e-6)
    quiet = (grid < edges_ref[-1] - 0.2e-6) | (grid > edges_ref[-1] + 20e-6)
    for corner in FLY.breakpoints():
        quiet &= ~((grid >= corner - 0.2e-6) & (grid < corner + 5e-6))
    for column in ("arc_current", "contact_voltage", "load_current"):
        ours = np.interp(grid, df.time, df[column])[quiet]
        theirs = np.interp(grid, reference.time, reference[column])[quiet]
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-6, err_msg=column)


def test_arc_follows_the_gap_through_the_bounces(fly_reference):
    """In each open interval the arc current is the closed form
        i_arc = (E - U_min - E_col d(t - L/R_total)) / R_total - C E_col d'(t),
    d the triangle gap of the schedule (apex 2 m/s x 40-238 us), L/R_total the 83 ns lag
    of the 1 uH wiring behind a ramp, C E_col d' = +-1 uA the current into the 100 pF as
    the gap voltage ramps. 5 us after each break and 3 us after each apex left out (the
    lag settling, first-order restarts); measured: 1.5e-7 A at the first points after
    those, within 1e-8 A elsewhere."""
    df = fly_reference
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    window = np.zeros_like(t, dtype=bool)
    for (_, brk), (make, _) in zip(BOUNCES[:-1], BOUNCES[1:]):
        apex = 0.5 * (brk + make)
        window |= (t > brk + 5e-6) & (t < make - 1e-7) & ~((t > apex - 1e-9) & (t < apex + 3e-6))
    window |= (t > BOUNCES[-1][1] + 5e-6) & (t < FLY_EXTINCTION - 1e-6)
    times = t[window]
    d = np.array([FLY.gap(s - FLY_LAG) for s in times])
    speed = np.array([(FLY.gap(s + 1e-9) - FLY.gap(s - 1e-9)) / 2e-9 for s in times])  # +-2 m/s
    assert d.max() > 1e-3 and window.sum() > 1000
    expected = (24.0 - FLY_ARC.min_voltage - FLY_ARC.column_gradient * d) / FLY_R_TOTAL
    expected -= 100e-12 * FLY_ARC.column_gradient * speed
    np.testing.assert_allclose(i_arc[window], expected, rtol=0, atol=2e-7)


# -- re-ignition voltage growing with the gap ------------------------------------------

def test_breakdown_voltage_grows_with_the_gap():
    """Coil 10 V / 5 ohm / 1 mH, 100 pF: the arc dies at I_min 218 us after the break,
    then the gap re-ignites each time |v| reaches V_bd0 + E_bd d(t) (300 V + 1 kV/mm,
    illustrative; d = 1 m/s x t): first at ~518 V, not 300 V."""
    counts = []
    for max_step in (1e-7, 1e-6):
        arc = ArcModel(breakdown_voltage=300.0, breakdown_gradient=1e6)
        coil = SwitchCircuit(DCSource(10.0, 0.0), InductiveLoad(5.0, 1e-3), wiring=Wiring(0.0, 0.0),
                             contact_capacitance=100e-12, arc=arc)
        schedule = ContactSchedule(((0.0, T_BREAK),), closed_resistance=0.01, opening_speed=1.0)
        df = run_transient(coil, schedule, 0.4e-3, options=SimulationOptions(max_step=max_step))
        t, v, i_arc = df.time.to_numpy(), np.abs(df.contact_voltage.to_numpy()), np.abs(df.arc_current.to_numpy())
        on = (i_arc > 1e-4).astype(int)
        last_off = np.where(np.diff(on) == 1)[0]  # the point deciding each re-ignition
        last_off = last_off[t[last_off] > T_BREAK + 1e-6]
        threshold = 300.0 + 1e6 * 1.0 * (t[last_off] - T_BREAK)
        # Located like V_bd itself: up to 1e-5 V_bd0 past it (measured <= 2.7e-3 V).
        assert np.all(v[last_off] >= threshold - 1e-9)
        np.testing.assert_allclose(v[last_off], threshold, rtol=0, atol=5e-3)
        assert threshold[0] == pytest.approx(518.0, abs=1.0)
        assert v.max() < threshold[-1] + 1.0
        counts.append(len(last_off))
    # Fewer, larger discharges than with a constant 300 V (19 there).
    assert counts[0] == counts[1] == 6


def test_state_machine_breakdown_margin_uses_the_gap():
    state = ArcState(ArcModel(breakdown_voltage=300.0, breakdown_gradient=1e6), "varc#branch", "a", "b", "contact_g")
    state.start(False)
    values = {"varc#branch": 0.0, "a": 0.0, "b": 0.0, "contact_g": 0.0, "arc_gap": 0.0}

    def point(t, voltage, gap):
        values.update(a=voltage, arc_gap=gap)
        return state.accepted(t, None, lambda names: [values[n] for n in names])

    point(1e-6, 400.0, 1e-4)  # V_bd(0.1 mm) = 400 V: reached
    assert state.burning
    state.start(False)
    point(1e-6, 350.0, 1e-4)  # margin |v| - E_bd d = 250 V < V_bd0
    step, _ = point(2e-6, 380.0, 1.1e-4)  # margin 270 V: |v| rises 30 V/us, V_bd 10 V/us
    assert not state.burning
    # The step aims at the margin reaching V_bd0, which it approaches at 2e7 V/s.
    assert step == pytest.approx((0.75 * 30.0 + 1e-5 * 300.0) / 2e7)
    point(3e-6, 420.0, 1.2e-4)  # margin 300 V
    assert state.burning


# -- ContactSchedule's gap ---------------------------------------------------------------

def test_schedule_gap_is_a_triangle_between_break_and_make():
    s = ContactSchedule(((0.0, 1e-3), (2e-3, 3e-3), (5e-3, 6e-3)), opening_speed=0.5)
    assert s.gap(0.5e-3) == 0.0 and s.gap(1e-3) == 0.0
    assert s.gap(1.2e-3) == pytest.approx(0.5 * 0.2e-3)
    assert s.gap(1.5e-3) == pytest.approx(0.5 * 0.5e-3)  # apex
    assert s.gap(1.9e-3) == pytest.approx(0.5 * 0.1e-3)  # closing towards the make
    assert s.gap(2.5e-3) == 0.0
    assert s.gap(7e-3) == pytest.approx(0.5 * 1e-3)  # flying off after the last break
    assert 1.5e-3 in s.breakpoints() and 4e-3 in s.breakpoints()
    late = ContactSchedule(((1e-3, 2e-3),), opening_speed=1.0)
    assert late.gap(0.25e-3) == pytest.approx(0.75e-3)  # closing towards the first make
    times, values = s.gap_pwl_points(8e-3)
    fine = np.linspace(0.0, 8e-3, 8001)
    np.testing.assert_allclose(np.interp(fine, times, values), [s.gap(t) for t in fine], rtol=0, atol=1e-15)
    # Without an opening speed nothing changes: no apexes, no gap.
    plain = ContactSchedule(((0.0, 1e-3), (2e-3, 3e-3)))
    assert plain.breakpoints() == (1e-3 - 1e-8, 1e-3, 2e-3, 2e-3 + 1e-8, 3e-3 - 1e-8, 3e-3)
    with pytest.raises(ValueError, match="opening_speed"):
        plain.gap(1.5e-3)


# -- (d) error paths -----------------------------------------------------------------------

def test_missing_gap_is_a_clear_error_before_anything_runs():
    options = SimulationOptions(max_step=1e-6)
    with pytest.raises(ValueError, match="column_gradient = 2000 V/m.*gap"):
        run_transient(resistive(), BREAK, 0.2e-3, options=options)  # a schedule without opening_speed
    with pytest.raises(ValueError, match="gap"):
        run_transient(resistive(), lambda t: 0.0, 0.2e-3, options=options)
    with pytest.raises(ValueError, match="gap.*opening_speed"):
        run_pwl_reference(resistive(), BREAK, 0.2e-3, options=options)
    breakdown_only = resistive(ArcModel(breakdown_voltage=300.0, breakdown_gradient=3e6))
    with pytest.raises(ValueError, match="breakdown_gradient = 3e\\+06 V/m"):
        run_transient(breakdown_only, BREAK, 0.2e-3, options=options)
    with Stepper(resistive(), 0.2e-3, options) as stepper:
        with pytest.raises(ValueError, match="gap distance"):
            stepper.advance(0.05e-3, BREAK)
        assert stepper.time == 0.0 and stepper.stats["points"] == 0
        # Nothing ran and nothing failed: the run goes on once the gap is given.
        stepper.advance(0.2e-3, BREAK, BREAK.breakpoints(0.0, 0.2e-3), gap=linear_gap)
        assert stepper.finished and stepper.stats["gap_calls"] > 0


def test_negative_gap_values_are_rejected():
    options = SimulationOptions(max_step=1e-6)
    with Stepper(resistive(), 0.2e-3, options) as stepper:
        with pytest.raises(ValueError, match=r"gap = -0.001 m: must be finite and >= 0"):
            stepper.advance(0.05e-3, BREAK, gap=-1e-3)
        with pytest.raises(TypeError, match="gap must be a function of time or a number"):
            stepper.advance(0.05e-3, BREAK, gap="open")
        stepper.advance(0.05e-3, BREAK, gap=0.0)  # still usable
        # A function returning a negative value: GapError with the time, the run stops.
        with pytest.raises(GapError, match=r"contact gap at t = [0-9.e-]+ s is -[0-9.e-]+ m; it must be finite"):
            stepper.advance(0.2e-3, BREAK, BREAK.breakpoints(0.05e-3, 0.2e-3),
                            gap=lambda t: SPEED * (t - T_BREAK))  # no max(0, ...): negative before the break
        with pytest.raises(RuntimeError, match="failed"):
            stepper.advance(0.2e-3, BREAK, gap=0.0)
    for bad in (math.nan, math.inf):
        with pytest.raises(GapError, match="must be finite and >= 0"):
            run_transient(resistive(), BREAK, 0.2e-3, options=options, gap=lambda t, b=bad: b if t > 0.15e-3 else 0.0)
    with pytest.raises(ZeroDivisionError, match="mechanics failed"):
        _raise_in_gap(options)
    with pytest.raises(ValueError, match=r"PWL gap: values must be finite and >= 0 \(vertex 1"):
        run_pwl_reference(resistive(), BREAK, 0.2e-3, options=options,
                          gap=([0.0, 0.1e-3, 0.2e-3], [0.0, -1e-6, 1e-3]))
    with pytest.raises(ValueError, match="gap = -1"):
        run_pwl_reference(resistive(), BREAK, 0.2e-3, options=options, gap=-1.0)
    with pytest.raises(TypeError, match="PWL vertices"):
        run_pwl_reference(resistive(), BREAK, 0.2e-3, options=options, gap=linear_gap)
    # The session is fine afterwards.
    df = run_transient(resistive(), BREAK_WITH_GAP, 0.2e-3, options=options)
    assert df.time.iloc[-1] == pytest.approx(0.2e-3, rel=1e-9)


def _raise_in_gap(options):
    def gap(t):
        if t > 0.15e-3:
            raise ZeroDivisionError("mechanics failed")
        return 0.0

    run_transient(resistive(), BREAK, 0.2e-3, options=options, gap=gap)


@pytest.mark.parametrize(
    "kwargs, match",
    [({"column_gradient": -1.0}, "circuit.arc.column_gradient"),
     ({"column_gradient": 2e6}, "circuit.arc.column_gradient"),
     ({"column_gradient": math.nan}, "circuit.arc.column_gradient"),
     ({"breakdown_gradient": -1.0, "breakdown_voltage": 300.0}, "circuit.arc.breakdown_gradient"),
     ({"breakdown_gradient": 3e6}, "breakdown_gradient = 3e\\+06 V/m needs breakdown_voltage")],
)
def test_bad_gradients_are_rejected(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ArcModel(**kwargs)


def test_bad_opening_speed_is_rejected():
    with pytest.raises(ValueError, match="circuit.schedule.opening_speed"):
        ContactSchedule(((0.0, 1e-3),), opening_speed=0.0)
    with pytest.raises(ValueError, match="circuit.schedule.opening_speed"):
        ContactSchedule((), opening_speed=1.0)


def test_gap_source_in_netlist_and_pyspice_circuits():
    """The gap source is written without a value (ngspice 38-40 segfault otherwise), its
    name is reserved, and a PySpice circuit with add_arc gets it too."""
    netlist = str(resistive().build())
    assert "Varc_gap arc_gap 0 external\n" in netlist
    assert "(12.0+2000.0*V(arc_gap))" in netlist
    assert "arc_gap" not in str(resistive(ArcModel()).build())
    with pytest.raises(ValueError, match="reserved"):
        NetlistCircuit("t\nV1 a 0 24\nXCONTACT a b\nVarc_gap b 0 0\n")
    c = Circuit("own")
    c.V("s", "a", c.gnd, 24.0)
    add_contact(c, "a", "b")
    add_arc(c, ARC, "a", "b")
    c.R("load", "b", c.gnd, 12.0)
    df = run_transient(c, BREAK, 0.5e-3, options=SimulationOptions(max_step=1e-6), gap=linear_gap)
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    late = t > 0.3e-3
    expected = (V_S - ARC.min_voltage - E_COL * SPEED * (t[late] - T_BREAK)) / (R_L + ARC.resistance)
    np.testing.assert_allclose(i_arc[late], expected, rtol=0, atol=2e-6)
