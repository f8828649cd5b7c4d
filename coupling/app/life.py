"""`switchsim life`: a contact's electrical life from its simulated operation.

The scene's run is one operation (a make and a break: `builtin_scene("relay_cycle")`). A
life study of N operations runs it at operations 0, K, 2K, ... (the samples) and wears the
contact between them:

- each sample's erosion (summary ``operations[0].erosion``: the net volume each electrode
  lost, coupling.core.duty) stands for the K operations from it to the next sample (the
  last one for those left up to N): the wear between samples is interpolated piecewise
  constant in the operation count, the explicit (forward Euler) rule, first order in K
  (docs/contact_duty.md, "Electrical life", measures it);
- the worn volume of each electrode comes off the top of its cap (coupling.laws.duty.
  eroded_cap: the base kept, the dome lower and flatter), and the next sample's scene is
  the base scene with these keys changed: ``[[rivet]]`` (the first) ``radius`` (the worn
  sphere) and ``offset`` (its centre moved so that the apex is lower by the height lost),
  ``block.radius`` (a spherical fixed contact), ``initial.height`` (the gap, grown by both
  heights lost: the blade sits where it sat), ``tribology.resistance.radius`` when the
  scene gives it (the rivet's radius of an elastic or multi-spot Holm law), and in [duty]
  ``cap_height`` (the worn heights) and ``conductor_radius`` (pinned at the first sample's:
  the cap's base, where the current lines run parallel, does not wear);
- it stops at N operations or at the first end criterion of [duty.life] (coupling.core.duty.
  LifeLimits): the gap out of its range, the held normal force below its least, the
  held contact resistance above its largest, a make's weld risk at ``stop_on_weld``, or a
  cap worn through.

A study folder (``--out``) holds life.json (the study: scene, N, K and, once it ended, the
outcome), checkpoint.json (the samples so far and the wear: what a resume continues from,
written whole after each sample), the table life.csv and life.parquet (one row per sample,
``LIFE_COLUMNS``) and life.png. One invocation at a time holds a folder (the sweeps' lock);
``--resume`` continues a study that was interrupted, losing no sampled operation.

Several designs: `switchsim life SWEEP.toml` runs one life study per run of the sweep's
design on Dask (coupling.app.sweep: its workers, resume and results rows; the row of a
design is its study's outcome, ``life.*``), each study in OUT/life/<run_id>/.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import os
import sys
import time
from pathlib import Path

from mech.frozen import frozen
from coupling.app.sweep import _FolderLock, _sweep_folder, _write_parquet_atomic

LIFE_COLUMNS = (
    "operation", "operations", "status", "bounces", "bounce_time", "peak_current", "make_arc_energy",
    "break_arc_energy", "break_arc_duration", "arc_energy", "moving_anodic_energy", "moving_cathodic_energy",
    "fixed_anodic_energy", "fixed_cathodic_energy", "moving_eroded_volume", "fixed_eroded_volume",
    "moving_worn_volume", "fixed_worn_volume", "moving_cap_height", "moving_cap_radius", "fixed_cap_height",
    "fixed_cap_radius", "gap", "held_force", "contact_resistance", "blow_off_current", "weld_risk", "wall_time")
ENDS = ("operations", "gap", "force", "resistance", "weld", "worn_through", "failed")
DEFAULT_SCENE = "relay_cycle"


class LifeError(ValueError):
    """A life study that cannot go on for a reason of its input (a one-line message)."""


@frozen
class LifeStudy:
    """How long a life study runs: ``operations`` N (>= 1) sampled ``every`` K (>= 1) operations."""

    operations: int
    every: int = 1

    def __post_init__(self):
        for key, value in (("operations", self.operations), ("every", self.every)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise LifeError(f"life {key} = {value!r} (--{key}): expected a whole number >= 1")
            if value > 10**9:
                raise LifeError(f"life {key} = {value!r} (--{key}): at most 1e9")

    @property
    def samples(self) -> list[int]:
        """The sampled operations: 0, K, 2K, ... below N."""
        return list(range(0, self.operations, self.every))


# --- the contact's geometry and its wear ------------------------------------------------------


@frozen
class ContactGeometry:
    """What a life study wears, from the base scene (SI): the moving rivet's cap (height,
    sphere radius, centre offset from the bar's axis), the fixed contact's cap (height and
    radius of a spherical block; None for a plane, whose wear is counted but does not change
    its shape), the gap and the conductor radius of the base scene."""

    moving_height: float
    moving_radius: float
    offset: float
    fixed_height: float | None
    fixed_radius: float | None
    gap: float
    conductor_radius: float

    @classmethod
    def of(cls, scene) -> "ContactGeometry":
        """The geometry of a scene that ``prepare`` returned (it has [duty])."""
        duty = scene.duty
        mech = scene.mech
        moving, fixed = duty.cap_height
        if moving is None:
            raise LifeError(f"{scene.name}: duty.cap_height: the rivet's cap is more than a hemisphere above the bar's "
                            "face (or not above it): give duty.cap_height = [moving, fixed] (m, each <= its radius)")
        rivet = mech.rivets[0]
        if moving > rivet.radius:
            raise LifeError(f"duty.cap_height[0] = {moving!r}: must be <= the rivet's radius {rivet.radius!r} m")
        sphere = mech.block.shape == "sphere"
        if sphere and fixed is not None and fixed > mech.block.radius:
            raise LifeError(f"duty.cap_height[1] = {fixed!r}: must be <= block.radius = {mech.block.radius!r} m")
        return cls(moving, rivet.radius, rivet.offset, fixed if sphere else None,
                   mech.block.radius if sphere else None, mech.initial.height, duty.conductor_radius)

    def worn(self, moving_volume: float, fixed_volume: float) -> dict:
        """The caps after these net volumes (m^3) came off their tops (coupling.laws.duty.eroded_cap;
        a net gain, material transferred onto a contact, leaves its shape as it was): heights,
        sphere radii, the rivet's offset and the gap (m). ValueError: a cap worn through."""
        from coupling.laws.duty import eroded_cap

        h, r = eroded_cap(self.moving_height, self.moving_radius, max(moving_volume, 0.0))
        out = {"moving_cap_height": h, "moving_cap_radius": r,
               "offset": self.offset + (r - self.moving_radius) + (self.moving_height - h),
               "fixed_cap_height": self.fixed_height, "fixed_cap_radius": self.fixed_radius}
        lost = self.moving_height - h
        if self.fixed_height is not None:
            hf, rf = eroded_cap(self.fixed_height, self.fixed_radius, max(fixed_volume, 0.0))
            out.update(fixed_cap_height=hf, fixed_cap_radius=rf)
            lost += self.fixed_height - hf
        out["gap"] = self.gap + lost
        return out


def worn_document(raw: dict, worn: dict, geometry: ContactGeometry) -> dict:
    """The base scene's document with the worn geometry's keys (module docstring)."""
    doc = copy.deepcopy(raw)
    rivet = doc["rivet"][0]
    rivet["radius"] = worn["moving_cap_radius"]
    rivet["offset"] = worn["offset"]
    if worn["fixed_cap_radius"] is not None:
        doc["block"]["radius"] = worn["fixed_cap_radius"]
    doc.setdefault("initial", {})["height"] = worn["gap"]
    resistance = doc.get("tribology", {}).get("resistance")
    if isinstance(resistance, dict) and "radius" in resistance:
        resistance["radius"] = worn["moving_cap_radius"]
    duty = doc.setdefault("duty", {})
    duty["conductor_radius"] = geometry.conductor_radius
    duty["cap_height"] = [worn["moving_cap_height"], worn["fixed_cap_height"]
                          if worn["fixed_cap_height"] is not None else worn["moving_cap_height"]]
    return doc


def with_duty(scene):
    """The scene with a [duty] section (its defaults) when it has none."""
    return scene if scene.duty is not None else scene.update({"duty.repulsion": True})


def prepare(scene) -> tuple:
    """(the scene with [duty], its ContactGeometry): LifeError when a life study cannot wear it,
    before anything runs."""
    mech = scene.mech
    if scene.kind != "coupled" or mech is None:
        raise LifeError(f"{scene.name}: a life study needs a coupled scene (mechanics, [tribology] and [circuit]) "
                        "that makes and breaks once")
    if not mech.mount.held or len(mech.rivets) != 1:
        raise LifeError(f"{scene.name}: a life study wears one [[rivet]] on a held bar ([mount] clamp or pivot); "
                        f"this scene has {len(mech.rivets)} rivet(s) on a {mech.mount.kind} bar")
    scene = with_duty(scene)
    return scene, ContactGeometry.of(scene)


# --- one sampled operation --------------------------------------------------------------------


def run_sample(scene):
    """Run one sampled operation (a seam for tests to interrupt)."""
    from coupling.core.master import run

    return run(scene)


def sample_row(result, operation: int, count: int, worn: dict, worn_volume: tuple[float, float]) -> dict:
    """The table row of a sampled operation (``LIFE_COLUMNS``, SI): the geometry it ran with, its
    make, break, held closure and erosion (summary ``operations[0]``). LifeError when the run
    is not one operation that makes and breaks."""
    ops = result.operations
    if len(ops) != 1 or "make" not in ops[0] or "break" not in ops[0]:
        kinds = [("make" in op) * "make" + "+" * ("make" in op and "break" in op) + ("break" in op) * "break"
                 for op in ops]
        raise LifeError(f"{result.scene.name}: a life study needs a run that makes and breaks once; this one holds "
                        f"{len(ops)} operation(s) ({', '.join(kinds) or 'none'}): e.g. builtin_scene(\"relay_cycle\")")
    op = ops[0]
    make, brk, held, ero = op["make"], op["break"], op.get("held", {}), op["erosion"]
    return {
        "operation": operation, "operations": count, "status": result.status.value,
        "bounces": make["bounces"], "bounce_time": make["bounce_time"], "peak_current": make["peak_current"],
        "make_arc_energy": make["arc_energy"], "break_arc_energy": brk["arc_energy"],
        "break_arc_duration": brk["arc_duration"], "arc_energy": ero["arc_energy"],
        "moving_anodic_energy": ero["moving"]["anodic"], "moving_cathodic_energy": ero["moving"]["cathodic"],
        "fixed_anodic_energy": ero["fixed"]["anodic"], "fixed_cathodic_energy": ero["fixed"]["cathodic"],
        "moving_eroded_volume": ero["moving"]["net_volume"], "fixed_eroded_volume": ero["fixed"]["net_volume"],
        "moving_worn_volume": worn_volume[0], "fixed_worn_volume": worn_volume[1],
        "moving_cap_height": worn["moving_cap_height"], "moving_cap_radius": worn["moving_cap_radius"],
        "fixed_cap_height": worn["fixed_cap_height"], "fixed_cap_radius": worn["fixed_cap_radius"],
        "gap": worn["gap"], "held_force": held.get("force"), "contact_resistance": held.get("contact_resistance"),
        "blow_off_current": held.get("blow_off_current"), "weld_risk": make.get("weld_risk"),
        "wall_time": float(result.stats.get("wall_time", 0.0)),
    }


# --- the study ---------------------------------------------------------------------------------


@dataclasses.dataclass
class LifeReport:
    """What a life study did: its rows, where it stands and why it ended (None: not yet)."""

    study: LifeStudy
    rows: list
    worn: tuple
    end: str | None = None
    end_note: str = ""
    limits: dict = dataclasses.field(default_factory=dict)
    folder: str = ""
    seconds: float = 0.0
    new_samples: int = 0

    @property
    def operations_done(self) -> int:
        """Operations the study covers: every sampled one and those it stands for."""
        return sum(r["operations"] for r in self.rows)

    @property
    def next_operation(self) -> int:
        return self.rows[-1]["operation"] + self.rows[-1]["operations"] if self.rows else 0

    def summary(self) -> dict:
        """The study's outcome (life.json ``outcome``; a sweep row's ``life.*``)."""
        last = self.rows[-1] if self.rows else {}
        risks = [r["weld_risk"] for r in self.rows if r.get("weld_risk")]
        from coupling.core.duty import WELD_LEVELS

        return {"operations": self.study.operations, "every": self.study.every, "samples": len(self.rows),
                "operations_done": self.operations_done, "end": self.end, "end_note": self.end_note,
                "moving_worn_volume": self.worn[0], "fixed_worn_volume": self.worn[1],
                **{k: last.get(k) for k in ("moving_cap_height", "moving_cap_radius", "fixed_cap_height",
                                            "fixed_cap_radius", "gap", "held_force", "contact_resistance",
                                            "bounce_time")},
                "weld_risk": max(risks, key=WELD_LEVELS.index) if risks else None, **self.limits}


def fingerprint(scene, study: LifeStudy) -> str:
    """A hash of what a study computes: a resume must continue the same study."""
    doc = dict(scene=scene.raw, base_dir=str(scene.base_dir), operations=study.operations, every=study.every)
    return hashlib.sha256(json.dumps(doc, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def _write_json(path: Path, doc: dict) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(doc, indent=1, default=_plain))
    os.replace(tmp, path)


def _plain(value):
    if hasattr(value, "item"):
        return value.item()
    return repr(value)


def _open_study(out: Path, scene, study: LifeStudy, resume: bool) -> LifeReport:
    """The study in ``out``: a new one (life.json written), or the one a checkpoint holds
    (``resume``; the same study only, as sweeps check theirs)."""
    manifest, checkpoint = out / "life.json", out / "checkpoint.json"
    key = fingerprint(scene, study)
    if checkpoint.is_file():
        try:
            state = json.loads(checkpoint.read_bytes())
            if not isinstance(state, dict):
                raise ValueError(f"a JSON {type(state).__name__}, not an object")
        except (OSError, ValueError, RecursionError) as err:
            raise LifeError(f"{checkpoint}: damaged, not a life study's checkpoint ({' '.join(str(err).split())[:120]})"
                            "; choose another --out") from None
        if not resume:
            raise LifeError(f"{out} already holds a life study: pass --resume to continue it, or choose another --out")
        if state.get("fingerprint") != key:
            raise LifeError(f"{out} holds a different life study (fingerprint {state.get('fingerprint')}, this one "
                            f"{key}): the scene, --operations or --every changed; choose another --out")
        return LifeReport(study, list(state["rows"]), tuple(state["worn"]), state.get("end"),
                          state.get("end_note", ""), dict(state.get("limits", {})), str(out))
    if manifest.is_file():  # a study that stopped before its first sample: the same one starts over
        try:
            same = json.loads(manifest.read_bytes()).get("fingerprint") == key
        except (OSError, ValueError, RecursionError, AttributeError):
            same = False
        if not same:
            raise LifeError(f"{out} holds another life study's life.json: choose another --out")
    elif any(not p.name.startswith(".") for p in out.iterdir()):
        raise LifeError(f"--out {str(out)!r} holds other files: give an empty or new folder for a life study")
    _write_json(manifest, {"fingerprint": key, "scene_name": scene.name, "base_dir": str(scene.base_dir),
                           "scene": scene.raw, "operations": study.operations, "every": study.every})
    return LifeReport(study, [], (0.0, 0.0), folder=str(out))


def _save(out: Path, scene, report: LifeReport) -> None:
    """checkpoint.json and the tables, each written whole (the checkpoint last: a resume
    never finds a sample it cannot see in the tables)."""
    if report.rows:
        import pandas as pd

        frame = pd.DataFrame(report.rows, columns=list(LIFE_COLUMNS))
        tmp = out / ".life.csv.tmp"
        frame.to_csv(tmp, index=False)
        os.replace(tmp, out / "life.csv")
        _write_parquet_atomic(frame, out / "life.parquet")
    _write_json(out / "checkpoint.json", {"fingerprint": fingerprint(scene, report.study), "rows": report.rows,
                                          "worn": list(report.worn), "end": report.end, "end_note": report.end_note,
                                          "limits": report.limits})


def _limits(scene, geometry: ContactGeometry, first: dict) -> dict:
    """The end criteria in numbers: [duty.life]'s, defaults from the first sample."""
    from coupling.core.duty import DEFAULT_FORCE_FRACTION, DEFAULT_GAP_RANGE, DEFAULT_RESISTANCE_FACTOR

    from coupling.core.duty import LifeLimits

    lim = scene.duty.life or LifeLimits()
    low, high = lim.gap_range or (DEFAULT_GAP_RANGE[0] * geometry.gap, DEFAULT_GAP_RANGE[1] * geometry.gap)
    force = lim.min_force if lim.min_force is not None else (
        DEFAULT_FORCE_FRACTION * first["held_force"] if first.get("held_force") is not None else None)
    resistance = lim.max_resistance if lim.max_resistance is not None else (
        DEFAULT_RESISTANCE_FACTOR * first["contact_resistance"] if first.get("contact_resistance") else None)
    return {"gap_low": low, "gap_high": high, "min_force": force, "max_resistance": resistance,
            "stop_on_weld": lim.stop_on_weld}


def _row_end(row: dict, limits: dict) -> tuple[str, str] | None:
    """(end, note) when the sampled operation meets an end criterion, else None."""
    from coupling.core.duty import WELD_LEVELS

    force, resistance, risk = row.get("held_force"), row.get("contact_resistance"), row.get("weld_risk")
    if limits["min_force"] is not None and force is not None and force < limits["min_force"]:
        return "force", f"held normal force {force:.4g} N below duty.life.min_force {limits['min_force']:.4g} N"
    if limits["max_resistance"] is not None and resistance is not None and resistance > limits["max_resistance"]:
        return "resistance", (f"held contact resistance {resistance:.4g} ohm above duty.life.max_resistance "
                              f"{limits['max_resistance']:.4g} ohm")
    stop = limits["stop_on_weld"]
    if stop != "never" and risk is not None and WELD_LEVELS.index(risk) >= WELD_LEVELS.index(stop):
        return "weld", f"weld risk {risk!r} at the make (duty.life.stop_on_weld = {stop!r})"
    return None


def life_study(scene, study: LifeStudy, out_dir, *, resume: bool = False, progress=None) -> LifeReport:
    """Run the life study of ``scene`` (module docstring) into ``out_dir``; resumable. progress:
    a callable taking one line per sample, or None. Returns the report (``end`` None if it
    was interrupted: Ctrl-C raises KeyboardInterrupt after the last finished sample is saved)."""
    if not isinstance(study, LifeStudy):
        raise TypeError(f"life_study(study={study!r:.60}): pass a LifeStudy(operations, every)")
    scene, geometry = prepare(scene)
    out = _sweep_folder(out_dir)
    tick = time.monotonic()
    with _FolderLock(out):
        report = _open_study(out, scene, study, resume)
        while report.end is None:
            _sample(scene, geometry, report, progress)
            report.new_samples += 1
            _save(out, scene, report)
        _finish(out, scene, report)
    report.seconds = time.monotonic() - tick
    return report


def _sample(scene, geometry: ContactGeometry, report: LifeReport, progress) -> None:
    """Run the next sampled operation, add its row, wear the contact for the operations it
    stands for and decide whether the study ends."""
    from coupling.core.master import CoupledRunError
    from coupling.core.scene import scene_from_dict

    study = report.study
    n = report.next_operation
    count = min(study.every, study.operations - n)
    worn = geometry.worn(*report.worn)
    doc = worn_document(scene.raw, worn, geometry)
    sample_scene = scene_from_dict(doc, base_dir=scene.base_dir, name=f"{scene.name} [operation {n}]")
    try:
        result = run_sample(sample_scene)
    except CoupledRunError as err:
        report.end, report.end_note = "failed", f"the run of operation {n} failed: {' '.join(str(err).split())}"
        return
    row = sample_row(result, n, count, worn, report.worn)
    report.rows.append(row)
    if len(report.rows) == 1:
        report.limits = _limits(scene, geometry, row)
    ended = _row_end(row, report.limits)
    if ended is not None:
        row["operations"] = 1  # the operation that met it is the last one
        report.end, report.end_note = ended
    else:
        report.worn = (report.worn[0] + count * row["moving_eroded_volume"],
                       report.worn[1] + count * row["fixed_eroded_volume"])
        try:
            gap = geometry.worn(*report.worn)["gap"]
        except ValueError as err:
            report.end, report.end_note = "worn_through", f"after operation {n + count}: {err}"
        else:
            if not report.limits["gap_low"] <= gap <= report.limits["gap_high"]:
                report.end, report.end_note = "gap", (
                    f"gap {gap:.4g} m after operation {n + count} outside duty.life.gap_range "
                    f"[{report.limits['gap_low']:.4g}, {report.limits['gap_high']:.4g}] m")
            elif n + count >= study.operations:
                report.end, report.end_note = "operations", f"{study.operations} operations"
    if progress is not None:
        progress(f"operation {n} of {study.operations} (sample {len(report.rows)}, {row['status']}): bounce time "
                 f"{row['bounce_time'] * 1e3:.4g} ms, arc energy {row['arc_energy']:.3g} J, worn "
                 f"{report.worn[0]:.3g} / {report.worn[1]:.3g} m^3, R_c {_g(row['contact_resistance'])} ohm, "
                 f"weld risk {row['weld_risk']}, {row['wall_time']:.2f} s"
                 + (f"; end: {report.end_note}" if report.end else ""))


def _g(value) -> str:
    return "none" if value is None else f"{value:.4g}"


def _finish(out: Path, scene, report: LifeReport) -> None:
    """The outcome into life.json and the plot (each written whole)."""
    manifest = out / "life.json"
    doc = json.loads(manifest.read_bytes()) if manifest.is_file() else {}
    doc["outcome"] = report.summary()
    _write_json(manifest, doc)
    if report.rows:
        from coupling.app.output import project_matplotlib

        project_matplotlib()
        fig = plot_life(report.rows)
        tmp = out / ".life.png.tmp"
        fig.savefig(tmp, dpi=110, format="png")
        os.replace(tmp, out / "life.png")


# --- the plot ------------------------------------------------------------------------------------

PANELS = (
    (("bounce_time",), "bounce time", "ms", 1e3),
    (("make_arc_energy", "break_arc_energy"), "arc energy", "mJ", 1e3),
    (("moving_worn_volume", "fixed_worn_volume"), "worn volume", "mm^3", 1e9),
    (("contact_resistance",), "held contact resistance", "mohm", 1e3),
    (("held_force",), "held normal force", "N", 1.0),
    (("gap",), "contact gap", "mm", 1e3),
)


def plot_life(rows: list[dict]):
    """The sampled operations against the operation count, one panel per quantity (matplotlib
    Figure, Agg)."""
    import numpy as np
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.0), layout="constrained")
    axes = fig.subplots(2, 3, sharex=True).ravel()
    x = np.array([r["operation"] for r in rows], float)
    for ax, (columns, name, unit, scale) in zip(axes, PANELS):
        for column in columns:
            y = np.array([np.nan if r.get(column) is None else r[column] for r in rows], float) * scale
            ax.plot(x, y, "o-", ms=3, label=column.replace("_", " "))
        ax.set_ylabel(f"{name} ({unit})")
        ax.ticklabel_format(axis="y", useOffset=False)  # a slow wear shows as digits, not as an offset
        ax.grid(alpha=0.3)
        if len(columns) > 1:
            ax.legend(fontsize=7)
    for ax in axes[3:]:
        ax.set_xlabel("operation (-)")
    return fig


# --- several designs, on Dask (coupling.app.sweep) --------------------------------------------------


@dataclasses.dataclass
class LifeResult:
    """A design's life study as a sweep row sees a run: ``summary`` (``life``: the outcome),
    ``status`` (ok: it ran to its end; failed: a sample failed), ``message``, no waveforms."""

    summary: dict
    status: object
    message: str = ""
    waveforms: object = None


def design_life(scene, life: dict, run_id: str) -> LifeResult:
    """One design's life study in OUT/life/<run_id>/ (the sweep's worker side; resumed from
    its checkpoint when the design ran before)."""
    from coupling.core.results import RunStatus

    study = LifeStudy(life["operations"], life["every"])
    folder = Path(life["folder"]) / run_id
    folder.parent.mkdir(parents=True, exist_ok=True)
    try:
        report = life_study(scene, study, folder, resume=True)
    except LifeError as err:
        return LifeResult({}, RunStatus.FAILED, str(err))
    failed = report.end == "failed"
    return LifeResult({"life": report.summary()}, RunStatus.FAILED if failed else RunStatus.OK,
                      report.end_note if failed else "")


def life_sweep(path, study: LifeStudy, out_dir, *, workers=None, scheduler=None, resume=False, progress=True):
    """A life study per run of the sweep file ``path`` (its design) on Dask: coupling.app.sweep's
    run_sweep with each run a life study; rows in OUT/results (``life.*``), tables in OUT/life/."""
    from coupling.app.sweep import load_sweep, run_sweep

    sweep = dataclasses.replace(load_sweep(path), life={"operations": study.operations, "every": study.every})
    for run in sweep.runs:  # every design must be one a life study can wear, before anything runs
        try:
            prepare(sweep.scene(run))
        except LifeError as err:
            raise LifeError(f"sweep run {run.run_id}: {err}") from None
    return run_sweep(sweep, out_dir, workers=workers, scheduler=scheduler, resume=resume, progress=progress)


# --- the command -----------------------------------------------------------------------------------


def life_command(path: str | None, out_dir: str, operations: int, every: int, *, resume: bool = False,
                 quiet: bool = False, workers: int | None = None, scheduler: str | None = None) -> int:
    """`switchsim life [SCENE.toml | SWEEP.toml] --operations N [--every K] --out DIR`: 0 when the
    study ended (its operations or an end criterion), 1 when a sampled run failed, 130 when
    interrupted (continue with --resume); bad input raises ValueError (one line, exit 2)."""
    from coupling.core.scene import builtin_scene, load_scene

    study = LifeStudy(operations, every)
    say = (lambda text: None) if quiet else (lambda text: print(f"switchsim life: {text}", file=sys.stderr,
                                                                 flush=True))
    if path is not None and _is_sweep_file(path):
        try:
            report = life_sweep(path, study, out_dir, workers=workers, scheduler=scheduler, resume=resume,
                                progress=not quiet)
        except KeyboardInterrupt:
            print("switchsim life: interrupted; continue with --resume", file=sys.stderr)
            return 130
        if report.interrupted:
            print(f"switchsim life: interrupted; {report.skipped + report.done} of {report.total} designs have rows "
                  f"in {out_dir}/results; continue with --resume", file=sys.stderr)
            return 130
        say(f"{report.done} design(s) now, {report.skipped} already done, {report.failed} failed; rows in "
            f"{out_dir}/results, tables in {out_dir}/life/")
        return 1 if report.failed else 0
    scene = builtin_scene(DEFAULT_SCENE) if path is None else load_scene(path)
    prepare(scene)  # a scene it cannot wear: one line before anything else
    say(f"{scene.name}: {study.operations} operations sampled every {study.every} "
        f"({len(study.samples)} runs at most) into {out_dir}")
    try:
        report = life_study(scene, study, out_dir, resume=resume, progress=say)
    except KeyboardInterrupt:
        print(f"switchsim life: interrupted; the sampled operations are kept in {out_dir}; continue with --resume",
              file=sys.stderr)
        return 130
    outcome = report.summary()
    print(f"switchsim life: {outcome['operations_done']} of {study.operations} operations, end: {report.end_note}; "
          f"worn {outcome['moving_worn_volume']:.3g} m^3 (moving), {outcome['fixed_worn_volume']:.3g} m^3 (fixed); "
          f"{report.new_samples} run(s) now, {report.seconds:.1f} s; wrote {out_dir}")
    return 1 if report.end == "failed" else 0


def _is_sweep_file(path) -> bool:
    """Whether a TOML file is a sweep (a top-level [sweep] table) rather than a scene."""
    from mech.scene import read_toml

    return isinstance(read_toml(path).get("sweep"), dict)
