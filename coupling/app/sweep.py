"""Design sweeps: one base scene, parameters varied over a design, runs on Dask.

A sweep is a base scene plus a list of runs, each a set of "section.key" values (any
scene key, as ``Scene.set`` takes them), built from one design:

- ``grid``: every combination of the listed values;
- ``cases``: a list of runs, each optionally named;
- ``random`` / ``lhs``: ``samples`` seeded draws (uniform, or Latin hypercube through
  scipy.stats.qmc) inside [low, high] per parameter, log-uniform with ``log = true``;
- ``tolerance``: ``samples`` seeded draws around the base scene's values, normal or
  uniform per key (coupling.app.tolerance), and DIR/statistics.json of the metrics.

Every run's scene is built and validated in the client before anything starts (and the
design's size, MAX_RUNS, before it is built). Runs go to dask.distributed workers (a
LocalCluster of process workers, one thread each, on loopback with TLS credentials of its
own, by default; an existing scheduler by address): a worker process imports once and
runs scene after scene, never two at once (one ngspice per process); a worker whose
ngspice ended its session is restarted before it runs another. As each run finishes the
client appends its row (run_id, name, the parameters, every scalar of summary.json
flattened with dots, status, error, wall_time, session) to a Parquet dataset, one file
per small batch under ``OUT/results/``, each written whole (temporary file, then rename):

    read_results(OUT)   # pandas DataFrame, one row per finished run

A failed run is a row with status "failed" and its error; it never stops the sweep. The
client keeps only a bounded window of runs in flight and no waveforms (a run's waveforms,
on request, are written by the worker to ``OUT/waveforms/<run_id>.parquet``), so its
memory does not grow with the sweep. ``resume=True`` runs the runs without a row and
reruns the failed ones (their rows replaced): after Ctrl-C, a killed worker (Dask reruns
its run elsewhere) or a killed client, nothing finished is redone and nothing is lost or
written twice; one invocation at a time holds the folder (a lock on OUT/.sweep.lock). ``OUT`` must be reachable from
the client (rows) and, for waveforms, from the workers (a shared file system).

Sweep file (TOML, SI units)::

    [sweep]
    scene = "base.toml"          # relative to this file; omitted: the built-in default scene
    design = "grid"              # grid | cases | random | lhs | tolerance
    samples = 20                 # random, lhs, tolerance
    seed = 1                     # random, lhs, tolerance
    waveforms = false            # true, or a list of columns to keep
    set = { "output.plots" = false }     # applied to every run (optional)

    [sweep.grid]                 # design = "grid": lists of values
    "circuit.snubber.resistance" = [10.0, 47.0]
    "circuit.snubber.capacitance" = [10e-9, 47e-9]

    [[sweep.cases]]              # design = "cases"
    name = "stiff"
    "contact.restitution" = 0.9

    [sweep.ranges]               # design = "random" / "lhs": [low, high] or {low, high, log}
    "initial.angle_deg" = [10.0, 80.0]

    [sweep.tolerances]           # design = "tolerance" (coupling.app.tolerance)
    "rivet[0].mass" = { tolerance = 2e-6, distribution = "normal" }    # T = 3 sigma
    # [sweep] limits = { "bounce.total_bounce_time" = 4e-3 }: the fraction beyond, in statistics.json
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import math
import os
import re
import sys
import threading
import time
import tomllib
import uuid
from pathlib import Path

from coupling.app import usable_cpus
from mech.frozen import frozen

DESIGNS = ("grid", "cases", "random", "lhs", "tolerance")
_SWEEP_KEYS = {"scene", "design", "samples", "seed", "waveforms", "set", "grid", "cases", "ranges", "tolerances",
               "limits", "check"}
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$")
RESERVED = ("run_id", "name", "status", "error", "wall_time", "session", "finished_at")

#: Most runs one sweep may hold: counted before the design is built (a 1e10 grid took
#: 5.6 GB before it failed); every run's scene is checked before anything runs, ~0.3 ms
#: each for the default scene, so this many take about 30 s. Split a larger study.
MAX_RUNS = 100_000
#: Largest sweep file, bytes (checked before it is read).
MAX_SWEEP_FILE_BYTES = 16_000_000
#: How long `--scheduler` waits for a Dask scheduler to answer, s.
SCHEDULER_TIMEOUT = 5.0
#: Waveform columns of a coupled run besides the circuit's (circuit.COLUMNS) and the
#: scene's [circuit] probes: the contact force and penetration per tip, the arc's gap, mu.
COUPLED_COLUMNS = ("normal_force_0", "penetration_0", "normal_force_1", "penetration_1", "normal_force", "gap", "mu")
#: Times a run is resubmitted because it found its worker's ngspice ended before it started.
_MAX_RETRIES = 3


# --- the design ------------------------------------------------------------------------


@frozen
class Run:
    """One run of a sweep: its id (file-safe, unique), optional name and "section.key" values."""

    run_id: str
    name: str | None
    params: dict


@frozen
class Sweep:
    """A base scene document and the runs to make of it (validated: see ``check``).

    base: the base scene's TOML document (``Scene.raw``); base_dir: where its relative
    paths point; waveforms: False, True (all columns) or a tuple of columns to keep."""

    base: dict
    runs: tuple[Run, ...]
    base_dir: str = "."
    base_name: str = "scene"
    waveforms: bool | tuple[str, ...] = False
    common: dict = dataclasses.field(default_factory=dict)
    life: dict | None = None  # a life study per run: {"operations": N, "every": K} (coupling.app.life)
    study: dict | None = None  # a tolerance study: {tolerances, limits, samples, seed} (coupling.app.tolerance)
    checked: bool = dataclasses.field(default=False, init=False, compare=False, repr=False)  # set by check()

    # constructors ----------------------------------------------------------------------
    @classmethod
    def grid(cls, base, values: dict, **kw) -> "Sweep":
        """Every combination of ``values`` ({"section.key": [v1, v2, ...]}), last key fastest."""
        _check_params(values, "grid")
        keys = list(values)
        for key in keys:
            if not isinstance(values[key], (list, tuple)) or not values[key]:
                raise ValueError(f"sweep grid {key!r} = {values[key]!r:.200}: expected a non-empty list of values")
        sizes = [len(values[key]) for key in keys]
        _check_size(math.prod(sizes), f"sweep grid: {' x '.join(map(str, sizes))} values")
        combos: list[dict] = [{}]
        for key in keys:
            combos = [dict(c, **{key: v}) for c in combos for v in values[key]]
        return cls._of(base, [(None, c) for c in combos], **kw)

    @classmethod
    def cases(cls, base, cases: list, **kw) -> "Sweep":
        """Runs given one by one: dicts of "section.key" values, each with an optional "name"."""
        if not isinstance(cases, (list, tuple)) or not cases:
            raise ValueError(f"sweep cases = {cases!r:.200}: expected a non-empty list of tables")
        _check_size(len(cases), "sweep cases")
        out = []
        for k, case in enumerate(cases):
            if not isinstance(case, dict):
                raise ValueError(f"sweep case {k}: {case!r} is not a table of 'section.key' = value")
            case = _flatten_keys(case)
            name = case.pop("name", None)
            _check_params(case, f"case {k}")
            out.append((name, case))
        return cls._of(base, out, **kw)

    @classmethod
    def sample(cls, base, ranges: dict, *, samples: int, seed: int = 0, method: str = "lhs", **kw) -> "Sweep":
        """``samples`` seeded draws in [low, high] per "section.key" (ranges: [low, high] or
        {low, high, log}); method "lhs" (Latin hypercube, scipy.stats.qmc) or "random"."""
        if method not in ("lhs", "random"):
            raise ValueError(f"sweep design = {method!r}: allowed values are 'lhs', 'random'")
        if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
            raise ValueError(f"sweep samples = {samples!r}: expected an integer >= 1")
        _check_size(samples, "sweep samples")
        if not isinstance(seed, int) or isinstance(seed, bool):
            raise ValueError(f"sweep seed = {seed!r}: expected an integer")
        ranges = _flatten_keys(ranges, leaf=lambda v: isinstance(v, dict) and "low" in v)
        _check_params(ranges, "ranges")
        bounds = [_range(key, spec) for key, spec in ranges.items()]
        import numpy as np

        if method == "lhs":
            from scipy.stats import qmc

            unit = qmc.LatinHypercube(d=len(bounds), seed=seed).random(samples)
        else:
            unit = np.random.default_rng(seed).random((samples, len(bounds)))
        rows = []
        for u in unit:
            case = {}
            for (key, low, high, log), x in zip(bounds, u):
                value = math.exp(math.log(low) + x * (math.log(high) - math.log(low))) if log else low + x * (high - low)
                case[key] = float(value)
            rows.append((None, case))
        return cls._of(base, rows, **kw)

    @classmethod
    def tolerance(cls, base, tolerances: dict, *, samples: int, seed: int = 0, limits: dict | None = None,
                  check: int = 0, **kw) -> "Sweep":
        """A tolerance study: ``samples`` seeded draws of the keys of ``tolerances`` ({key:
        {tolerance, distribution = "normal" | "uniform", relative}}) around the values the
        base scene (with ``common``) gives them; ``limits`` {metric: limit} (SI). After the
        runs, run_sweep writes DIR/statistics.json (coupling.app.tolerance). ``check``: how
        many of the runs (the first) are also rerun refined, as ``run --check`` does, to set
        the numerical error beside the scatter."""
        from coupling.app.tolerance import check_limits, check_tolerances, draw

        if not isinstance(samples, int) or isinstance(samples, bool) or samples < 2:
            raise ValueError(f"sweep samples = {samples!r}: expected an integer >= 2")
        _check_size(samples, "sweep samples")
        if not isinstance(seed, int) or isinstance(seed, bool):
            raise ValueError(f"sweep seed = {seed!r}: expected an integer")
        if not isinstance(tolerances, dict):
            raise ValueError(f"sweep.tolerances = {tolerances!r:.200}: expected a table of 'key' = {{ tolerance, "
                             "distribution }")
        tolerances = _flatten_keys(tolerances, leaf=lambda v: isinstance(v, dict) and "tolerance" in v)
        _check_params(tolerances, "tolerances")
        common = _flatten_keys(dict(kw.get("common") or {}))
        raw = base.raw if hasattr(base, "raw") else base
        checked = check_tolerances(tolerances, apply_changes(raw, common) if isinstance(raw, dict) else raw)
        limits = check_limits(limits)
        if not isinstance(check, int) or isinstance(check, bool) or not 0 <= check <= samples:
            raise ValueError(f"sweep check = {check!r}: expected a whole number of runs, 0 to samples = {samples}")
        sweep = cls._of(base, [(None, values) for values in draw(checked, samples, seed)], **kw)
        study = dict(tolerances={k: dict(v) for k, v in tolerances.items()}, limits=limits, samples=samples,
                     seed=seed, base_values={k: v[0] for k, v in checked.items()}, check=check,
                     check_runs=[r.run_id for r in sweep.runs[:check]])
        return dataclasses.replace(sweep, study=study)

    @classmethod
    def _of(cls, base, rows, *, waveforms=False, common: dict | None = None) -> "Sweep":
        from coupling.core.scene import Scene

        if isinstance(base, Scene):
            raw, base_dir, name = copy.deepcopy(base.raw), str(base.base_dir), base.name
        elif isinstance(base, dict):
            raw, base_dir, name = copy.deepcopy(base), ".", "scene"
        else:
            raise ValueError(f"sweep base = {base!r}: expected a Scene or a scene document (dict)")
        common = _flatten_keys(dict(common or {}))
        _check_params(common, "set")
        runs, seen = [], set()
        width = max(4, len(str(len(rows) - 1)))
        for k, (label, params) in enumerate(rows):
            if label is not None and (not isinstance(label, str) or not _NAME.match(label)):
                raise ValueError(f"sweep case {k} name = {label!r}: expected letters, digits, '_', '.', '-' "
                                 "(at most 100, starting with a letter or digit)")
            run_id = label if label is not None else f"run{k:0{width}d}"
            if run_id in seen:
                raise ValueError(f"sweep case {k} name = {label!r}: used twice")
            seen.add(run_id)
            runs.append(Run(run_id=run_id, name=label, params=dict(params)))
        return cls(base=raw, runs=tuple(runs), base_dir=base_dir, base_name=name,
                   waveforms=_waveforms_option(waveforms), common=common)

    # ---------------------------------------------------------------------------------
    @property
    def parameters(self) -> list[str]:
        """The varied "section.key" names, in first-seen order."""
        seen: dict[str, None] = {}
        for run in self.runs:
            for key in run.params:
                seen.setdefault(key, None)
        return list(seen)

    def document(self, run: Run) -> dict:
        """The scene document of one run: the base with the common and the run's values set."""
        return apply_changes(self.base, {**self.common, **run.params})

    def scene(self, run: Run):
        """The validated Scene of one run."""
        from coupling.core.scene import scene_from_dict

        return scene_from_dict(self.document(run), base_dir=self.base_dir, name=f"{self.base_name} [{run.run_id}]")

    def check(self) -> None:
        """Build every run's scene: a bad key or value is reported, naming the run, before
        anything runs; so is a ``waveforms`` column no run records (with a did-you-mean)."""
        columns: set[str] = set()
        for run in self.runs:
            try:
                scene = self.scene(run)
            except (ValueError, FileNotFoundError) as err:
                raise ValueError(f"sweep run {run.run_id} ({_describe(run.params)}): {err}") from None
            columns.update(_waveform_columns(scene))
        if isinstance(self.waveforms, tuple):
            from mech.validation import suggest

            for column in self.waveforms:
                if column not in columns:
                    raise ValueError(f"sweep waveforms: unknown column {column!r}{suggest(column, columns)}; "
                                     f"the runs record: {', '.join(sorted(columns)) or 'none (no circuit)'}")
        object.__setattr__(self, "checked", True)

    def fingerprint(self) -> str:
        """A hash of what the sweep computes (base, common values, runs, waveforms): a resume
        must continue the same sweep."""
        doc = dict(base=self.base, base_dir=self.base_dir, common=self.common, waveforms=self.waveforms,
                   runs=[(r.run_id, r.params) for r in self.runs])
        if self.life is not None:
            doc["life"] = self.life
        if self.study is not None:
            doc["study"] = self.study
        return hashlib.sha256(json.dumps(doc, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def apply_changes(raw: dict, changes: dict) -> dict:
    """A copy of a scene document with scene keys set as ``Scene.set`` sets them
    ("section.key", "rivet[0].mass", "circuit.params.RF": coupling.core.scene.set_keys)."""
    from coupling.core.scene import set_keys

    return set_keys(raw, changes, "sweep parameter")


def _flatten_keys(table: dict, prefix: str = "", leaf=lambda v: False) -> dict:
    """{"circuit": {"snubber": {"resistance": [..]}}} (TOML dotted keys) -> {"circuit.snubber.resistance": [..]}."""
    out = {}
    for key, value in table.items():
        full = f"{prefix}{key}"
        if isinstance(value, dict) and not leaf(value) and key != "name":
            out.update(_flatten_keys(value, f"{full}.", leaf))
        else:
            out[full] = value
    return out


def _check_params(params: dict, where: str) -> None:
    from coupling.core.scene import key_steps

    for key in params:
        try:
            key_steps(key)
        except ValueError as err:
            raise ValueError(f"sweep {where}: {err}") from None
        if key in RESERVED:
            raise ValueError(f"sweep {where}: key {key!r} is reserved for the results table")


def _range(key: str, spec) -> tuple[str, float, float, bool]:
    log = False
    if isinstance(spec, dict):
        unknown = set(spec) - {"low", "high", "log"}
        if unknown:
            raise ValueError(f"sweep ranges {key!r}: unknown key(s) {sorted(unknown)}; allowed: low, high, log")
        log = spec.get("log", False)
        if not isinstance(log, bool):
            raise ValueError(f"sweep ranges {key!r} log = {log!r}: expected true or false")
        spec = [spec.get("low"), spec.get("high")]
    if (not isinstance(spec, (list, tuple)) or len(spec) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in spec)
            or not spec[0] < spec[1]):
        raise ValueError(f"sweep ranges {key!r} = {spec!r}: expected [low, high] with finite low < high "
                         "or {low, high, log = true}")
    if log and spec[0] <= 0:
        raise ValueError(f"sweep ranges {key!r}: a log range needs low > 0, got {spec[0]!r}")
    return key, float(spec[0]), float(spec[1]), log


def _check_size(runs: int, what: str) -> None:
    if runs > MAX_RUNS:
        raise ValueError(f"{what} make {runs} runs, more than the {MAX_RUNS} one sweep may hold "
                         "(coupling.app.sweep.MAX_RUNS): split the study into several sweeps")


def _waveform_columns(scene) -> tuple[str, ...]:
    """The waveform columns a run of ``scene`` records (none without a circuit)."""
    if scene.circuit is None:
        return ()
    from circuit import COLUMNS

    probes = tuple(p.text for p in scene.circuit.probes)
    return COLUMNS + (COUPLED_COLUMNS if scene.kind == "coupled" else ()) + probes


def _waveforms_option(value) -> bool | tuple[str, ...]:
    if isinstance(value, bool):
        return value
    if isinstance(value, (list, tuple)) and value and all(isinstance(c, str) for c in value):
        return tuple(value) if "time" in value else ("time",) + tuple(value)
    raise ValueError(f"sweep waveforms = {value!r}: expected true, false or a list of column names")


def _describe(params: dict) -> str:
    return ", ".join(f"{k} = {v!r}" for k, v in params.items()) or "base scene"


def _read_sweep_file(path) -> dict:
    """The TOML document of a sweep file, checked as any input file is: a regular file (not
    a folder, device or pipe, which are never opened), at most MAX_SWEEP_FILE_BYTES, UTF-8
    text (line and column of the first bad byte), valid TOML; one line otherwise."""
    from mech.validation import check_file

    path = check_file("sweep file", path)
    try:
        size = path.stat().st_size
        if size > MAX_SWEEP_FILE_BYTES:
            raise ValueError(f"sweep file {str(path)!r} is {size} bytes, more than the {MAX_SWEEP_FILE_BYTES} "
                             "a sweep file may have")
        with open(path, "rb") as fh:
            data = fh.read(MAX_SWEEP_FILE_BYTES + 1)
    except OSError as err:
        raise ValueError(f"sweep file {str(path)!r} cannot be read: {err.strerror or err}") from None
    if len(data) > MAX_SWEEP_FILE_BYTES:
        raise ValueError(f"sweep file {str(path)!r} grew beyond the {MAX_SWEEP_FILE_BYTES} bytes a sweep file may "
                         "have while it was read")
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        column = err.start - (data.rfind(b"\n", 0, err.start) + 1) + 1
        raise ValueError(f"{path}: line {line}, column {column}: byte 0x{data[err.start]:02x} is not UTF-8 text; "
                         "save the sweep file as UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{path}: not valid TOML: {err}") from None
    except RecursionError:
        raise ValueError(f"{path}: arrays or inline tables nested too deeply") from None


def load_sweep(path) -> Sweep:
    """Read and validate a sweep TOML file (see the module docstring); every run's scene is checked."""
    doc = _read_sweep_file(path)
    path = Path(path)
    table = doc.get("sweep")
    if not isinstance(table, dict) or set(doc) != {"sweep"}:
        raise ValueError(f"{path}: expected one [sweep] table (with scene, design and the design's values); "
                         f"found {sorted(doc) or 'nothing'}")
    for key in table:
        if key not in _SWEEP_KEYS:
            raise ValueError(f"{path}: unknown key sweep.{key}; allowed: {', '.join(sorted(_SWEEP_KEYS))}")
    design = table.get("design")
    if design not in DESIGNS:
        raise ValueError(f"{path}: sweep.design = {design!r}: allowed values are {', '.join(map(repr, DESIGNS))}")
    need = {"grid": "grid", "cases": "cases", "random": "ranges", "lhs": "ranges", "tolerance": "tolerances"}[design]
    if need not in table:
        raise ValueError(f"{path}: sweep.design = {design!r} needs sweep.{need}")
    for other in sorted({"grid", "cases", "ranges", "tolerances"} - {need}):
        if other in table:
            raise ValueError(f"{path}: sweep.{other} is unused with sweep.design = {design!r}; remove it")
    for key in ("samples", "seed"):
        if key in table and design not in ("random", "lhs", "tolerance"):
            raise ValueError(f"{path}: sweep.{key} is unused with sweep.design = {design!r}; remove it")
    for key in ("limits", "check"):
        if key in table and design != "tolerance":
            raise ValueError(f"{path}: sweep.{key} is used by sweep.design = \"tolerance\" only; remove it")
    from coupling.core.scene import default_scene, load_scene

    scene_key = table.get("scene")
    if scene_key is None:
        base = default_scene()
    elif isinstance(scene_key, str):
        base = load_scene(path.parent / scene_key)
    else:
        raise ValueError(f"{path}: sweep.scene = {scene_key!r}: expected a scene file name")
    common = table.get("set", {})
    if not isinstance(common, dict):
        raise ValueError(f"{path}: sweep.set = {common!r}: expected a table of 'section.key' = value")
    kw = dict(waveforms=table.get("waveforms", False), common=common)
    if design == "grid":
        grid = table["grid"]
        if not isinstance(grid, dict) or not grid:
            raise ValueError(f"{path}: sweep.grid = {grid!r}: expected a table of 'section.key' = [values]")
        sweep = Sweep.grid(base, _flatten_keys(grid), **kw)
    elif design == "cases":
        sweep = Sweep.cases(base, table["cases"], **kw)
    elif design == "tolerance":
        if "samples" not in table:
            raise ValueError(f"{path}: sweep.design = \"tolerance\" needs sweep.samples (the number of runs)")
        sweep = Sweep.tolerance(base, table["tolerances"], samples=table["samples"], seed=table.get("seed", 0),
                                limits=table.get("limits"), check=table.get("check", 0), **kw)
    else:
        if "samples" not in table:
            raise ValueError(f"{path}: sweep.design = {design!r} needs sweep.samples (the number of runs)")
        ranges = table["ranges"]
        if not isinstance(ranges, dict) or not ranges:
            raise ValueError(f"{path}: sweep.ranges = {ranges!r}: expected a table of 'section.key' = [low, high]")
        sweep = Sweep.sample(base, ranges, samples=table["samples"], seed=table.get("seed", 0), method=design, **kw)
    sweep.check()
    return sweep


# --- one run, on a worker --------------------------------------------------------------

_RUN_LOCK = threading.Lock()  # one ngspice per process: never two runs of this process at once


def flatten_summary(summary: dict, prefix: str = "") -> dict:
    """Every scalar of a summary.json document, keys joined with dots (lists left out,
    except ``flags``, joined with '; ', ``warnings``, one per line: a warning may hold a
    '; ' itself, never a line break; "" when the run has none, and the first of
    ``operations``, as ``operations.0.``)."""
    out: dict = {}
    for key, value in summary.items():
        full = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten_summary(value, f"{full}."))
        elif key == "flags" and isinstance(value, list):
            out[full] = "; ".join(map(str, value))
        elif key == "warnings" and isinstance(value, list):
            out[full] = "\n".join(" ".join(str(w).split()) for w in value)
        elif key == "operations" and not prefix and isinstance(value, list) and value:
            # the first operation (make, break, held closure): a study of a relay's gap or
            # spring reads its held force and its break's arc from the row
            out.update(flatten_summary(value[0], f"{full}.0."))
        elif value is None or isinstance(value, (bool, int, float, str)):
            out[full] = value
    return out


def _cell(value):
    """A parameter value as a Parquet cell: scalars as they are, anything else as JSON text."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return json.dumps(value)


def execute(sweep_doc: dict, run_doc: dict, wave_dir: str | None) -> dict:
    """Run one scene (worker side) and return its results row; never raises for a failing run."""
    from coupling.core.master import CoupledRunError, run
    from coupling.core.scene import scene_from_dict

    tick = time.perf_counter()
    row = {"run_id": run_doc["run_id"], "name": run_doc["name"]}
    params = run_doc["params"]
    summary = None
    numerical: dict = {}
    status, error = "ok", None
    with _RUN_LOCK:
        worker = _worker_address()
        if worker is not None and _ngspice_exited():
            # an earlier run here ended ngspice: this process cannot run a circuit; the client
            # restarts the worker and submits the run again
            return {**row, "_retry": worker}
        try:
            doc = apply_changes(sweep_doc["base"], {**sweep_doc["common"], **params})
            scene = scene_from_dict(doc, base_dir=sweep_doc["base_dir"], name=f"{sweep_doc['base_name']} "
                                                                           f"[{run_doc['run_id']}]")
            result = run(scene) if sweep_doc.get("life") is None else _life(scene, sweep_doc["life"], run_doc)
            summary = result.summary
            waveforms = result.waveforms
            status, error = result.status.value, result.message or None  # judged where it was made
            if run_doc["run_id"] in sweep_doc.get("check_runs", ()) and status == "ok":
                from coupling.app.accuracy import check as accuracy_check
                from coupling.app.tolerance import numerical_changes

                try:
                    numerical = numerical_changes(accuracy_check(scene, result, sensitivity=False))
                except Exception as err:  # noqa: BLE001 - the run stands; only its check failed
                    numerical = {"numerical.status": f"check failed: {type(err).__name__}: {_one_line(err)}"}
        except CoupledRunError as err:
            status, error = "failed", _one_line(err)
            summary = err.partial.summary if err.partial is not None else None
            waveforms = err.partial.waveforms if err.partial is not None else None
        except Exception as err:  # noqa: BLE001 - a failed run is a row, never the end of the sweep
            status, error, waveforms = "failed", f"{type(err).__name__}: {_one_line(err)}", None
        if wave_dir is not None and waveforms is not None:
            keep = sweep_doc["waveforms"]
            if isinstance(keep, (list, tuple)):
                waveforms = waveforms[[c for c in keep if c in waveforms.columns]]
            _write_parquet_atomic(waveforms, Path(wave_dir) / f"{run_doc['run_id']}.parquet")
    for key, value in params.items():
        row[key] = _cell(value)
    if summary is not None:
        for key, value in flatten_summary(summary).items():
            if key == "status":
                continue
            row[f"summary.{key}" if key in row or key in RESERVED else key] = value
    row.update(numerical)
    row.update(status=status, error=error, wall_time=time.perf_counter() - tick)
    if worker is not None and _ngspice_exited():
        row["_restart"] = worker  # this run ended ngspice ("cannot recover"): the worker needs a new process
    return row


def _life(scene, life: dict, run_doc: dict):
    """A life study of one run's scene (coupling.app.life.design_life), in place of its run."""
    from coupling.app.life import design_life

    return design_life(scene, life, run_doc["run_id"])


def _worker_address() -> str | None:
    """The Dask worker this runs in, or None (run_sweep_inline)."""
    if "distributed" not in sys.modules:
        return None
    from distributed import get_worker

    try:
        return get_worker().address
    except ValueError:  # not in a worker
        return None


def _ngspice_exited() -> bool:
    """True when this process's ngspice has ended its session (only a new process has one)."""
    if "circuit.ngspice" not in sys.modules:
        return False  # no circuit ran here
    from circuit.ngspice import get_session

    try:
        return get_session().exited
    except Exception:  # noqa: BLE001 - no ngspice to be had at all: the runs say why themselves
        return False


def _one_line(err) -> str:
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _write_parquet_atomic(frame, path: Path) -> None:
    """A pandas frame or an Arrow table to ``path``, whole or not at all (rename)."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    if hasattr(frame, "to_parquet"):
        frame.to_parquet(tmp, index=False)
    else:
        import pyarrow.parquet as pq

        pq.write_table(frame, tmp)
    os.replace(tmp, path)


# --- the results dataset ---------------------------------------------------------------


_PART = re.compile(r"^part-(?P<session>.+)-(?P<first>\d+)(?:to(?P<last>\d+))?\.parquet$")


def _part_range(path: Path) -> tuple[str, int, int] | None:
    """(session, first, last) of a batch file: ``part-S-00007.parquet`` holds batch 7 of
    session S, ``part-S-00000to00015.parquet`` batches 0 to 15 merged (RowWriter)."""
    m = _PART.match(path.name)
    if m is None:
        return None
    first = int(m["first"])
    return m["session"], first, int(m["last"]) if m["last"] is not None else first


def _result_files(out: Path) -> list[Path]:
    """The batch files holding the rows, in the order written. A file whose batches a merged
    file of its session also covers is left out: a merge writes the merged file first and
    then deletes the files it replaces, so one stopped in between leaves both, and the
    rows are read once."""
    folder = out / "results"
    if not folder.is_dir():
        return []
    parts = [(r, f) for f in folder.glob("part-*.parquet") if (r := _part_range(f)) is not None]
    kept = [(r, f) for r, f in parts
            if not any(o[0] == r[0] and o[1] <= r[1] and r[2] <= o[2] and o[1:] != r[1:] for o, _ in parts)]
    return [f for _, f in sorted(kept, key=lambda rf: rf[0])]


def read_results(out_dir, columns: list[str] | None = None):
    """The sweep's results: one pandas row per finished run (all batch files of
    OUT/results as one Parquet dataset; columns missing from a batch are null there)."""
    import pyarrow as pa
    import pyarrow.dataset as ds
    import pyarrow.parquet as pq

    files = _result_files(Path(out_dir))
    if not files:
        import pandas as pd

        return pd.DataFrame({c: [] for c in ("run_id", "name", "status", "error", "wall_time")})
    schema = pa.unify_schemas([pq.read_schema(f) for f in files], promote_options="permissive")
    table = ds.dataset([str(f) for f in files], schema=schema, format="parquet").to_table(columns=columns)
    return table.to_pandas()


def finished_run_ids(out_dir) -> set[str]:
    """run_id of every run with a row (reads that one column only)."""
    return set(_row_statuses(Path(out_dir)))


def _row_statuses(out: Path) -> dict[str, str]:
    """run_id -> status of every row (two columns read)."""
    import pyarrow.parquet as pq

    statuses: dict[str, str] = {}
    for f in _result_files(out):
        table = pq.read_table(f, columns=["run_id", "status"])
        statuses.update(zip(table.column("run_id").to_pylist(), table.column("status").to_pylist()))
    return statuses


def _drop_rows(out: Path, run_ids: set[str]) -> None:
    """Remove the rows of ``run_ids`` from the batch files (each rewritten whole, by rename;
    a batch left empty is deleted): a rerun's row then replaces them, never joins them."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    for f in _result_files(out):
        table = pq.read_table(f)
        keep = pc.invert(pc.is_in(table.column("run_id"), value_set=pa.array(sorted(run_ids))))
        if pc.all(keep).as_py():
            continue
        kept = table.filter(keep)
        if kept.num_rows == 0:
            f.unlink()
            continue
        tmp = f.with_name(f".{f.name}.{uuid.uuid4().hex}.tmp")
        pq.write_table(kept, tmp)
        os.replace(tmp, f)


def read_waveforms(out_dir, run_id: str):
    """The waveforms kept for one run (pandas), from OUT/waveforms/<run_id>.parquet."""
    import pandas as pd

    path = Path(out_dir) / "waveforms" / f"{run_id}.parquet"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no waveforms kept for run {run_id!r} (sweep.waveforms = true keeps them)")
    return pd.read_parquet(path)


class RowWriter:
    """Appends rows to OUT/results as Parquet batch files, each written whole (rename), a batch
    every ``every`` seconds or ``size`` rows, and on close.

    Every ``merge`` files of one size are merged into one (``part-S-00000to00015.parquet``),
    and so on up: a long study then leaves a few dozen files, not one per batch. Reading
    many small files costs memory by the file, not by the row (measured: 629 batches of
    1020 rows took 340 MiB to read as one dataset, 100 MiB one by one), which made the
    client's memory grow with the study's length at its statistics stage."""

    def __init__(self, folder: Path, session: str, every: float = 0.5, size: int = 64, merge: int = 16):
        self.folder, self.session, self.every, self.size, self.merge = folder, session, every, size, merge
        self.rows: list[dict] = []
        self.count = 0
        self.last = time.monotonic()
        self.levels: list[list[tuple[int, int, Path]]] = [[]]  # per merge level: (first, last, file)
        folder.mkdir(parents=True, exist_ok=True)

    def add(self, row: dict) -> None:
        self.rows.append(row)
        if len(self.rows) >= self.size or time.monotonic() - self.last >= self.every:
            self.flush()

    def flush(self) -> None:
        self.last = time.monotonic()
        if not self.rows:
            return
        import pandas as pd

        frame = pd.DataFrame(self.rows)
        path = self.folder / f"part-{self.session}-{self.count:05d}.parquet"
        _write_parquet_atomic(_typed_batch(frame), path)
        self.levels[0].append((self.count, self.count, path))
        self.count += 1
        self.rows = []
        level = 0
        while len(self.levels[level]) >= self.merge:
            merged = self._merged(self.levels[level])
            self.levels[level] = []
            if level + 1 == len(self.levels):
                self.levels.append([])
            self.levels[level + 1].append(merged)
            level += 1

    def _merged(self, files: list[tuple[int, int, Path]]) -> tuple[int, int, Path]:
        """One file holding the rows of ``files`` (written whole first, then they are deleted)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        first, last = files[0][0], files[-1][1]
        table = pa.concat_tables([pq.read_table(f) for _, _, f in files], promote_options="permissive")
        path = self.folder / f"part-{self.session}-{first:05d}to{last:05d}.parquet"
        _write_parquet_atomic(table, path)
        for _, _, f in files:
            f.unlink(missing_ok=True)
        return first, last, path


def _typed_batch(frame):
    """A batch of rows as an Arrow table whose columns with no value at all are of null type:
    pandas makes such a column float (NaN), and a batch in which a text column (a
    settle_note) happened to be missing in every row then had a double column where another
    batch had strings, which no schema unifies (a 1000-run study stopped on it); null merges
    with any type."""
    import pyarrow as pa

    table = pa.Table.from_pandas(frame, preserve_index=False)
    for k, fld in enumerate(table.schema):
        col = table.column(k)
        if len(col) and col.null_count == len(col) and not pa.types.is_null(fld.type):
            table = table.set_column(k, pa.field(fld.name, pa.null()), pa.nulls(len(col)))
    return table


# --- running a sweep -------------------------------------------------------------------


@dataclasses.dataclass
class SweepReport:
    """What one call of run_sweep did: runs in the sweep, skipped (already finished), done now, failed now."""

    total: int
    skipped: int
    done: int = 0
    failed: int = 0
    seconds: float = 0.0
    run_seconds: float = 0.0
    interrupted: bool = False
    out_dir: str = ""
    rerun: int = 0  # runs that had a failed row and were run again (resume)
    statistics: str | None = None  # a tolerance study's DIR/statistics.json, once every run has a row

    @property
    def complete(self) -> bool:
        return not self.interrupted and self.skipped + self.done == self.total


class _ProgressLine:
    def __init__(self, total: int, skipped: int, enabled: bool, stream=sys.stderr, every: float = 1.0):
        self.total, self.skipped, self.enabled, self.stream, self.every = total, skipped, enabled, stream, every
        self.start = time.monotonic()
        self.last = -math.inf
        self.shown = None
        self.tty = enabled and hasattr(stream, "isatty") and stream.isatty()

    def __call__(self, done: int, failed: int, final: bool = False) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if not final and now - self.last < (0.2 if self.tty else self.every):
            return
        if final and self.shown == (done, failed) and not self.tty:
            return
        self.last, self.shown = now, (done, failed)
        elapsed = now - self.start
        rate = done / elapsed if elapsed > 0 else 0.0
        todo = self.total - self.skipped
        eta = f", {(todo - done) / rate:.0f} s left" if rate > 0 and done < todo else ""
        line = (f"switchsim sweep: {self.skipped + done}/{self.total} runs done, {failed} failed, "
                f"{rate:.2f} runs/s{eta}")
        if self.tty:
            print("\r" + line, end="\n" if final else "", file=self.stream, flush=True)
        else:
            print(line, file=self.stream, flush=True)


def _sweep_folder(out_dir) -> Path:
    """The --out folder, created if missing; one line for a file, a device or no permission."""
    if not isinstance(out_dir, (str, os.PathLike)) or not str(out_dir).strip():
        raise ValueError(f"--out {out_dir!r}: give the name of a folder for the sweep's results")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        kind = "a file" if out.is_file() else "not a folder (a device or special file)"
        raise ValueError(f"--out {str(out_dir)!r} is {kind}; give a folder name")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ValueError(f"--out {str(out_dir)!r}: cannot create the folder: {err.strerror or err}") from None
    return out


class _FolderLock:
    """An exclusive lock on a sweep folder for one invocation (flock on OUT/.sweep.lock, let
    go by the system when the process ends, however it ends): two invocations on the same
    folder would both run the runs without a row, and write them twice."""

    def __init__(self, out: Path):
        self.path = out / ".sweep.lock"
        self.fd: int | None = None

    def __enter__(self) -> "_FolderLock":
        import fcntl

        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise ValueError(f"--out {str(self.path.parent)!r}: cannot write there: {err.strerror or err}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.read(fd, 64).decode("ascii", "replace").strip() or "another process"
            os.close(fd)
            raise ValueError(f"{self.path.parent} is in use by another sweep (process {holder}): "
                             "wait for it to finish, or use another --out") from None
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            os.close(self.fd)  # releases the lock; the empty file stays (harmless)
            self.fd = None


def _manifest(sweep: Sweep, out: Path, resume: bool, write: bool = True) -> None:
    """Write OUT/sweep.json for a new sweep (``write``); for one with rows already, check it
    is the same sweep and that --resume was asked for. A folder without rows (a sweep that
    never got to run: its cluster did not start, it was stopped at once) starts over."""
    path = out / "sweep.json"
    fingerprint = sweep.fingerprint()
    has_rows = bool(_result_files(out))
    if path.is_file() and has_rows:
        try:
            old = json.loads(path.read_bytes())
            if not isinstance(old, dict):
                raise ValueError(f"a JSON {type(old).__name__}, not an object")
        except (OSError, ValueError, RecursionError) as err:
            raise ValueError(f"{path}: damaged, not the record of a sweep ({' '.join(str(err).split())[:120]}): "
                             "the rows in its results/ cannot be matched to a sweep; choose another --out") from None
        if not resume:
            raise ValueError(f"{out} already holds a sweep: pass --resume (resume=True) to continue it, "
                             "or choose another --out")
        if old.get("fingerprint") != fingerprint:
            raise ValueError(f"{out} holds a different sweep (fingerprint {old.get('fingerprint')}, this one "
                             f"{fingerprint}): the base scene, values or runs changed; choose another --out")
        return
    if has_rows:
        raise ValueError(f"{out}/results holds results without sweep.json: choose another --out")
    if not write:
        return
    doc = dict(fingerprint=fingerprint, base_name=sweep.base_name, base_dir=sweep.base_dir, base=sweep.base,
               common=sweep.common, waveforms=sweep.waveforms, parameters=sweep.parameters,
               runs=[dataclasses.asdict(r) for r in sweep.runs], **({} if sweep.life is None else {"life": sweep.life}),
               **({} if sweep.study is None else {"study": sweep.study}))
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(doc, indent=1, default=repr))
    os.replace(tmp, path)


# Dask's worker settings that slow a run down and buy a sweep nothing (benchmarks/bench_sweep.py):
# - the statistical profiler samples every thread's stack every 10 ms; with ngspice calling
#   back into Python thousands of times per run it made each run ~2.5x slower;
# - MALLOC_TRIM_THRESHOLD_ = 65536, set by the nanny before it starts a worker, makes glibc
#   hand freed memory back to the system at every 64 KiB: the run allocates and frees small
#   arrays at every macro step and was ~10 % slower, while a worker's memory after 60 runs
#   was the same without it (87 MiB). None unsets it (Dask's documented way).
WORKER_SETTINGS = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
}


def local_cluster(workers: int, **kw):
    """A dask LocalCluster for sweeps: `workers` processes with one thread each (one ngspice
    per process), no dashboard, WORKER_SETTINGS (no profiler, no aggressive malloc trim),
    listening on loopback only and with Dask's own security: TLS with credentials made for
    this cluster alone (``Security.temporary()``, mutual: a process without them can neither
    connect to the scheduler nor to a worker or nanny, so none can run code in the workers).
    ``Client(cluster)`` takes the credentials from the cluster."""
    import dask
    from distributed import LocalCluster
    from distributed.security import Security

    kw.setdefault("security", Security.temporary())
    kw.setdefault("protocol", "tls://")
    kw.setdefault("host", "127.0.0.1")
    with dask.config.set(WORKER_SETTINGS):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                            silence_logs=40, **kw)


def _refuse_in_a_worker_start() -> None:
    """A script without ``if __name__ == "__main__":`` is imported again by every worker
    process the local cluster starts (multiprocessing's spawn runs the main module as
    ``__mp_main__``), and so calls run_sweep again there: stop that worker at once with
    the fix, instead of a cluster that never starts."""
    # while spawn re-runs the script, it is sys.modules["__mp_main__"] but not yet "__main__"
    if "__mp_main__" in sys.modules and sys.modules["__mp_main__"] is not sys.modules.get("__main__"):
        raise SystemExit(f"switchsim sweep: {_GUARD_HINT}")


_GUARD_HINT = ("a Dask worker process imported the script that calls run_sweep and ran it again: put the sweep "
               "under `if __name__ == \"__main__\":` (docs/sweeps.md, Python)")


def _scheduler_client(scheduler: str):
    """A Client of the Dask scheduler at ``scheduler``, or one line within SCHEDULER_TIMEOUT.

    The address is parsed and its port tried with a plain socket first: a Client that fails
    to connect is left half-built in a reference cycle, and when the garbage collector
    later ends it from another thread its close() can deadlock the next Client's start
    (seen in one process: a sweep with a wrong --scheduler, then a good one)."""
    import gc
    import socket

    from distributed import Client
    from distributed.comm.addressing import parse_address, parse_host_port

    if not isinstance(scheduler, str):
        raise ValueError(f"--scheduler {scheduler!r}: expected an address, e.g. tcp://127.0.0.1:8786")
    try:
        scheme, location = parse_address(scheduler)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as err:
        raise ValueError(f"--scheduler {scheduler!r}: not a Dask scheduler address ({_one_line(err)[:160]}); "
                         "e.g. tcp://127.0.0.1:8786") from None
    unreachable = None
    if host is not None:
        try:
            socket.create_connection((host, port), timeout=SCHEDULER_TIMEOUT).close()
        except OSError as err:
            unreachable = f"{type(err).__name__}: {err.strerror or err}"
    if unreachable is None and scheme == "tcp":
        unreachable = _ask_identity(scheduler)
    if unreachable is None:
        try:
            return Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT}s")
        except (OSError, TimeoutError, ValueError, TypeError) as err:
            unreachable = f"{type(err).__name__}: {_one_line(err)[:160]}"
        gc.collect()  # the failed Client ends here, in this thread (see above)
    raise ValueError(f"--scheduler {scheduler!r}: no Dask scheduler answered within {SCHEDULER_TIMEOUT:g} s "
                     f"({unreachable}); start one (`dask scheduler`) or check the address")


def _ask_identity(address: str) -> str | None:
    """None if a Dask scheduler at ``address`` says who it is within SCHEDULER_TIMEOUT, else
    why not: a port that accepts connections and says nothing would hold a Client's start
    for as long as it stays open (Dask's connect timeout ends at the TCP connection)."""
    import asyncio

    from distributed.core import rpc

    try:
        asyncio.get_running_loop()
        return None  # called from a running event loop (a notebook): the Client's own checks only
    except RuntimeError:
        pass

    async def identity():
        async with rpc(address, timeout=SCHEDULER_TIMEOUT) as remote:
            return await remote.identity()

    try:
        info = asyncio.run(asyncio.wait_for(identity(), SCHEDULER_TIMEOUT))
    except (OSError, asyncio.TimeoutError, TimeoutError):
        return "the port takes connections but no Dask scheduler speaks there"
    except Exception as err:  # noqa: BLE001 - anything else that answered: not a scheduler
        return f"{type(err).__name__}: {_one_line(err)[:120]}"
    kind = info.get("type") if isinstance(info, dict) else None
    return None if kind == "Scheduler" else f"a Dask {kind or 'process'} answers there, not a scheduler"


def _start_local(n: int):
    """A local cluster of ``n`` workers and its client; one line saying why if it cannot start."""
    from distributed import Client

    try:
        cluster = local_cluster(n)
    except Exception as err:  # noqa: BLE001 - Dask reports a worker that died at start in several ways
        main = sys.modules.get("__main__")
        hint = (f"; if run_sweep is called from a script: {_GUARD_HINT}" if getattr(main, "__spec__", None) is None
                and getattr(main, "__file__", None) else "")
        raise RuntimeError(f"the local Dask cluster did not start ({type(err).__name__}: "
                           f"{_one_line(err)[:160]}){hint}") from None
    try:
        return cluster, Client(cluster)
    except BaseException:
        cluster.close()
        raise


def run_sweep(sweep: Sweep, out_dir, *, workers: int | None = None, scheduler: str | None = None,
              client=None, resume: bool = False, progress: bool = True, window: int | None = None) -> SweepReport:
    """Run every run of ``sweep`` without a row in OUT/results (or with a failed one, on
    resume), on Dask; rows appended as runs finish.

    workers: worker processes of the local cluster (default: the machine's CPUs);
    scheduler: address of an existing Dask scheduler ("tcp://host:8786") instead of a local
    cluster; client: a distributed.Client to use as it is (left open); resume: continue a
    sweep already in out_dir, failed runs included; window: runs in flight at once (default
    2 per worker). Ctrl-C stops cleanly: what finished is kept (``interrupted``). One
    invocation at a time per out_dir (a second one is refused). A worker whose ngspice
    ended ("cannot recover") is restarted before it runs anything else.
    """
    _refuse_in_a_worker_start()
    if workers is not None and (not isinstance(workers, int) or isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers = {workers!r}: expected an integer >= 1")
    if not sweep.checked:
        sweep.check()
    out = _sweep_folder(out_dir)
    with _FolderLock(out):
        report = _run_locked(sweep, out, workers, scheduler, client, resume, progress, window)
        if sweep.study is not None and report.complete:
            from coupling.app.tolerance import write_statistics

            write_statistics(out, sweep.study)
            report.statistics = str(out / "statistics.json")
        return report


def _run_locked(sweep, out: Path, workers, scheduler, client, resume, progress, window) -> SweepReport:
    _manifest(sweep, out, resume, write=False)  # a folder holding another sweep: refused before any cluster
    statuses = _row_statuses(out) if resume else {}
    failed_before = {run_id for run_id, status in statuses.items() if status == "failed"}
    todo = [r for r in sweep.runs if r.run_id not in statuses or r.run_id in failed_before]
    report = SweepReport(total=len(sweep.runs), skipped=len(sweep.runs) - len(todo), out_dir=str(out),
                         rerun=len(failed_before & {r.run_id for r in sweep.runs}))
    line = _ProgressLine(report.total, report.skipped, progress)
    if not todo:
        line(0, 0, final=True)
        return report
    wave_dir = None
    if sweep.waveforms:
        wave_dir = out / "waveforms"
        wave_dir.mkdir(exist_ok=True)
        wave_dir = str(wave_dir.resolve())
    from distributed import as_completed

    tick = time.monotonic()
    session = f"{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:6]}"
    sweep_doc = dict(base=sweep.base, base_dir=str(Path(sweep.base_dir).resolve()), base_name=sweep.base_name,
                     common=sweep.common, waveforms=sweep.waveforms,
                     life=None if sweep.life is None else dict(sweep.life, folder=str((out / "life").resolve())),
                     check_runs=_check_runs(sweep))
    cluster = None
    own_client = client is None
    started = None
    writer = None
    try:
        if not own_client:
            n = max(1, len(client.scheduler_info().get("workers", {})))
        elif scheduler is not None:
            client = _scheduler_client(scheduler)
            n = max(1, len(client.scheduler_info().get("workers", {})))
        else:
            n = workers or usable_cpus()  # (a local cluster: a worker a CPU)
            cluster, client = _start_local(n)
        _manifest(sweep, out, resume)
        if progress:  # only now: bad input before this point is one line and nothing else
            print(f"switchsim sweep: {len(sweep.runs)} runs of {sweep.base_name}, varying "
                  f"{', '.join(sweep.parameters) or 'nothing'}", file=sys.stderr)
            if report.rerun:
                print(f"switchsim sweep: rerunning {report.rerun} failed run(s); their rows are replaced",
                      file=sys.stderr)
        if failed_before:
            _drop_rows(out, failed_before)  # only now: a sweep that could not start keeps its rows as they were
        writer = RowWriter(out / "results", session)
        line.start = started = time.monotonic()  # the rate counts runs, not the cluster's start
        pending = iter(todo)
        in_flight = as_completed()
        runs_of: dict = {}
        retries: dict[str, int] = {}
        restarted: set[str] = set()

        def submit(run: Run) -> None:
            future = _submit(client, sweep_doc, run, wave_dir)
            runs_of[future.key] = run
            in_flight.add(future)

        for run in _take(pending, window or 2 * n):
            submit(run)
        for future in in_flight:
            run = runs_of.pop(future.key)
            try:
                row = future.result()
            except Exception as err:  # the run's worker died repeatedly (KilledWorker) or similar
                row = {"run_id": run.run_id, "name": run.name, **{k: _cell(v) for k, v in run.params.items()},
                       "status": "failed", "error": f"{type(err).__name__}: {_one_line(err)}", "wall_time": None}
            future.release()
            dead = row.pop("_restart", None) or row.get("_retry")
            if dead is not None and dead not in restarted:
                restarted.add(dead)
                _restart_worker(client, dead, run, progress)
            if row.get("_retry"):  # it never ran: its worker's ngspice had ended before it started
                retries[run.run_id] = retries.get(run.run_id, 0) + 1
                if retries[run.run_id] <= _MAX_RETRIES:
                    submit(run)
                    continue
                row = {"run_id": run.run_id, "name": run.name, **{k: _cell(v) for k, v in run.params.items()},
                       "status": "failed", "error": "every worker it was sent to had lost its ngspice "
                                                    "(restarting them failed)", "wall_time": None}
            row.update(session=session, finished_at=time.time())
            writer.add(row)
            report.done += 1
            report.failed += row["status"] != "ok"
            line(report.done, report.failed)
            for run in _take(pending, 1):
                submit(run)
    except KeyboardInterrupt:
        report.interrupted = True
    finally:
        if writer is not None:
            writer.flush()
        report.seconds = time.monotonic() - tick
        report.run_seconds = time.monotonic() - started if started is not None else 0.0
        if started is not None:
            line(report.done, report.failed, final=True)
        for closable in ((client, cluster) if own_client else ()):
            if closable is not None:
                try:
                    closable.close()
                except (Exception, KeyboardInterrupt):  # noqa: BLE001 - after Ctrl-C or a lost scheduler
                    report.interrupted = True  # best effort; the rows are already written
    return report


def _restart_worker(client, address: str, run: Run, progress: bool) -> None:
    """Give the worker at ``address`` a new process (its nanny starts one; ngspice cannot be
    restarted inside a process). A worker without a nanny is removed from the cluster."""
    try:
        outcome = client.restart_workers([address], timeout=120, raise_for_error=False).get(address, "gone")
    except Exception as err:  # noqa: BLE001 - the sweep goes on with the other workers
        outcome = f"{type(err).__name__}: {_one_line(err)}"
    if progress:
        print(f"switchsim sweep: run {run.run_id} ended ngspice in its worker; worker restarted ({outcome})",
              file=sys.stderr)


def _take(iterator, n: int) -> list:
    out = []
    for item in iterator:
        out.append(item)
        if len(out) >= n:
            break
    return out


def _submit(client, sweep_doc: dict, run: Run, wave_dir):
    run_doc = dict(run_id=run.run_id, name=run.name, params=run.params)
    return client.submit(execute, sweep_doc, run_doc, wave_dir, key=f"switchsim-run-{run.run_id}-{uuid.uuid4().hex[:8]}",
                         pure=False, retries=0)


def _check_runs(sweep: Sweep) -> list[str]:
    """The run_ids a tolerance study reruns refined (``check``)."""
    return list(sweep.study.get("check_runs", ())) if sweep.study is not None else []


def run_sweep_inline(sweep: Sweep) -> list[dict]:
    """Every run of the sweep in this process, one after the other, rows returned (no Dask,
    no files): for small studies and for comparing against the Dask path."""
    doc = dict(base=sweep.base, base_dir=sweep.base_dir, base_name=sweep.base_name, common=sweep.common,
               waveforms=False, check_runs=_check_runs(sweep))
    return [execute(doc, dict(run_id=r.run_id, name=r.name, params=r.params), None) for r in sweep.runs]


def sweep_command(path: str, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
                  resume: bool = False, quiet: bool = False) -> int:
    """`switchsim sweep SWEEP.toml --out DIR`: 0 when every run has a row, 1 if some failed
    (or the cluster could not start), 130 when interrupted (continue with --resume); bad
    input (the sweep file, --out, --scheduler, a folder in use) raises ValueError: one line, 2."""
    try:
        sweep = load_sweep(path)
        report = run_sweep(sweep, out_dir, workers=workers, scheduler=scheduler, resume=resume, progress=not quiet)
    except KeyboardInterrupt:  # before the runs started, or a second Ctrl-C while stopping
        print(f"switchsim sweep: interrupted; the rows written are in {out_dir}/results; continue with --resume",
              file=sys.stderr)
        return 130
    except RuntimeError as err:  # the local cluster did not start
        print(f"switchsim sweep: {_one_line(err)}", file=sys.stderr)
        return 1
    except (ValueError, FileNotFoundError):
        raise  # bad input: the command line's one line and exit 2
    except Exception as err:  # noqa: BLE001 - e.g. the scheduler went away mid-sweep
        print(f"switchsim sweep: stopped ({type(err).__name__}: {_one_line(err)[:200]}); the rows written are in "
              f"{out_dir}/results; continue with --resume", file=sys.stderr)
        return 1
    if report.interrupted:
        print(f"switchsim sweep: interrupted; {report.skipped + report.done} of {report.total} runs have rows in "
              f"{out_dir}/results; continue with --resume", file=sys.stderr)
        return 130
    if not quiet:
        print(f"switchsim sweep: {report.done} run(s) now ({report.rerun} of them failed before), "
              f"{report.skipped} already done, {report.failed} failed, {report.seconds:.1f} s; results in "
              f"{out_dir}/results (coupling.app.sweep.read_results)"
              + (f"; statistics in {report.statistics}" if report.statistics else ""), file=sys.stderr)
    return 1 if report.failed else 0
