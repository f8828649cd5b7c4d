"""The examples/ scripts in fast mode: each runs once, and its output obeys the physics it shows.

Checks are closed forms and physical bounds computed from the scenes' own parameters
(tomllib on the example's TOML), applied to the files the example writes and to the
numbers its main() returns; no number is taken from a previous run.
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from circuit import ArcModel
from coupling.laws.tribology import default_fit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _load(name: str):
    if str(EXAMPLES) not in sys.path:  # the scripts import their shared example_cli
        sys.path.insert(0, str(EXAMPLES))
    spec = importlib.util.spec_from_file_location(f"switchsim_example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _toml(name: str) -> dict:
    return tomllib.loads((EXAMPLES / f"{name}.toml").read_text())


def _run(tmp_path_factory, name: str):
    out = tmp_path_factory.mktemp(name)
    numbers = _load(name).main(fast=True, out=out)
    return numbers, out


def _closed(out: Path, tip: int | None = None) -> list[tuple[float, float]]:
    """Merged contact intervals (s) from the mechanics' contacts.csv in folder ``out``, of
    every contact pair or of pair ``tip``."""
    c = pd.read_csv(out / "contacts.csv")
    c = (c if tip is None else c[c.tip == tip]).sort_values("t_start")
    merged: list[list[float]] = []
    for a, b in zip(c.t_start, c.t_end):
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    return [(a, b) for a, b in merged]


def _gap(out: Path, times: np.ndarray) -> np.ndarray:
    h = pd.read_csv(out / "history.csv")
    heights = np.minimum(h.tip_height_0.to_numpy(), h.tip_height_1.to_numpy())
    return np.maximum(np.interp(times, h.time.to_numpy(), heights), 0.0)


def _series_resistance(c: dict) -> float:
    return c["source_resistance"] + c["wiring_resistance"] + c["load_resistance"]


# --- resistive_bounce ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def resistive(tmp_path_factory):
    return _run(tmp_path_factory, "resistive_bounce")


def test_resistive_bounces_and_contact_voltage_is_the_divider(resistive):
    numbers, out = resistive
    c = _toml("resistive_bounce")["circuit"]
    E, R = c["voltage"], _series_resistance(c)
    assert numbers["bounces"] >= 1
    closed = _closed(out)
    assert numbers["bounces"] == len(closed) - 1
    w = pd.read_csv(out / "waveforms.csv")
    t, v = w.time.to_numpy(), w.contact_voltage.to_numpy()
    assert np.all(np.abs(v[t < closed[0][0]] - E) < 1e-4)  # open before the first make: the full supply
    firm = np.zeros(len(t), bool)
    for a, b in closed:
        firm |= (t > a + 1e-6) & (t < b - 1e-6)
    firm &= (w.normal_force.to_numpy() >= 1.0) & np.isfinite(w.contact_resistance.to_numpy())
    assert firm.sum() > 50
    rc, i_c, i_load = (w[col].to_numpy()[firm] for col in ("contact_resistance", "contact_current", "load_current"))
    # Ohm across the contact (to the node voltages' accuracy: the mV contact voltage is the
    # difference of two ~E node potentials, each converged to RELTOL = 1e-6 of E), the loop
    # as a divider, and R_c as the tribometer law says
    assert np.max(np.abs(v[firm] - i_c * rc)) < 5e-6 * E
    assert np.max(np.abs(i_load / (E / (R + rc)) - 1.0)) < 5e-3
    laws = default_fit().laws
    assert np.max(np.abs(rc / laws.contact_resistance(w.normal_force.to_numpy()[firm], i_c) - 1.0)) < 1e-4
    assert np.all(v[firm] < 0.1)  # a closed contact drops millivolts


def test_resistive_arc_at_each_break_holds_the_gap_voltage(resistive):
    numbers, out = resistive
    doc = _toml("resistive_bounce")
    c, arc = doc["circuit"], doc["circuit"]["arc"]
    E, R = c["voltage"], _series_resistance(c)
    U, I_min, E_col = arc["min_voltage"], arc["min_current"], arc["column_gradient"]
    assert E / R > I_min and E - I_min * R > U  # so every break must arc (closed form)
    assert numbers["breaks"] >= 1 and numbers["breaks_that_arced"] == numbers["breaks"]
    w = pd.read_csv(out / "waveforms.csv")
    t, v, i_arc = w.time.to_numpy(), w.contact_voltage.to_numpy(), w.arc_current.to_numpy()
    burning = np.abs(i_arc) >= I_min
    for a, b in _closed(out):  # the gap is open (the contact carries nothing) 1 us after a break
        burning &= ~((t >= a) & (t <= b + 1e-6))
    assert burning.sum() > 20
    assert np.all(v[burning] >= U)
    r_arc = arc.get("resistance", ArcModel().resistance)
    u_arc = U + E_col * _gap(out, t[burning]) + r_arc * np.abs(i_arc[burning])
    assert np.max(np.abs(v[burning] - u_arc)) < 2e-3
    assert np.max(np.abs(i_arc[burning] - (E - v[burning]) / R)) < 2e-3
    L, C = c["wiring_inductance"], c["contact_capacitance"]
    assert numbers["peak_contact_voltage"] <= E + I_min * math.sqrt(L / C) + 1e-6  # energy bound


# --- relay_coil_arc -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def relay(tmp_path_factory):
    return _run(tmp_path_factory, "relay_coil_arc")


def test_relay_arc_burns_above_u_min_and_is_chopped_at_i_min(relay):
    numbers, out = relay
    doc = _toml("relay_coil_arc")
    c, arc = doc["circuit"], doc["circuit"]["arc"]
    a = numbers["arc"]
    assert a["status"] == "ok" and a["bounces"] >= 1
    assert a["breaks_that_arced"] >= 1
    assert a["arc_voltage_min"] >= arc["min_voltage"]
    w = pd.read_csv(out / "arc" / "waveforms.csv")
    burning = np.abs(w.arc_current.to_numpy()) >= arc["min_current"]
    assert np.all(np.abs(w.contact_voltage.to_numpy()[burning]) >= arc["min_voltage"])
    assert a["extinction_time"] is not None
    assert abs(a["extinction_current"] / arc["min_current"] - 1.0) < 1e-3


def test_relay_opening_spike_is_e_plus_i_min_sqrt_l_over_c(relay):
    numbers, _ = relay
    c = _toml("relay_coil_arc")["circuit"]
    arc = c["arc"]
    E, U, I_min = c["voltage"], arc["min_voltage"], arc["min_current"]
    Z = math.sqrt((c["load_inductance"] + c["wiring_inductance"]) / c["contact_capacitance"])
    peak = numbers["arc"]["peak_after_extinction"]
    assert 0.95 * (E + I_min * Z) <= peak <= E + math.hypot(I_min * Z, E - U) + 1e-6
    assert numbers["arc"]["peak_contact_voltage"] == pytest.approx(peak)  # the opening sets the peak


def test_relay_flyback_and_snubber_suppress_the_spike(relay):
    numbers, _ = relay
    c = _toml("relay_coil_arc")["circuit"]
    arc = c["arc"]
    E, U, I_min = c["voltage"], arc["min_voltage"], arc["min_current"]
    spike = numbers["arc"]["peak_contact_voltage"]
    fly = numbers["arc + flyback diode"]
    assert fly["status"] == "ok"
    top = E + 1.5  # supply + a diode drop at <= 1 A
    bound = top + math.hypot(I_min * math.sqrt(c["wiring_inductance"] / c["contact_capacitance"]), top - U)
    assert fly["peak_contact_voltage"] <= bound < spike / 10
    snub = numbers["arc + RC snubber"]
    assert snub["status"] == "ok"
    L = c["load_inductance"] + c["wiring_inductance"]
    snubber = _load("relay_coil_arc").variants(True)["arc + RC snubber"].circuit.circuit.snubber
    Rs, Cs = snubber.resistance, snubber.capacitance
    assert snub["peak_contact_voltage"] <= E + I_min * (Rs + math.sqrt(L / Cs)) + (E - U) < spike / 10


def test_relay_without_arc_model_nothing_holds_the_gap(relay):
    numbers, _ = relay
    c = _toml("relay_coil_arc")["circuit"]
    E, R = c["voltage"], _series_resistance(c)
    Z = math.sqrt((c["load_inductance"] + c["wiring_inductance"]) / c["contact_capacitance"])
    no_arc = numbers["no arc model"]
    assert no_arc["status"] == "ok"
    assert no_arc["arc_energy"] == 0.0 and no_arc["breaks_that_arced"] == 0
    # the coil's current (at most E/R) rings into the gap capacitance: far above the arc's U_min
    assert c["arc"]["min_voltage"] * 10 < no_arc["peak_contact_voltage"] <= E + math.hypot(E / R * Z, E)
    bare = numbers["no arc model, no gap capacitance"]  # nothing physical bounds dv/dt: refused before running
    assert bare["status"] == "refused" and "contact_capacitance = 0 F" in bare["error"]


# --- capacitive_inrush --------------------------------------------------------------------


@pytest.fixture(scope="module")
def inrush(tmp_path_factory):
    return _run(tmp_path_factory, "capacitive_inrush")


def test_inrush_peak_is_e_over_r_series(inrush):
    numbers, _ = inrush
    c = _toml("capacitive_inrush")["circuit"]
    E, R = c["voltage"], _series_resistance(c)
    assert numbers["bounces"] >= 1
    assert 0.97 * E / R <= numbers["inrush_peak_a"] <= E / R
    for k in numbers["contacts"]:  # each re-make on a partly charged capacitor
        assert 0 <= k["capacitor_voltage_at_make"] < E
        assert k["peak_current"] == pytest.approx(k["predicted_peak"], rel=0.02)
    assert numbers["contacts"][-1]["peak_current"] < numbers["contacts"][0]["peak_current"]


def test_inrush_arcs_only_while_the_gap_voltage_allows(inrush):
    numbers, _ = inrush
    c = _toml("capacitive_inrush")["circuit"]
    arc = c["arc"]
    R = _series_resistance(c)
    for k in numbers["contacts"]:
        if k["gap_voltage_available"] < arc["min_voltage"]:
            assert not k["arced_after_break"]
        elif (k["gap_voltage_available"] > arc["min_voltage"] + arc["min_current"] * R + 0.5
              and k["current_before_break"] > arc["min_current"]):
            assert k["arced_after_break"]


def test_inrush_current_lowers_r_c_and_raises_mu_as_the_fit_says(inrush):
    numbers, out = inrush
    laws = default_fit().laws
    lo, hi = laws.resistance_law.current_range_A
    w = pd.read_csv(out / "waveforms.csv")
    f, rc, i_c = w.normal_force.to_numpy(), w.contact_resistance.to_numpy(), w.contact_current.to_numpy()
    firm = (f >= 1.0) & np.isfinite(rc)
    ratio = rc[firm] / laws.contact_resistance(f[firm], 0.0)
    # ngspice evaluates g(I) at its last Newton iterate, converged to RELTOL (the scene's,
    # the circuit package's 1e-4 unless set): the agreement to expect
    reltol = float(_toml("capacitive_inrush")["circuit"].get("reltol", 1e-4))
    assert np.max(np.abs(ratio / laws.resistance_law.current_factor(i_c[firm]) - 1.0)) < 2 * reltol
    g_floor = float(laws.resistance_law.current_factor(hi))
    assert np.all((ratio >= g_floor * (1 - 1e-6)) & (ratio <= 1.0 + 1e-9))
    assert numbers["current_factor_min"] < 1.0  # the inrush lowers R_c at the same force
    mu = w.mu.to_numpy()
    assert np.all((mu >= laws.mu(0.0) - 1e-12) & (mu <= laws.mu(hi) + 1e-12))
    assert numbers["mu_max"] > laws.mu(0.0)


# --- mu_feedback --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def feedback(tmp_path_factory):
    return _run(tmp_path_factory, "mu_feedback")


def test_feedback_off_keeps_mu0_and_on_follows_the_current(feedback):
    numbers, out = feedback
    laws = default_fit().laws
    mu0 = float(laws.mu(0.0))
    for case in ("impact", "sliding"):
        off, on = numbers[case]["off"]["mu"], numbers[case]["on"]["mu"]
        assert off["max_dev_from_mu0"] < 1e-12
        assert on["tracking_max_rel_dev"] < 1e-3
        assert on["mu_max"] > mu0
    # "no current": below 1 uA (the open gap leaks E x 1 nS = 24 nA; mu(24 nA) - mu(0) ~ 2e-9)
    assert numbers["impact"]["on"]["mu"]["max_dev_from_mu0_without_current"] < 1e-7
    w = pd.read_csv(out / "impact_feedback_on" / "waveforms.csv")
    before = w.time < pd.read_csv(out / "impact_feedback_on" / "contacts.csv").t_start.min()
    assert np.allclose(w.mu[before], mu0, rtol=0, atol=1e-7)  # no current before the first make


def test_feedback_sliding_stop_time_is_the_closed_form(feedback):
    numbers, _ = feedback
    laws = default_fit().laws
    sl = numbers["sliding"]
    for key in ("on", "off"):
        assert sl[key]["t_stop"] == pytest.approx(sl[key]["t_stop_closed_form"], rel=0.02)
        assert sl[key]["distance"] == pytest.approx(sl[key]["distance_closed_form"], rel=0.03)
    assert sl["off"]["mu_used"] == pytest.approx(float(laws.mu(0.0)), rel=1e-9)
    assert sl["on"]["mu_used"] == pytest.approx(float(laws.mu(sl["on"]["current"])), rel=1e-6)
    ratio = sl["on"]["t_stop"] / sl["off"]["t_stop"]
    assert ratio == pytest.approx(sl["off"]["mu_used"] / sl["on"]["mu_used"], rel=0.02)


def test_feedback_on_impacts_scales_the_friction_impulse_by_the_mu_ratio(feedback):
    numbers, _ = feedback
    imp = numbers["impact"]
    mu_ratio = numbers["summary"]["mu_at_current"] / numbers["summary"]["mu0"]
    on, off = imp["on"]["contacts"][0], imp["off"]["contacts"][0]
    assert on["tangential_impulse"] / off["tangential_impulse"] == pytest.approx(mu_ratio, rel=0.05)
    gamma = default_fit().laws.gamma
    for row in imp["on"]["contacts"] + imp["off"]["contacts"]:
        # |F_t| <= mu_max F_n^(1 - gamma) and F_n^(1 - gamma) <= F_peak^(1 - gamma): J_t bounded by the contact time
        bound = numbers["summary"]["mu_at_current"] * 1.1 * row["peak_force"] ** (1 - gamma) * (row["t_end"] - row["t_start"])
        assert 0 < row["tangential_impulse"] <= bound


# --- incidence_angle_study ----------------------------------------------------------------


@pytest.fixture(scope="module")
def angles(tmp_path_factory):
    return _run(tmp_path_factory, "incidence_angle_study")


def test_incidence_rigid_bar_rebounds_at_the_calibration_target(angles):
    numbers, out = angles
    target = _toml("incidence_angle_study")["contact"]["restitution"]
    rigid = numbers["results"]["rigid, e = 0.8"]
    assert all(abs(r["kinematic"] - target) < 5e-3 for r in rigid)
    undamped = numbers["results"]["rigid, e = 1 (no contact damping)"]
    assert all(r["damping"] == 0.0 and abs(r["kinematic"] - 1.0) < 5e-3 for r in undamped)
    assert (out / "restitution_vs_angle.png").stat().st_size > 0 and (out / "vibration_vs_angle.png").is_file()


def test_incidence_flexible_bar_loses_energy_to_vibration(angles):
    numbers, _ = angles
    res = numbers["results"]
    flex = next(k for k in res if k.startswith("flexible") and "e = 0.8" in k)
    flex1 = next(k for k in res if k.startswith("flexible") and "e = 1" in k)
    for name in (flex, flex1):
        for r, rigid in zip(res[name], res["rigid, e = 0.8" if name == flex else "rigid, e = 1 (no contact damping)"]):
            assert r["damping"] == pytest.approx(rigid["damping"], rel=1e-12)  # the same contact law
            assert r["complete"] and 0.0 < r["kinematic"] <= 1.0
            assert 0.0 < r["vibration_fraction"] < 1.0
            assert r["vibration_fraction"] + r["dissipated_fraction"] <= 1.0 + 1e-3  # energy bound
    for r in res[flex1]:  # no contact damping: what the bar does not give back stays in vibration
        assert r["dissipated_fraction"] == pytest.approx(0.0, abs=1e-9)
        assert r["kinematic"] < 1.0
    for rows in res.values():
        assert all(r["energy_relative_residual"] < 1e-3 for r in rows)
    s = numbers["summary"]
    assert s[flex]["kinematic_spread"] > s["rigid, e = 0.8"]["kinematic_spread"]


def test_examples_write_their_json(resistive, relay, inrush, feedback, angles):
    for numbers, out in (resistive, relay, inrush, feedback, angles):
        assert json.loads((out / "example.json").read_text()).keys() == numbers.keys()


# --- paper_experiment ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    return _run(tmp_path_factory, "paper_experiment")


def test_paper_closed_contact_carries_the_set_current(paper):
    """A supply in constant-current mode: while firmly closed (the make's ring settled) the loop
    carries I_set R_out / (R_out + R_loop + R_c), so I_set within the output resistance's share, to
    ngspice's RELTOL (the scene's, 1e-4: the 5e-5 share is below it) and the make ring's envelope."""
    numbers, out = paper
    doc = _toml("paper_experiment")["circuit"]
    reltol = float(doc.get("reltol", 1e-4))
    share = (doc["load_resistance"] + doc["wiring_resistance"]) / doc["output_resistance"]
    for current in (1.0, 2.0, 5.0):
        run_ = numbers["runs"][f"{current:g} A"]
        c = run_["circuit"]
        assert run_["status"] == "ok" and c["set_current"] == current
        assert c["closed_points"] >= 5
        assert c["closed_current_max_rel_error"] <= 2 * reltol + c["make_ring_bound"]
        assert c["output_resistance_share"] == pytest.approx(share, rel=0.05)  # R_c adds milliohms
        # every make discharges C_out (charged to the compliance) into the loop: above I_set, at most
        # I_set + V_comp / sqrt(L / C_out)
        z = math.sqrt(doc["wiring_inductance"] / doc["output_capacitance"])
        assert current < c["peak_current"] <= current + doc["compliance_voltage"] / z
    w = pd.read_csv(out / "1_A" / "waveforms.csv")
    first_make = _closed(out / "1_A")[0][0]
    open_v = numbers["runs"]["1 A"]["circuit"]["open_voltage"]
    assert np.allclose(w.contact_voltage[w.time < first_make], open_v, atol=1e-4)  # open: at the compliance
    assert abs(open_v - doc["compliance_voltage"]) < 0.01


def test_paper_friction_dissipation_rises_with_current_as_mu_does(paper):
    numbers, _ = paper
    laws = default_fit().laws
    mus, diss = numbers["mu_by_current"], numbers["friction_dissipation_by_current"]
    assert mus == pytest.approx([float(laws.mu(i)) for i in numbers["currents"]], rel=1e-12)
    assert all(a < b for a, b in zip(mus, mus[1:]))  # the fit's mu rises with current ...
    assert all(a < b for a, b in zip(diss, diss[1:]))  # ... and so does the energy friction takes
    # the impact's normal motion barely changes (gamma = 0.7: F_t/F_n ~ 1e-3 at ~1 kN) and the tip
    # slips throughout, so friction's energy mu(I) int F_n^0.3 v_slip dt scales with mu(I)
    for mu, d in zip(mus[1:], diss[1:]):
        assert d / diss[0] == pytest.approx(mu / mus[0], rel=0.03)
    e = numbers["first_restitution_by_current"]
    assert max(e) - min(e) < 0.01
    assert numbers["gamma"] == pytest.approx(laws.gamma)


def test_paper_flexible_bar_rebounds_lower_than_the_rigid_bar(paper):
    numbers, out = paper
    assert numbers["first_restitution_rigid_1A"] == pytest.approx(_toml("paper_experiment")["contact"]["restitution"],
                                                                   abs=5e-3)
    assert numbers["first_restitution_by_current"][1] < numbers["first_restitution_rigid_1A"] - 0.1
    for png in ("tip_velocity_1A.png", "friction_resistance_vs_load.png", "mu_vs_current.png"):
        assert (out / png).stat().st_size > 0
    assert json.loads((out / "example.json").read_text()).keys() == numbers.keys()


# --- relay_spring -------------------------------------------------------------------------


def _relay_closed_form(doc: dict, gravity: float = 9.80665) -> tuple[float, float]:
    """(R0 N, relative friction band) of the relay blade: cantilever statics + Hertz of the
    rivet pair, from the TOML's values alone."""
    from scipy.optimize import brentq
    bar, rv, blk, f = doc["bar"], doc["rivet"][0], doc["block"], doc["force"][0]
    clamp = doc["mount"]["position"]
    EI = bar["youngs_modulus"] * bar["width"] * bar["thickness"] ** 3 / 12.0
    a, b, span = clamp - f["position"], clamp - rv["position"], clamp
    e_star = 1.0 / ((1 - rv["poisson_ratio"] ** 2) / rv["youngs_modulus"]
                    + (1 - blk["poisson_ratio"] ** 2) / blk["youngs_modulus"])
    k = 4.0 / 3.0 * e_star * math.sqrt(rv["radius"] * blk["radius"] / (rv["radius"] + blk["radius"]))
    q = bar["density"] * bar["width"] * bar["thickness"] * gravity
    P = max(f["value"])
    w_free = (P * a * a * (3 * b - a) / (6 * EI) + q * b * b * (6 * span**2 - 4 * span * b + b * b) / (24 * EI)
              + rv["mass"] * gravity * b**3 / (3 * EI))
    R0 = brentq(lambda R: w_free - R * b**3 / (3 * EI) - doc["initial"]["height"] - (R / k) ** (2 / 3), 0.0, 10 * P)
    band = doc["tribology"]["mu"] * (abs(rv["offset"]) + rv["radius"]) * 1.5 / b
    return R0, band


@pytest.fixture(scope="module")
def relay_spring(tmp_path_factory):
    return _run(tmp_path_factory, "relay_spring")


def test_relay_spring_held_force_is_beam_statics(relay_spring):
    numbers, _ = relay_spring
    R0, band = _relay_closed_form(_toml("relay_spring"))
    v = {row["variant"]: row for row in numbers["variants"]}
    # friction made negligible: the closed form itself (residual ringing averaged over 0.5 ms)
    assert v["resistive, frictionless, closing only"]["held_force"] == pytest.approx(R0, rel=5e-3)
    # with mu = 0.3 the rivet's tangential force bends the blade too: within the friction band
    for name in ("resistive", "inductive"):
        assert abs(v[name]["held_force"] / R0 - 1.0) <= band * 1.02
        assert v[name]["settled"] and v[name]["closing_bounces"] >= 1
        # the summary's operations[].held.force, reported without a [duty] section: the median
        # over the whole held closure, the same statics (the closing-only variant's closure
        # starts on the force table's ramp, so its median lies below R0 by definition)
        assert abs(v[name]["summary_held_force"] / R0 - 1.0) <= band * 1.02


def test_relay_spring_loads_and_break(relay_spring):
    numbers, _ = relay_spring
    doc = _toml("relay_spring")
    c = doc["circuit"]
    E, R = c["voltage"], _series_resistance(c)
    v = {row["variant"]: row for row in numbers["variants"]}
    res, ind = v["resistive"], v["inductive"]
    # the mechanics does not see the load: same makes and bounces
    assert res["first_make"] == pytest.approx(ind["first_make"], abs=1e-9)
    assert res["closing_bounces"] == ind["closing_bounces"]
    # first make: the quasi-static time, when the ramped armature force's static deflection
    # at the rivet reaches the gap, give or take the blade's dynamic lag: each mode's response
    # to a ramp, r (t - sin(w t)/w), differs from the static one by at most r/w, so the make
    # lies within 1/w1 (w1: the bare blade's clamped-free fundamental, the rivet lowers it)
    bar, rv, f = doc["bar"], doc["rivet"][0], doc["force"][0]
    clamp = doc["mount"]["position"]
    EI = bar["youngs_modulus"] * bar["width"] * bar["thickness"] ** 3 / 12.0
    a, b = clamp - f["position"], clamp - rv["position"]
    p_make = doc["initial"]["height"] * 6 * EI / (a * a * (3 * b - a))
    t_qs = np.interp(p_make, f["value"][:2], f["time"][:2])
    w1 = 1.875104**2 / clamp**2 * math.sqrt(EI / (bar["density"] * bar["width"] * bar["thickness"]))
    assert abs(res["first_make"] - t_qs) < 1.0 / w1
    # both open after the release and end open
    for row in (res, ind):
        assert row["final_state"] == "open"
        assert row["break_time"] > numbers["release_start"]
    # the coil current builds with L/R: while the contact bounces (within ~1 ms of the
    # first make) it is far below E/R, so the bounce gaps draw much less arc energy
    # than the resistive load's
    assert ind["bounce_arc_energy"] < 0.1 * res["bounce_arc_energy"]
    # at the break the coil carries its full current E/(R + R_c), at most E/R
    assert ind["current_at_break"] <= E / R * 1.001
    assert ind["current_at_break"] > 0.95 * E / R
    # energy of the break: while the arc burns, E i - R i^2 >= 0 (i <= E/R), so the supply
    # pays at least the load's losses and the arc takes at least what the coil gives up
    # from the break current to I_min, 1/2 L (I^2 - I_min^2), less what the gap
    # capacitance holds at the peak (1/2 C V^2)
    L = 10e-3
    arc = c["arc"]
    bound = 0.5 * L * (ind["current_at_break"] ** 2 - arc["min_current"] ** 2) \
        - 0.5 * c["contact_capacitance"] * ind["break_peak_voltage"] ** 2
    assert ind["break_arc_energy"] >= bound
    assert ind["break_arc_energy"] > res["break_arc_energy"]
    # resistive break: the wiring's ringing after the arc goes out is bounded by E + I_min sqrt(L/C)
    bound = E + arc["min_current"] * math.sqrt(c["wiring_inductance"] / c["contact_capacitance"])
    assert res["break_peak_voltage"] <= bound
    # the coil's chopped current is clamped by the gap's breakdown, at most the breakdown of the largest gap
    assert ind["break_peak_voltage"] > bound
    assert ind["break_peak_voltage"] <= E + arc["min_current"] * math.sqrt(L / c["contact_capacitance"])


# --- pushbutton ---------------------------------------------------------------------------


def _lever_closed_form(doc: dict, gravity: float = 9.80665) -> tuple[float, float, float]:
    """(angle rad, R0 N, friction band N) of the rigid lever at rest, from the TOML alone."""
    from scipy.optimize import brentq
    bar, rv, blk, f, mnt = doc["bar"], doc["rivet"][0], doc["block"], doc["force"][0], doc["mount"]
    d, h, g = mnt["position"] - rv["position"], rv["offset"], doc["initial"]["height"]
    e_star = 1.0 / ((1 - rv["poisson_ratio"] ** 2) / rv["youngs_modulus"]
                    + (1 - blk["poisson_ratio"] ** 2) / blk["youngs_modulus"])
    k = 4.0 / 3.0 * e_star * math.sqrt(rv["radius"])
    m_bar = bar["density"] * bar["width"] * bar["thickness"] * bar["length"]
    torque = max(f["value"]) * (mnt["position"] - f["position"]) + gravity * (
        m_bar * (mnt["position"] - bar["length"] / 2) + rv["mass"] * d)

    def R(th):
        return k * max(d * math.sin(th) + h * (1 - math.cos(th)) - g, 0.0) ** 1.5

    th = brentq(lambda th: torque * math.cos(th) - mnt["stiffness"] * th - R(th) * (d * math.cos(th) + h * math.sin(th)),
                math.asin(g / d), 0.5)
    depth = abs(h * math.cos(th) - d * math.sin(th)) + rv["radius"]
    return th, R(th), doc["tribology"]["mu"] * R(th) * depth / d


@pytest.fixture(scope="module")
def pushbutton(tmp_path_factory):
    return _run(tmp_path_factory, "pushbutton")


def test_pushbutton_held_force_is_the_lever_moment_balance(pushbutton):
    numbers, _ = pushbutton
    th, R0, band = _lever_closed_form(_toml("pushbutton"))
    v = {row["variant"]: row for row in numbers["variants"]}
    free = v["frictionless"]
    # (finger torque - spring torque at that angle) / arm, the lever nearly rigid (2 mm steel)
    assert free["held_angle"] == pytest.approx(th, rel=2e-3)
    assert free["held_force"] == pytest.approx(R0, rel=2e-3)
    fr = v["with friction"]
    assert fr["held_angle"] == pytest.approx(th, rel=2e-3)
    assert abs(fr["held_force"] - R0) <= band
    # friction's moment about the hinge accounts for the difference: F_t at the contact
    # point's depth below the hinge, over the arm
    depth = abs(_toml("pushbutton")["rivet"][0]["offset"]) + _toml("pushbutton")["rivet"][0]["radius"] \
        + (_toml("pushbutton")["mount"]["position"] - _toml("pushbutton")["rivet"][0]["position"]) * math.sin(th)
    arm = _toml("pushbutton")["mount"]["position"] - _toml("pushbutton")["rivet"][0]["position"]
    assert abs(fr["held_force"] - R0) == pytest.approx(abs(fr["held_friction"]) * depth / arm, rel=0.05)


def test_pushbutton_first_make_is_the_rigid_lever_ode(pushbutton):
    # the lever (2 mm steel) turns as a rigid body until it touches: I th'' = (F(t) d_F +
    # weights) cos th - k_t th - c th', integrated here independently of mech; the make is
    # when the rivet reaches the pad
    from scipy.integrate import solve_ivp
    numbers, _ = pushbutton
    doc = _toml("pushbutton")
    bar, rv, f, mnt = doc["bar"], doc["rivet"][0], doc["force"][0], doc["mount"]
    g = 9.80665
    m_bar = bar["density"] * bar["width"] * bar["thickness"] * bar["length"]
    d, h, d_f = mnt["position"] - rv["position"], rv["offset"], mnt["position"] - f["position"]
    inertia = m_bar * (bar["length"] ** 2 / 3 + bar["thickness"] ** 2 / 12) + rv["mass"] * (
        d * d + h * h + 0.4 * rv["radius"] ** 2)
    weights = g * (m_bar * (mnt["position"] - bar["length"] / 2) + rv["mass"] * d)

    def rhs(t, y):
        torque = (np.interp(t, f["time"], f["value"]) * d_f + weights) * math.cos(y[0])
        return [y[1], (torque - mnt["stiffness"] * y[0] - mnt["damping"] * y[1]) / inertia]

    def touch(t, y):
        return d * math.sin(y[0]) + h * (1 - math.cos(y[0])) - doc["initial"]["height"]
    touch.terminal, touch.direction = True, 1
    sol = solve_ivp(rhs, (0.0, numbers["release_start"]), [0.0, 0.0], events=touch, rtol=1e-10, atol=1e-14)
    t_make = float(sol.t_events[0][0])
    for row in numbers["variants"]:
        assert row["first_make"] == pytest.approx(t_make, rel=1e-3)


def test_pushbutton_opens_after_release(pushbutton):
    numbers, _ = pushbutton
    doc = _toml("pushbutton")
    for row in numbers["variants"]:
        assert row["settled"]
        assert row["final_state"] == "open"
        assert row["break_time"] > numbers["release_start"]
        # the return spring turns the lever back towards its start: the gap at the end is positive,
        # at most twice the travel (an undamped swing through the start and back)
        assert 0.0 < row["final_gap"] <= 2.0 * doc["initial"]["height"]
        # 5 V, no arc: the contact voltage never exceeds the supply by more than the wiring's ringing
        c = doc["circuit"]
        assert row["bounce_peak_voltage"] <= c["voltage"] + c["voltage"] / _series_resistance(c) * math.sqrt(
            c["wiring_inductance"] / c["contact_capacitance"])


# --- free_drop ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def free_drop(tmp_path_factory):
    return _run(tmp_path_factory, "free_drop")


def test_free_drop_is_the_builtin_scene():
    assert _toml("free_drop") == tomllib.loads(
        (EXAMPLES.parent / "coupling" / "scenes" / "free_drop.toml").read_text())


def test_free_drop_touches_down_in_free_fall_and_flies_off(free_drop):
    numbers, _ = free_drop
    doc = _toml("free_drop")
    g = 9.80665
    v0, h = -doc["initial"]["velocity"][2], doc["initial"]["height"]
    v = math.sqrt(v0 * v0 + 2 * g * h)
    first = numbers["contacts"][0]
    assert first["t_start"] == pytest.approx((v - v0) / g, rel=1e-4)
    assert first["normal_speed_in"] == pytest.approx(v, rel=1e-4)
    assert 0.0 < first["kinematic_restitution"] < 1.0
    assert numbers["final_state"] == "open"
    assert numbers["flight_acceleration"] == pytest.approx(-g, rel=1e-3)


# --- pushbutton_debounce ------------------------------------------------------------------


@pytest.fixture(scope="module")
def debounce(tmp_path_factory):
    return _run(tmp_path_factory, "pushbutton_debounce")


def _pin_edges(intervals, t_end: float, c: dict, r_pull: float, c_in: float) -> tuple[int, float]:
    """(edges, margin V) of the pin on the run's own contact intervals, by the closed form of
    the mcu_input network: after each make an exponential towards 0 with tau = R_series C
    (R_c, milliohms, and the 5 pF across the contact neglected against kOhm and nF), after each
    break towards Vcc with (R_pull + R_series) C; a Schmitt input with the scene's thresholds.
    margin: the smallest distance to the threshold that would switch the input at the end of
    an interval that does not switch it."""
    vcc, low, high = c["voltage"], c["logic_low"], c["logic_high"]
    bounds = [0.0] + [t for iv in intervals for t in iv if 0.0 < t < t_end] + [t_end]
    v, level, edges, margin = vcc, True, 0, math.inf
    for k, (t0, t1) in enumerate(zip(bounds[:-1], bounds[1:])):
        closed = k % 2 == 1
        r_series = c["series_resistance"]
        target, tau = (0.0, r_series * c_in) if closed else (vcc, (r_pull + r_series) * c_in)
        v_end = target + (v - target) * math.exp(-(t1 - t0) / tau)
        threshold = low if level else high
        if (level and v_end < low) or (not level and v_end > high):
            edges, level = edges + 1, not level
        else:
            margin = min(margin, abs(v_end - threshold))
        v = v_end
    return edges, margin


def test_debounce_edges_are_the_rc_closed_form_on_the_bounces(debounce):
    numbers, out = debounce
    c = _toml("pushbutton_debounce")["circuit"]
    compared = 0
    for row in numbers["grid"]:
        assert row["status"] == "ok" and row["final_level"] == "low"  # pressed: the input reads low
        expected, margin = _pin_edges(row["closed_intervals"], _toml("pushbutton_debounce")["solver"]["t_end"], c,
                                      row["pull_resistance"], row["input_capacitance"])
        if margin > 0.02 * c["voltage"]:  # the neglected R_c and 5 pF move the pin by < 0.5 % of Vcc
            assert row["edges"] == expected, row
            compared += 1
    assert compared == len(numbers["grid"])  # no grid point is a near miss
    summary = json.loads((out / "summary.json").read_text())
    assert summary["logic"]["edges"] == 1 and summary["logic"]["node"] == "v(pin)"


def test_debounce_edge_count_falls_with_r_and_c(debounce):
    numbers, _ = debounce
    edges = {(r["pull_resistance"], r["input_capacitance"]): r["edges"] for r in numbers["grid"]}
    pullups, caps = sorted({k[0] for k in edges}), sorted({k[1] for k in edges})
    for r in pullups:
        assert all(edges[(r, a)] >= edges[(r, b)] for a, b in zip(caps[:-1], caps[1:]))
    for cap in caps:
        assert all(edges[(a, cap)] >= edges[(b, cap)] for a, b in zip(pullups[:-1], pullups[1:]))
    # a press starts high and ends low: an odd number of edges; with the smallest R C the input
    # follows every make and break (7 makes, 6 breaks in this press)
    n_contacts = len(numbers["grid"][0]["closed_intervals"])
    assert all(n % 2 == 1 for n in edges.values())
    assert edges[(pullups[0], caps[0])] == 2 * n_contacts - 1 and n_contacts > 1


def test_debounce_chosen_rc_bridges_the_longest_bounce_opening(debounce):
    numbers, _ = debounce
    c = _toml("pushbutton_debounce")["circuit"]
    vcc, high, r_series = c["voltage"], c["logic_high"], c["series_resistance"]
    longest = max(numbers["bounce_openings"])
    contacts = [b - a for a, b in numbers["grid"][0]["closed_intervals"]]
    chosen = numbers["chosen"]
    assert chosen is not None and chosen["edges"] == 1
    # every contact discharges C through R_series to ~0 (>= 5 time constants), so each opening
    # starts from 0 and the pin reads high again after tau ln(Vcc / (Vcc - V_high))
    for row in numbers["grid"]:
        assert min(contacts) > 5 * r_series * row["input_capacitance"]
        crossing = (row["pull_resistance"] + r_series) * row["input_capacitance"] * math.log(vcc / (vcc - high))
        assert (row["edges"] == 1) == (crossing > longest), row
    assert chosen["rc"] == min(r["rc"] for r in numbers["grid"] if r["edges"] == 1)
    # the one edge comes when the first contact has discharged C to V_low: R_series C ln(Vcc / V_low),
    # 12 us; the edge time is interpolated between ngspice's points, ~2.5 us apart there, off by up to
    # h^2 / (8 tau) = 80 ns (0.7 %; measured 0.6 %)
    assert chosen["latency"] == pytest.approx(r_series * chosen["input_capacitance"] * math.log(vcc / c["logic_low"]),
                                              rel=0.02)


# --- plunger_solenoid: the solenoid pulled in by a 12 V step ------------------------

@pytest.fixture(scope="module")
def solenoid(tmp_path_factory):
    return _run(tmp_path_factory, "plunger_solenoid")


def test_solenoid_current_rises_with_the_open_magnets_l_over_r(solenoid):
    numbers, out = solenoid
    coil = _toml("plunger_solenoid")["coil"]
    assert numbers["status"] == "ok"
    early = numbers["early"]
    # before the armature has moved (travel below 1e-4 of its 4.75 mm) the coil is an R-L
    # with the open magnet's unsaturated inductance
    assert early["travel"] < 1e-4 * numbers["travel"]
    tau = numbers["tau_open"]
    assert early["current"] == pytest.approx(coil["voltage"] / coil["resistance"] * (1 - math.exp(-early["time"] / tau)),
                                             rel=2e-3)


def test_solenoid_current_dips_while_the_armature_flies_and_then_rises_to_v_over_r(solenoid):
    numbers, out = solenoid
    coil = _toml("plunger_solenoid")["coil"]
    w = pd.read_csv(out / "waveforms.csv")
    # the back-EMF i dL/dt of the closing gap: the current falls towards the arrival
    assert numbers["current_at_arrival"] < 0.6 * numbers["peak_current_before_arrival"]
    # the arrival (the mechanics' located stop event) is where the travel first reaches the
    # pole: short of it at every sample before; the stop holds it ~1.6 us (1e11 N/m), and the
    # first sample after it has left is no further from the pole than its rebound speed
    # carries it (the magnet pulls it back)
    x, t = w.armature_position.to_numpy(), w.time.to_numpy()
    travel, arrival = numbers["travel"], numbers["arrival"]
    assert x[t < arrival].max() < travel
    events = pd.read_csv(out / "events.csv")
    pole = events[events.stop == "pole"]
    (start,) = pole[pole.kind == "armature_stop_start"].time.to_numpy()[:1]
    left = pole[(pole.kind == "armature_stop_end") & (pole.time > start)].iloc[0]
    assert start == pytest.approx(arrival, abs=1e-12) and left.time - start < 5e-6
    k = np.searchsorted(t, left.time)
    assert 0.0 <= travel - x[k] <= abs(left.armature_velocity) * (t[k] - left.time) * (1 + 1e-6) + 1e-12
    # below V / R while the gap only closes (the back-EMF opposes the supply); the armature
    # rebounds from the nearly elastic stop (e = 0.99 from its 1e11 N/m and 400 N s/m), and
    # while the gap opens again the trapped flux drives the current above V / R
    before = w.time <= numbers["arrival"]
    assert w.coil_current[before].max() < coil["voltage"] / coil["resistance"]
    assert numbers["final_current"] > 0.95 * numbers["steady_current"]
    # the force F = psi^2 h(g) grows as the gap closes
    assert numbers["force_at_pole"] > 3 * numbers["force_at_peak_current"]


def test_solenoid_coil_energy_balance_closes(solenoid):
    numbers, _ = solenoid
    e = numbers["energy"]
    assert e["copper"] > 0 and e["magnetic_change"] > 0 and e["armature_work"] > 0
    assert e["into_coil"] == pytest.approx(e["copper"] + e["magnetic_change"] + e["armature_work"], rel=2e-3)


# --- relay_suppression: the default relay released with each coil suppression ---------------

@pytest.fixture(scope="module")
def suppression(tmp_path_factory):
    return _run(tmp_path_factory, "relay_suppression")


def test_suppression_clamps_the_coil_voltage_where_its_parts_say(suppression):
    numbers, _ = suppression
    import dataclasses

    from circuit.coil_drive import CoilDrive

    parts = {f.name: f.default for f in dataclasses.fields(CoilDrive)}
    rows = numbers["suppressions"]
    assert all(r["status"] == "ok" and r["break_complete"] for r in rows.values()), rows
    supply = 12.0
    # none: the driver avalanches, the coil sees supply - breakdown; a diode: one forward drop;
    # diode + zener: -(V_z + V_d)
    assert rows["none"]["coil_voltage_min"] == pytest.approx(supply - parts["switch_breakdown"], abs=1.0)
    assert -1.2 < rows["diode"]["coil_voltage_min"] < -0.3
    assert rows["zener"]["coil_voltage_min"] == pytest.approx(-parts["zener_voltage"] - 0.8, abs=0.7)
    # the RC: the current's first jump into R (I R) and then the capacitor's swing, bounded
    # by the coil's stored energy: C V^2 / 2 <= L I^2 / 2 (L from the closed magnet)
    assert rows["none"]["coil_voltage_min"] < rows["rc"]["coil_voltage_min"] < -numbers["rc"]["resistance"] * 0.01


def test_a_diode_slows_the_release_and_lengthens_the_break_arc(suppression):
    numbers, _ = suppression
    rows = numbers["suppressions"]
    release = {k: r["release_time"] for k, r in rows.items()}
    arc = {k: r["arc_duration"] for k, r in rows.items()}
    # the higher the coil's clamp, the faster its flux (and the armature's hold) collapses
    assert release["none"] < release["zener"] < release["diode"]
    assert release["none"] < release["rc"] < release["diode"]
    # a slow opening keeps the gap short while the current is still large: a longer arc
    assert arc["diode"] > max(arc["none"], arc["zener"], arc["rc"])
    assert rows["diode"]["arc_energy"] > max(rows[k]["arc_energy"] for k in ("none", "zener", "rc"))
    # the make is nearly the same in all four: while the coil is on the diodes are reverse
    # biased and the RC only charges (measured 4.4517-4.4537 ms)
    operate = [r["operate_time"] for r in rows.values()]
    assert max(operate) - min(operate) < 1e-3 * min(operate)


# --- bridge_contactor ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def bridge(tmp_path_factory):
    return _run(tmp_path_factory, "bridge_contactor")


def _extinction_gap(c: dict, arcs: int) -> float:
    """m: the summed gap at which ``arcs`` arcs in series go out, from the scene's circuit:
    V_s = (R_s + R_w + R_L + n R_arc) I_min + n U_min + E_col d_sum."""
    arc = c["arc"]
    loop = _series_resistance(c) + arcs * arc["resistance"]
    return (c["voltage"] - arcs * arc["min_voltage"] - arc["min_current"] * loop) / arc["column_gradient"]


def test_bridge_arcs_go_out_at_twice_the_arc_voltage(bridge):
    """The bridge's two arcs go out at the summed gap the closed form gives with 2 U_min, one
    contact of the same gap in the same circuit at the gap it gives with U_min: to 1e-3 (the
    last burning sample lies within ngspice's last step of the crossing; measured < 3e-4)."""
    numbers, out = bridge
    c = _toml("bridge_contactor")["circuit"]
    assert numbers["status"] == {"bridge": "ok", "one_contact": "ok"}
    b, one = numbers["bridge"], numbers["one_contact"]
    assert b["complete"] and one["complete"]
    assert b["gap"] == pytest.approx(_extinction_gap(c, 2), rel=1e-3)
    assert one["gap"] == pytest.approx(_extinction_gap(c, 1), rel=1e-3)
    # the bridge breaks when its first rivet parts, one contact (both rivets in parallel) when
    # its last does (contacts.csv: each rivet's last contact interval)
    ends = {}
    for case in ("bridge", "one_contact"):
        c = pd.read_csv(out / case / "contacts.csv")
        ends[case] = [float(c.t_end[c.tip == k].max()) for k in (0, 1)]
    assert b["break_time"] == pytest.approx(min(ends["bridge"]), rel=1e-12)
    assert one["break_time"] == pytest.approx(max(ends["one_contact"]), rel=1e-12)
    assert numbers["arc_duration_ratio"] < 0.5 and b["arc_energy"] < 0.5 * one["arc_energy"]


def test_bridge_is_closed_only_while_both_rivets_touch(bridge):
    """The bridge's closed intervals are the two rivets' contact intervals (contacts.csv, tip 0
    and tip 1) intersected; the load current flows in them (Ohm's law of the loop) and, after
    the break's arcs, not at all."""
    numbers, out = bridge
    c = pd.read_csv(out / "bridge" / "contacts.csv")
    per_tip = [sorted(zip(c.t_start[c.tip == k], c.t_end[c.tip == k])) for k in (0, 1)]
    both = sorted((max(p[0], q[0]), min(p[1], q[1])) for p in per_tip[0] for q in per_tip[1]
                  if max(p[0], q[0]) < min(p[1], q[1]))
    np.testing.assert_allclose(np.array(numbers["bridge"]["closed_intervals"]), np.array(both), rtol=1e-12)
    w = pd.read_parquet(out / "bridge" / "waveforms.parquet")
    t, i = w.time.to_numpy(), w.load_current.to_numpy()
    circuit = _toml("bridge_contactor")["circuit"]
    steady = np.zeros(len(t), bool)
    for a, e in both:
        steady |= (t > a + 50e-6) & (t < e - 50e-6)  # (past the make's ringing, before the parting)
    # Ohm's law with each contact's own resistance (10-20 milliohm at ~1 N each), to ngspice's
    # RELTOL 1e-4 on the current and on each contact's conductance node
    loop = _series_resistance(circuit) + w.contact_resistance_a.to_numpy() + w.contact_resistance_b.to_numpy()
    assert steady.sum() > 10
    np.testing.assert_allclose(i[steady], circuit["voltage"] / loop[steady], rtol=2e-4)
    after = t > numbers["bridge"]["time"] + 50e-6
    assert np.max(np.abs(i[after])) < 1e-6


# --- changeover_relay ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def changeover(tmp_path_factory):
    return _run(tmp_path_factory, "changeover_relay")


def test_changeover_transfers_break_before_make_at_the_mechanics_instants(changeover):
    """Form C on the coil-driven relay: from the mechanics' own contact table (contacts.csv,
    pair 0 on NO, pair 1 on NC), NC holds until the operate break, NO makes after it (the
    transfer time), bounces and holds; at release NO breaks and NC makes after it, with
    bounces of its own. The example's numbers are those instants and counts; no instant has
    both throws closed. The relay's operate and release times are NO's (the first contact:
    the unsuffixed results), from the coil's switching times in the scene."""
    numbers, out = changeover
    coil = _toml("changeover_relay")["coil"]
    assert numbers["status"] == "ok" and numbers["warnings"] == []
    no, nc = _closed(out / "changeover", 0), _closed(out / "changeover", 1)
    co = numbers["changeover"]
    op, rel = co["operate"][0], co["release"][0]
    assert nc[0][0] < 1e-9 and nc[0][1] == op["nc_break"] and no[0][0] == op["no_make"]
    assert co["transfer_time"] == pytest.approx(no[0][0] - nc[0][1], rel=1e-12)
    window = 1e-3  # the default settle window: the bounces are the closures before the held one
    held = next(k for k, (a, b) in enumerate(no) if b - a >= window)
    assert op["no_bounces"] == held > 0
    assert rel["no_break"] == no[held][1] and rel["nc_make"] == nc[1][0]
    held_nc = next(k for k, (a, b) in enumerate(nc[1:]) if b - a >= window)
    assert rel["nc_bounces"] == held_nc > 0
    assert co["break_before_make"] and all(b <= c or d <= a for a, b in no for c, d in nc)
    assert numbers["relay"]["operate_time"] == pytest.approx(op["no_make"] - coil["on_time"], rel=1e-12)
    assert numbers["relay"]["release_time"] == pytest.approx(rel["no_break"] - coil["off_time"], rel=1e-12)
    for name in ("NO", "NC"):
        assert (out / "changeover" / f"openings_{name}.csv").exists()
    assert (out / "throws.png").exists()


def test_changeover_arcs_go_out_at_their_throws_closed_form(changeover):
    """Each break's arc (NC's at operate, NO's at release) goes out where its loop can no
    longer hold I_min across U_min plus the column: d* = (V - U_min - I_min (R_s + R_w +
    R_load + R_arc)) / E_col with that throw's own load (20 ohm on NC, 10 ohm on NO), to
    1e-3 as the bridge's (the last burning sample lies within ngspice's last step of the
    crossing)."""
    numbers, out = changeover
    c = _toml("changeover_relay")["circuit"]
    arc = ArcModel(**c["arc"])
    w = pd.read_csv(out / "changeover" / "waveforms.csv")
    t = w.time.to_numpy()
    co = numbers["changeover"]
    for name, start, stop, load in (("NC", co["operate"][0]["nc_break"], co["operate"][0]["no_make"],
                                     c["nc_load_resistance"]),
                                    ("NO", co["release"][0]["no_break"], co["release"][0]["nc_make"],
                                     c["load_resistance"])):
        burning = np.flatnonzero((np.abs(w[f"arc_current_{name}"].to_numpy()) > 1e-3) & (t > start) & (t < stop))
        assert len(burning) and t[burning[-1]] < stop  # out before the other throw makes
        gap = w[f"gap_{name}"].to_numpy()[burning[-1]]
        loop = c["source_resistance"] + c["wiring_resistance"] + load + arc.resistance
        closed_form = (c["voltage"] - arc.min_voltage - arc.min_current * loop) / arc.column_gradient
        assert gap == pytest.approx(closed_form, rel=1e-3), name


# --- tactile_switch: a snap dome pressed and released by a finger ---------------------------


def test_tactile_switch_snaps_breaks_at_the_return_force_and_its_rc_gives_one_edge_each_way(tmp_path_factory):
    """The finger (a time table rising to 3 N, held, falling) on the dome (press and release
    branches, examples/tactile_switch.toml): the make comes only once the finger has passed
    the dome's peak (1.6 N at 5.33 ms: below it the press branch holds the plunger
    quasi-statically, the 0.5 ms ramp steps being far slower than its ~0.2 ms period); the
    break comes when the finger has fallen to the dome's return force at the pad, its
    release branch at the contact gap (the contact's elastic recovery of ~1 um unloads the
    dome across its band, k_s = 1000 max F_h / span; within 1 %: the dashpot and the smooth
    element's lag); nothing recloses after it. The pin's edges on each (R, C) are the
    mcu_input network's closed form on the run's own contact intervals (_pin_edges), and the
    chosen R C is the smallest that gives one edge per press and one per release."""
    numbers, out = _run(tmp_path_factory, "tactile_switch")
    doc = _toml("tactile_switch")
    finger, dome, c = doc["force"][0], doc["spring"][0], doc["circuit"]
    gap = doc["initial"]["height"]
    peak = max(dome["force"][:4])

    def finger_force(t):
        return float(np.interp(t, finger["time"], finger["value"]))

    p = numbers["patterns"]
    t_peak = float(np.interp(peak, finger["value"][:2], finger["time"][:2]))
    assert t_peak < p["first_make"] < finger["time"][1]
    # the break on the release branch (the press branch there is 0.85 N: 60 % off)
    released = float(np.interp(gap, dome["travel"], dome["release_force"]))
    assert finger_force(p["last_break"]) == pytest.approx(released, rel=0.01)
    assert finger["time"][2] < p["last_break"] < finger["time"][3] and p["release_chatter"] == 0.0
    for row in numbers["grid"]:
        assert row["status"] == "ok" and row["final_level"] == "high"  # released: the input reads high
        assert row["closed_intervals"][-1][1] == pytest.approx(p["last_break"], abs=1e-6)
        expected, margin = _pin_edges(row["closed_intervals"], doc["solver"]["t_end"], c,
                                      row["pull_resistance"], row["input_capacitance"])
        assert margin > 0.02 * c["voltage"] and row["edges"] == expected, row
    chosen = numbers["chosen"]
    assert chosen is not None and chosen["edges"] == 2
    assert chosen["rc"] == min(r["rc"] for r in numbers["grid"] if r["edges"] == 2)
    assert any(r["edges"] > 2 for r in numbers["grid"])  # the make's bounce: the smallest R C sees it
    summary = json.loads((out / "summary.json").read_text())
    assert summary["logic"]["edges"] == 2


# --- relay_ac_point_on_wave: the default relay breaking 230 V AC at six phases ---------------

@pytest.fixture(scope="module")
def point_on_wave(tmp_path_factory):
    return _run(tmp_path_factory, "relay_ac_point_on_wave")


def test_an_ac_break_arc_burns_from_the_parting_to_the_next_current_zero(point_on_wave):
    """The contact parts at the same instant whatever the mains' phase (to 10 ns: mu(I) moves
    it that little). Its arc then burns until the source's voltage can no longer drive I_min
    through it: it goes out before the source's next zero, at |v_s| = U_arc + I_min R with the
    arc's voltage U_arc between 0 and its largest, i.e. within asin((U_max + I_min R) / V_p) / omega
    of that zero (U_max: 12 V + 2e4 V/m over the ~0.6 mm the gap reaches, bounded here by 40 V).
    So the arc lasts at most a half period, and from nearly nothing (parting just before a zero)
    to nearly all of it (just after one); its energy follows."""
    n, _ = point_on_wave
    f, r_loop, i_min = n["frequency"], n["loop_resistance"], n["min_current"]
    v_peak, omega = math.sqrt(2.0) * n["voltage_rms"], 2.0 * math.pi * n["frequency"]
    rows = n["runs"]
    assert all(r["status"] == "ok" and r["complete"] for r in rows), rows
    parts = [r["break_time"] for r in rows]
    assert max(parts) - min(parts) < 1e-8
    window = math.asin((40.0 + i_min * r_loop) / v_peak) / omega
    for r in rows:
        out = r["break_time"] + r["arc_duration"]
        phase = math.radians(r["phase_deg"]) + omega * r["break_time"]  # the source's phase at the parting
        zero = r["break_time"] + (math.pi - phase % math.pi) / omega  # its next zero
        assert zero - window <= out <= zero, (r["phase_deg"], zero - out, window)
        assert r["arc_duration"] < 0.5 / f
    # the later after a zero it parts, the shorter and weaker the arc
    by_parting = sorted(rows, key=lambda r: (math.radians(r["phase_deg"]) + omega * r["break_time"]) % math.pi)
    durations = [r["arc_duration"] for r in by_parting]
    energies = [r["arc_energy"] for r in by_parting]
    assert durations == sorted(durations, reverse=True) and energies == sorted(energies, reverse=True)
