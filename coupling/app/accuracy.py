"""Every run can tell its own error: rerun a scene refined and report what moved.

``run(scene, check=True)`` (``switchsim run --check``) runs the scene, then reruns it
once per refinement, each refinement alone so the verdict can name the one that moved
the result:

    modes       every mode family 1.5x its count (rounded up, at least +1, at most 40)
    rtol        solver.rtol / 10 (at least 1e-13)
    macro_step  coupling.macro_step / 2 and every other step rule of the coupling
                (STEP_RULES: the free step, the time-scale fractions of the current
                and of the coil's flux, the gap rule) / 2      (coupled scenes)
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
    operate_time, release_time   s (a relay: coil switched on to the first make, off to
                         the break after it; summary.json relay)
    pole_arrival, last_pole_arrival, pole_bounces   s, s, count (an armature: its first
                         and last arrival on the pole stop and how often it bounced off
                         it; summary.json armature; only for an actuator alone, with
                         no contact: the only switching the run has). With no contact, the
                         sensitivity reruns change the armature's travel and its stops'
                         damping instead of the gap and the contact's dissipation.

The switching window of a run: from its first make to its last switching instant (the
last make when the run ends closed, the last break when it ends open), without the held
closures (closures at least [metrics] settle_window long). Relative tolerances are taken
on it, so holding a contact longer does not loosen them.

TOLERANCES (a refinement "did not move" the result when all hold):
    mismatch_time       <= max(1 us, 2 % of the base run's contact time in its switching
                        window, both tips)
    contacts, bounces   equal
    first/last make, total bounce time, operate and release time   within max(1 us, 1 % of
                        the switching window); operate and release time also within
                        max(1 us, 1 % of themselves)
    peak_force          within 2 %
    peak_contact_voltage within 2 % + 10 mV
    arc_energy          within 5 % + 1 uJ

Sensitivity: the check also reruns the scene with two inputs no designer knows to 1 %
changed by 1 % each way (SENSITIVITY): the contact gap (initial.height; where the fixed
contacts sit at their own gaps, every open one's `fixed[i].gap` together) and the contact's
dissipation (contact.restitution, or contact.damping); where one cannot be changed (a
contact that starts closed, an elastic contact, a restitution of 1 upwards) the gap by
0.5 % each way takes its place. Each perturbed contact sequence is shifted onto the base
run's first make (a longer travel delays the whole sequence; the pattern after the first
make is what is compared). A metric that so small a change of an input moves beyond its
tolerance is ill-conditioned: no numerical setting makes it more certain than that, and
its range over the five runs is reported. Late micro-bounces of a switch closure are
typically so (a grazing opening comes and goes); four samples give a lower bound of the
spread. The status is "converged" when no refinement moves a
metric; "within sensitivity" when every metric a refinement moves, it moves no more than
the input perturbations do (the numerical error is not what limits it); else "not
converged".

A circuit of several contacts (a changeover's NO and NC, a bridge's two breaks) is also
judged contact by contact (``per_contact``: each contact's status and verdict line): the
same reruns, the contact metrics (mismatch, contacts, bounces, makes) of the contact pairs
that feed it alone, a perturbed run's sequence shifted onto that contact's own first make.
An ill-conditioned tail of one contact (a changeover's NC bouncing back at release) then
no longer sets the scale the other contact's refinements are judged against. The overall
status still judges every contact pair together.
"""

from __future__ import annotations

import math
import time

from coupling.core.metrics import DEFAULT_SETTLE_WINDOW, intersection
from coupling.core.results import merge_intervals

TOLERANCES = dict(mismatch_fraction=0.02, time_floor=1e-6, time_fraction=0.01, peak_force=0.02,
                  voltage_rel=0.02, voltage_abs=0.01, arc_rel=0.05, arc_abs=1e-6)
SENSITIVITY = 0.01  # the relative change of an input in the sensitivity reruns
SENSITIVITY_RERUNS = 4
COUNT_KEYS = ("contacts", "bounces", "pole_bounces")
TIME_KEYS = ("first_make", "last_make", "total_bounce_time", "operate_time", "release_time", "pole_arrival",
             "last_pole_arrival")
MAX_MODES = 40  # the largest count a family may have (mech.parameters)
MIN_RTOL = 1e-13
MIN_RELTOL = 1e-9
# the coupling's step rules (coupling.core.scene.CouplingOptions), all halved by the macro_step
# refinement: the contact's macro step and free step, the time-scale rules of the loop current
# and the coil's flux, the gap rule (a coil-driven run's steps are mostly set by the last two)
STEP_RULES = ("macro_step", "max_macro_step", "time_scale_fraction", "coil_time_scale_fraction",
              "gap_change_fraction", "coil_point_fraction")

# ---------------------------------------------------------------------------------------
# metrics: pure functions


def measure(intervals) -> float:
    """s: total length of the union of intervals [(a, b), ...]."""
    return float(sum(b - a for a, b in merge_intervals(intervals)))


def mismatch_time(a, b) -> float:
    """s: measure of the symmetric difference of two sets of contact intervals: the time
    during which one run has the tip touching and the other not."""
    return max(0.0, measure(a) + measure(b) - 2.0 * measure(intersection(a, b)))


def contact_metrics(tip_intervals, closed_at_end: bool = False,
                    settle_window: float = DEFAULT_SETTLE_WINDOW) -> dict:
    """The contact metrics of per-tip interval lists {tip: [(t_start, t_end), ...]} (s).

    closed_at_end: the contact is closed when the run ends (its last interval is the
    final closure, not a contact that broke). settle_window: s, a closure at least this
    long is a held contact (coupling.core.metrics). Besides the metrics of the module
    docstring: contact_time (s, both tips, whole run), span (s, first make to the last
    interval's end), window (s, s: first make to the last switching instant, the last make
    when closed at the end, else the last break), window_length (s, its length without
    the held closures) and window_contact_time (s, both tips' contact time there).
    """
    all_iv = [iv for ivs in tip_intervals.values() for iv in ivs]
    union = merge_intervals(all_iv)
    out = dict(contacts=len(all_iv), bounces=max(len(union) - 1, 0), first_make=None, last_make=None,
               total_bounce_time=0.0, contact_time=float(sum(measure(v) for v in tip_intervals.values())),
               span=0.0, window=None, window_length=0.0, window_contact_time=0.0)
    if union:
        end = union[-1][0] if closed_at_end else union[-1][1]
        window = (union[0][0], end)
        active = active_window(union, window, settle_window)
        out.update(first_make=union[0][0], last_make=union[-1][0], total_bounce_time=union[-1][0] - union[0][0],
                   span=union[-1][1] - union[0][0], window=window, window_length=measure(active),
                   window_contact_time=float(sum(measure(intersection(v, active)) for v in tip_intervals.values())))
    return out


def active_window(union, window, settle_window: float) -> list[tuple[float, float]]:
    """The switching window (s, s) without the held closures (union intervals at least
    settle_window long): the stretches where the contact makes, bounces or breaks."""
    out, t = [], window[0]
    for a, b in union:
        if b - a >= settle_window and a < window[1]:
            if a > t:
                out.append((t, a))
            t = max(t, b)
    if window[1] > t:
        out.append((t, window[1]))
    return out


def time_tolerance(base: dict, tol: dict = TOLERANCES) -> float:
    """s: how far an instant or duration may move: max(1 us, 1 % of the switching window
    without its held closures)."""
    return max(tol["time_floor"], tol["time_fraction"] * base["window_length"])


#: durations a datasheet quotes on their own, from the coil's switching (a relay's)
RELAY_DURATIONS = ("operate_time", "release_time")


def duration_tolerance(value: float | None, time_tol: float, tol: dict = TOLERANCES) -> float:
    """s: how far a relay's operate or release time (``value``, s) may move: the time
    tolerance, but no more than the same fraction of the duration itself (floor 1 us): a
    release of 0.22 ms against a 2 ms switching window was allowed 20 us, 9 % of itself."""
    if value is None:
        return time_tol
    return min(time_tol, max(tol["time_floor"], tol["time_fraction"] * abs(value)))


def mismatch_allowance(base: dict, tol: dict = TOLERANCES) -> float:
    """s: the contact-state mismatch allowed: max(1 us, 2 % of the contact time in the
    switching window without its held closures)."""
    return max(tol["time_floor"], tol["mismatch_fraction"] * base["window_contact_time"])


def agreeing_contacts(a, b, time_tol: float) -> int:
    """How many of the first closed intervals of two runs (unions of the tips' contacts, s)
    agree, in order, make and break each within time_tol."""
    a, b = merge_intervals(a), merge_intervals(b)
    k = 0
    for (a0, a1), (b0, b1) in zip(a, b):
        if abs(a0 - b0) > time_tol or abs(a1 - b1) > time_tol:
            break
        k += 1
    return k


def shifted(tips: dict, dt: float) -> dict:
    """Per-tip intervals moved by dt (s)."""
    return {k: [(a + dt, b + dt) for a, b in v] for k, v in tips.items()}


def aligned_on_first_make(base_first_make, metrics: dict, tips: dict, closed_at_end: bool,
                          settle_window: float) -> tuple[float, dict, dict]:
    """(dt in s, the tips shifted by dt, ``metrics`` with the contact metrics of the shifted
    tips): a perturbed run's contact sequence moved onto the base run's first make (s; none
    in either run: not moved)."""
    if base_first_make is None or metrics["first_make"] is None:
        return 0.0, tips, metrics
    dt = base_first_make - metrics["first_make"]
    tips = shifted(tips, dt)
    return dt, tips, dict(metrics, **contact_metrics(tips, closed_at_end, settle_window))


def compare(base: dict, refined: dict, base_tips: dict, refined_tips: dict, tol: dict = TOLERANCES) -> dict:
    """Per metric {base, refined, change, within} and the mismatch time, for two runs'
    metric dicts (see ``metrics_of``) and per-tip intervals; ``moved`` lists the metrics
    outside the tolerances; ``agreeing_contacts``: how many of the base run's first
    closures the refined run reproduces within the time tolerance (of ``contacts_total``)."""
    out: dict = {}
    mism = sum(mismatch_time(base_tips.get(k, []), refined_tips.get(k, []))
               for k in set(base_tips) | set(refined_tips))
    allowed = mismatch_allowance(base, tol)
    out["mismatch_time"] = dict(base=0.0, refined=mism, change=mism, within=mism <= allowed + 1e-15,
                                allowed=allowed)
    for key in COUNT_KEYS:
        if key not in base and key not in refined:
            continue
        a, b = base.get(key, 0), refined.get(key, 0)
        out[key] = dict(base=a, refined=b, change=b - a, within=b == a)
    time_tol = time_tolerance(base, tol)
    for key in TIME_KEYS:
        a, b = base.get(key), refined.get(key)
        if a is None and b is None:
            continue
        change = None if (a is None or b is None) else b - a
        allowed = duration_tolerance(a, time_tol, tol) if key in RELAY_DURATIONS else time_tol
        out[key] = dict(base=a, refined=b, change=change, within=change is not None and abs(change) <= allowed,
                        allowed=allowed)
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
    union_a = [iv for v in base_tips.values() for iv in v]
    union_b = [iv for v in refined_tips.values() for iv in v]
    return dict(metrics=out, moved=[k for k, v in out.items() if not v["within"]],
                agreeing_contacts=agreeing_contacts(union_a, union_b, time_tol),
                contacts_total=len(merge_intervals(union_a)))


def within_sensitivity(moved: dict, spread: dict) -> bool:
    """Whether a refinement's moved metrics {key: entry} each moved no more than the
    sensitivity reruns moved them: spread {key: largest |change| (mismatch: the mismatch
    time itself) under the input perturbations}; first_make never (the perturbed runs are
    aligned on it), a metric without a spread never."""
    for key, v in moved.items():
        if key == "first_make" or v.get("change") is None or key not in spread:
            return False
        if abs(v["change"]) > spread[key] * (1 + 1e-12):
            return False
    return True


def sensitivity_spread(entries: list[dict]) -> dict:
    """{metric: largest |change|} over the sensitivity reruns that ran (mismatch_time: the
    largest mismatch), counting only changes outside the tolerances."""
    spread: dict = {}
    for e in entries:
        if e.get("status") != "ok":
            continue
        for key in e["moved"]:
            v = e["metrics"][key]
            if v.get("change") is not None:
                spread[key] = max(spread.get(key, 0.0), abs(v["change"]))
    return spread


# ---------------------------------------------------------------------------------------
# from results


def tip_intervals(result) -> dict:
    """{tip: [(t_start, t_end), ...]} (s) of a CoupledResult with mechanics; for a prescribed
    schedule (no mechanics) the closed intervals as tip 0."""
    if result.mechanics is None:
        return {0: list(result.closed_intervals)}
    c = result.mechanics.contacts
    pairs = sorted({0, 1} | {int(t) for t in c.tip})  # (a [[fixed]] scene may have up to four)
    return {i: [(float(a), float(b)) for a, b in zip(c.t_start[c.tip == i], c.t_end[c.tip == i])] for i in pairs}


def metrics_of(result) -> dict:
    """The metrics (module docstring) of a CoupledResult."""
    out = contact_metrics(tip_intervals(result), result.closed_at_end, _settle_window(result))
    if result.mechanics is not None:
        c = result.mechanics.contacts
        out["peak_force"] = float(c.peak_force.max()) if len(c) else 0.0
        out["energy_residual"] = float(result.mechanics.energy["relative_residual"])
        armature = result.mechanics.armature
        if armature is not None and not result.mechanics.model.has_bar:
            # an actuator alone (no contact): the armature's impacts on its pole stop are
            # the only switching the run has. (Beside a contact they are left out: the
            # relay's pole bounces are a grazing contact whose count a 1 % input change
            # moves over 0-9, and the contact's own metrics judge the device.)
            out["pole_arrival"] = armature["first_arrival"]
            out["last_pole_arrival"] = armature["last_arrival"]
            out["pole_bounces"] = armature["pole_bounces"]
    if result.waveform_columns is not None and result.scene.circuit is not None:
        b = result.bounce
        out["peak_contact_voltage"] = b.get("peak_contact_voltage")
        out["arc_energy"] = b.get("arc_energy")
        relay = getattr(result, "relay", None)
        if relay:
            out["operate_time"] = relay.get("operate_time")
            out["release_time"] = relay.get("release_time")
    return out


def contact_groups(result) -> dict:
    """{circuit contact name: indices of the contact pairs that feed it} of a coupled result
    whose circuit has several contacts (coupling.core.arrangement.contact_feeds); {} else."""
    circuit = getattr(getattr(result.scene, "circuit", None), "circuit", None)
    contacts = getattr(circuit, "contacts", ())
    if len(contacts) < 2 or result.mechanics is None:
        return {}
    from coupling.core.arrangement import contact_feeds

    return {c.name: tuple(int(i) for i in pairs) for c, pairs in zip(contacts, contact_feeds(result.scene.mech,
                                                                                                 contacts))}


def _settle_window(result) -> float:
    settings = getattr(result.scene, "metrics", None)
    return settings.settle_window if settings is not None else DEFAULT_SETTLE_WINDOW


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
        out.append(("macro_step", *refined_steps(scene)))
    if scene.circuit is not None:
        reltol = scene.circuit.options.reltol
        if reltol <= MIN_RELTOL * (1 + 1e-9):
            out.append(("reltol", f"not applicable: RELTOL already {MIN_RELTOL:g}", None))
        else:
            new = max(reltol / 10.0, MIN_RELTOL)
            out.append(("reltol", f"ngspice RELTOL {reltol:g} -> {new:g}", scene.set("circuit.reltol", new)))
    return out


def refined_steps(scene) -> tuple[str, object]:
    """The macro_step refinement: every step rule of the coupling halved (STEP_RULES), so that
    whichever rule sets a run's macro steps, they halve; (description, refined scene)."""
    c = scene.coupling
    keys = [key for key in STEP_RULES if getattr(c, key) is not None]  # (max_macro_step may be None)
    changes = {f"coupling.{key}": getattr(c, key) / 2.0 for key in keys}
    return (f"macro step {c.macro_step * 1e6:g} -> {c.macro_step * 5e5:g} us, every other step rule halved too "
            f"({', '.join(keys[1:])})"), scene.update(changes)


def perturbations(scene) -> list[tuple[str, str, object]]:
    """The sensitivity reruns: [(name, description, perturbed scene or None: the reason as
    description)] (module docstring): the gap and the contact's dissipation changed by
    SENSITIVITY each way, the gap by half as much in place of what cannot be changed."""
    if scene.mech is None:
        return [("inputs", "not applicable: no mechanics (prescribed contact schedule)", None)]
    # each input: the keys it sets, each at its ratio to the value shown
    gap_label, gap_keys, gap_scale, gap_unit, gap_shown = "gap", {"initial.height": 1.0}, 1e6, " um", ""
    if scene.mech.bar is None:
        # an armature alone (an actuator): its travel is the gap it closes, its stops'
        # damping the dissipation of the impacts it bounces with
        arm = scene.mech.armature
        gap_label, gap_keys, gap_scale, gap_unit = "travel", {"armature.travel": 1.0}, 1.0, ""
        gap = arm.travel if arm.travel and arm.travel > 0.0 else None
        dissipation = ("stop damping", "armature.stop_damping", arm.stop_damping, math.inf) if arm.stop_damping \
            else None
    else:
        ini, con = scene.mech.initial, scene.mech.contact
        gap = None if (ini.resting or not ini.height > 0.0) else ini.height
        fixed = [(k, float(entry["gap"])) for k, entry in enumerate(scene.raw.get("fixed") or [])
                 if isinstance(entry.get("gap"), (int, float)) and entry["gap"] > 0.0]
        if fixed:
            # [[fixed]] contacts sit at their own gaps from the bar: initial.height only moves
            # the world frame there (the changeover's NO moved 0.2 us for 1 % of it, 226-232 us
            # for 0.5 % of its own gap); every open contact's gap changes together
            gap = fixed[0][1]
            gap_keys = {f"fixed[{k}].gap": value / gap for k, value in fixed}
            gap_shown = f" ({', '.join(gap_keys)})"
        if con.restitution is not None:
            dissipation = ("restitution", "contact.restitution", con.restitution, 1.0)
        elif con.damping:
            dissipation = ("damping", "contact.damping", con.damping, math.inf)
        else:
            dissipation = None
    out = []

    def add(label, keys, value, rel, top, unit_scale=1.0, unit="", shown=""):
        new = value * (1.0 + rel)
        if new <= top:
            out.append((f"{label} {rel:+.1%}",
                        f"{label}{shown} {value * unit_scale:.4g} -> {new * unit_scale:.4g}{unit}",
                        scene.update({key: new * ratio for key, ratio in keys.items()})))

    for rel in (-SENSITIVITY, SENSITIVITY):
        if gap is not None:
            add(gap_label, gap_keys, gap, rel, math.inf, gap_scale, gap_unit, gap_shown)
        if dissipation is not None:
            add(dissipation[0], {dissipation[1]: 1.0}, dissipation[2], rel, dissipation[3])
    for rel in (-0.5 * SENSITIVITY, 0.5 * SENSITIVITY):
        if gap is not None and len(out) < SENSITIVITY_RERUNS:
            add(gap_label, gap_keys, gap, rel, math.inf, gap_scale, gap_unit, gap_shown)
    if not out:
        return [("inputs", "not applicable: no contact gap and no contact dissipation to change", None)]
    return out


def sensitivity_ranges(entries: list[dict]) -> dict:
    """{metric: (lowest, highest)} over the base run and the sensitivity reruns that ran,
    for every metric one of them moved beyond its tolerance (mismatch_time: (0, largest))."""
    ran = [e for e in entries if e.get("status") == "ok"]
    keys = [k for e in ran for k in e["moved"]]
    out: dict = {}
    for key in dict.fromkeys(keys):
        values = [e["metrics"][key]["refined"] for e in ran if key in e["metrics"]]
        values += [ran[0]["metrics"][key]["base"]]
        values = [v for v in values if v is not None]
        if values:
            out[key] = (min(values), max(values))
    return out


def status_of(entries: list[dict], sensitivity: list[dict] | None = None) -> str:
    """"converged", "within sensitivity" or "not converged" (module docstring)."""
    moved = [e for e in entries if e["status"] == "ok" and e["moved"]]
    failed = [e for e in entries if e["status"] not in ("ok", "not applicable")]
    if failed:
        return "not converged"
    if not moved:
        return "converged"
    spread = sensitivity_spread(sensitivity or [])
    if all(within_sensitivity({k: e["metrics"][k] for k in e["moved"]}, spread) for e in moved):
        return "within sensitivity"
    return "not converged"


def verdict(entries: list[dict], sensitivity: list[dict] | None = None) -> tuple[str, str]:
    """(status, one line) from the per-refinement entries of ``check`` and its sensitivity
    reruns (module docstring)."""
    sensitivity = sensitivity or []
    status = status_of(entries, sensitivity)
    moved = [e for e in entries if e["status"] == "ok" and e["moved"]]
    failed = [e for e in entries if e["status"] not in ("ok", "not applicable")]
    done = [e["name"] for e in entries if e["status"] == "ok"]
    parts = [f"{e['name']} ({e['refinement']}) moved {'; '.join(_describe(k, e['metrics'][k]) for k in e['moved'])}"
             for e in moved]
    parts += [f"{e['name']} refinement {e['status']}" for e in failed]
    ranges = sensitivity_ranges(sensitivity)
    inputs = sorted({e["name"].rsplit(" ", 1)[0] for e in sensitivity if e.get("status") == "ok"})
    band = f"{SENSITIVITY:.0%} change of the {' or the '.join(inputs) or 'inputs'}"
    spans = "; ".join(_describe_range(k, lo, hi) for k, (lo, hi) in ranges.items())
    if status == "converged":
        line = ("converged within the documented tolerances: "
                + (", ".join(done) if done else "no refinement applies") + " did not move the result")
        if spans:
            line += f"; ill-conditioned over a {band}: {spans}"
    elif status == "within sensitivity":
        line = ("within sensitivity: " + "; ".join(parts)
                + f"; no more than a {band} does ({spans}): quote these with that range")
    else:
        line = "NOT converged: " + "; ".join(parts)
        if spans:
            line += f"; for scale, over a {band}: {spans}"
    runs = [e for e in entries + sensitivity if e.get("status") == "ok" and "agreeing_contacts" in e]
    if runs and any(e["moved"] for e in runs) and runs[0]["contacts_total"]:
        k = min(e["agreeing_contacts"] for e in runs)
        line += f"; the first {k} of {runs[0]['contacts_total']} closures agree in every rerun"
    return status, line


_UNITS = {"first_make": ("ms", 1e3), "last_make": ("ms", 1e3), "total_bounce_time": ("ms", 1e3),
          "operate_time": ("ms", 1e3), "release_time": ("ms", 1e3), "pole_arrival": ("ms", 1e3),
          "last_pole_arrival": ("ms", 1e3),
          "peak_force": ("N", 1.0), "peak_contact_voltage": ("V", 1.0), "arc_energy": ("mJ", 1e3)}


def _describe_range(key: str, lo, hi) -> str:
    if key == "mismatch_time":
        return f"contact-state mismatch up to {hi * 1e6:.3g} us"
    if key in COUNT_KEYS:
        return f"{key} {lo}-{hi}"
    unit, scale = _UNITS[key]
    return f"{key} {lo * scale:.4g}-{hi * scale:.4g} {unit}"


def _describe(key: str, v: dict) -> str:
    if key == "mismatch_time":
        return f"contact-state mismatch {v['refined'] * 1e6:.3g} us (allowed {v['allowed'] * 1e6:.3g} us)"
    if key in ("contacts", "bounces"):
        return f"{key} {v['base']} -> {v['refined']}"
    unit, scale = _UNITS[key]

    def f(x):
        return "none" if x is None else f"{x * scale:.4g}"

    return f"{key} {f(v['base'])} -> {f(v['refined'])} {unit}"


def _rerun(name: str, description: str, scene, run_fn, compare_fn) -> dict:
    """One rerun's entry: status, wall_time and, when it ran, compare_fn(result)."""
    from coupling.core.master import CoupledRunError

    entry: dict = dict(name=name, refinement=description)
    if scene is None:
        entry.update(status="not applicable", moved=[])
        return entry
    tick = time.perf_counter()
    try:
        res = run_fn(scene)
    except CoupledRunError as err:
        entry.update(status=f"failed: {err}", moved=[], wall_time=time.perf_counter() - tick)
        return entry
    entry.update(status="ok", wall_time=time.perf_counter() - tick)
    entry.update(compare_fn(res))
    return entry


def check(scene, base_result, *, run_fn=None, sensitivity: bool = True) -> dict:
    """summary.accuracy for ``base_result`` of ``scene``: reruns the refined scenes and,
    unless sensitivity is False, the input-perturbed ones (module docstring)."""
    from coupling.core.master import run

    run_fn = run_fn or run
    base = metrics_of(base_result)
    base_tips = tip_intervals(base_result)

    def closed(tips):  # the contact's closed intervals (both tips), for the plot
        return [[a, b] for a, b in merge_intervals(iv for v in tips.values() for iv in v)]

    groups = contact_groups(base_result)
    base_by_contact = {name: contact_metrics({i: base_tips.get(i, []) for i in pairs},
                                             base_result.contact_closed[name][1], _settle_window(base_result))
                       for name, pairs in groups.items()}

    def by_contact(res, tips, align: bool) -> dict:
        """{"per_contact": each contact's comparison, of the pairs that feed it alone} ({} for
        one contact); ``align``: its sequence shifted onto its own first make in the base run
        (a perturbed input delays each contact's sequence by its own travel)."""
        if not groups:
            return {}
        out = {}
        for name, pairs in groups.items():
            mine = {i: tips.get(i, []) for i in pairs}
            at_end, settle = res.contact_closed[name][1], _settle_window(res)
            m = contact_metrics(mine, at_end, settle)
            dt = 0.0
            if align:
                dt, mine, m = aligned_on_first_make(base_by_contact[name]["first_make"], m, mine, at_end, settle)
            out[name] = dict(compare(base_by_contact[name], m, {i: base_tips.get(i, []) for i in pairs}, mine),
                             shift=dt)
        return {"per_contact": out}

    def refined(res):
        tips = tip_intervals(res)
        return dict(compare(base, metrics_of(res), base_tips, tips), closed=closed(tips),
                    **by_contact(res, tips, align=False))

    def aligned(res):  # the perturbed sequence moved onto the base run's first make
        tips = tip_intervals(res)
        dt, moved, m = aligned_on_first_make(base["first_make"], metrics_of(res), tips, res.closed_at_end,
                                             _settle_window(res))
        return dict(compare(base, m, base_tips, moved), shift=dt, closed=closed(moved),
                    **by_contact(res, tips, align=True))

    entries = [_rerun(n, d, sc, run_fn, refined) for n, d, sc in refinements(scene, base_result)]
    sens = ([_rerun(n, d, sc, run_fn, aligned) for n, d, sc in perturbations(scene)] if sensitivity else [])
    status, line = verdict(entries, sens)
    out = dict(converged=status == "converged", status=status, verdict=line, closed=closed(base_tips),
               tolerances=dict(TOLERANCES),
               sensitivity_change=SENSITIVITY, refinements=entries, sensitivity=sens,
               sensitivity_ranges={k: list(v) for k, v in sensitivity_ranges(sens).items()})
    if groups:
        out["per_contact"] = {}
        for name in groups:
            # each rerun's entry as that contact alone sees it (a rerun that did not run has none)
            own, own_sens = ([dict(e, **e["per_contact"][name]) if "per_contact" in e else e for e in runs]
                             for runs in (entries, sens))
            status_c, line_c = verdict(own, own_sens)
            out["per_contact"][name] = dict(status=status_c, verdict=line_c,
                                            sensitivity_ranges={k: list(v) for k, v in
                                                                sensitivity_ranges(own_sens).items()})
    return out


def run_checked(scene, *, progress: bool = False):
    """Run ``scene`` and attach ``accuracy`` (``check``) to its CoupledResult."""
    from coupling.core.master import run

    result = run(scene, progress=progress)
    result.accuracy = check(scene, result)
    return result
