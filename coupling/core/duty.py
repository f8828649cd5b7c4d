"""Contact duty in a run: the scene's [duty] settings, Holm's repulsion the master hands the
mechanics, and what each operation did to the contact (weld risk, blow-off current, arc
stage energies and erosion), from the run's waveforms.

The laws are coupling.laws.duty's; this module applies them to a scene and a run (SI units
throughout). docs/contact_duty.md, "In a run", says what each key is.
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from mech.validation import (
    check_bool, check_choice, check_keys, check_nonnegative, check_positive, scene_key,
)
from mech.frozen import frozen

from coupling.laws.duty import (
    MELT_FRACTION, TRANSITION_GAP, ContactPair, arc_stage_energies, blow_off_current, constriction_repulsion,
    erosion, shrinking_blow_off_current, weld_verdict,
)
from coupling.laws.materials import MATERIALS, material, plastic_radius

from coupling.core.metrics import arc_energy

NODES = ("a", "b")
WELD_LEVELS = ("none", "possible", "likely")
STOP_ON_WELD = ("likely", "possible", "never")
ELECTRODES = ("moving", "fixed")
# The data each duty model reads from the material library, checked once when the scene is
# built (the model names are those coupling.laws.duty puts in its errors).
MODEL_DATA = {
    "Slade's threshold welding current": ("melting_voltage", "melting_point", "temperature_coefficient"),
    "the molten-bridge model": ("melting_voltage", "boiling_voltage", "melting_point", "temperature_coefficient"),
    "the bounce-arc weld (molten pool)": ("density", "specific_heat", "melting_point", "latent_heat"),
    "the a-spot temperature from a room-temperature contact voltage": ("temperature_coefficient",),
}
EROSION_DATA = ("erosion_anode", "erosion_cathode", "density")
DEFAULT_GAP_RANGE = (0.5, 1.5)  # x the initial gap: `switchsim life` stops outside it
DEFAULT_FORCE_FRACTION = 0.5  # x the first sampled operation's held force
DEFAULT_RESISTANCE_FACTOR = 10.0  # x the first sampled operation's held R_c


def _pair_of(name: str, value) -> tuple:
    """A number (both) or a [first, second] list, as a 2-tuple."""
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise ValueError(f"{name} = {value!r}: expected one number or two [moving, fixed]")
        return tuple(value)
    return value, value


@frozen
class LifeLimits:
    """[duty.life]: when `switchsim life` stops before its operation count (SI).

    gap_range: m, [low, high] of the contact gap (None: 0.5 and 1.5 x the scene's gap);
    min_force: N, the least held normal force (None: 0.5 x the first sampled operation's);
    max_resistance: ohm, the largest held contact resistance (None: 10 x the first sampled
    operation's); stop_on_weld: stop at a make whose weld risk reaches "likely" (default),
    "possible", or "never".
    """

    gap_range: tuple[float, float] | None = scene_key(
        None, unit="m", doc="[low, high] of the contact gap as the caps wear", shown="[0.5, 1.5] x `initial.height`")
    min_force: float | None = scene_key(
        None, unit="N", doc="the least held normal force", shown="0.5 x the first sample's held force")
    max_resistance: float | None = scene_key(
        None, unit="ohm", doc="the largest held contact resistance", shown="10 x the first sample's held R_c")
    stop_on_weld: str = scene_key(
        "likely", unit="-", doc='stop at a make whose weld risk reaches it: "likely", "possible" or "never"')

    def __post_init__(self):
        if self.gap_range is not None:
            rng = self.gap_range
            if not (isinstance(rng, (list, tuple)) and len(rng) == 2):
                raise ValueError(f"duty.life.gap_range = {rng!r}: expected [low, high] (m)")
            lo = check_nonnegative("duty.life.gap_range[0]", rng[0])
            hi = check_positive("duty.life.gap_range[1]", rng[1])
            if lo >= hi:
                raise ValueError(f"duty.life.gap_range = {list(rng)!r}: low must be below high (m)")
            object.__setattr__(self, "gap_range", (lo, hi))
        if self.min_force is not None:
            check_nonnegative("duty.life.min_force", self.min_force)
        if self.max_resistance is not None:
            check_positive("duty.life.max_resistance", self.max_resistance)
        check_choice("duty.life.stop_on_weld", self.stop_on_weld, STOP_ON_WELD)


@frozen
class DutySettings:
    """The scene's [duty] section, resolved and validated (SI units).

    materials: (moving, fixed) contact materials, library names.
    moving_node: the circuit node the moving contact is on, "a" (supply side) or "b": the
        arc current is positive from a to b, and its anode wears in the anodic stage.
    repulsion: Holm's repulsion acts on the mechanics' contact points (coupled scenes).
    conductor_radius: m, the member radius R of Holm's ln(R / a) (None: no mechanics).
    transition_gap: m, the anodic-to-cathodic arc stage transition.
    transfer_fraction: of one electrode's loss that lands on the other (0..1).
    erosion_coefficient: (anodic stage, cathodic stage) m^3/J for both electrodes, or None
        (the library's per material).
    weld_margin: a weld ratio >= 1 / margin is "possible" (coupling.laws.duty.weld_verdict).
    melt_fraction: of a bounce arc's energy that melts metal at each root.
    cap_height: (moving, fixed) m, the contact caps' heights above their carriers, or None
        where not known (only `switchsim life` needs them).
    life: the end criteria of `switchsim life` ([duty.life]; None: its defaults).
    """

    materials: tuple[str, str] = scene_key(
        unit="-", doc='`["moving", "fixed"]` (or one name for both) from the material library '
        "(docs/contact_materials.md); without a Holm law: required",
        shown='`[tribology]` `resistance = { law = "holm" }`\'s')
    moving_node: str = scene_key(
        "a", unit="-",
        doc='the circuit node of the moving contact: "a" (the supply side) or "b"; the arc current is positive '
            "from a to b, and its anode erodes in the anodic stage")
    repulsion: bool = scene_key(
        True, unit="-",
        doc="Holm's repulsion acts on the mechanics' contact points (`repulsion.<i>`); a `[circuit.schedule]` "
            "scene has no mechanics: off there (true is refused)")
    conductor_radius: float | None = scene_key(
        None, unit="m", doc="R of Holm's ln(R / a): where the current lines run parallel again",
        shown="the first rivet's `radius` (no rivet: `bar.tip_radius`)")
    transition_gap: float = scene_key(
        TRANSITION_GAP, unit="m", doc="anodic to cathodic arc stage (Ben Jemaa et al.: 15-30 um)")
    transfer_fraction: float = scene_key(0.0, unit="-", doc="of one electrode's loss that lands on the other, 0..1")
    erosion_coefficient: tuple[float, float] | None = scene_key(
        None, unit="m^3/J",
        doc="one number, or [anodic stage, cathodic stage], for both electrodes instead of the library's (a "
            "coefficient calibrated on a life test), >= 0")
    weld_margin: float = scene_key(2.0, unit="-", doc='a weld ratio >= 1 / margin is "possible", >= 1 "likely"; >= 1')
    melt_fraction: float = scene_key(
        MELT_FRACTION, unit="-", doc="of a bounce arc's energy that melts metal at each root, (0, 1]")
    cap_height: tuple[float | None, float | None] = scene_key(
        (None, None), unit="m",
        doc="one number or [moving, fixed]: the caps' heights `switchsim life` wears (each <= its sphere's radius)",
        shown="the rivet's cap above the bar's face; a spherical block's radius")
    life: LifeLimits | None = scene_key(None, unit="-", doc="`[duty.life]`: when `switchsim life` stops early")

    def __post_init__(self):
        mats = self.materials
        if isinstance(mats, str):
            mats = (mats, mats)
        if not (isinstance(mats, (list, tuple)) and len(mats) == 2 and all(isinstance(m, str) for m in mats)):
            raise ValueError(f"duty.materials = {self.materials!r}: expected two names [\"moving\", \"fixed\"] "
                             f"(or one for both) from: {', '.join(MATERIALS)}")
        object.__setattr__(self, "materials", tuple(mats))
        members = [material(m, "duty.materials") for m in mats]
        check_choice("duty.moving_node", self.moving_node, NODES)
        check_bool("duty.repulsion", self.repulsion)
        if self.conductor_radius is not None:
            check_positive("duty.conductor_radius", self.conductor_radius, high=10.0)
        elif self.repulsion:
            raise ValueError("duty.repulsion = true needs duty.conductor_radius (m): the mechanics give it by default")
        check_positive("duty.transition_gap", self.transition_gap, high=1.0)
        check_nonnegative("duty.transfer_fraction", self.transfer_fraction, high=1.0)
        if self.erosion_coefficient is not None:
            k = _pair_of("duty.erosion_coefficient", self.erosion_coefficient)
            k = tuple(check_nonnegative(f"duty.erosion_coefficient[{i}]", v, high=1e-6) for i, v in enumerate(k))
            object.__setattr__(self, "erosion_coefficient", k)
        check_positive("duty.weld_margin", self.weld_margin)
        if self.weld_margin < 1.0:
            raise ValueError(f"duty.weld_margin = {self.weld_margin!r}: must be >= 1 (a ratio >= 1 / margin is "
                             "\"possible\", >= 1 \"likely\")")
        check_positive("duty.melt_fraction", self.melt_fraction, high=1.0)
        heights = _pair_of("duty.cap_height", self.cap_height)
        object.__setattr__(self, "cap_height", tuple(None if h is None else check_positive(
            f"duty.cap_height[{i}]", h, high=10.0) for i, h in enumerate(heights)))
        if self.life is not None and not isinstance(self.life, LifeLimits):
            raise ValueError(f"duty.life = {self.life!r}: expected a table of keys")
        # every datum a model will read, named with its model now rather than after the run
        data = [(prop, model) for model, props in MODEL_DATA.items() for prop in props]
        if self.erosion_coefficient is None:
            data += [(prop, "arc erosion") for prop in EROSION_DATA]
        else:
            data += [("density", "arc erosion")]
        for member in members:
            for prop, model in data:
                try:
                    member.datum(prop, model)
                except ValueError as err:
                    raise ValueError(f"duty.materials: {err}") from None
        object.__setattr__(self, "_pair", ContactPair(tuple(mats)))

    @property
    def pair(self) -> ContactPair:
        """The (moving, fixed) pair, for the welding models (symmetric in its members)."""
        return self._pair

    @property
    def electrode_pair(self) -> ContactPair:
        """The pair in the circuit's order (electrode a, electrode b), for arc erosion."""
        return self._pair if self.moving_node == "a" else ContactPair(self.materials[::-1])

    @property
    def hardness(self) -> float:
        """Pa: the softer member's, which carries the load (Holm's plastic a-spot)."""
        return self._pair.hardness()

    def spot_radius(self, force):
        """m: the plastic a-spot of a contact point carrying ``force`` (N)."""
        return plastic_radius(force, self.hardness)

    def repulsion_force(self, current: float, force: float) -> float:
        """N: Holm's repulsion of one contact point carrying ``current`` (A) at ``force`` (N);
        0 out of contact (no spot, no constriction to repel)."""
        if not (force > 0.0) or current == 0.0 or not self.repulsion:
            return 0.0
        return float(constriction_repulsion(current, float(self.spot_radius(force)), self.conductor_radius))


DUTY_KEYS = tuple(f.name for f in fields(DutySettings))
LIFE_KEYS = tuple(f.name for f in fields(LifeLimits))


def duty_from_table(table: dict, mech, tribology, circuit) -> DutySettings:
    """[duty] of a scene, its defaults resolved from the scene's other sections:
    materials from [tribology] resistance = { law = "holm", materials = [...] }; repulsion on
    with mechanics; conductor_radius the moving contact's radius (the first rivet's, or the
    bar's tip radius); cap_height of the moving rivet from its geometry (the cap above the
    bar's face) and of a spherical fixed contact its radius (a hemisphere). mech, tribology,
    circuit: the scene's MechScene, TribologySpec and CircuitSpec (or None)."""
    check_keys("[duty]", table, DUTY_KEYS)
    if circuit is None:
        raise ValueError("[duty] needs a [circuit]: contact duty comes from the current and the arcs")
    if mech is not None and getattr(mech, "fixed", ()):
        # its geometry (the fixed cap's radius and height, the gap) is read from [block]
        raise ValueError("[duty] with [[fixed]] contacts: contact duty reads the fixed contact's geometry from "
                         "[block]; describe the one electrical contact with [block] for a duty run")
    kw = dict(table)
    if "materials" not in kw:
        law = tribology.laws.resistance_law if tribology is not None else None
        if getattr(law, "name", None) != "holm":
            raise ValueError("duty.materials: missing: give the contact materials [\"moving\", \"fixed\"] from the "
                             f"material library ({', '.join(MATERIALS)}); a [tribology] resistance = "
                             "{ law = \"holm\", materials = [...] } gives them by default")
        kw["materials"] = tuple(law.materials)
    if mech is None:
        if kw.get("repulsion", False) is not False:
            raise ValueError(f"duty.repulsion = {kw['repulsion']!r}: Holm's repulsion acts on the mechanics; "
                             "a prescribed [circuit.schedule] has none (remove it, or set false)")
        kw["repulsion"] = False
        if circuit.schedule is not None and circuit.schedule.opening_speed is None:
            raise ValueError("[duty] with [circuit.schedule] needs circuit.schedule.opening_speed (m/s): the arc "
                             "stages of erosion are told apart by the gap")
    else:
        rivets = mech.rivets
        kw.setdefault("conductor_radius", rivets[0].radius if rivets else mech.bar.tip_radius)
        if "cap_height" not in kw:
            kw["cap_height"] = (_rivet_cap_height(mech), mech.block.radius if mech.block.shape == "sphere" else None)
    if "life" in kw:
        life = kw["life"]
        if not isinstance(life, dict):
            raise ValueError(f"duty.life = {life!r}: expected a table of keys ({', '.join(LIFE_KEYS)})")
        kw["life"] = LifeLimits(**check_keys("duty.life", life, LIFE_KEYS))
    return DutySettings(**kw)


def _rivet_cap_height(mech) -> float | None:
    """m: the first rivet's cap above the bar's underside face (None: no rivet, or more than a
    hemisphere, whose erosion from the top the cap model does not cover)."""
    if not mech.rivets:
        return None
    rivet = mech.rivets[0]
    bar = mech.bar
    half = 0.5 * (bar.thickness if bar.thickness is not None else bar.diameter)
    height = rivet.radius - half - rivet.offset  # face at -half, apex at offset - radius
    if height <= 0.0 or height > rivet.radius * (1.0 + 1e-12):
        return None
    return min(height, rivet.radius)


# --- what each operation did to the contact ---------------------------------------------------


def _left(t: np.ndarray, y: np.ndarray, at: float, guard: float) -> float | None:
    """y just before ``at`` (the first sample within ``guard`` of it: ngspice keeps the left
    limit at a breakpoint; else the last sample before it)."""
    k = int(np.searchsorted(t, at - guard, side="left"))
    if k < len(t) and t[k] <= at + guard:
        return float(y[k])
    return float(y[k - 1]) if k >= 1 else None


def time_median(t: np.ndarray, y: np.ndarray) -> float | None:
    """The median of y(t) in time over the samples' span: the value y is below for half the
    time (each sample weighted by half its two intervals); None without finite samples."""
    if len(t) == 0:
        return None
    dt = np.diff(t)
    weight = np.concatenate([dt, [0.0]]) + np.concatenate([[0.0], dt]) if len(t) > 1 else np.ones(1)
    ok = np.isfinite(y)
    if not ok.any():
        return None
    y, weight = y[ok], weight[ok]
    if weight.sum() <= 0.0:
        return float(np.median(y))
    order = np.argsort(y, kind="stable")
    cumulative = np.cumsum(weight[order])
    return float(y[order][int(np.searchsorted(cumulative, 0.5 * cumulative[-1]))])


def _spans(ops: list[dict], t_end: float, t_start: float = 0.0) -> list[tuple[float, float]]:
    """Each operation's share of the run: from its first make (the run's start for the first
    one) to the next operation's, the last to the end of the run."""
    starts = [op["make"]["time"] if "make" in op else t_start for op in ops]
    starts[0] = min(starts[0], t_start) if ops else t_start
    return [(a, starts[k + 1] if k + 1 < len(starts) else t_end) for k, a in enumerate(starts)]


def _held_span(op: dict, span: tuple[float, float], t_end: float) -> tuple[float, float] | None:
    """(start, end) s of the operation's held closure: from the settle instant (the run's start
    if it starts closed) to its break or the end of the run; None when the make never held."""
    if "make" in op:
        make = op["make"]
        if make.get("settle_time") is None:
            return None
        start = make["time"] + make["settle_time"]
    else:
        start = span[0]
    end = op["break"]["time"] if "break" in op else t_end
    return start, end


def operation_duty(result, ops: list[dict]) -> list[dict]:
    """The operations (coupling.core.metrics.operations) with what each did to the contact:
    ``held`` (the held closure: force, a-spot, blow-off currents, R_c, contact voltage),
    ``make.weld_risk`` and ``make.weld`` (coupling.laws.duty.weld_verdict with its inputs and
    the bounce separations), and ``erosion`` (arc stage energies and the volume and mass each
    electrode lost). New dicts; ``ops`` is left as it was."""
    scene = result.scene
    duty: DutySettings = scene.duty
    w = result.waveform_columns
    if w is None or not len(w.get("time", ())) or not ops:
        return ops
    t_end = scene.t_end
    t = np.asarray(w["time"], float)
    v = np.asarray(w["contact_voltage"], float)
    i_arc = np.asarray(w["arc_current"], float) if "arc_current" in w else np.zeros_like(t)
    loop = w.get("load_current")
    if loop is None or not np.all(np.isfinite(loop)):
        loop = w["contact_current"] + i_arc
    loop = np.asarray(loop, float)
    force = np.asarray(w["normal_force"], float) if "normal_force" in w else None
    if "gap" in w:
        gap = np.asarray(w["gap"], float)
    else:  # a prescribed schedule: its gap (the scene requires an opening speed with [duty])
        schedule = scene.circuit.schedule
        gap = np.array([schedule.gap(s) for s in t])
    settings = getattr(scene, "metrics", None)
    guard = settings.guard(t_end) if settings is not None else max(1e-12, 1e-9 * t_end)
    law = scene.tribology.laws.resistance_law if scene.tribology is not None else None
    intervals = result.closed_intervals
    out = []
    for op, span in zip(ops, _spans(ops, t_end)):
        op = {k: (dict(v_) if isinstance(v_, dict) else v_) for k, v_ in op.items()}
        held = _held(duty, t, w["contact_current"], force, w.get("contact_resistance"), _held_span(op, span, t_end))
        if held is not None:
            op["held"] = held
        if "make" in op and force is not None:
            op["make"].update(_weld(duty, op["make"], held, t, v, loop, i_arc, force, intervals, law, guard))
        op["erosion"] = _erosion(duty, t, v, i_arc, gap, span)
        out.append(op)
    return out


def _held(duty: DutySettings | None, t, i_contact, force, resistance, span) -> dict | None:
    """The held closure's figures (None without a held closure).

    force: the closure's median normal force in time (N: half of the closure at a force
    below it, half above: what the contact is held at, whatever impacts at its start or a
    ramp of the actuator do); contact_resistance: R_c at that force, the closure's median in
    time (ohm); contact_voltage: the largest |contact current| of the closure times that R_c
    (V): the room-temperature voltage of the contact held at its force. (The waveform's own
    voltage also shows the parting at the closure's end, where the force and the spot
    vanish and the voltage passes the melting voltage: that is the bridge of the break,
    not the held contact.) With ``duty`` also the a-spot and the blow-off currents at that
    force."""
    if span is None:
        return None
    sel = (t >= span[0]) & (t <= span[1])
    if not sel.any() or resistance is None:
        return None
    ts = t[sel]
    current = float(np.max(np.abs(np.asarray(i_contact, float)[sel])))
    out = {"start": span[0], "end": span[1], "current": current}
    r = time_median(ts, np.asarray(resistance, float)[sel])
    if r is not None:
        out.update(contact_resistance=r, contact_voltage=current * r)
    f = time_median(ts, force[sel]) if force is not None else None
    if f is None or not f > 0.0:
        return out
    out["force"] = f
    if duty is None:
        return out
    a = float(duty.spot_radius(f))
    out.update(spot_radius=a,
               conductor_radius=duty.conductor_radius,
               blow_off_current=float(blow_off_current(f, a, duty.conductor_radius)),
               shrinking_blow_off_current=shrinking_blow_off_current(f, duty.hardness, duty.conductor_radius))
    return out


def held_closures(result, ops: list[dict]) -> list[dict]:
    """The operations (coupling.core.metrics.operations) with each one's ``held`` closure
    (force, R_c, current, contact voltage; ``_held``) where it has one: what a datasheet
    calls the contact force, reported with or without a [duty] section (``operation_duty``
    adds the rest). New dicts; ``ops`` is left as it was."""
    w = result.waveform_columns
    if w is None or not len(w.get("time", ())) or not ops:
        return ops
    t = np.asarray(w["time"], float)
    force = np.asarray(w["normal_force"], float) if "normal_force" in w else None
    t_end = result.scene.t_end
    out = []
    for op, span in zip(ops, _spans(ops, t_end)):
        held = _held(None, t, w["contact_current"], force, w.get("contact_resistance"), _held_span(op, span, t_end))
        out.append({**op, "held": held} if held is not None else dict(op))
    return out


def _weld(duty, make, held, t, v, loop, i_arc, force, intervals, law, guard) -> dict:
    """make.weld_risk and make.weld: the verdict of coupling.laws.duty.weld_verdict from the held
    force (the largest force of the make when it never held), the make's peak current, the held
    contact voltage and each bounce separation of the make."""
    last_make = make["time"] + make["bounce_time"]
    closures = [(a, b) for a, b in intervals if make["time"] - guard <= a <= last_make + guard]
    if held is not None and "force" in held:
        held_force, held_voltage = held["force"], held["contact_voltage"]
    else:  # never held: the largest force of its closures, no held voltage
        sel = (t >= make["time"]) & (t <= (closures[-1][1] if closures else last_make))
        held_force = float(np.max(force[sel])) if sel.any() else 0.0
        held_voltage = 0.0
    if not held_force > 0.0:
        return {"weld_risk": None, "weld": None}
    separations = []
    force_law = law is None or getattr(law, "load_exponent", 1.0) > 0.0
    for (_, parting), (remake, _) in zip(closures[:-1], closures[1:]):
        current = _left(t, loop, parting, guard) or 0.0
        burning = _left(t, i_arc, remake, guard)
        separations.append(dict(
            time=parting, current=current,
            # a force law's R_c grows without bound as the force goes: the voltage passes U_m
            voltage=None if force_law else abs(current) * float(law.resistance(1.0)),
            arc_energy=arc_energy(t, v, i_arc, parting, remake),  # where the arc burns, as the openings'
            arc_at_remake=bool(burning is not None and abs(burning) > 1e-3)))
    verdict = weld_verdict(duty.pair, held_force=held_force, peak_current=float(make.get("peak_current") or 0.0),
                           held_voltage=held_voltage, separations=separations, margin=duty.weld_margin,
                           melt_fraction=duty.melt_fraction)
    for sep, detail in zip(separations, verdict["separations"]):
        detail.update(time=sep["time"], voltage=sep["voltage"], arc_energy=sep["arc_energy"],
                      arc_at_remake=sep["arc_at_remake"])
    verdict.update(held_force=held_force, held_voltage=held_voltage,
                   peak_current=float(make.get("peak_current") or 0.0))
    return {"weld_risk": verdict.pop("weld_risk"), "weld": verdict}


def split_at_gap(t, v, i, gap, level: float):
    """The samples with one more at each crossing of the gap ``level`` (m), everything linear
    between its neighbours: arc_stage_energies classes a sample interval by its midpoint, and
    ngspice's steps along a smoothly lengthening arc grow to many microns of gap, so the
    interval across the transition would go to one stage whole (20 % of the anodic stage
    at 1 m/s: tests/coupling/test_duty_erosion.py)."""
    across = np.flatnonzero((gap[:-1] - level) * (gap[1:] - level) < 0.0)
    if not len(across):
        return t, v, i, gap
    f = (level - gap[across]) / (gap[across + 1] - gap[across])
    cols = [np.insert(x, across + 1, x[across] + f * (x[across + 1] - x[across])) for x in (t, v, i)]
    return (*cols, np.insert(gap, across + 1, np.full(len(across), level)))


def _erosion(duty: DutySettings, t, v, i_arc, gap, span) -> dict:
    """The operation's arc energy by stage and electrode, and what each electrode lost."""
    sel = (t >= span[0]) & (t <= span[1])
    cols = split_at_gap(t[sel], v[sel], i_arc[sel], gap[sel], duty.transition_gap)
    stages = arc_stage_energies(*cols, duty.transition_gap)
    lost = erosion(stages, duty.electrode_pair, duty.transfer_fraction, duty.erosion_coefficient)
    side = {"moving": duty.moving_node, "fixed": "b" if duty.moving_node == "a" else "a"}
    out = {"arc_energy": stages["total"]}
    for name, node in side.items():
        out[name] = {**stages[node], **lost[node]}
    return out


def duty_totals(duty: DutySettings, ops: list[dict]) -> dict:
    """summary.json ``duty``: the settings and the run's totals over its operations: the worst
    weld risk of its makes, the least blow-off current of its held closures, the first held
    force and R_c, the arc energy by stage, the volume and mass each electrode lost."""
    risks = [op["make"].get("weld_risk") for op in ops if "make" in op and op["make"].get("weld_risk")]
    held = [op["held"] for op in ops if "held" in op]
    blow = [h["blow_off_current"] for h in held if h.get("blow_off_current") is not None]
    out = {"materials": list(duty.materials), "moving_node": duty.moving_node, "repulsion": duty.repulsion,
           "conductor_radius": duty.conductor_radius,
           "weld_risk": max(risks, key=WELD_LEVELS.index) if risks else None,
           "blow_off_current": min(blow) if blow else None,
           "held_force": next((h["force"] for h in held if "force" in h), None),
           "contact_resistance": next((h["contact_resistance"] for h in held if h.get("contact_resistance")), None),
           "arc_energy": sum(op["erosion"]["arc_energy"] for op in ops if "erosion" in op)}
    for name in ELECTRODES:
        parts = [op["erosion"][name] for op in ops if "erosion" in op]
        out[f"{name}_anodic_energy"] = sum(p["anodic"] for p in parts)
        out[f"{name}_cathodic_energy"] = sum(p["cathodic"] for p in parts)
        out[f"{name}_eroded_volume"] = sum(p["net_volume"] for p in parts)
        out[f"{name}_eroded_mass"] = sum(p["net_mass"] for p in parts)
    return out

