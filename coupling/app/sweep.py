"""Design sweeps: one base scene, parameters varied over a design, runs on Dask.

A sweep is a base scene plus a list of runs, each a set of "section.key" values (any
scene key, as ``Scene.set`` takes them), built from one design:

- ``grid``: every combination of the listed values;
- ``cases``: a list of runs, each optionally named;
- ``random`` / ``lhs``: ``samples`` seeded draws (uniform, or Latin hypercube through
  scipy.stats.qmc) inside [low, high] per parameter, log-uniform with ``log = true``.

Every run's scene is built and validated in the client before anything starts. Runs go
to dask.distributed workers (a LocalCluster of process workers, one thread each, by
default; an existing scheduler by address): a worker process imports once and runs
scene after scene, never two at once (one ngspice per process). As each run finishes the
client appends its row (run_id, name, the parameters, every scalar of summary.json
flattened with dots, status, error, wall_time, session) to a Parquet dataset, one file
per small batch under ``OUT/results/``, each written whole (temporary file, then rename):

    read_results(OUT)   # pandas DataFrame, one row per finished run

A failed run is a row with status "failed" and its error; it never stops the sweep. The
client keeps only a bounded window of runs in flight and no waveforms (a run's waveforms,
on request, are written by the worker to ``OUT/waveforms/<run_id>.parquet``), so its
memory does not grow with the sweep. ``resume=True`` runs only the runs without a row:
after Ctrl-C, a killed worker (Dask reruns its run elsewhere) or a killed client, nothing
finished is redone and nothing is lost or written twice. ``OUT`` must be reachable from
the client (rows) and, for waveforms, from the workers (a shared file system).

Sweep file (TOML, SI units)::

    [sweep]
    scene = "base.toml"          # relative to this file; omitted: the built-in default scene
    design = "grid"              # grid | cases | random | lhs
    samples = 20                 # random, lhs
    seed = 1                     # random, lhs
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
from typing import Any

DESIGNS = ("grid", "cases", "random", "lhs")
_SWEEP_KEYS = {"scene", "design", "samples", "seed", "waveforms", "set", "grid", "cases", "ranges"}
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$")
RESERVED = ("run_id", "name", "status", "error", "wall_time", "session", "finished_at")


# --- the design ------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Run:
    """One run of a sweep: its id (file-safe, unique), optional name and "section.key" values."""

    run_id: str
    name: str | None
    params: dict


@dataclasses.dataclass(frozen=True)
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

    # constructors ----------------------------------------------------------------------
    @classmethod
    def grid(cls, base, values: dict, **kw) -> "Sweep":
        """Every combination of ``values`` ({"section.key": [v1, v2, ...]}), last key fastest."""
        _check_params(values, "grid")
        keys = list(values)
        for key in keys:
            if not isinstance(values[key], (list, tuple)) or not values[key]:
                raise ValueError(f"sweep grid {key!r} = {values[key]!r}: expected a non-empty list of values")
        combos: list[dict] = [{}]
        for key in keys:
            combos = [dict(c, **{key: v}) for c in combos for v in values[key]]
        return cls._of(base, [(None, c) for c in combos], **kw)

    @classmethod
    def cases(cls, base, cases: list, **kw) -> "Sweep":
        """Runs given one by one: dicts of "section.key" values, each with an optional "name"."""
        if not isinstance(cases, (list, tuple)) or not cases:
            raise ValueError(f"sweep cases = {cases!r}: expected a non-empty list of tables")
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
        """Build every run's scene: a bad key or value is reported, naming the run, before anything runs."""
        for run in self.runs:
            try:
                self.scene(run)
            except ValueError as err:
                raise ValueError(f"sweep run {run.run_id} ({_describe(run.params)}): {err}") from None

    def fingerprint(self) -> str:
        """A hash of what the sweep computes (base, common values, runs, waveforms): a resume
        must continue the same sweep."""
        doc = dict(base=self.base, base_dir=self.base_dir, common=self.common, waveforms=self.waveforms,
                   runs=[(r.run_id, r.params) for r in self.runs])
        return hashlib.sha256(json.dumps(doc, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def apply_changes(raw: dict, changes: dict) -> dict:
    """A copy of a scene document with "section.key" (or "section.sub.key") values set."""
    doc = copy.deepcopy(raw)
    for key, value in changes.items():
        parts = key.split(".")
        node = doc
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ValueError(f"sweep parameter {key!r}: {part!r} is not a table in the base scene")
        node[parts[-1]] = list(value) if isinstance(value, tuple) else value
    return doc


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
    for key in params:
        parts = key.split(".")
        if len(parts) < 2 or not all(parts):
            raise ValueError(f"sweep {where}: key {key!r}: expected a scene key 'section.key', e.g. 'initial.angle_deg'")
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


def _waveforms_option(value) -> bool | tuple[str, ...]:
    if isinstance(value, bool):
        return value
    if isinstance(value, (list, tuple)) and value and all(isinstance(c, str) for c in value):
        return tuple(value) if "time" in value else ("time",) + tuple(value)
    raise ValueError(f"sweep waveforms = {value!r}: expected true, false or a list of column names")


def _describe(params: dict) -> str:
    return ", ".join(f"{k} = {v!r}" for k, v in params.items()) or "base scene"


def load_sweep(path) -> Sweep:
    """Read and validate a sweep TOML file (see the module docstring); every run's scene is checked."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{path}: not valid TOML: {err}") from None
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
    need = {"grid": "grid", "cases": "cases", "random": "ranges", "lhs": "ranges"}[design]
    if need not in table:
        raise ValueError(f"{path}: sweep.design = {design!r} needs sweep.{need}")
    for other in {"grid", "cases", "ranges"} - {need}:
        if other in table:
            raise ValueError(f"{path}: sweep.{other} is unused with sweep.design = {design!r}; remove it")
    for key in ("samples", "seed"):
        if key in table and design not in ("random", "lhs"):
            raise ValueError(f"{path}: sweep.{key} is unused with sweep.design = {design!r}; remove it")
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
    except ``flags``, joined with '; ')."""
    out: dict = {}
    for key, value in summary.items():
        full = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten_summary(value, f"{full}."))
        elif key == "flags" and isinstance(value, list):
            out[full] = "; ".join(map(str, value))
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
    status, error = "ok", None
    with _RUN_LOCK:
        try:
            doc = apply_changes(sweep_doc["base"], {**sweep_doc["common"], **params})
            scene = scene_from_dict(doc, base_dir=sweep_doc["base_dir"], name=f"{sweep_doc['base_name']} "
                                                                           f"[{run_doc['run_id']}]")
            result = run(scene)
            summary = result.summary
            waveforms = result.waveforms
            status, error = result.status.value, result.message or None  # judged where it was made
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
    row.update(status=status, error=error, wall_time=time.perf_counter() - tick)
    return row


def _one_line(err) -> str:
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _write_parquet_atomic(frame, path: Path) -> None:
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    frame.to_parquet(tmp, index=False)
    os.replace(tmp, path)


# --- the results dataset ---------------------------------------------------------------


def _result_files(out: Path) -> list[Path]:
    folder = out / "results"
    return sorted(folder.glob("part-*.parquet")) if folder.is_dir() else []


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
    import pyarrow.parquet as pq

    done: set[str] = set()
    for f in _result_files(Path(out_dir)):
        done.update(pq.read_table(f, columns=["run_id"]).column("run_id").to_pylist())
    return done


def read_waveforms(out_dir, run_id: str):
    """The waveforms kept for one run (pandas), from OUT/waveforms/<run_id>.parquet."""
    import pandas as pd

    path = Path(out_dir) / "waveforms" / f"{run_id}.parquet"
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no waveforms kept for run {run_id!r} (sweep.waveforms = true keeps them)")
    return pd.read_parquet(path)


class RowWriter:
    """Appends rows to OUT/results as Parquet batch files, each written whole (rename), a batch
    every ``every`` seconds or ``size`` rows, and on close."""

    def __init__(self, folder: Path, session: str, every: float = 0.5, size: int = 64):
        self.folder, self.session, self.every, self.size = folder, session, every, size
        self.rows: list[dict] = []
        self.count = 0
        self.last = time.monotonic()
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
        _write_parquet_atomic(frame, path)
        self.count += 1
        self.rows = []


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


def default_workers() -> int:
    """Worker processes for a local cluster: the CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _manifest(sweep: Sweep, out: Path, resume: bool) -> None:
    path = out / "sweep.json"
    fingerprint = sweep.fingerprint()
    if path.is_file():
        old = json.loads(path.read_text())
        if not resume:
            raise ValueError(f"{out} already holds a sweep: pass --resume (resume=True) to continue it, "
                             "or choose another --out")
        if old.get("fingerprint") != fingerprint:
            raise ValueError(f"{out} holds a different sweep (fingerprint {old.get('fingerprint')}, this one "
                             f"{fingerprint}): the base scene, values or runs changed; choose another --out")
        return
    if _result_files(out):
        raise ValueError(f"{out}/results holds results without sweep.json: choose another --out")
    doc = dict(fingerprint=fingerprint, base_name=sweep.base_name, base_dir=sweep.base_dir, base=sweep.base,
               common=sweep.common, waveforms=sweep.waveforms, parameters=sweep.parameters,
               runs=[dataclasses.asdict(r) for r in sweep.runs])
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
    per process), no dashboard, and WORKER_SETTINGS (no profiler, no aggressive malloc trim)."""
    import dask
    from distributed import LocalCluster

    with dask.config.set(WORKER_SETTINGS):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                            silence_logs=40, **kw)


def run_sweep(sweep: Sweep, out_dir, *, workers: int | None = None, scheduler: str | None = None,
              client=None, resume: bool = False, progress: bool = True, window: int | None = None) -> SweepReport:
    """Run every run of ``sweep`` without a row in OUT/results, on Dask; rows appended as runs finish.

    workers: worker processes of the local cluster (default: the machine's CPUs);
    scheduler: address of an existing Dask scheduler ("tcp://host:8786") instead of a local
    cluster; client: a distributed.Client to use as it is (left open); resume: continue a
    sweep already in out_dir; window: runs in flight at once (default 2 per worker). Ctrl-C stops cleanly: what finished is kept (``interrupted``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    _manifest(sweep, out, resume)
    done_ids = finished_run_ids(out) if resume else set()
    todo = [r for r in sweep.runs if r.run_id not in done_ids]
    report = SweepReport(total=len(sweep.runs), skipped=len(sweep.runs) - len(todo), out_dir=str(out))
    line = _ProgressLine(report.total, report.skipped, progress)
    if not todo:
        line(0, 0, final=True)
        return report
    wave_dir = None
    if sweep.waveforms:
        wave_dir = out / "waveforms"
        wave_dir.mkdir(exist_ok=True)
        wave_dir = str(wave_dir.resolve())
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers = {workers!r}: expected an integer >= 1")
    from distributed import Client, as_completed

    tick = time.monotonic()
    session = f"{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:6]}"
    writer = RowWriter(out / "results", session)
    sweep_doc = dict(base=sweep.base, base_dir=str(Path(sweep.base_dir).resolve()), base_name=sweep.base_name,
                     common=sweep.common, waveforms=sweep.waveforms)
    cluster = None
    own_client = client is None
    started = None
    try:
        if not own_client:
            n = max(1, len(client.scheduler_info().get("workers", {})))
        elif scheduler is not None:
            client = Client(scheduler, timeout="30s")
            n = max(1, len(client.scheduler_info().get("workers", {})))
        else:
            n = workers or default_workers()
            cluster = local_cluster(n)
            client = Client(cluster)
        line.start = started = time.monotonic()  # the rate counts runs, not the cluster's start
        pending = iter(todo)
        in_flight = as_completed()
        runs_of: dict = {}

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
        writer.flush()
        report.seconds = time.monotonic() - tick
        report.run_seconds = time.monotonic() - started if started is not None else 0.0
        line(report.done, report.failed, final=True)
        for closable in ((client, cluster) if own_client else ()):
            if closable is not None:
                try:
                    closable.close()
                except (Exception, KeyboardInterrupt):  # noqa: BLE001 - after Ctrl-C or a lost scheduler
                    report.interrupted = True  # best effort; the rows are already written
    return report


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


def run_sweep_inline(sweep: Sweep) -> list[dict]:
    """Every run of the sweep in this process, one after the other, rows returned (no Dask,
    no files): for small studies and for comparing against the Dask path."""
    doc = dict(base=sweep.base, base_dir=sweep.base_dir, base_name=sweep.base_name, common=sweep.common,
               waveforms=False)
    return [execute(doc, dict(run_id=r.run_id, name=r.name, params=r.params), None) for r in sweep.runs]


def sweep_command(path: str, out_dir: str, *, workers: int | None = None, scheduler: str | None = None,
                  resume: bool = False, quiet: bool = False) -> int:
    """`switchsim sweep SWEEP.toml --out DIR`: 0 when every run has a row, 1 if some failed,
    130 when interrupted (continue with --resume)."""
    try:
        sweep = load_sweep(path)
        if not quiet:
            print(f"switchsim sweep: {len(sweep.runs)} runs of {sweep.base_name}, varying "
                  f"{', '.join(sweep.parameters) or 'nothing'}", file=sys.stderr)
        report = run_sweep(sweep, out_dir, workers=workers, scheduler=scheduler, resume=resume, progress=not quiet)
    except KeyboardInterrupt:  # before the runs started, or a second Ctrl-C while stopping
        print(f"switchsim sweep: interrupted; the rows written are in {out_dir}/results; continue with --resume",
              file=sys.stderr)
        return 130
    if report.interrupted:
        print(f"switchsim sweep: interrupted; {report.skipped + report.done} of {report.total} runs have rows in "
              f"{out_dir}/results; continue with --resume", file=sys.stderr)
        return 130
    if not quiet:
        print(f"switchsim sweep: {report.done} run(s) now, {report.skipped} already done, {report.failed} failed, "
              f"{report.seconds:.1f} s; results in {out_dir}/results (coupling.app.sweep.read_results)",
              file=sys.stderr)
    return 1 if report.failed else 0
