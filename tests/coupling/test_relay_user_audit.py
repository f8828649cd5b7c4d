"""What a relay designer met using switchsim as the README says: each
test reproduces a finding through the command line or the sweep API and holds its fix."""

from __future__ import annotations

import textwrap
import types

import numpy as np
import pandas as pd
import pytest
from cli_checks import FAR, assert_one_line_error, run_cli

from coupling import default_scene
from coupling.app.cli import main
from coupling.app.sweep import Sweep, run_sweep_inline
from coupling.core.master import run
from coupling.core.metrics import bounce_metrics
from coupling.core.scene import builtin_scene_text, load_scene, scene_from_dict

# The bar that never touches (cli_checks.FAR), coupled: the open contact holds the whole
# supply for the run.
NEVER_CLOSES = FAR + textwrap.dedent("""
    [tribology]
    source = "illustrative"
    [circuit]
    template = "resistive"
    voltage = 24.0
    [output]
    plots = false
    """)

# The same bar released 0.2 mm above the block at 1000 V without an arc model: the open
# contact's field passes air's breakdown as the gap closes, which summary.json warns about.
WARNED = {"bar": {"modes": 0},
          "initial": {"height": 2e-4, "angle_deg": 90.0, "velocity": [0.0, 0.0, -0.5]},
          "solver": {"t_end": 1e-3},
          "tribology": {"source": "illustrative"},
          "circuit": {"template": "resistive", "voltage": 1000.0, "load_resistance": 500.0},
          "output": {"plots": False}}


def test_a_contact_that_never_opened_reports_no_peak_voltage_not_zero_volts(tmp_path, capsys):
    """Without an opening there is no opening's peak (summary: None); the result line said
    "peak contact voltage 0 V" while the open contact held the 24 V supply the whole run."""
    scene = tmp_path / "never.toml"
    scene.write_text(NEVER_CLOSES)
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "first make" in x)
    assert "the contact never closed" in line
    assert "peak contact voltage none (no opening)" in line and "peak contact voltage 0 V" not in line


def test_a_sweep_row_carries_the_runs_warnings_one_per_line():
    """A sweep's row held every summary scalar but not `warnings`: a study could not tell a
    warned run (a truncated arc, a field beyond breakdown) from a clean one. The row's
    `warnings` are the run's own, in order, one per line; "" for a run without any."""
    base = scene_from_dict(WARNED, name="warned")
    rows = run_sweep_inline(Sweep.grid(base, {"circuit.voltage": [1000.0, 24.0]}))
    assert [r["status"] for r in rows] == ["ok", "ok"]
    warned, clean = rows
    lines = warned["warnings"].split("\n")
    assert len(lines) >= 1 and any("exceeds air breakdown" in w for w in lines)
    assert lines == run(base).summary["warnings"]  # the run's own lines, in order
    # 24 V stays below air's Paschen minimum (~327 V) at every gap: no breakdown warning
    assert "air breakdown" not in clean["warnings"]


@pytest.mark.parametrize("voltage, zener, refused", [(12.0, 95.0, True), (12.0, 150.0, True), (24.0, 80.0, True),
                                                      (12.0, 80.0, False), (12.0, 24.0, False)])
def test_a_zener_the_drivers_avalanche_would_beat_is_refused_by_its_key(tmp_path, voltage, zener, refused):
    """Switched off, the driver's node rises to voltage + V_z + V_d before the zener path
    conducts; the driver avalanches at switch_breakdown (100 V) first when voltage + V_z
    reaches it. The default relay with a 95 or 150 V zener then released exactly as with no
    suppression (coil clamped at -88.1 V, release 0.324 ms, both) and nothing said so."""
    changes = {"coil.suppression": "zener", "coil.zener_voltage": zener, "coil.voltage": voltage}
    if not refused:
        assert default_scene().update(changes).raw["coil"]["zener_voltage"] == zener  # built and checked
        return
    with pytest.raises(ValueError, match=r"coil\.zener_voltage = .* V: the driver avalanches"):
        default_scene().update(changes)
    text = builtin_scene_text("default").replace('suppression = "none"', f'suppression = "zener"\n'
                                                 f'zener_voltage = {zener!r}')
    text = text.replace("voltage = 12.0", f"voltage = {voltage!r}", 1)  # [coil] comes before [circuit]
    path = tmp_path / "zener.toml"
    path.write_text(text)
    line = assert_one_line_error(*run_cli(["run", str(path), "--out", str(tmp_path / "out")]))
    assert line.startswith(f"switchsim: error: {path}: coil.zener_voltage = {zener:g} V")
    assert "coil.switch_breakdown = 100 V" in line
    assert f"allowed zener_voltage < switch_breakdown - voltage = {100 - voltage:g} V" in line

# The default relay's load and its coil's drive as a user's netlist (the coil by its XCOIL line).
RELAY_NETLIST = """* 24 V into 10 ohm; the coil's 12 V supply switched by a low-side driver, a freewheeling diode
Vsrc src 0 24
XCONTACT src b
VLOAD b load 0
Rload load 0 10
Vcoil csup 0 12
XCOIL csup cdrv
Sdrv cdrv 0 ctl 0 swmod
Vctl ctl 0 PULSE(0 1 1m 1u 1u 8m 100m)
.model swmod SW(VT=0.5 RON=0.1 ROFF=1e9)
Dsupp cdrv csup dmod
.model dmod D(IS=1e-9 N=1.8)
"""


def _netlist_relay(folder, coil_lines: str):
    """The default relay with its [circuit] a netlist and its [coil] as given: the scene file."""
    text = builtin_scene_text("default")
    coil_at, magnet_at = text.index("[coil]"), text.index("[magnet]")
    text = text[:coil_at] + "[coil]\n" + coil_lines + "\n" + text[magnet_at:]
    circuit_at, coupling_at = text.index("[circuit]"), text.index("[coupling]")
    text = text[:circuit_at] + '[circuit]\ntemplate = "netlist"\nnetlist = "relay.cir"\narc = true\n\n' + \
        text[coupling_at:]
    (folder / "relay.cir").write_text(RELAY_NETLIST)
    path = folder / "relay.toml"
    path.write_text(text)
    return path


def test_coil_drive_keys_beside_a_netlist_that_drives_the_coil_are_refused(tmp_path):
    """With template "netlist" the netlist drives its XCOIL: [coil] voltage, on_time,
    off_time, suppression ... were silently ignored (a user's 'voltage = 24' changed nothing).
    Each is named; resistance and turns alone build."""
    path = _netlist_relay(tmp_path, "resistance = 360.0\nturns = 4500\nvoltage = 12.0\non_time = 1e-3\n"
                                    'suppression = "diode"')
    line = assert_one_line_error(*run_cli(["run", str(path), "--out", str(tmp_path / "out")]))
    assert line.startswith(f"switchsim: error: {path}: coil.voltage, coil.on_time, coil.suppression do(es) not "
                           "apply with circuit.template = \"netlist\"")
    assert "[coil] takes resistance and turns" in line
    scene = load_scene(_netlist_relay(tmp_path, "resistance = 360.0\nturns = 4500"))
    assert scene.raw["coil"] == {"resistance": 360.0, "turns": 4500}


def test_a_netlist_driving_its_xcoil_operates_the_relay_as_the_template_does(tmp_path):
    """Two routes to the same relay: the default scene with suppression = "diode" (the
    template's drive), and a user's netlist holding the same supplies, a switch turned on at
    1 ms over 1 us and the diode, with the coil as its XCOIL line. The armature leaves its
    rest at the same current (the magnet's force against the preload: to 1e-6), and the
    contact makes and the armature arrives within the driver's 1 us edge (the SW element
    switches at its half, the template's conductance ramps through it)."""
    netlist = run(load_scene(_netlist_relay(tmp_path, "resistance = 360.0\nturns = 4500")))
    template = run(default_scene().set("coil.suppression", "diode"))
    assert netlist.status.value == template.status.value == "ok"
    a, b = netlist.relay, template.relay
    assert a["pull_in_current"] == pytest.approx(b["pull_in_current"], rel=1e-6)
    assert abs(a["armature_arrival"] - b["armature_arrival"]) < 1e-6
    assert abs(netlist.bounce["first_make"] - template.bounce["first_make"]) < 1e-6


@pytest.mark.parametrize("material_line, words", [
    ('material = "steel"', ["magnet.iron[0].material: unknown magnetic material 'steel'", "allowed: 9SMnPb28"]),
    ("", ["magnet.iron[0] needs material: a built-in name"]),
])
def test_an_iron_material_error_says_how_to_give_the_yokes_own_curve(tmp_path, material_line, words):
    """One steel is built in; a relay's yoke is often another. The error named only
    9SMnPb28 (and a missing material read "expected a table of keys, got None"): it now says
    how to give a curve of one's own, as docs/magnet.md's keys allow."""
    text = builtin_scene_text("default").replace('material = "9SMnPb28"', material_line, 1)
    path = tmp_path / "relay.toml"
    path.write_text(text)
    line = assert_one_line_error(*run_cli(["run", str(path), "--out", str(tmp_path / "out")]))
    for w in words + ["{relative_permeability = ...}", "{flux_density = [...], field_strength = [...]} (T, A/m)"]:
        assert w in line, line


def test_the_waveform_plots_title_is_inside_the_figure():
    """The title of waveforms.png (bounces, settling, peaks, arc energy) was centred over the
    axes, which the legends outside them make narrower than the figure: on the default relay
    it began left of the figure's edge ("ounce window: ..."). A run built by hand as the
    default relay's: a bounce, held closed from 1.3 to 4 ms (R_c rising without bound as it
    parts), then open with a 60 V spike (24 V open, 12 V arcs in the openings)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    from coupling.app.plots import plot_waveforms

    closed_iv, t_end = [(1.0e-3, 1.2e-3), (1.3e-3, 4e-3)], 5e-3
    t = np.linspace(0.0, t_end, 5001)
    closed = np.zeros_like(t, bool)
    for a, b in closed_iv:
        closed |= (t >= a) & (t <= b)
    v = np.where(closed, 0.01, np.where((t < 1e-3) | (t > 4.5e-3), 24.0, 12.0))
    v[np.searchsorted(t, 4.6e-3)] = 60.8
    arc = np.where(closed | (t < 1e-3) | (t > 4.5e-3), 0.0, 1.0)
    current = np.where(closed, 2.0, 0.0) + arc
    resistance = np.where(closed, 0.005, np.inf)
    resistance[np.searchsorted(t, 4e-3) - 1] = 1.07e21  # the last closed sample, parting
    w = pd.DataFrame(dict(time=t, contact_voltage=v, contact_current=np.where(closed, 2.0, 0.0),
                          load_current=current, contact_resistance=resistance, arc_current=arc,
                          gap=np.where(closed, 0.0, 1e-5)))
    bounce = bounce_metrics(closed_iv, t_end, False, t, v, current, arc)
    assert bounce["settled"] and bounce["final_state"] == "open"  # the long title: settled, both peaks
    result = types.SimpleNamespace(waveforms=w, bounce=bounce, closed_intervals=closed_iv,
                                   openings=pd.DataFrame(bounce["openings"]),
                                   scene=types.SimpleNamespace(t_end=t_end))
    for whole_run in (False, True):
        fig = plot_waveforms(result, whole_run=whole_run)
        renderer = FigureCanvasAgg(fig).get_renderer()
        (title,) = [x for x in fig.findobj(Text) if "bounce(s), settled" in x.get_text()]
        box, width = title.get_window_extent(renderer), fig.bbox.width
        assert 0.0 <= box.x0 and box.x1 <= width, (title.get_text(), box, width)
