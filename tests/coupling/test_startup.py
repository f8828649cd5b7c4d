"""The import contract of `switchsim run`: a scene imports only what it uses.

Each check runs the command in a fresh interpreter and lists the heavy packages it
loaded: numba never while the ahead-of-time module is there (mech.aot); scipy not for a
run (the quadrature, the mode roots, the damping calibration and the held bars' finite
element modes are numpy or compiled); pandas never for a run with its default outputs
(tables written from arrays, the waveforms kept as arrays, the tribology laws read without
it); pyarrow only to write waveforms.parquet; matplotlib only when plotting; plotly's
Python side never (waveforms.html is written directly); PySpice only with a circuit, and
never cffi's C parser (pycparser: ngspice's declarations come pre-parsed,
circuit/ngspice_api.py); Dask never; numpy.ma never (np.unique and np.quantile import it, ~10 ms of a start: the magnet's
points and the waveform page's axes use their own, tests/coupling/test_sorted_values.py).
Nor the standard modules of UNREACHED (an AOT build's, an error's did-you-mean, a quoted
table's, importlib.resources) where the run does not use them, and a circuit that is a
coil's drive alone none of circuit's other circuits or one-shot runs; a free bar or an
armature alone not the finite-element beam (BEAM).
"""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from fit_compare import assert_same_fit

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("numba", "scipy", "pandas", "pyarrow", "matplotlib", "plotly", "PySpice", "pycparser", "dask",
         "distributed", "numpy.ma")
# standard modules imported where they are used, which a run does not reach: the AOT
# module's and the C callbacks' builds and ldconfig's listing of libraries, the loader's
# lookup failing (subprocess, sysconfig), an error's did-you-mean (difflib), a table whose
# cells need quoting (csv); and importlib.resources, which no run uses (the built-in
# scenes and the contact materials are read by path)
UNREACHED = ("subprocess", "sysconfig", "difflib", "importlib.resources", "csv")
# the finite-element beam, which only a held bar (a mechanism) builds, and numpy.polynomial,
# which no run imports (beam_fe and coupling.core.exchange take their Gauss rules from mech.gauss)
BEAM = ("mech.beam_fe", "numpy.polynomial")
# the template families the default scene (template "resistive", no snubber, no flyback) does
# not use, each ~0.85 ms a dataclass to define (circuit/templates/__init__.py)
UNUSED_TEMPLATES = ("circuit.templates.suppression", "circuit.templates.bridge", "circuit.templates.changeover",
                    "circuit.templates.mcu_input", "circuit.templates.short_circuit")

MECH = """
[bar]
length = 0.1
diameter = 0.006
tip_radius = 0.003
modes = 2
[initial]
height = 0.0001
angle_deg = 30.0
velocity = [0.0, 0.0, -1.0]
[contact]
restitution = 0.7
[solver]
t_end = 0.0003
[output]
plots = {plots}
"""

CIRCUIT = """
[tribology]
source = "illustrative"
[circuit]
template = "resistive"
voltage = 24.0
load_resistance = 12.0
"""


def _loaded(tmp_path: Path, scene_text: str | None, *args: str) -> set[str]:
    """The heavy packages `switchsim run` imported (scene_text None: the built-in default scene)."""
    return {name for name in HEAVY if name in _imported(tmp_path, scene_text, *args)}


def _imported(tmp_path: Path, scene_text: str | None, *args: str) -> set[str]:
    """Every module `switchsim run` imported (scene_text None: the built-in default scene)."""
    scene = []
    if scene_text is not None:
        (tmp_path / "scene.toml").write_text(scene_text)
        scene = [str(tmp_path / "scene.toml")]
    code = textwrap.dedent(f"""
        import json, sys
        from coupling.app.cli import main
        rc = main(["run", *{scene!r}, "--out", {str(tmp_path / 'out')!r}, "--quiet", *{list(args)!r}])
        print(json.dumps([rc, sorted(sys.modules)]))
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    rc, modules = json.loads(done.stdout.strip().splitlines()[-1])
    assert rc == 0
    return set(modules)


def _requires_aot():
    import mech.compiled

    if mech.compiled.ROUTE != "aot":
        pytest.skip("the ahead-of-time module could not be built here: the JIT route imports numba")


def test_mechanics_only_scene_with_its_default_outputs_imports_nothing_heavy(tmp_path):
    """restitution given: the damping is calibrated (compiled), without scipy; nor the
    modules of UNREACHED, nor the beam's (a free bar)."""
    _requires_aot()
    modules = _imported(tmp_path, MECH.format(plots="false"))
    assert {name for name in HEAVY if name in modules} == set()
    assert modules.isdisjoint(UNREACHED)
    assert modules.isdisjoint(BEAM)
    out = tmp_path / "out"
    assert {p.name for p in out.iterdir()} == {"summary.json", "history.csv", "contacts.csv", "phases.csv",
                                               "events.csv"}


def test_plots_bring_matplotlib_and_pandas_only(tmp_path):
    _requires_aot()
    assert _loaded(tmp_path, MECH.format(plots="true")) - {"pyarrow", "numpy.ma"} == {"matplotlib", "pandas"}
    assert (tmp_path / "out" / "normal_force.png").stat().st_size > 0


def test_coupled_scene_imports_pyspice_and_pyarrow_only(tmp_path):
    """The illustrative laws come from their stored fit: no scipy.stats, no fitting, no
    pandas; pyarrow writes waveforms.parquet."""
    _requires_aot()
    assert _loaded(tmp_path, MECH.format(plots="false") + CIRCUIT) == {"PySpice", "pyarrow"}
    assert (tmp_path / "out" / "waveforms.html").stat().st_size > 1_000_000
    # the summary, written last, records the page as docs/coupling.md says
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["waveforms_html"] == "waveforms.html"


def test_default_scene_imports_pyspice_and_pyarrow_only_and_writes_its_documented_outputs(tmp_path):
    """The built-in default scene (the coil-driven relay, inline laws) with its default outputs; the
    files are the ones README.md lists for it."""
    _requires_aot()
    modules = _imported(tmp_path, None)
    assert {name for name in HEAVY if name in modules} == {"PySpice", "pyarrow"}
    assert modules.isdisjoint(UNREACHED)  # (ngspice's library found through the loader, no ldconfig -p)
    assert "mech.beam_fe" in modules and "numpy.polynomial" not in modules  # (its Gauss rules written out)
    # a template's deck passes the last guard alone, not the netlist-file reader
    assert "circuit.deck_guard" in modules and "circuit.netlist_check" not in modules
    # its template's families alone: the one-contact switch with its sources and loads
    assert {"circuit.templates.switch", "circuit.templates.sources", "circuit.templates.loads"} <= modules
    assert modules.isdisjoint(UNUSED_TEMPLATES)
    written = {p.name for p in (tmp_path / "out").iterdir()}
    assert written == {"summary.json", "waveforms.csv", "waveforms.parquet", "waveforms.html", "openings.csv",
                       "history.csv", "contacts.csv", "phases.csv", "events.csv"}
    readme = (ROOT / "README.md").read_text()
    assert all(f"`{name}`" in readme for name in written)


def test_a_coil_drive_alone_imports_no_templates_netlist_circuit_or_one_shot_runs(tmp_path):
    """examples/plunger_solenoid.toml, whose circuit is its coil's drive: circuit's templates
    (thirteen dataclasses, ~11 ms; none of their families), the netlist circuit, the schedule and the one-shot runs are
    imported on first use (circuit/__init__.py) and never by this run."""
    _requires_aot()
    modules = _imported(tmp_path, (ROOT / "examples" / "plunger_solenoid.toml").read_text())
    assert modules.isdisjoint({"circuit.templates", "circuit.netlist", "circuit.schedule", "circuit.transient",
                               "circuit.netlist_check"})
    assert "circuit.coil_drive" in modules
    assert modules.isdisjoint(UNREACHED)
    assert modules.isdisjoint(BEAM)  # (an armature on no bar)


def test_the_stored_default_fit_is_current_and_equals_a_fresh_fit():
    """default_fit reads the stored fit only while its key matches; the stored fit must be
    what fitting the shipped CSV gives now (else: coupling.laws.tribology.write_default_fit_cache())."""
    from coupling.laws.tribology import DEFAULT_FIT_CACHE, default_fit_key, fit_tribometer, illustrative_data_path, \
        read_tribometer_csv
    from coupling.laws.tribology.fits import TribometerFit

    doc = json.loads(DEFAULT_FIT_CACHE.read_text())
    assert doc["key"] == default_fit_key(), "stored fit is stale: run coupling.laws.tribology.write_default_fit_cache()"
    stored = TribometerFit.from_dict(doc["fit"])
    fresh = fit_tribometer(read_tribometer_csv(illustrative_data_path()))
    # the stored fit names the dataset by its place in the package, a fresh one by this machine's path
    assert_same_fit(stored, dataclasses.replace(fresh, source=stored.source))


def test_a_new_build_removes_earlier_builds_their_locks_and_failure_notes_only(tmp_path):
    from mech.aot import remove_stale

    current = tmp_path / "aot-new-np2-cp311"
    for name in ("aot-old-np2-cp311", "aot-new-np2-cp311", "aot-old2-np2-cp311.build-x1"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "module.so").write_bytes(b"\0")
    for name in ("aot-old-np2-cp311.lock", "aot-old3-np2-cp311.failed", "aot-new-np2-cp311.lock",
                 "aot-new-np2-cp311.failed", "other.txt"):
        (tmp_path / name).write_text("x")
    remove_stale(current)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "aot-new-np2-cp311", "aot-new-np2-cp311.failed", "aot-new-np2-cp311.lock", "aot-old2-np2-cp311.build-x1",
        "other.txt"]
