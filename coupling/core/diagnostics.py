"""Warnings about physically doubtful states of a run (``warnings`` in summary.json).

Each is one line that says what was seen, when, and what to add to the scene. Checks
(documented in docs/coupling.md, "Warnings"):

1. Field across the open gap beyond air breakdown: |V| > V_bd(d) at an open-contact
   sample with no arc burning, where V_bd is Paschen's law for air at 1 atm,
   V = B p d / (ln(A p d) - ln(ln(1 + 1/gamma_se))) with A = 15 /(cm Torr),
   B = 365 V/(cm Torr), gamma_se = 0.01 (textbook constants for air), on the branch
   above its minimum, and the measured minimum of air, 327 V, for smaller gaps (the
   micrometre gaps of a bounce). Large gaps tend to ~3 MV/m (35 kV at 1 cm).
2. Currents beyond what the circuit's own source and impedances allow: a template
   circuit's source E behind R_source + R_wiring can drive at most E / (R_source +
   R_wiring) (its short-circuit current); a contact or arc current above it comes from a
   parasitic capacitance discharging through the contact or the arc's small incremental
   resistance.
3. More arc ignitions and extinctions than ``[metrics] arc_toggle_limit`` (a showering arc).
4. A contact law used outside the data it was fitted on (normal force or current range),
   or outside a material law's stated validity range.
5. Hertz's law stretched: a contact point's deepest penetration y puts the paraboloid
   y / (4 R) off the sphere at the contact's edge by more than 1 % (y > 0.04 R; beyond 5 %
   the run is unsound, coupling.core.soundness).
6. The arc model on without a breakdown voltage, when an open gap's voltage passes air
   breakdown: that gap would re-ignite (item 1 names the setting to add).
7. Fixed contacts ([[fixed]]) a circuit of one unnamed contact does not tell apart: its one
   contact is fed by the mechanics' first two contact pairs in parallel (conductances
   summed, closed while either touches), whatever their fixed contacts are. Said whenever
   that is not one electrical fixed contact; a circuit of several contacts (the bridge and
   changeover templates, a netlist naming each) or one named contact has each fed by its
   own fixed contact and no line.
8. A clamp's travel given by a linear table whose points ring the blade: each point is a
   jump of the clamp's velocity dv, which sets the blade's first mode ringing with a free-
   end amplitude of about 1.566 dv / omega_1 (a clamped-free beam's first-mode participation
   at its tip, Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1); said when
   that exceeds RINGING_FRACTION of the contact gap, with interpolation = "pchip" as the
   remedy when the travel is meant to be smooth.
9. The coil-armature interface's residual above solver.energy_tolerance of the energy into
   the coil (``interface_audit_warning``).
10. coil.on_time or coil.off_time at or after [solver] t_end (``coil_time_warnings``).
11. A relay's armature not seated at the pole when its drive ends (``pole_seat_warning``).
12. A relay's armature at the pole with its contact never made (``no_make_warning``).
13. A DC break whose arc the source holds above min_current at the run's largest gap: its
    still-burning arc is not a matter of t_end (``uncleared_break_advice``).
"""

from __future__ import annotations

import math

import numpy as np

from coupling.core.metrics import ARC_BURNING_CURRENT, arc_toggles
from coupling.core.soundness import (
    COIL_UNSOUND_FACTOR, HERTZ_UNSOUND_ERROR, HERTZ_WARN_ERROR, coil_energy_line, hertz_gap_error, hertz_validity_line,
)

PASCHEN_A = 15.0  # 1/(cm Torr), air
PASCHEN_B = 365.0  # V/(cm Torr), air
PASCHEN_GAMMA = 0.01  # secondary emission coefficient
PASCHEN_MINIMUM_V = 327.0  # V: measured minimum breakdown voltage of air
ATMOSPHERE_TORR = 760.0


def air_breakdown_voltage(gap_m, pressure_torr: float = ATMOSPHERE_TORR):
    """V: breakdown voltage of an air gap of d metres (Paschen, right branch; 327 V floor).

    Vectorized; d <= 0 gives the floor (a closing/closed contact is checked elsewhere)."""
    d_cm = np.asarray(gap_m, dtype=float) * 100.0
    pd_ = np.maximum(pressure_torr * d_cm, 1e-30)
    denom = np.log(PASCHEN_A * pd_) - math.log(math.log(1.0 + 1.0 / PASCHEN_GAMMA))
    with np.errstate(divide="ignore", invalid="ignore"):
        paschen = np.where(denom > 1.0, PASCHEN_B * pd_ / np.where(denom > 1.0, denom, 1.0), 0.0)
    return np.maximum(paschen, PASCHEN_MINIMUM_V)


NO_ARC_ADVICE = ("add the arc model ([circuit] arc = true, with breakdown_voltage), a snubber or the "
                 "contact capacitance")
# the arc model is on, but an extinguished gap never re-ignites without a breakdown voltage
NO_BREAKDOWN_ADVICE = ("the arc model is on without [circuit.arc] breakdown_voltage, so its gap never "
                       "re-ignites and the circuit alone limits the voltage: set breakdown_voltage (air: "
                       "~330 V across micrometre gaps, Paschen's minimum; with breakdown_gradient ~3e6 V/m "
                       "for mm gaps), or add a snubber")


def breakdown_warning(t, v, gap, open_mask, advice: str = NO_ARC_ADVICE) -> str | None:
    """The worst open-gap sample whose |V| exceeds air breakdown, as a warning line ending
    with what to add (``advice``)."""
    t, v, gap = (np.asarray(x, float) for x in (t, v, gap))
    sel = open_mask & np.isfinite(gap) & (gap > 0.0)
    if not sel.any():
        return None
    ratio = np.where(sel, np.abs(v) / air_breakdown_voltage(gap), 0.0)
    k = int(np.argmax(ratio))
    if ratio[k] <= 1.0:
        return None
    n = int(np.count_nonzero(ratio > 1.0))
    return (f"contact voltage {abs(v[k]):.4g} V across a {gap[k] * 1e6:.4g} um gap at t = {t[k] * 1e3:.6g} ms "
            f"exceeds air breakdown (~{float(air_breakdown_voltage(gap[k])):.4g} V; {n} sample(s)): the gap would "
            f"break down; {advice}")


def hertz_warnings(mres) -> list[str]:
    """A line per contact point whose deepest penetration stretches Hertz's law past
    HERTZ_WARN_ERROR (and not past HERTZ_UNSOUND_ERROR, which makes the run unsound)."""
    return [hertz_validity_line(y, r, name) for name, y, r in mres.contact_depths
            if HERTZ_WARN_ERROR < hertz_gap_error(y, r) <= HERTZ_UNSOUND_ERROR]


def _relay_energy_share(result, key: str) -> tuple[float, float] | None:
    """(relay.energy[key], solver.energy_tolerance): a relative residual of the relay's energy
    audit and the bound it is judged against; None without a relay or that key."""
    relay = result.relay if result.mechanics is not None else None
    energy = relay.get("energy") if relay else None
    rel = energy.get(key) if energy else None
    if rel is None:
        return None
    return rel, result.mechanics.model.scene.solver.energy_tolerance


def coil_audit_warning(result) -> str | None:
    """One line where the coil's energy audit is above solver.energy_tolerance (and not past
    COIL_UNSOUND_FACTOR times it, which makes the run unsound): the coil's side is then
    approximate to about that fraction."""
    share = _relay_energy_share(result, "relative_residual")
    if share is None:
        return None
    rel, tolerance = share
    if tolerance < rel <= COIL_UNSOUND_FACTOR * tolerance:
        return coil_energy_line(rel, tolerance, tolerance)
    return None


INTERFACE_FIX = ("the macro steps are too long for the coil's flux: lower [coupling] coil_time_scale_fraction "
                 "(e.g. 0.05) or cap [coupling] max_macro_step (e.g. 1e-4 s)")


def interface_audit_warning(result) -> str | None:
    """One line where the coil-armature interface's residual (coupling.core.relay: the magnet's
    work as the circuit sees it less the work the mechanics received from the drive) is above
    solver.energy_tolerance of the energy into the coil: the drive the mechanics got was
    extrapolated too far from the circuit's flux, or held through a ringing (the default relay
    at 10 times its coil's time-scale fraction: 5.5e-3; the shipped relays at their own steps,
    and the default one released through each suppression: at most 1.5e-4, docs/coupling.md
    "The relay"; it is a net energy, a lower bound on the exchange's error). A warning only: the
    mechanics' and the coil's own audits still balance."""
    share = _relay_energy_share(result, "interface_relative_residual")
    if share is None:
        return None
    rel, tolerance = share
    if rel <= tolerance:
        return None
    return (f"coil-armature interface: the magnet's work and the work the armature received from its drive "
            f"differ by {rel:.3g} of the energy into the coil, above {tolerance:g} (solver.energy_tolerance); "
            f"{INTERFACE_FIX}")


def release_warning(result) -> str | None:
    """One line where the coil was switched off within the run after the contact had made,
    and the run ended before the contact broke: ``release_time`` is then missing, not a
    result (a diode's slow release outlasts the default relay's 3 ms after its switch-off)."""
    relay = result.relay  # (None without a coil: nothing of the circuit is imported then)
    if not relay or relay.get("operate_time") is None or relay.get("release_time") is not None:
        return None
    drive = result.coil_drive
    if drive is None:
        return None
    off, end = drive.off_time, result.scene.t_end
    if off is None or not off < end:
        return None
    left = relay.get("drop_out_current") is not None
    where = "the armature had left the pole" if left else "the armature was still at the pole"
    return (f"relay: the contact was still closed when the run ended, {(end - off) * 1e3:.3g} ms after the coil "
            f"was switched off (coil.off_time = {off * 1e3:.4g} ms; {where}): release_time is missing, not "
            f"measured; run longer ([solver] t_end)")


def _ms(x: float) -> str:
    return f"{x * 1e3:.4g} ms"


def _mm(x: float) -> str:
    return f"{x * 1e6:.3g} um" if abs(x) < 1e-4 else f"{x * 1e3:.4g} mm"


def coil_time_warnings(result) -> list[str]:
    """Item 10: a line for coil.on_time, and one for coil.off_time, at or beyond the run's end:
    that switching is not simulated. Warnings, not errors: a coil kept off through the run
    (on_time beyond t_end, on_time's default being a step at 0) is how a de-energized relay is
    shaken or timed, and a coil left on (off_time beyond t_end) is the operate part alone;
    an error would also stop a sweep over t_end at the points it crosses."""
    if result.relay is None:  # first: a scene without a coil imports nothing of the circuit
        return []
    drive = result.coil_drive
    if drive is None:
        return []
    end = result.scene.t_end
    if drive.on_time >= end:
        return [f"relay: coil.on_time = {_ms(drive.on_time)} is at or after the run's end ([solver] t_end = "
                f"{_ms(end)}): the coil is never switched on and nothing of the relay operates; if it is meant "
                "to, set coil.on_time before t_end (0: a step at the start) or run longer"]
    if drive.off_time is not None and drive.off_time >= end:
        return [f"relay: coil.off_time = {_ms(drive.off_time)} is at or after the run's end ([solver] t_end = "
                f"{_ms(end)}): the coil is never switched off, the release is not simulated and release_time "
                "and drop_out_current stay null; to see it, set [solver] t_end a few ms beyond coil.off_time "
                "(or omit coil.off_time: the coil then stays on)"]
    return []


def _drive_window(result):
    """(on, end, end's name) s: the coil on from its driver's on_time to its off_time or the
    run's last sample, whichever comes first; None without a template coil's drive, a
    waveform, or when the coil is never on within the run."""
    drive = result.coil_drive
    w = result.waveform_columns
    if drive is None or w is None or not len(w["time"]) or "armature_position" not in w:
        return None
    last = float(w["time"][-1])
    off = drive.off_time
    end, name = (off, "coil.off_time") if off is not None and off < last else (last, "the run's end")
    if not drive.on_time < end:
        return None
    return drive.on_time, end, name


def _pole_state(events: list[dict], when: float) -> tuple[bool, float | None]:
    """(seated at ``when``, the last time the armature left the pole before it or None): the
    mechanics' pole stop events, an arrival or a seat putting it on, a departure taking it off."""
    pole = sorted((float(e["time"]), e["kind"]) for e in events
                  if e.get("stop") == "pole" and e["kind"] in ("armature_stop_start", "armature_seat",
                                                              "armature_stop_end") and float(e["time"]) <= when)
    left = [t for t, kind in pole if kind == "armature_stop_end"]
    return bool(pole) and pole[-1][1] != "armature_stop_end", (left[-1] if left else None)


POLE_ADVICE = ("give more ampere-turns (coil.voltage, coil.turns), a weaker return spring (armature.spring_preload, "
               "armature.spring_rate) or less overtravel (a larger [initial] height or armature.card_free_travel), "
               "or keep the coil on longer (coil.off_time) if its current was still rising")


def pole_seat_warning(result) -> str | None:
    """Item 11: the line for a relay whose coil is on while its armature is not seated at the
    pole when the drive ends (coil.off_time, or the run's end with the coil on): it never got
    there, or left it while the coil was on and its contact is closed then (held off by the
    contact spring; without a closed contact it is rebounding off its stop, no line). The magnet's pull then does not overcome the
    return spring and the contact spring's load at the pole, and the contact force is the
    magnet's balance against the contact spring (it follows the coil current), not the
    overtravel's. Shortfall (m of the pole face's travel) and the coil current against its
    steady coil.voltage / coil.resistance say how far it was."""
    if result.relay is None or result.mechanics is None:
        return None
    window = _drive_window(result)
    if window is None:
        return None
    on, end, name = window
    seated, left = _pole_state(result.mechanics.events, end)
    arrived = result.relay.get("armature_arrival") if result.relay else None
    reached = arrived is not None and arrived <= end
    # Off the pole after reaching it is a hold-off only while the contact spring pushes back
    # (the contact closed): an armature without one in flight at `end` is rebounding off its stop.
    if seated or (reached and not any(a <= end <= b for a, b in result.closed_intervals)):
        return None
    from coupling.core.device import device

    spec = device(result.scene.raw)
    w = result.waveform_columns
    t = np.asarray(w["time"], float)
    pole = spec.lever * float(result.scene.mech.armature.travel)  # m: the pole face's travel to the pole
    sel = (t >= on) & (t <= end)
    nearest = pole - float(np.max(np.asarray(w["armature_position"], float)[sel])) if sel.any() else pole
    at_end = pole - float(np.interp(end, t, w["armature_position"]))
    drive = result.coil_drive
    i_end = abs(float(np.interp(end, t, w["coil_current"])))
    steady = abs(drive.voltage) / float(spec.resistance)
    current = f"the coil current {i_end * 1e3:.3g} mA of its steady {steady * 1e3:.3g} mA (coil.voltage / resistance)"
    if not reached:
        what = (f"the armature never reached the pole while the coil was on ({_ms(on)} to {_ms(end)}, {name}): "
                f"it came within {_mm(max(nearest, 0.0))} of it ({current} at {_ms(end)})")
    else:
        when = f"at {_ms(left)}" if left is not None and left >= on else "before the coil was switched on"
        what = (f"the armature left the pole {when} while the coil was on and was not back at {_ms(end)} ({name}; "
                f"{_mm(max(at_end, 0.0))} short of it, {current})")
    makes = [op["make"]["time"] for op in result.operations if "make" in op and op["make"]["time"] <= end]
    force = ("the contact force is then the magnet's balance against the contact spring (it follows the coil "
             "current), not the overtravel's" if makes else
             "the contact did not make" if result.has_contact else "the armature carries no contact")
    return (f"relay: {what}: the magnet's pull does not hold the armature at the pole against the return "
            f"spring and the contact spring; {force}, and the operate and release figures are not those of a "
            f"seated relay; {POLE_ADVICE}")


def no_make_warning(result) -> str | None:
    """Item 12: the line for a relay whose armature reached the pole while its contact never
    made (a contact open at the start that stayed open): the card's travel at the pole
    (armature.card_lever x travel - card_free_travel, m at the card) against the contact gap
    ([initial] height) and the gap left with the armature at the pole."""
    relay = result.relay
    arrived = relay.get("armature_arrival") if relay else None
    if arrived is None or result.mechanics is None or not result.has_contact:
        return None
    bounce = result.bounce
    if bounce.get("first_make") is not None or bounce.get("initial_state") != "open":
        return None
    mech = result.scene.mech
    arm, gap = mech.armature, float(mech.initial.height)
    w = result.waveform_columns
    left = (f", and the contact was still {_mm(float(np.interp(arrived, w['time'], w['gap'])))} open with the "
            "armature there" if w is not None and "gap" in w else "")
    if arm.card_position is None:
        card = "the armature has no card (armature.card_position) to push the contact spring"
        fix = "give the armature a card (armature.card_position, card_lever)"
    else:
        travel = arm.card_lever * arm.travel - arm.card_free_travel
        card = (f"the card's travel at the pole is {_mm(travel)} (armature.card_lever x travel - card_free_travel) "
                f"against a contact gap of {_mm(gap)} ([initial] height)")
        fix = ("check [initial] height (a gap in mm written as m?) and the card's travel (armature.card_lever, "
               "travel, card_free_travel): the card must push the contact spring across the gap before the pole")
    return (f"relay: the armature reached the pole at {_ms(arrived)} but the contact never made: {card}{left}; "
            f"{fix}")


def arc_floor(arc, gap: float, current: float) -> float:
    """V: the arc model's burning voltage at a gap (m) and current (A) (circuit.arc.ArcModel,
    docs/circuit.md section 7): U_min + E_col d + R_arc I, or with the Ayrton characteristic
    U_min + E_col d + (C + D d) / I."""
    u = arc.min_voltage + arc.column_gradient * gap
    if arc.characteristic == "ayrton":
        return u + (arc.ayrton_c + arc.ayrton_d * gap) / current
    return u + arc.resistance * current


def held_arc_current(arc, gap: float, source: float, loop: float) -> float | None:
    """A: the current a DC source (V) behind a resistance (ohm) holds in the arc at a fixed gap
    (m), its steady operating point on the arc model's characteristic; None where there is
    none (the source cannot hold an arc there)."""
    a = arc.min_voltage + arc.column_gradient * gap
    if arc.characteristic == "ayrton":  # source - loop I = a + b / I: the larger root is the stable one
        b = arc.ayrton_c + arc.ayrton_d * gap
        disc = (source - a) ** 2 - 4.0 * loop * b
        if source <= a or disc < 0.0 or loop <= 0.0:
            return None
        return ((source - a) + math.sqrt(disc)) / (2.0 * loop)
    return (source - a) / (loop + arc.resistance) if source > a else None


def uncleared_break_advice(result) -> str | None:
    """Item 13: for a coupled run's one template contact with a DC source and a resistive (or
    resistive-inductive) load, the advice that no t_end clears its break when at the largest
    gap of the run the source still holds at least the arc's minimum current I_min through
    the arc (``held_arc_current``): its voltage there (``arc_floor``) is below the source's.
    None otherwise (the arc would go out: run longer is the advice)."""
    scene = result.scene
    circ = getattr(scene.circuit, "circuit", None)
    arc = getattr(circ, "arc", None)
    w = result.waveform_columns
    if (arc is None or result.mechanics is None or w is None or "gap" not in w
            or len(getattr(circ, "contacts", ())) != 1):
        return None
    source, load, wiring = getattr(circ, "source", None), getattr(circ, "load", None), getattr(circ, "wiring", None)
    if (source is None or hasattr(source, "compliance_voltage") or wiring is None
            or getattr(source, "frequency", 0.0) > 0.0  # (an AC arc goes out at a current zero)
            or not hasattr(load, "load_resistance") or hasattr(load, "load_capacitance")):
        return None
    rest = float(scene.mech.initial.height)
    gap = max(float(np.nanmax(w["gap"])), rest)  # the blade may swing past its rest gap at a release
    e = abs(float(source.voltage))
    loop = float(source.source_resistance) + float(wiring.wiring_resistance) + float(load.load_resistance)
    held = held_arc_current(arc, gap, e, loop)
    if held is None or held < arc.min_current:
        return None
    law = ("min_voltage + column_gradient d + (ayrton_c + ayrton_d d) / I" if arc.characteristic == "ayrton"
           else "min_voltage + column_gradient d + resistance I")
    return (f"this break cannot clear in this gap, whatever t_end: at the run's largest gap, d = {_mm(gap)} "
            f"([initial] height {_mm(rest)}), the arc's voltage ({law}, circuit.arc) is "
            f"{arc_floor(arc, gap, held):.4g} V, below the {e:.4g} V source, which holds I = {held:.3g} A through "
            f"it behind {loop:.4g} ohm, "
            f"above its min_current {arc.min_current:.3g} A; a DC break needs an arc voltage above the source "
            "at the full gap: a larger gap ([initial] height), a higher arc voltage (circuit.arc column_gradient, "
            "as a blow-out magnet or arc splitters give, which the model does not follow), a lower source "
            "voltage or a load that holds the current below min_current")


def overcurrent_warning(t, currents: dict, limit: float, source: str) -> str | None:
    """The largest |current| among ``currents`` (name -> array, A) if above ``limit`` (A)."""
    worst = None
    for name, i in currents.items():
        if i is None:
            continue
        i = np.abs(np.asarray(i, float))
        if not len(i) or not np.isfinite(i).any():
            continue
        k = int(np.nanargmax(i))
        if i[k] > limit and (worst is None or i[k] > worst[1]):
            worst = (name, float(i[k]), float(t[k]))
    if worst is None:
        return None
    name, peak, when = worst
    return (f"{name} peaks at {peak:.4g} A at t = {when * 1e3:.6g} ms, above the {limit:.4g} A {source}: "
            "a capacitance discharging through the contact or the arc; add a snubber resistor, "
            "the real contact capacitance, or wiring resistance/inductance")


def toggle_warning(toggles: int, limit: int) -> str | None:
    if toggles <= limit:
        return None
    return (f"the arc switched on/off {toggles} times (more than [metrics] arc_toggle_limit = {limit}): "
            "a re-igniting (showering) arc; add a snubber (RC across the contact), a flyback diode, "
            "or the contact capacitance")


def range_warnings(what: str, used: tuple[float, float] | None, valid: tuple[float, float] | None,
                   unit: str, note: str = "") -> list[str]:
    """A line when a quantity used over ``used`` = (min, max) exceeds the ``valid`` range's top.

    Only the top: every make and break passes through F_n = 0 and I = 0, below any range."""
    if used is None or valid is None:
        return []
    lo, hi = valid
    umin, umax = used
    out = []
    if umax > hi * (1.0 + 1e-9):
        out.append(f"{what} used up to {umax:.4g} {unit}, above the {lo:.4g}-{hi:.4g} {unit} it is valid for "
                   f"(extrapolated{note})")
    return out


def _law_ranges(scene):
    """(name, force range N, current range A, note) of the contact-resistance law, or None."""
    trib = scene.tribology
    if trib is None:
        return None
    law = trib.laws.resistance_law
    validity = getattr(law, "validity", None)
    if validity is not None:  # a material law (coupling.laws.materials)
        return (f"contact-resistance law {law.name}", validity.get("force_N"), validity.get("current_A"),
                validity.get("note", ""))
    if trib.fit is not None:
        dr = trib.fit.data_range
        return (f"contact-resistance law ({trib.source})", tuple(dr.load_range_N), tuple(dr.current_range_A),
                f" with exponent m = {law.load_exponent:.3g}")
    return None


def fit_warnings(scene) -> list[str]:
    """The rows the scene's tribometer fit left out as outliers (a fit on the fly from
    ``data =`` reports them nowhere else)."""
    trib = scene.tribology
    if trib is None or trib.fit is None or not (trib.fit.friction.n_outliers or trib.fit.resistance.n_outliers):
        return []
    from coupling.laws.tribology.fits import outlier_lines

    return [f"contact laws from {trib.source}: {line}" for line in outlier_lines(trib.fit)]


def pairs_warning(scene) -> str | None:
    """Item 7: the line for a coupled scene whose [[fixed]] contacts the circuit's one contact
    does not stand for (more than one electrical fixed contact, a stop feeding it, an
    electrical one left out), None otherwise (a [block] scene: its contact points all strike
    the one fixed contact, which the circuit's contact is; a circuit of several contacts,
    a bridge, a changeover, or one named contact: each is fed by the fixed contact of its
    name, which the scene checked)."""
    mech = scene.mech
    contacts = getattr(getattr(scene.circuit, "circuit", None), "contacts", ())
    if mech is None or mech.bar is None or not mech.fixed or len(contacts) != 1 or contacts[0].name:
        return None
    names = mech.fixed_names()
    pairs = [f"{i} ({fx.point} on {name})" for i, (fx, name) in enumerate(zip(mech.fixed, names))]
    fed = set(range(min(len(mech.fixed), 2)))  # the ContactLink's points (0, 1)
    electrical = {i for i, fx in enumerate(mech.fixed) if fx.electrical}
    if len(electrical) <= 1 and fed == electrical:
        return None
    line = (f"[[fixed]]: the circuit's contact {contacts[0].label} stands for contact pair"
            f"{'s' if len(fed) > 1 else ''} {' and '.join(pairs[i] for i in sorted(fed))} in parallel, "
            "as one circuit contact (their conductances summed, closed while either touches, the arc's gap "
            "the nearest of all pairs)")
    stops = [names[i] for i in sorted(fed - electrical)]
    if stops:
        line += f", the stop {', '.join(map(repr, stops))} (electrical = false) among them"
    left = [pairs[i] for i in sorted(electrical - fed)]
    if left:
        line += f"; the electrical pair {', '.join(left)} is not in the circuit"
    return (line + "; to give each fixed contact its own circuit contact use circuit.template = \"bridge\" (two "
            "in series), \"changeover\" (NO and NC) or a netlist naming each contact, XCONTACT_<name>: as it is, "
            "its waveforms, bounce metrics and operations are those of that one parallel contact")


RINGING_FRACTION = 0.02  # of the contact gap: item 8
CANTILEVER_TIP_PARTICIPATION = 1.566  # first mode of a clamped-free beam, base excitation, at the free end


def table_ringing_warning(mres) -> str | None:
    """Item 8: the line for a linear clamp travel whose velocity jumps ring the blade's first
    mode beyond RINGING_FRACTION of the contact gap (mres: the mechanics' result), else None."""
    from mech.mechanism import base_velocity_jumps

    scene = mres.model.scene
    bm = scene.mount.base_motion
    freqs = np.asarray(mres.model.basis.frequencies, dtype=float)
    if bm is None or bm["interpolation"] != "linear" or len(bm["time"]) < 3 or not len(freqs):
        return None
    jumps = base_velocity_jumps(scene)
    gap = float(scene.initial.height)
    if not jumps or not gap > 0.0:
        return None
    t_jump, dv = max(jumps, key=lambda j: float(np.linalg.norm(j[1])))
    omega = 2.0 * math.pi * float(freqs.min())
    amplitude = CANTILEVER_TIP_PARTICIPATION * float(np.linalg.norm(dv)) / omega
    if amplitude <= RINGING_FRACTION * gap:
        return None
    return (f"mount.base_motion is linear between its {len(bm['time'])} points: each is a jump of the clamp's "
            f"velocity (up to {float(np.linalg.norm(dv)):.3g} m/s, at {t_jump:.6g} s) that rings the blade's first "
            f"mode ({float(freqs.min()):.4g} Hz) by about {amplitude:.3g} m at its free end, "
            f"{amplitude / gap:.2g} of the contact gap; if the travel is meant to be smooth, set "
            "mount.base_motion.interpolation = \"pchip\" (or give many more points)")


def run_warnings(result) -> list[str]:
    """All warnings for a CoupledResult."""
    scene = result.scene
    out = fit_warnings(scene)
    line = pairs_warning(scene)
    if line:
        out.append(line)
    if result.mechanics is not None:
        out += hertz_warnings(result.mechanics)
        line = table_ringing_warning(result.mechanics)
        if line:
            out.append(line)
        line = coil_audit_warning(result)
        if line:
            out.append(line)
        line = interface_audit_warning(result)
        if line:
            out.append(line)
        line = release_warning(result)
        if line:
            out.append(line)
        if result.relay is not None:  # (without a coil nothing of the circuit is imported)
            out += coil_time_warnings(result)
            for check in (pole_seat_warning, no_make_warning):
                line = check(result)
                if line:
                    out.append(line)
    w = result.waveform_columns
    if w is not None and len(w["time"]) and "contact_voltage" in w:  # (an actuator's coil drive has no contact)
        t = w["time"]
        v = w["contact_voltage"]
        i_arc = w["arc_current"] if "arc_current" in w else np.zeros_like(t)
        burning = np.abs(i_arc) > ARC_BURNING_CURRENT
        gap = _gap_series(result, t)
        if gap is not None:
            open_mask = (w["contact_conductance"] <= 0.0) & ~burning
            arc = getattr(getattr(scene.circuit, "circuit", None), "arc", None)
            advice = NO_BREAKDOWN_ADVICE if arc is not None and arc.breakdown_voltage is None else NO_ARC_ADVICE
            line = breakdown_warning(t, v, gap, open_mask, advice)
            if line:
                out.append(line)
        limit = _current_limit(scene)
        if limit is not None:
            line = overcurrent_warning(t, {"contact current": w["contact_current"],
                                           "arc current": i_arc}, *limit)
            if line:
                out.append(line)
        stats = result.stats.get("circuit", {}) if isinstance(result.stats, dict) else {}
        toggles = int(stats.get("arc_switches", arc_toggles(i_arc)))
        settings = scene.metrics
        line = toggle_warning(toggles, settings.arc_toggle_limit if settings is not None else 50)
        if line:
            out.append(line)
        out += incomplete_break_warnings(result.operations, uncleared_break_advice(result))
        ranges = _law_ranges(scene)
        if ranges is not None and "normal_force" in w:
            name, force_range, current_range, note = ranges
            f = w["normal_force"]
            closed = f > 0.0
            if closed.any():
                out += range_warnings(name + ": normal force", (float(f[closed].min()), float(f[closed].max())),
                                      force_range, "N", note)
                current = np.abs(w["load_current"] if np.isfinite(w["load_current"]).all()
                                 else w["contact_current"])[closed]
                out += [line + "; the current factor is held at its edge value" for line in range_warnings(
                    name + ": current", (float(current.min()), float(current.max())), current_range, "A")]
    return out


def incomplete_break_warnings(operations: list[dict], cannot_clear: str | None = None) -> list[str]:
    """One line per break whose arc still burned when the run ended: its arc duration,
    energy and peak voltage are those of a truncated arc. The advice is to run longer,
    unless ``cannot_clear`` (``uncleared_break_advice``) says no run length would do."""
    out = []
    for op in operations:
        brk = op.get("break")
        if brk is None or brk.get("complete", True):
            continue
        if cannot_clear is not None:
            advice = cannot_clear
        else:
            more = brk.get("more_time_needed")
            need = (f"about {more * 1e3:.3g} ms more at the rate its current falls" if more is not None else
                    "its current was not falling, so how much longer cannot be estimated")
            advice = f"run longer ([solver] t_end): {need}"
        out.append(f"the break at t = {brk['time'] * 1e3:.4g} ms: its arc still burned when the run ended (after "
                   f"{(brk['arc_duration'] or 0.0) * 1e3:.3g} ms): arc duration, energy and peak voltage are "
                   f"truncated; {advice}")
    return out


def _gap_series(result, t):
    """m: the gap at the waveform's times (coupled: the mechanics' gap column; prescribed
    schedule: its gap when it has an opening speed), or None when unknown."""
    w = result.waveform_columns
    if "gap" in w:
        return w["gap"]
    spec = result.scene.circuit
    schedule = getattr(spec, "schedule", None) if spec is not None else None
    if schedule is not None and getattr(schedule, "opening_speed", None) is not None:
        return np.array([schedule.gap(s) for s in t])
    return None


def _current_limit(scene):
    """(A, description) the template circuit's source can drive, or None (netlist, zero resistance)."""
    spec = scene.circuit
    circ = getattr(spec, "circuit", None)
    source, wiring = getattr(circ, "source", None), getattr(circ, "wiring", None)
    if source is None or wiring is None:
        return None
    if hasattr(source, "compliance_voltage"):  # a constant-current supply: I_set, plus at a make
        rw = float(wiring.wiring_resistance)            # its output capacitor discharging into the wiring
        if rw <= 0.0:
            return None
        v = float(source.compliance_voltage)
        return (float(source.current) + v / rw,
                f"the {float(source.current):.4g} A supply plus its output capacitor at {v:.4g} V through "
                f"the {rw:.4g} ohm wiring")
    r = float(source.source_resistance) + float(wiring.wiring_resistance)
    if r <= 0.0:
        return None
    e = abs(float(getattr(source, "amplitude", source.voltage)))  # (an AC source's peak)
    return e / r, f"the {e:.4g} V source can drive through its own {r:.4g} ohm (source + wiring)"
