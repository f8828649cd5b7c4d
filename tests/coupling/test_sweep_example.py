"""examples/snubber_design.py in fast mode (two sweeps on a local Dask cluster): its numbers
obey closed forms and bounds computed from the example's own TOML."""

from __future__ import annotations

import importlib.util
import math
import sys
import tomllib
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from coupling.app.sweep import read_results, read_waveforms  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def snubber(tmp_path_factory):
    if str(EXAMPLES) not in sys.path:
        sys.path.insert(0, str(EXAMPLES))
    spec = importlib.util.spec_from_file_location("switchsim_example_snubber_design", EXAMPLES / "snubber_design.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    out = tmp_path_factory.mktemp("snubber_design")
    return module, module.main(fast=True, out=out), out


def _circuit() -> dict:
    return tomllib.loads((EXAMPLES / "snubber_design.toml").read_text())["circuit"]


def test_a_larger_snubber_capacitor_lowers_the_peak_opening_voltage(snubber):
    module, n, out = snubber
    c = _circuit()
    rows = sorted(n["rc"], key=lambda r: r["C"])
    assert n["runs"]["failed"] == 0 and all(r["status"] == "ok" for r in rows)
    peaks = [r["peak_voltage"] for r in rows]
    assert all(a > b for a, b in zip(peaks, peaks[1:]))
    for r in rows:
        # after the arc goes out at I_min the coil rings into C + C_contact from about E:
        # peak <= E + I_min sqrt(L / C_total), and the open contact ends at the supply
        z = math.sqrt(c["load_inductance"] / (r["C"] + c["contact_capacitance"]))
        assert c["voltage"] <= r["peak_voltage"] <= c["voltage"] + c["arc"]["min_current"] * z
        # the arc cannot take more than the coil's stored energy plus what the supply gave
        i0 = c["voltage"] / (c["load_resistance"] + c["source_resistance"] + c["wiring_resistance"])
        t_end = tomllib.loads((EXAMPLES / "snubber_design.toml").read_text())["solver"]["t_end"]
        assert 0.0 < r["arc_energy"] <= 0.5 * c["load_inductance"] * i0**2 + c["voltage"] * i0 * t_end
    chosen = n["chosen"]
    assert chosen is not None
    assert chosen["peak_voltage"] <= module.PEAK_LIMIT and chosen["arc_energy"] <= module.ARC_LIMIT


def test_the_sweep_results_hold_every_run_once_with_its_waveforms(snubber):
    module, n, out = snubber
    df = read_results(out / "rc")
    assert sorted(df.run_id) == sorted(r["run_id"] for r in n["rc"]) and df.run_id.is_unique
    for run_id in df.run_id:
        w = read_waveforms(out / "rc", run_id)
        assert list(w.columns) == ["time"] + module.WAVES
        # the waveform's own peak after the make at t = 0 is the row's peak
        row = next(r for r in n["rc"] if r["run_id"] == run_id)
        assert w.contact_voltage[w.time > 0].abs().max() == pytest.approx(row["peak_voltage"], rel=1e-9)
    for name in ("peak_voltage.png", "arc_energy.png", "opening_overlay.png", "bounce_map.png"):
        assert (out / name).stat().st_size > 10_000


def test_drop_map_first_make_is_the_free_fall_time(snubber):
    """A pure drop (no spin) from height h at v0 down: the lowest tip touches at
    t = (sqrt(v0^2 + 2 g h) - v0) / g, whatever the angle."""
    module, n, out = snubber
    v0, g = n["drop"]["speed"], n["drop"]["gravity"]
    assert len(n["drops"]) == len(module.ANGLES_FAST) * len(module.HEIGHTS_FAST)
    for d in n["drops"]:
        assert d["status"] == "ok"
        expected = (math.sqrt(v0**2 + 2 * g * d["height"]) - v0) / g
        assert d["first_make"] == pytest.approx(expected, rel=1e-4)
        assert d["bounce_time"] >= 0.0
