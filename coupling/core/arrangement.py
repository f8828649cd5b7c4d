"""Which contact pairs of the mechanics feed which contact of the circuit, and when the
circuit's switch counts as closed (how its contacts are arranged in the loop).

A circuit with one unnamed contact is fed by the mechanics' first two contact pairs (a [block]
scene's contact points, which all strike its one fixed contact; a [[fixed]] scene's first
two pairs, diagnostics item 7 says when that is not what the scene means). A circuit with
several contacts (a double-break bridge, a changeover), or one named contact in a
[[fixed]] scene, has each fed by the electrical
[[fixed]] contact of its name (names compare ignoring case, as SPICE reads them). The
topology decides what "closed" means:
- contacts in series in one loop (the bridge, ``arrangement = "series"``; a netlist whose
  contacts form one chain): the switch is closed only while every one of them touches, its
  closed intervals the intersection of the contacts' own;
- otherwise the contacts are independent (a changeover's NO and NC, each in its own
  branch; a netlist's contacts not in one chain): each is closed while its own points
  touch. The switch's unsuffixed results (columns contact_voltage ..., ``bounce``,
  ``operations``, the relay's times) are then the first contact's (the changeover
  template's NO), and every contact has its own (``contact_results``).
A changeover (two independent contacts named NO and NC) also gets its transfer times and
break-before-make (``changeover_metrics``).
"""

from __future__ import annotations

import numpy as np

from coupling.core.metrics import ARC_BURNING_CURRENT, intersection, merge_intervals

LEGACY_POINTS = (0, 1)  # the one circuit contact's feeding pairs


def contact_feeds(mech, contacts) -> tuple[tuple[int, ...], ...]:
    """Per circuit contact (``circuit.ContactBlock``, in order), the indices of the contact
    pairs that feed it: one unnamed contact (or one named contact of a [block] scene) the
    first two pairs; several contacts, or one named contact of a [[fixed]] scene (a netlist's
    XCONTACT_NO), each the electrical fixed contact of its name. ValueError (one line, naming
    both sides) when those and the scene's electrical [[fixed]] contacts do not match one to
    one (a netlist that does not place a declared contact)."""
    fixed = list(getattr(mech, "fixed", ()) or ()) if mech is not None else []
    if len(contacts) == 0 or (len(contacts) == 1 and not (contacts[0].name and fixed)):
        return tuple(LEGACY_POINTS for _ in contacts)
    circuit_names = [c.name for c in contacts]
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
    ValueErrors): each circuit contact has its contact pairs and each electrical fixed
    contact its circuit contact (``contact_feeds``). Several contacts in series are a bridge,
    any other arrangement independent contacts (module docstring)."""
    contact_feeds(mech, getattr(circuit, "contacts", ()))


def is_series(circuit) -> bool:
    """True when the circuit's contacts are in series in one loop (a bridge)."""
    return getattr(circuit, "arrangement", None) == "series" and len(getattr(circuit, "contacts", ())) > 1


def is_independent(circuit) -> bool:
    """True when the circuit has several contacts not in series (a changeover's, each in its
    own branch): each is closed while it touches."""
    return len(getattr(circuit, "contacts", ())) > 1 and not is_series(circuit)


def changeover_names(circuit) -> tuple[str, str] | None:
    """(NO's name, NC's name) as the circuit names them, for a changeover: two independent
    contacts named NO and NC (ignoring case; the template's, or a netlist's XCONTACT_NO and
    XCONTACT_NC); None otherwise."""
    contacts = getattr(circuit, "contacts", ())
    if len(contacts) != 2 or not is_independent(circuit):
        return None
    names = {c.name.lower(): c.name for c in contacts}
    return (names["no"], names["nc"]) if set(names) == {"no", "nc"} else None


def switch_closed(scene, contact_columns) -> tuple[list[tuple[float, float]], bool]:
    """(closed intervals s, closed at the end) of the circuit's switch from the mechanics'
    contact intervals (``contact_columns``: tip, t_start, t_end, complete): every pair's
    union for a circuit of one unnamed contact (as always), the intersection of the contacts'
    own for contacts in series, the first contact's own for independent contacts (and for
    one named contact fed by its own fixed contact)."""
    tips = np.asarray(contact_columns["tip"])
    starts, ends = contact_columns["t_start"], contact_columns["t_end"]
    still = ~np.asarray(contact_columns["complete"], dtype=bool)
    circuit = getattr(getattr(scene, "circuit", None), "circuit", None)
    contacts = getattr(circuit, "contacts", ())
    feeds = contact_feeds(scene.mech, contacts) if contacts else ()
    if not is_series(circuit):
        if feeds and feeds[0] != LEGACY_POINTS:  # the first contact's own (module docstring)
            mine = np.isin(tips, feeds[0])
            return merge_intervals(zip(starts[mine], ends[mine])), bool((still & mine).any())
        return merge_intervals(zip(starts, ends)), bool(still.any())
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


def contact_closed(scene, contact_columns) -> dict[str, tuple[list[tuple[float, float]], bool]]:
    """Per circuit contact of a circuit of several (its name -> (closed intervals s, closed
    at the end)): the union of its own contact pairs' intervals; {} for one contact."""
    circuit = getattr(getattr(scene, "circuit", None), "circuit", None)
    contacts = getattr(circuit, "contacts", ())
    if len(contacts) < 2:
        return {}
    tips = np.asarray(contact_columns["tip"])
    starts, ends = np.asarray(contact_columns["t_start"]), np.asarray(contact_columns["t_end"])
    still = ~np.asarray(contact_columns["complete"], dtype=bool)
    out = {}
    for block, points in zip(contacts, contact_feeds(scene.mech, contacts)):
        mine = np.isin(tips, points)
        out[block.name] = merge_intervals(zip(starts[mine], ends[mine])), bool((still & mine).any())
    return out


def switch_columns(waves: dict, circuit) -> dict:
    """The switch's unsuffixed columns from its contacts' (SI): the whole bridge's for
    contacts in series (``series_columns``), the first contact's own for independent
    contacts (a changeover's NO) and for one named contact; {} for one unnamed contact
    (its columns are unsuffixed already)."""
    from circuit.probes import CONTACT_COLUMNS

    contacts = getattr(circuit, "contacts", ())
    if is_series(circuit):
        return series_columns(waves, contacts)
    if contacts and contacts[0].name:
        suffix = contacts[0].suffix
        return {name: waves[name + suffix] for name in CONTACT_COLUMNS}
    return {}


# --- a changeover: transfer times and break before make ------------------------------------

def _first_after(times, t: float) -> float | None:
    later = [s for s in times if s > t]
    return min(later) if later else None


def _burning_before(times, arc, at: float) -> bool | None:
    """Whether the arc current ``arc`` (A, at ``times`` s) burns at the last sample before ``at``."""
    if times is None or arc is None:
        return None
    k = int(np.searchsorted(times, at, side="left")) - 1
    return bool(k >= 0 and abs(arc[k]) > ARC_BURNING_CURRENT)


def changeover_metrics(no: dict, nc: dict) -> dict:
    """summary.json ``changeover`` from the NO and NC contacts' own results (each a dict with
    ``intervals``, the closed intervals s, ``operations``, coupling.core.metrics.operations
    of that contact, and optionally ``time`` and ``arc_current``, its arc's current A at the
    circuit's points; docs/coupling.md, "A changeover"):

    - ``operate``: per NC break (the blade leaving its rest), ``nc_break`` (s), its arc
      (``nc_arc_duration`` s, ``nc_arc_energy`` J), the next NO make ``no_make`` (s) with its
      bounces (``no_bounces``, ``no_bounce_time`` s) and ``transfer_time`` = no_make - nc_break
      (s; None when NO does not make after it in the run), ``arc_at_make``: whether NC's arc
      still burns at NO's make (the arc then joins the two throws; None without waveforms);
    - ``release``: per NO break, ``no_break`` (s), its arc, the next NC make ``nc_make`` with
      its bounces and ``transfer_time`` = nc_make - no_break;
    - ``transfer_time``: the first operate's (s, the contract key: NC break to NO make);
      ``release_transfer_time``: the first release's;
    - ``overlaps``: the intervals (s) with both contacts closed at once, ``overlap_time``
      their sum (s); ``break_before_make``: True when there are none (the changeover opens one
      throw before it closes the other), False when there are, None when neither ever moved.
    """
    def rows(first: dict, second: dict, a: str, b: str) -> list[dict]:
        out = []
        makes = {op["make"]["time"]: op["make"] for op in second["operations"] if "make" in op}
        for op in first["operations"]:
            if "break" not in op:
                continue
            brk = op["break"]
            made = _first_after(makes, brk["time"])
            make = makes.get(made)
            out.append({f"{a}_break": brk["time"], f"{a}_arc_duration": brk.get("arc_duration"),
                        f"{a}_arc_energy": brk.get("arc_energy"), f"{b}_make": made,
                        f"{b}_bounces": None if make is None else make["bounces"],
                        f"{b}_bounce_time": None if make is None else make["bounce_time"],
                        f"{b}_settled": None if make is None else make["settled"],
                        "transfer_time": None if made is None else made - brk["time"],
                        "arc_at_make": None if made is None else _burning_before(first.get("time"),
                                                                                 first.get("arc_current"), made)})
        return out

    operate = rows(nc, no, "nc", "no")
    release = rows(no, nc, "no", "nc")
    both = [(a, b) for a, b in intersection(no["intervals"], nc["intervals"]) if b > a]
    moved = bool(operate or release or any("make" in op for op in no["operations"]))
    return dict(transfer_time=operate[0]["transfer_time"] if operate else None,
                release_transfer_time=release[0]["transfer_time"] if release else None,
                operate=operate, release=release, overlaps=[list(iv) for iv in both],
                overlap_time=float(sum(b - a for a, b in both)),
                break_before_make=(not both) if moved or both else None)


def changeover_warnings(metrics: dict, names: tuple[str, str]) -> list[str]:
    """The warning lines of a changeover: both throws closed at once (it makes before it
    breaks), and a break's arc still burning when the other throw makes (the arc joins the
    two throws); [] when neither."""
    lines = []
    if metrics.get("break_before_make") is False:
        first = metrics["overlaps"][0]
        lines.append(f"changeover: {names[0]} and {names[1]} are closed at once for "
                     f"{metrics['overlap_time'] * 1e6:.4g} us in total (first from {first[0] * 1e3:.6g} ms to "
                     f"{first[1] * 1e3:.6g} ms): it makes before it breaks, joining its two loads through the "
                     "common; widen the contact gaps or check the blade's travel")
    for key, (a, b) in (("operate", (names[1], names[0])), ("release", (names[0], names[1]))):
        late = [row for row in metrics.get(key, []) if row.get("arc_at_make")]
        if late:
            made = late[0]["no_make" if key == "operate" else "nc_make"]
            lines.append(f"changeover: {a}'s arc still burns when {b} makes at {made * 1e3:.6g} ms ({key}, "
                         f"{len(late)} time(s)): the arc joins the two throws through the common; a longer "
                         "transfer (wider gap) or arc suppression keeps them apart")
    return lines
