"""Which contact pairs of the mechanics feed which contact of the circuit, and when the
circuit's switch counts as closed (how its contacts are arranged in the loop).

A circuit with one contact is fed by the mechanics' first two contact pairs (a [block]
scene's contact points, which all strike its one fixed contact; a [[fixed]] scene's first
two pairs, diagnostics item 7 says when that is not what the scene means). A circuit with
several contacts (a double-break bridge) has each fed by the electrical [[fixed]] contact
of its name (names compare ignoring case, as SPICE reads them). Contacts in series (the
bridge: ``arrangement = "series"`` on the circuit) are closed only while every one of them
touches: the switch's closed intervals are the intersection of the contacts' own.
"""

from __future__ import annotations

import numpy as np

from coupling.core.metrics import intersection, merge_intervals

LEGACY_POINTS = (0, 1)  # the one circuit contact's feeding pairs


def contact_feeds(mech, contacts) -> tuple[tuple[int, ...], ...]:
    """Per circuit contact (``circuit.ContactBlock``, in order), the indices of the contact
    pairs that feed it. ValueError (one line, naming both sides) when a circuit of several
    contacts and the scene's electrical [[fixed]] contacts do not match one to one."""
    if len(contacts) <= 1:
        return tuple(LEGACY_POINTS for _ in contacts)
    circuit_names = [c.name for c in contacts]
    fixed = list(getattr(mech, "fixed", ()) or ()) if mech is not None else []
    names = list(mech.fixed_names()) if fixed else []
    electrical = {names[i].lower(): i for i, fx in enumerate(fixed) if fx.electrical}
    said = (f"the circuit's contacts ({', '.join(circuit_names)}) and the electrical [[fixed]] contacts "
            f"({', '.join(names[i] for i in sorted(electrical.values())) or 'none'})")
    if not fixed:
        raise ValueError(f"{said} do not match: a circuit of several contacts needs a [[fixed]] contact of each "
                         "contact's name (this scene has one [block])")
    wanted = {c.name.lower() for c in contacts}
    missing = [c.name for c in contacts if c.name.lower() not in electrical]
    unfed = [names[i] for name, i in sorted(electrical.items(), key=lambda kv: kv[1]) if name not in wanted]
    if missing or unfed or len(electrical) != len([i for i, fx in enumerate(fixed) if fx.electrical]):
        parts = ([f"no electrical [[fixed]] contact named {', '.join(map(repr, missing))}"] if missing else []) + (
            [f"no circuit contact named {', '.join(map(repr, unfed))}"] if unfed else [])
        raise ValueError(f"{said} do not match: {'; '.join(parts) or 'two fixed contacts share a name'} "
                         "(each circuit contact is fed by the electrical fixed contact of its name, ignoring case)")
    return tuple((electrical[c.name.lower()],) for c in contacts)


def check_arrangement(mech, circuit) -> None:
    """A coupled scene's circuit against its mechanics, before anything runs (one-line
    ValueErrors): each circuit contact has its contact pairs (``contact_feeds``), and
    several circuit contacts are in series (a bridge: the one arrangement of several built)."""
    contacts = getattr(circuit, "contacts", ())
    contact_feeds(mech, contacts)
    if len(contacts) > 1 and not is_series(circuit):
        raise ValueError(f"the circuit's contacts ({', '.join(c.name for c in contacts)}) are not one chain in series "
                         "(XCONTACT_A a m, XCONTACT_B m b, the inner node joining nothing else but elements across a "
                         "contact): several circuit contacts are a double-break bridge for now (a changeover's are "
                         "not built yet)")


def is_series(circuit) -> bool:
    """True when the circuit's contacts are in series in one loop (a bridge)."""
    return getattr(circuit, "arrangement", None) == "series" and len(getattr(circuit, "contacts", ())) > 1


def switch_closed(scene, contact_columns) -> tuple[list[tuple[float, float]], bool]:
    """(closed intervals s, closed at the end) of the circuit's switch from the mechanics'
    contact intervals (``contact_columns``: tip, t_start, t_end, complete): every pair's
    union for a circuit of one contact (as always), the intersection of the contacts' own
    for contacts in series."""
    tips = np.asarray(contact_columns["tip"])
    starts, ends = contact_columns["t_start"], contact_columns["t_end"]
    still = ~np.asarray(contact_columns["complete"], dtype=bool)
    circuit = getattr(getattr(scene, "circuit", None), "circuit", None)
    if not is_series(circuit):
        return merge_intervals(zip(starts, ends)), bool(still.any())
    feeds = contact_feeds(scene.mech, circuit.contacts)
    closed, at_end = None, True
    for points in feeds:
        mine = np.isin(tips, points)
        own = merge_intervals(zip(starts[mine], ends[mine]))
        closed = own if closed is None else intersection(closed, own)
        at_end = at_end and bool((still & mine).any())
    return closed, at_end


def series_columns(waves: dict, contacts) -> dict:
    """The whole bridge's columns from its contacts' (SI): contact_voltage, the sum of
    theirs (V across the bridge); contact_resistance, the sum (ohm; inf while one is open);
    contact_conductance, its inverse (S); contact_current, the metallic current through
    the whole bridge, the smaller in magnitude of the contacts' (A: the current that flows
    through metal all the way); arc_current, the larger of the arcs' (A: the bridge's arc
    current while either burns)."""
    v = sum(waves[f"contact_voltage{c.suffix}"] for c in contacts)
    r = sum(waves[f"contact_resistance{c.suffix}"] for c in contacts)
    with np.errstate(divide="ignore"):
        g = np.where(np.isfinite(r) & (r > 0.0), 1.0 / np.where(np.isfinite(r) & (r > 0.0), r, 1.0), 0.0)
    metal = np.array([waves[f"contact_current{c.suffix}"] for c in contacts])
    arcs = np.array([waves[f"arc_current{c.suffix}"] for c in contacts])
    pick = np.argmin(np.abs(metal), axis=0)
    arc_pick = np.argmax(np.abs(arcs), axis=0)
    cols = np.arange(metal.shape[1])
    return {"contact_voltage": v, "contact_current": metal[pick, cols], "contact_resistance": r,
            "contact_conductance": g, "arc_current": arcs[arc_pick, cols]}
