"""User probes: any node voltage or branch current recorded beside the contact waveforms."""

from __future__ import annotations

import numpy as np
import pytest

from circuit.probes import parse_probe, spice_number
from coupling import run
from coupling.core.scene import scene_from_dict

PROBES = ["v(snubber,contact_b)", "i(Rsnubber)", "i(Csnubber)", "i(Lload)", "v(contact_a,contact_b)"]


def _doc(probes):
    return {"circuit": {"template": "inductive", "load_resistance": 24.0, "load_inductance": 1e-3,
                        "snubber": {"resistance": 100.0, "capacitance": 100e-9}, "probes": probes, "max_step": 2e-7,
                        "schedule": {"make": [1e-4], "break": [5e-4], "closed_resistance": 0.01}},
            "solver": {"t_end": 1e-3}}


def test_probes_record_the_snubber_and_the_coil():
    res = run(scene_from_dict(_doc(PROBES)))
    w = res.waveforms
    assert set(PROBES) <= set(w.columns)
    # the snubber is R and C in series: Ohm's law on R and C dV/dt on C are one current
    i_r, i_c = w["i(Rsnubber)"].to_numpy(), w["i(Csnubber)"].to_numpy()
    after = (w.time > 5.2e-4).to_numpy()  # past the break corner (C dV/dt is a finite difference)
    assert np.max(np.abs(i_r[after])) > 1e-3
    np.testing.assert_allclose(i_c[after], i_r[after], atol=0.02 * np.max(np.abs(i_r[after])))
    # charge: the current through R (Ohm's law) integrates to C times the capacitor's voltage change
    t, v_c = w.time.to_numpy(), w["v(snubber,contact_b)"].to_numpy()
    charge = np.concatenate([[0.0], np.cumsum(0.5 * (i_r[1:] + i_r[:-1]) * np.diff(t))])
    np.testing.assert_allclose(charge - charge[0], 100e-9 * (v_c - v_c[0]), atol=1e-3 * 100e-9 * np.ptp(v_c))
    # the coil is in series with the load probe: the same branch current
    np.testing.assert_allclose(w["i(Lload)"], w.load_current, atol=1e-9)
    # while open, the node difference is the contact voltage
    open_ = (w.contact_conductance == 0).to_numpy()
    np.testing.assert_allclose(w["v(contact_a,contact_b)"][open_], w.contact_voltage[open_], atol=1e-9)


@pytest.mark.parametrize("probes,match", [
    (["v(nosuch)"], r"probe 'v\(nosuch\)': no node 'nosuch' in the circuit; nodes: 0, contact_a"),
    (["i(Bcontact)"], r"no element 'bcontact' whose current can be recorded"),
    (["p(load)"], r"expected 'v\(node\)', 'v\(node1,node2\)' or 'i\(element\)'"),
    ("v(load)", r"expected a list"),
    (["v(load)", "v(load)"], r"given twice"),
])
def test_bad_probes_are_one_line_errors_naming_the_key(probes, match):
    with pytest.raises(ValueError, match=match) as err:
        scene_from_dict(_doc(probes))
    assert "[circuit] probes" in str(err.value) and "\n" not in str(err.value)


def test_probe_text_and_spice_numbers():
    p = parse_probe(" V( a , b ) ")
    assert (p.kind, p.names) == ("v", ("a", "b"))
    assert spice_number("100n") == pytest.approx(1e-7) and spice_number("2.2meg") == pytest.approx(2.2e6)
    assert spice_number("1e-06") == 1e-6 and spice_number("4.7kOhm") == pytest.approx(4700.0)
