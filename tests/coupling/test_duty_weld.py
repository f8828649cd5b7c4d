"""Welding per make in a run: the trend the literature reports for lamp-like inrush.

A relay closing onto a capacitive load (a lamp's or a supply's input capacitor) carries
its inrush through the first bounce: the current is largest while the contact bounces, an
arc burns through the first bounce separation into the re-make, and by the time the
contact is held the inrush is over. Welding then comes from the first bounce separation
(the bounce arc's molten pool, closed on at the re-make: Kulas; Slade), not from the held
contact (Slade's static threshold and Holm's melting voltage are far away). The verdict
``make.weld_risk`` and its numbers come from coupling.laws.duty.weld_verdict on the run's
own held force, peak current, held contact voltage and separations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling import builtin_scene, run
from coupling.laws.duty import ContactPair, hot_contact_voltage, welding_current

LAMP = {"circuit.template": "capacitive", "circuit.voltage": 48.0, "circuit.load_resistance": 0.05,
        "circuit.load_capacitance": 470e-6, "circuit.bleed_resistance": 1000.0, "duty.materials": ["Ag", "Ag"]}


@pytest.fixture(scope="module")
def lamp():
    return run(builtin_scene("relay_force").update(LAMP))


def test_welding_appears_at_the_first_bounce_separation_not_in_the_held_contact(lamp):
    assert lamp.status == "ok", lamp.message
    (op,) = lamp.summary["operations"]
    make, weld = op["make"], op["make"]["weld"]
    seps = weld["separations"]
    assert make["bounces"] == len(seps) >= 2
    # the inrush is the first bounce's: its parting current is the make's largest, hundreds of A
    assert seps[0]["current"] == max(s["current"] for s in seps) > 100.0
    assert seps[0]["arc_at_remake"]
    # the verdict: likely, by the separation criterion, decided by the first separation
    assert make["weld_risk"] == "likely" and weld["criterion"] == "separation"
    assert seps[0]["ratio"] == weld["ratios"]["separation"] >= 1.0
    assert all(s["ratio"] < 0.5 for s in seps[1:])
    # the held contact alone: below both criteria by their margin
    assert weld["ratios"]["static"] < 0.5 and weld["ratios"]["held_spot"] < 0.5


def test_the_held_criteria_are_the_runs_own_numbers(lamp):
    """The static ratio is the make's peak current over Slade's i_W at the held force, and the
    held spot's the hot voltage of the held contact (its largest current at the held R_c) over
    U_m: both from the run's waveforms, recomputed here."""
    (op,) = lamp.summary["operations"]
    weld, held = op["make"]["weld"], op["held"]
    w = lamp.waveform_columns
    sel = (w["time"] >= held["start"]) & (w["time"] <= held["end"])
    assert held["current"] == pytest.approx(float(np.max(np.abs(w["contact_current"][sel]))), rel=1e-12)
    assert held["current"] < 5.0  # the capacitor has charged before the contact is held
    pair = ContactPair(("Ag", "Ag"))
    assert weld["held_force"] == held["force"] == pytest.approx(1.6, rel=0.05)  # the relay's settled force
    assert weld["ratios"]["static"] == pytest.approx(op["make"]["peak_current"]
                                                     / float(welding_current(held["force"], pair)), rel=1e-12)
    hot = float(hot_contact_voltage(held["current"] * held["contact_resistance"], pair))
    assert weld["ratios"]["held_spot"] == pytest.approx(hot / pair.melting_voltage(), rel=1e-9)
    # the first separation's arc energy is the opening's |v i_arc| integral (the bounce table's)
    first = lamp.bounce["openings"][0]
    assert weld["separations"][0]["arc_energy"] == pytest.approx(first["arc_energy"], rel=1e-9)
    assert weld["separations"][0]["current"] == pytest.approx(first["current_at_break"], rel=1e-12)


def test_a_resistive_make_of_the_same_relay_welds_nowhere_near_as_likely(lamp):
    """The same relay closing 24 V onto 10 ohm: 2.4 A through the bounces, a first-bounce weld
    ratio an order of magnitude below the lamp's, no criterion reached."""
    res = run(builtin_scene("relay_force").set("duty.materials", ["Ag", "Ag"]))
    (op,) = res.summary["operations"]
    ratios = op["make"]["weld"]["ratios"]
    assert max(ratios.values()) < 1.0 and op["make"]["weld_risk"] != "likely"
    assert ratios["separation"] < 0.1 * lamp.summary["operations"][0]["make"]["weld"]["ratios"]["separation"]
    assert math.isfinite(op["held"]["blow_off_current"]) and op["held"]["blow_off_current"] > 1e3


def test_every_number_of_the_duty_summary_has_a_unit(lamp):
    """A sweep row is the flattened summary: its duty numbers each have a unit in the one
    table the plots read (coupling.app.quantities)."""
    from coupling.app.quantities import quantity
    from coupling.app.sweep import flatten_summary

    numbers = {k: v for k, v in flatten_summary(lamp.summary).items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)}
    duty = [k for k in numbers if k.startswith("duty.")]
    assert len(duty) >= 12
    assert [k for k in numbers if quantity(k) is None] == []
    assert quantity("duty.moving_eroded_volume").unit == "m^3" and quantity("duty.blow_off_current").unit == "A"
