"""Every run can tell its own error: rerun a scene refined and report what moved.

``run(scene, check=True)`` (``switchsim run --check``) runs the scene, then reruns it
once per refinement, each refinement alone so the verdict can name the one that moved
the result:

    modes       every mode family 1.5x its count (rounded up, at least +1, at most 40)
    rtol        solver.rtol / 10 (at least 1e-13)
    macro_step  coupling.macro_step / 2                       (coupled scenes)
    reltol      ngspice RELTOL / 10 (at least 1e-9)            (coupled scenes)

and writes ``summary.accuracy``: per refinement the base and refined value of each
metric below, its change, whether the change is within TOLERANCES, and one verdict line.

Metrics (pure functions of the per-tip contact intervals and the waveforms, SI):
    mismatch_time        s, total time over the run where "tip i touches" differs between
                         the two runs, summed over both tips
    contacts             number of tip contact intervals (both tips)
    bounces              re-closures of the contact (union of both tips) after the first make
    first_make, last_make, total_bounce_time (last_make - first_make)   s
    peak_force           N, largest normal force of any contact
    peak_contact_voltage V, largest |contact voltage| after the first make (coupled)
    arc_energy           J (coupled)

TOLERANCES (a refinement "did not move" the result when all hold):
    mismatch_time       <= 2 % of the base run's total contact time (both tips)
    contacts, bounces   equal
    first/last make, total bounce time   within max(1 us, 1 % of the contact span: first
                        make to last break)
    peak_force          within 2 %
    peak_contact_voltage within 2 % + 10 mV
    arc_energy          within 5 % + 1 uJ
"""

from __future__ import annotations

import math
import time

from .results import merge_intervals

TOLERANCES = dict(mismatch_fraction=0.02, time_floor=1e-6, time_fraction=0.01, peak_force=0.02,
                  voltage_rel=0.02, voltage_abs=0.01, arc_rel=0.05, arc_abs=1e-6)
MAX_MODES = 40  # the largest count a family may have (mech.parameters)
MIN_RTOL = 1e-13
MIN_RELTOL = 1e-9

# ---------------------------------------------------------------------------------------
# metrics: pure functions


def measure(intervals) -> float:
    """s: total length of the union of intervals [(a, b), ...]."""
    return float(sum(b - a for a, b in merge_intervals(intervals)))


def intersection(a, b) -> list[tuple[float, float]]:
    """The intersection of two unions of intervals, as sorted disjoint intervals."""
    a, b = merge_intervals(a), merge_intervals(b)
    out, i, j = [], 0, 0
    while i < len(a) and j < len(b):
        lo, hi = max(a[i][0], b[j][0]), min(a[i][1], b[j][1])
        if hi > lo:
            out.append((lo, hi))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out


def mismatch_time(a, b) -> float:
    """s: measure of the symmetric difference of two sets of contact intervals: the time
    during which one run has the tip touching and the other not."""
    return max(0.0, measure(a) + measure(b) - 2.0 * measure(intersection(a, b)))


def contact_metrics(tip_intervals) -> dict:
    """The contact metrics of per-tip interval lists {tip: [(t_start, t_end), ...]} (s)."""
    all_iv = [iv for ivs in tip_intervals.values() for iv in ivs]
    union = merge_intervals(all_iv)
    out = dict(contacts=len(all_iv), bounces=max(len(union) - 1, 0), first_make=None, last_make=None,
               total_bounce_time=0.0, contact_time=float(sum(measure(v) for v in tip_intervals.values())),
               span=0.0)
    if union:
        out.update(first_make=union[0][0], last_make=union[-1][0], total_bounce_time=union[-1][0] - union[0][0],
                   span=union[-1][1] - union[0][0])
    return out


def compare(base: dict, refined: dict, base_tips: dict, refined_tips: dict, tol: dict = TOLERANCES) -> dict:
    """Per metric {base, refined, change, within} and the mismatch time, for two runs'
    metric dicts (see ``metrics_of``) and per-tip intervals; ``moved`` lists the metrics
    outside the tolerances."""
    out: dict = {}
    mism = sum(mismatch_time(base_tips.get(k, []), refined_tips.get(k, []))
               for k in set(base_tips) | set(refined_tips))
    allowed = tol["mismatch_fraction"] * base["contact_time"]
    out["mismatch_time"] = dict(base=0.0, refined=mism, change=mism, within=mism <= allowed + 1e-15,
                                allowed=allowed)
    for key in ("contacts", "bounces"):
        out[key] = dict(base=base[key], refined=refined[key], change=refined[key] - base[key],
                        within=refined[key] == base[key])
    time_tol = max(tol["time_floor"], tol["time_fraction"] * base["span"])
    for key in ("first_make", "last_make", "total_bounce_time"):
        a, b = base.get(key), refined.get(key)
        if a is None and b is None:
            continue
        change = None if (a is None or b is None) else b - a
        out[key] = dict(base=a, refined=b, change=change, within=change is not None and abs(change) <= time_tol,
                        allowed=time_tol)
    for key, rel, absolute in (("peak_force", tol["peak_force"], 0.0),
                               ("peak_contact_voltage", tol["voltage_rel"], tol["voltage_abs"]),
                               ("arc_energy", tol["arc_rel"], tol["arc_abs"])):
        a, b = base.get(key), refined.get(key)
        if a is None and b is None:
            continue
        change = None if (a is None or b is None) else b - a
        bound = rel * abs(a or 0.0) + absolute
        out[key] = dict(base=a, refined=b, change=change, within=change is not None and abs(change) <= bound,
                        allowed=bound)
    return dict(metrics=out, moved=[k for k, v in out.items() if not v["within"]])


# ---------------------------------------------------------------------------------------
# from results


def tip_intervals(result) -> dict:
    """{tip: [(t_start, t_end), ...]} (s) of a CoupledResult with mechanics; for a prescribed
    schedule (no mechanics) the closed intervals as tip 0."""
    if result.mechanics is None:
        return {0: list(result.closed_intervals)}
    c = result.mechanics.contacts
    return {i: [(float(a), float(b)) for a, b in zip(c.t_start[c.tip == i], c.t_end[c.tip == i])] for i in (0, 1)}


def metrics_of(result) -> dict:
    """The metrics (module docstring) of a CoupledResult."""
    out = contact_metrics(tip_intervals(result))
    if result.mechanics is not None:
        c = result.mechanics.contacts
        out["peak_force"] = float(c.peak_force.max()) if len(c) else 0.0
        out["energy_residual"] = float(result.mechanics.energy["relative_residual"])
    if result.waveform_columns is not None and result.scene.circuit is not None:
        b = result.bounce
        out["peak_contact_voltage"] = b.get("peak_contact_voltage")
        out["arc_energy"] = b.get("arc_energy")
    return out


# ---------------------------------------------------------------------------------------
# refinements


def mode_counts(result) -> dict:
    """{"axial": n, "bending": n} modes per family the run used (from its modal basis; the
    scene's counts when the result carries no basis)."""
    basis = getattr(getattr(result.mechanics, "model", None), "basis", None)
    if basis is None:
        bar = result.scene.mech.bar
        return {"axial": int(bar.axial_modes), "bending": int(bar.bending_modes)}
    fams = list(basis.families)
    return {"axial": fams.count("axial"), "bending": max(fams.count("bend2"), fams.count("bend3"))}


def refined_count(n: int) -> int:
    """1.5x a family's mode count, rounded up, at least one more, at most MAX_MODES."""
    return min(MAX_MODES, max(n + 1, math.ceil(1.5 * n)))


def refinements(scene, base_result) -> list[tuple[str, str, object]]:
    """[(name, description, refined scene or None when not applicable: the reason as description)]."""
    out = []
    if scene.mech is not None:
        counts = mode_counts(base_result)
        if not any(counts.values()):
            out.append(("modes", "not applicable: rigid bar (modes = 0)", None))
        elif all(v >= MAX_MODES or v == 0 for v in counts.values()):
            out.append(("modes", f"not applicable: already {MAX_MODES} modes per family", None))
        else:
            new = {k: (refined_count(v) if v else 0) for k, v in counts.items()}
            out.append(("modes", f"modes per family axial {counts['axial']} -> {new['axial']}, "
                                 f"bending {counts['bending']} -> {new['bending']}", scene.set("bar.modes", new)))
        rtol = scene.mech.solver.rtol
        if rtol <= MIN_RTOL * (1 + 1e-9):
            out.append(("rtol", f"not applicable: rtol already {MIN_RTOL:g}", None))
        else:
            new_rtol = max(rtol / 10.0, MIN_RTOL)
            out.append(("rtol", f"rtol {rtol:g} -> {new_rtol:g}", scene.set("solver.rtol", new_rtol)))
    if scene.kind == "coupled":
        h = scene.coupling.macro_step
        out.append(("macro_step", f"macro step {h * 1e6:g} -> {h * 5e5:g} us", scene.set("coupling.macro_step", h / 2.0)))
    if scene.circuit is not None:
        reltol = scene.circuit.options.reltol
        if reltol <= MIN_RELTOL * (1 + 1e-9):
            out.append(("reltol", f"not applicable: RELTOL already {MIN_RELTOL:g}", None))
        else:
            new = max(reltol / 10.0, MIN_RELTOL)
            out.append(("reltol", f"ngspice RELTOL {reltol:g} -> {new:g}", scene.set("circuit.reltol", new)))
    return out


def verdict(entries: list[dict]) -> tuple[bool, str]:
    """(converged, one line) from the per-refinement entries of ``check``."""
    moved = [e for e in entries if e["status"] == "ok" and e["moved"]]
    failed = [e for e in entries if e["status"] not in ("ok", "not applicable")]
    done = [e["name"] for e in entries if e["status"] == "ok"]
    if not moved and not failed:
        return True, ("converged within the documented tolerances: "
                      + (", ".join(done) if done else "no refinement applies") + " did not move the result")
    parts = []
    for e in moved:
        m = e["metrics"]
        what = []
        for key in e["moved"]:
            v = m[key]
            what.append(_describe(key, v))
        parts.append(f"{e['name']} ({e['refinement']}) moved {'; '.join(what)}")
    for e in failed:
        parts.append(f"{e['name']} refinement {e['status']}")
    return False, "NOT converged: " + "; ".join(parts)


def _describe(key: str, v: dict) -> str:
    if key == "mismatch_time":
        return f"contact-state mismatch {v['refined'] * 1e6:.3g} us (allowed {v['allowed'] * 1e6:.3g} us)"
    if key in ("contacts", "bounces"):
        return f"{key} {v['base']} -> {v['refined']}"
    unit, scale = {"first_make": ("ms", 1e3), "last_make": ("ms", 1e3), "total_bounce_time": ("ms", 1e3),
                   "peak_force": ("N", 1.0), "peak_contact_voltage": ("V", 1.0), "arc_energy": ("mJ", 1e3)}[key]

    def f(x):
        return "none" if x is None else f"{x * scale:.4g}"

    return f"{key} {f(v['base'])} -> {f(v['refined'])} {unit}"


def check(scene, base_result, *, run_fn=None) -> dict:
    """summary.accuracy for ``base_result`` of ``scene`` (reruns the refined scenes)."""
    from .master import CoupledRunError, run

    run_fn = run_fn or run
    base = metrics_of(base_result)
    base_tips = tip_intervals(base_result)
    entries = []
    for name, description, refined_scene in refinements(scene, base_result):
        entry: dict = dict(name=name, refinement=description)
        if refined_scene is None:
            entry.update(status="not applicable", moved=[])
            entries.append(entry)
            continue
        tick = time.perf_counter()
        try:
            ref = run_fn(refined_scene)
        except CoupledRunError as err:
            entry.update(status=f"failed: {err}", moved=[], wall_time=time.perf_counter() - tick)
            entries.append(entry)
            continue
        entry["wall_time"] = time.perf_counter() - tick
        entry["status"] = "ok"
        entry.update(compare(base, metrics_of(ref), base_tips, tip_intervals(ref)))
        entries.append(entry)
    converged, line = verdict(entries)
    return dict(converged=converged, verdict=line, tolerances=dict(TOLERANCES), refinements=entries)


def run_checked(scene, *, progress: bool = False):
    """Run ``scene`` and attach ``accuracy`` (``check``) to its CoupledResult."""
    from .master import run

    result = run(scene, progress=progress)
    result.accuracy = check(scene, result)
    return result
