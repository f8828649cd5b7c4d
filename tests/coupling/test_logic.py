"""The digital-input metric (coupling.core.logic, [metrics] logic): a Schmitt trigger's edges.

Pure function: edge times against the analytic crossings of a sine and a ramp, and the
hysteresis (a ripple between the thresholds, or one that crosses only the threshold of the
level the input already has, gives no edge). Through ngspice: a prescribed contact
schedule on the mcu_input template, whose pin relaxes exponentially after each make and
break (tau = (R_series + R_pull || R_c) C after a make, towards the divider; tau =
(R_pull + R_series) C after a break, towards the open level): the closed form says which
contacts and openings cross a threshold and when, and the run must see exactly those
edges at those times. Bad scene input: one line naming the key.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from coupling import run
from coupling.core.logic import LogicInput, logic_metrics, schmitt_edges
from coupling.core.scene import scene_from_dict

LOW, HIGH = 0.99, 2.31


# --- the pure function ----------------------------------------------------------------------


def test_ripple_between_the_thresholds_gives_no_edge():
    t = np.linspace(0.0, 1e-3, 20001)
    mid, half = 0.5 * (LOW + HIGH), 0.5 * (HIGH - LOW)
    for amplitude in (0.5 * half, 0.999 * half):
        v = mid + amplitude * np.sin(2 * np.pi * 10e3 * t)
        assert schmitt_edges(t, v, LOW, HIGH) == []
        m = logic_metrics(t, v, LogicInput("v(pin)", LOW, HIGH))
        assert m["edges"] == 0 and m["initial_level"] == m["final_level"] == "high"  # v(0) at the midpoint
        assert m["stable_margin"] == pytest.approx(half - amplitude, abs=1e-6 * half)
    # a ripple around the high threshold of an input that is already high: no edge either
    v = HIGH + 0.3 * np.sin(2 * np.pi * 10e3 * t)
    assert schmitt_edges(t, v, LOW, HIGH) == []


def test_the_margin_after_the_last_edge_counts_the_edge_and_not_where_the_samples_fall():
    """A rise through HIGH that goes on rising: the margin is the hysteresis, HIGH - LOW,
    whether the first sample after the crossing is 0.1 or 0.3 V above it (it was that
    sample's distance from LOW: 1.43 or 1.59 V on the tactile switch for two step sequences of
    one run). A dip after the edge to 1.5 V, not below LOW, is the margin: 1.5 - LOW. Falling
    through LOW the same, mirrored."""
    for first_after in (HIGH + 0.1, HIGH + 0.3):
        t = np.array([0.0, 1e-3, 2e-3, 3e-3, 4e-3])
        v = np.array([0.0, 2.0, first_after, 3.0, 3.3])
        m = logic_metrics(t, v, LogicInput("v(pin)", LOW, HIGH))
        assert m["edges"] == 1 and m["final_level"] == "high"
        assert m["stable_margin"] == pytest.approx(HIGH - LOW, rel=1e-12)
        dipped = logic_metrics(t, np.array([0.0, 2.0, first_after, 1.5, 3.3]), LogicInput("v(pin)", LOW, HIGH))
        assert dipped["stable_margin"] == pytest.approx(1.5 - LOW, rel=1e-12)
        falling = logic_metrics(t, 3.3 - v, LogicInput("v(pin)", 3.3 - HIGH, 3.3 - LOW))
        assert falling["final_level"] == "low" and falling["stable_margin"] == pytest.approx(HIGH - LOW, rel=1e-12)


def test_sine_across_both_thresholds_edges_at_the_analytic_crossings():
    """v = mid + A sin(w t), A beyond both thresholds: it falls below LOW at
    w t = pi + asin((mid - LOW)/A) and rises above HIGH at w t = 2 pi + asin((HIGH - mid)/A),
    each period; linear interpolation between samples h apart is within h^2 max|v''| / (8 min|v'|)."""
    f, amplitude = 10e3, 1.5
    mid, w = 0.5 * (LOW + HIGH), 2 * np.pi * 10e3
    t = np.linspace(0.0, 3 / f, 30001)
    v = mid + amplitude * np.sin(w * t)
    edges = schmitt_edges(t, v, LOW, HIGH)
    fall, rise = math.asin((mid - LOW) / amplitude), math.asin((HIGH - mid) / amplitude)
    expected = []
    for k in range(3):
        expected += [((math.pi + fall + 2 * math.pi * k) / w, "falling"), ((2 * math.pi + rise + 2 * math.pi * k) / w,
                                                                            "rising")]
    expected = [e for e in expected if e[0] < t[-1]]
    h = t[1] - t[0]
    slope = amplitude * w * math.cos(fall)  # |v'| at both crossings (same |sin|)
    tol = h**2 * amplitude * w**2 / (8 * slope)
    assert [d for _, d in edges] == [d for _, d in expected]
    assert np.max(np.abs(np.array([e for e, _ in edges]) - [e for e, _ in expected])) <= tol


def test_ramp_edges_are_exact_and_non_finite_samples_are_skipped():
    t = np.array([0.0, 1.0, 2.0, 3.0, 3.0, 4.0, 5.0])
    v = np.array([3.0, 2.0, np.nan, 0.0, 0.0, 1.5, 3.0])  # falls through LOW, then rises through HIGH
    edges = schmitt_edges(t, v, LOW, HIGH)
    # 2.0 V at 1 s to 0 V at 3 s: LOW at 1 + (2 - 0.99)/1; 1.5 V at 4 s to 3 V at 5 s: HIGH at 4 + 0.81/1.5
    assert edges == [(pytest.approx(2.01, abs=1e-12), "falling"), (pytest.approx(4.54, abs=1e-12), "rising")]
    m = logic_metrics(t, v, LogicInput("v(pin)", LOW, HIGH))
    assert (m["edges"], m["rising_edges"], m["falling_edges"]) == (2, 1, 1)
    assert m["edge_table"][1]["since_previous"] == pytest.approx(2.53, abs=1e-12)
    assert m["edge_burst"] == pytest.approx(2.53, abs=1e-12) and m["final_level"] == "high"


# --- a prescribed schedule on the mcu_input template, against the closed form ------------------

VCC, R_PULL, R_SERIES, C_IN, MAX_STEP = 3.3, 10e3, 1e3, 10e-9, 0.5e-6
# make/break instants (s): a 4 us contact that leaves the pin above LOW, a 60 us opening that
# lets it rise past LOW but not to HIGH, and contacts and openings long enough to cross
MAKES = [100e-6, 204e-6, 314e-6, 644e-6]
BREAKS = [104e-6, 254e-6, 344e-6]
T_END = 1e-3


def pin_levels(pull: str, r_closed: float):
    """The pin's closed form on the schedule: (interval bounds (s), closed?, target level (V), tau (s)) per
    interval, and the pin voltage at every bound. An exponential towards the interval's level
    (open: Vcc pulled up, 0 pulled down; closed: the divider R_pull : R_c) with its tau."""
    divider = r_closed / (R_PULL + r_closed) if pull == "up" else R_PULL / (R_PULL + r_closed)
    open_level, closed_level = (VCC, VCC * divider) if pull == "up" else (0.0, VCC * divider)
    tau_open = (R_PULL + R_SERIES) * C_IN
    tau_closed = (R_SERIES + R_PULL * r_closed / (R_PULL + r_closed)) * C_IN
    bounds = [0.0] + sorted(MAKES + BREAKS) + [T_END]
    segments, v = [], [open_level]
    for k, (t0, t1) in enumerate(zip(bounds[:-1], bounds[1:])):
        closed = k % 2 == 1
        target, tau = (closed_level, tau_closed) if closed else (open_level, tau_open)
        segments.append((t0, t1, closed, target, tau))
        v.append(target + (v[-1] - target) * math.exp(-(t1 - t0) / tau))
    return segments, v


def closed_form(pull: str, r_closed: float) -> tuple[list[tuple[float, str, float, float]], float]:
    """(edges: time, direction, the interval's tau (s) and the pin's slope there (V/s); the
    smallest distance of a non-crossing interval's end to the threshold that would switch the
    input, V) of a Schmitt input on the pin: at most one crossing per interval (each is monotone)."""
    segments, v = pin_levels(pull, r_closed)
    level = v[0] > 0.5 * (LOW + HIGH)
    edges, margin = [], math.inf
    for (t0, t1, _, target, tau), v0, v1 in zip(segments, v[:-1], v[1:]):
        threshold = LOW if level else HIGH
        crosses = (level and target < LOW < v0) or (not level and v0 < HIGH < target)
        when = t0 + tau * math.log((v0 - target) / (threshold - target)) if crosses else math.inf
        if when < t1:
            edges.append((when, "falling" if level else "rising", tau, abs(threshold - target) / tau))
            level = not level
        else:
            margin = min(margin, abs(v1 - threshold))
    return edges, margin


def _schedule_scene(pull: str, r_closed: float):
    doc = {"circuit": {"template": "mcu_input", "voltage": VCC, "pull": pull, "pull_resistance": R_PULL,
                       "series_resistance": R_SERIES, "input_capacitance": C_IN, "logic_low": LOW,
                       "logic_high": HIGH, "contact_capacitance": 0.0, "max_step": MAX_STEP,
                       "schedule": {"make": MAKES, "break": BREAKS, "closed_resistance": r_closed,
                                    "edge_time": 0.0}},
           "solver": {"t_end": T_END}}
    return scene_from_dict(doc, name="mcu_schedule")


@pytest.mark.parametrize("pull, r_closed, n_edges", [
    ("up", 0.01, 3), ("down", 0.01, 3),
    ("up", 2e3, 3),   # a resistive contact: the divider 0.55 V and tau = (R_s + R_p || R_c) C = 26.7 us
    ("up", 5e3, 0),   # the divider holds the pin at 1.1 V > LOW: the input never reads the contact
])
def test_schedule_edges_are_the_closed_form(pull, r_closed, n_edges):
    expected, margin = closed_form(pull, r_closed)
    assert len(expected) == n_edges  # the schedule does what its comment says
    # every interval that does not cross ends >= 0.1 V from the threshold that would switch the
    # input: far beyond ngspice's RELTOL 1e-4 of 3.3 V, so the count cannot depend on round-off
    assert margin > 0.1
    result = run(_schedule_scene(pull, r_closed))
    logic = result.logic
    assert logic["edges"] == n_edges
    assert [row["direction"] for row in logic["edge_table"]] == [e[1] for e in expected]
    # An edge time is off by the linear interpolation between points at most h = MAX_STEP apart,
    # h^2 |v''| / (8 |v'|) = h^2 / (8 tau), plus ngspice's voltage error (RELTOL 1e-4 of Vcc) over
    # the slope |v'|; allowed twice their sum (measured: 3-7 ns against 13-74 ns allowed)
    for (when, _, tau, slope), row in zip(expected, logic["edge_table"]):
        tolerance = 2.0 * (MAX_STEP**2 / (8.0 * tau) + 1e-4 * VCC / slope)
        assert abs(row["time"] - when) <= tolerance, (row, when, tolerance)
    summary = result.summary
    assert summary["logic"]["node"] == "v(pin)" and summary["logic"]["edges"] == n_edges
    assert json.loads(json.dumps(summary))["logic"]["edge_table"] == summary["logic"]["edge_table"]
    if n_edges:
        assert logic["first_edge"] == logic["edge_table"][0]["time"]
        assert logic["last_edge"] == logic["edge_table"][-1]["time"]
        assert logic["final_level"] == ("low" if pull == "up" else "high")


def test_logic_on_any_node_reads_the_probe_and_its_own_thresholds():
    """[metrics] logic on the switch node, thresholds 1.0 / 2.0 V: the node is recorded once
    although [circuit] probes names it too. Closed, the contact holds the node at ~0 (a
    falling edge at each make itself, C_contact = 0); open, it is the divider of R_pull to
    Vcc and R_series to the pin, v_sw = (Vcc R_s + v_pin R_p) / (R_p + R_s): it jumps at the
    break and then follows the pin's exponential, so it reads high once the pin passes
    (2.0 (R_p + R_s) - Vcc R_s) / R_p."""
    low, high = 1.0, 2.0
    scene = _schedule_scene("up", 0.01).update({"circuit.probes": ["v(sw)"],
                                                "metrics.logic": {"node": "v(sw)", "low": low, "high": high}})
    assert [p.text for p in scene.circuit.probes] == ["v(sw)"]
    segments, v = pin_levels("up", 0.01)
    pin_high = (high * (R_PULL + R_SERIES) - VCC * R_SERIES) / R_PULL
    expected, level = [], True
    for (t0, t1, closed, target, tau), v0 in zip(segments, v[:-1]):
        if closed and level:
            expected.append((t0, "falling"))
            level = False
        elif not closed and not level and target > pin_high:
            when = t0 + tau * math.log((v0 - target) / (pin_high - target)) if v0 < pin_high else t0
            if when < t1:
                expected.append((when, "rising"))
                level = True
    # the 4 us contact leaves the pin high enough for the node to jump above 2 V at its break; the
    # 60 us opening does not bring it there; the 300 us one does, 92 us after its break
    assert [d for _, d in expected] == ["falling", "rising", "falling", "rising", "falling"]
    logic = run(scene).logic
    assert [r["direction"] for r in logic["edge_table"]] == [d for _, d in expected]
    # at a make or a break the node jumps: its edge lies between the breakpoint and ngspice's next
    # point (a restart step, far below MAX_STEP); the pin-driven edge as in the test above
    for (when, _), row in zip(expected, logic["edge_table"]):
        assert abs(row["time"] - when) <= (MAX_STEP if when in MAKES + BREAKS else 2e-3 * (R_PULL + R_SERIES) * C_IN)


# --- bad input: one line naming the key --------------------------------------------------------

BASE = {"circuit": {"template": "mcu_input", "schedule": {"make": [1e-4], "break": []}}, "solver": {"t_end": 1e-3}}


@pytest.mark.parametrize("patch, words", [
    ({"metrics": {"logic": {"low": 2.4, "high": 2.31}}}, "metrics.logic.low = 2.4 V must be below metrics.logic.high"),
    ({"metrics": {"logic": {"low": 1.0, "high": 1.0}}}, "metrics.logic.low = 1 V must be below"),
    ({"metrics": {"logic": {"node": "v(pim)"}}}, "metrics.logic.node: probe 'v(pim)': no node 'pim'"),
    ({"metrics": {"logic": {"node": "i(Rpull)"}}},
     "metrics.logic.node = 'i(Rpull)': a logic input reads a node voltage"),
    ({"metrics": {"logic": {"node": "v(pin)", "hi": 2.0}}}, "metrics.logic: unknown key 'hi'"),
    ({"metrics": {"logic": {"high": "2.3"}}}, "metrics.logic.high = '2.3': expected a finite number of volts"),
    ({"circuit": {"logic_low": 2.5}}, "circuit.logic_low = 2.5 V must be below circuit.logic_high = 2.31 V"),
    ({"circuit": {"logic_high": 3.5}}, "circuit.logic_high = 3.5 V must be below circuit.voltage = 3.3 V"),
    ({"circuit": {"pull_resistance": -10e3}}, "circuit.pull_resistance = -10000 ohm is out of range"),
    ({"circuit": {"series_resistance": -1.0}}, "circuit.series_resistance = -1 ohm is out of range"),
    ({"circuit": {"input_capacitance": -1e-9}}, "circuit.input_capacitance = -1e-09 F is out of range"),
    ({"circuit": {"pull": "sideways"}}, "circuit.pull = 'sideways': allowed values are 'up'"),
    ({"circuit": {"load_resistance": 10.0}}, "circuit.load_resistance do(es) not apply to template 'mcu_input'"),
])
def test_bad_logic_input_is_one_line_naming_the_key(patch, words):
    doc = {"circuit": {**BASE["circuit"], **patch.get("circuit", {})}, "solver": BASE["solver"]}
    if "metrics" in patch:
        doc["metrics"] = patch["metrics"]
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, name="bad.toml")
    message = str(err.value)
    assert "\n" not in message and message.startswith("bad.toml: ") and words in message, message


def test_logic_needs_a_circuit_and_all_three_keys_without_the_template():
    resistive = {"circuit": {"template": "resistive", "schedule": {"make": [1e-4], "break": []}}}
    with pytest.raises(ValueError, match=r"^s: metrics.logic needs low, high \("):
        scene_from_dict({**resistive, "metrics": {"logic": {"node": "v(load)"}}}, name="s")
    with pytest.raises(ValueError, match=r"^s: metrics.logic reads a node voltage of the circuit: it needs a "
                                         r"\[circuit\]"):
        scene_from_dict({"metrics": {"logic": {"node": "v(pin)", "low": 1.0, "high": 2.0}}}, name="s")
    scene = scene_from_dict({**resistive, "metrics": {"logic": {"node": "v(load)", "low": 1.0, "high": 2.0}}})
    assert scene.metrics.logic == LogicInput("v(load)", 1.0, 2.0)
    assert scene_from_dict(resistive).metrics.logic is None  # off unless asked for (or an mcu_input)
