"""Holm's repulsion acting on the motion in a coupled run, against closed forms.

The contact is a rigid steel arm hinged at one end under a constant preload torque (a
statically determinate support: the normal force plus the repulsion balance the same
moments), its tip on a silver pair (Holm's plastic law), switching a supply whose load is
shorted at a time (the short_circuit template):

- before the fault the contact carries the preload P = (T0 + m g L / 2) / (L - R_tip);
- under a steady fault current I the mechanics' normal force is F = P - mu0 I^2 / (4 pi)
  ln(R / a(F)), the a-spot a = sqrt(F / (pi H)) at the force it carries, and the current is
  the template's closed form E / (R_source + R_c + R_fault || R_load);
- with the fault current ramped slowly, the force follows that equilibrium until it has
  none left: the contact opens at I_c = coupling.laws.duty.shrinking_blow_off_current(P),
  where Holm's force at the spot of the force still carried takes the rest of the preload.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from coupling import run
from coupling.core.scene import scene_from_dict
from coupling.laws.duty import blow_off_current, shrinking_blow_off_current
from coupling.laws.materials import MATERIALS

MU0_CODATA = 1.25663706212e-6  # N/A^2: an independent value of the constant (the code's 4e-7 pi agrees to 5.5e-10)
STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
L, D, RT, T0 = 0.05, 0.005, 0.0025, 0.01  # arm length, diameter, tip radius (m); preload torque (N m)
H = MATERIALS["Ag"].hardness
G = 9.80665
PRELOAD = (T0 + STEEL["density"] * math.pi / 4 * D ** 2 * L * G * L / 2) / (L - RT)  # N
R_SOURCE, R_FAULT, R_LOAD = 0.01, 0.01, 10.0
FAULT_AT = 20e-3  # s: the arm has come to rest on its contact well before


def arm(voltage: float, fault_rise: float, t_end: float, duty=None) -> dict:
    """The arm dropped 10 um onto its contact (it rests there within a few ms), the load
    shorted at FAULT_AT; mu ~ 0 so that friction takes no part in the statics."""
    doc = {"bar": dict(length=L, diameter=D, tip_radius=RT, modes=0, **STEEL),
           "mount": dict(kind="pivot", position=L, preload_torque=T0),
           "contact": dict(restitution=0.5), "initial": dict(height=1e-5), "solver": dict(t_end=t_end),
           "tribology": {"resistance": {"law": "holm", "materials": ["Ag", "Ag"]}, "mu": 1e-9},
           "circuit": dict(template="short_circuit", voltage=voltage, source_resistance=R_SOURCE, wiring_resistance=0.0,
                           wiring_inductance=1e-6, load_resistance=R_LOAD, fault_time=FAULT_AT,
                           fault_resistance=R_FAULT, fault_rise=fault_rise, arc=True)}
    if duty is not None:
        doc["duty"] = duty
    return doc


def holm(current, force) -> float:
    """N: Holm's force at the plastic spot of ``force`` (N) with the member radius R_tip."""
    return MU0_CODATA / (4 * math.pi) * current ** 2 * math.log(RT / math.sqrt(force / (math.pi * H)))


@pytest.fixture(scope="module")
def steady():
    """A 5 V supply shorted: about 240 A, 0.4 of the opening current, reached in 0.1 ms."""
    return run(scene_from_dict(arm(5.0, 1e-4, 30e-3, duty={}), name="steady fault"))


def _at(result, t: float, column: str) -> float:
    w = result.waveform_columns
    return float(w[column][np.searchsorted(w["time"], t)])


def test_the_held_contact_carries_the_preload_less_holms_force(steady):
    """The preload less Holm's force at the spot of the force carried, before the fault (0.5 A:
    5e-7 of the preload) and under it (240 A: 12 %), to 1e-7 of the preload: the hold's
    static equilibrium (rtol x the Hertz penetration scale) and the fixed point of the spot,
    evaluated at each macro step's start (it contracts by dF_holm/dF = F_holm / 2F ~ 0.07
    per step over thousands of steps), both far below that."""
    assert steady.status == "ok", steady.message
    for t, low in ((FAULT_AT - 0.1e-3, 0.4), (29.9e-3, 200.0)):
        force, current = _at(steady, t, "normal_force"), _at(steady, t, "load_current")
        assert current > low
        assert force == pytest.approx(PRELOAD - holm(current, force), abs=1e-7 * PRELOAD)
    # the drop is Holm's force, not a constant fraction: 12 % of the preload here
    assert 0.1 < (PRELOAD - force) / PRELOAD < 0.15


def test_the_fault_current_is_the_templates_closed_form(steady):
    """E / (R_source + R_c + R_fault || R_load), R_c the contact's resistance then (Holm's law
    at its force): the short's PWL conductance in ngspice against Ohm's law, to ngspice's
    RELTOL (1e-6 here: the default option)."""
    r_c = _at(steady, 29.9e-3, "contact_resistance")
    expected = 5.0 / (R_SOURCE + r_c + R_FAULT * R_LOAD / (R_FAULT + R_LOAD))
    assert _at(steady, 29.9e-3, "load_current") == pytest.approx(expected, rel=1e-5)
    assert steady.scene.circuit.circuit.fault_current(r_c) == pytest.approx(expected, rel=1e-12)


def test_the_summary_gives_the_held_closures_blow_off_current(steady):
    """summary operations[0].held: the held force (the closure's median in time: the preload,
    held longer than the fault) and the blow-off currents at it; Holm's force at the held
    spot with the summary's blow-off current is that force (CODATA mu0, 1e-9)."""
    held = steady.summary["operations"][0]["held"]
    assert held["force"] == pytest.approx(PRELOAD, rel=1e-6)
    a = math.sqrt(held["force"] / (math.pi * H))
    assert held["spot_radius"] == pytest.approx(a, rel=1e-12)
    i_b = held["blow_off_current"]
    assert MU0_CODATA / (4 * math.pi) * i_b ** 2 * math.log(RT / a) == pytest.approx(held["force"], rel=1e-9)
    assert held["shrinking_blow_off_current"] < i_b
    assert steady.summary["duty"]["blow_off_current"] == i_b


def test_the_opening_current_solves_the_last_equilibrium():
    """The law itself: at I_c the equilibria x - 1 + q L0 - (q/2) ln x = 0 (x = F / P, q =
    k I^2 / P) have their double root, x = q / 2 (g = 0 and g' = 0 there), and just below
    I_c two roots remain."""
    i_c = shrinking_blow_off_current(PRELOAD, H, RT)
    l0 = math.log(RT / math.sqrt(PRELOAD / (math.pi * H)))
    q = MU0_CODATA / (4 * math.pi) * i_c ** 2 / PRELOAD
    x = q / 2
    assert x - 1 + q * l0 - q / 2 * math.log(x) == pytest.approx(0.0, abs=1e-9)
    q_below = 0.99 * q
    g = lambda y: y - 1 + q_below * l0 - q_below / 2 * math.log(y)  # noqa: E731
    assert g(q_below / 2) < 0 < g(1.0)
    assert i_c < float(blow_off_current(PRELOAD, math.sqrt(PRELOAD / (math.pi * H)), RT))


@pytest.fixture(scope="module")
def ramped():
    """24 V shorted through a conductance ramped over 20 ms: the current passes I_c (593 A)
    at ~68 A/ms, slowly against the arm's 17 us period on its contact."""
    return run(scene_from_dict(arm(24.0, 20e-3, 30e-3, duty={}), name="ramped fault"))


def test_the_contact_leaves_its_equilibrium_at_the_opening_current_and_opens(ramped):
    """The force follows the quasi-static equilibrium F = P - holm(I, F) (to 1e-3 of P: the
    ramp's lag) until that branch ends at I_c, where it meets the unstable one at F* = q P / 2
    (q = k I_c^2 / P): the largest current the contact carries before its force first falls
    below F* / 2 is I_c to 0.2 %. The force then collapses; as the spot vanishes its
    resistance cuts the current, the arm floats and chatters on its contact under the arc,
    and the contact opens."""
    w = ramped.waveform_columns
    i_c = shrinking_blow_off_current(PRELOAD, H, RT)
    f_star = MU0_CODATA / (4 * math.pi) * i_c ** 2 / 2
    after = w["time"] > FAULT_AT
    collapse = float(w["time"][after & (w["normal_force"] < f_star / 2)][0])
    sel = after & (w["time"] < collapse)
    assert float(np.max(w["load_current"][sel])) == pytest.approx(i_c, rel=2e-3)
    for current, force in zip(w["load_current"][sel][::50], w["normal_force"][sel][::50]):
        if current < 0.9 * i_c:
            stable = MU0_CODATA / (4 * math.pi) * current ** 2 / 2  # the branches meet there: the stable one is above
            equilibrium = brentq(lambda f: f - PRELOAD + holm(current, f), stable, PRELOAD)
            assert force == pytest.approx(equilibrium, abs=1e-3 * PRELOAD)
    assert [e for e in ramped.mechanics.events if e["kind"] == "contact_end" and e["time"] > collapse]
    # and without [duty] the current does not act on the motion: the contact stays closed
    still = run(scene_from_dict(arm(24.0, 20e-3, 30e-3), name="no duty"))
    assert not [e for e in still.mechanics.events if e["kind"] == "contact_end" and e["time"] > FAULT_AT]


def test_repulsion_false_changes_nothing():
    """[duty] repulsion = false: the run is the run without [duty], bit for bit (the same
    process, the same computation: the repulsion channels are not given at all)."""
    doc = arm(12.0, 1e-4, 22e-3)
    plain = run(scene_from_dict(doc, name="plain")).waveform_columns
    off = run(scene_from_dict(dict(doc, duty={"repulsion": False}), name="off")).waveform_columns
    for column in ("time", "normal_force", "load_current"):
        np.testing.assert_array_equal(plain[column], off[column])
