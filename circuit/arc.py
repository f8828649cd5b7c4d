"""Arc and breakdown model of an opening contact gap (minimum arc voltage, minimum arc current).

Physics kept (short arcs between contact metals, the bounce regime):

- A burning arc holds the gap voltage near the minimum arc voltage U_min (anode +
  cathode fall, ~10-15 V for Ag, Cu, Au), nearly independent of current; a small
  incremental resistance R_arc regularises the characteristic.
- An arc needs at least the minimum arc current I_min (~0.3-1 A) to sustain its
  cathode spot: it extinguishes as soon as its current falls below I_min.
- When a current-carrying contact parts, a molten bridge and then the arc form: the
  gap is "armed" while closed and for ``formation_time`` after parting (the closed
  indicator low-pass filtered, above 1/2; a make arms it ``formation_time`` after
  closing); if in that window the gap voltage reaches U_min and the arc takes at least
  I_min, it burns.
  Otherwise (gap voltage stays below U_min, e.g. a supply below U_min with a resistive
  load, or the current goes into a snubber) no arc forms.
- Optionally, an extinguished gap re-ignites when its voltage reaches the breakdown
  voltage V_bd (repeated re-ignitions give the "showering arc" of inductive loads).
- Optionally the burning voltage grows with the gap distance d(t) >= 0 (m), given
  from Python like G(t): U_arc = U_min + E_col d + R_arc |i| (``column_gradient``
  E_col, V/m: the arc column's field, a few V/mm for short arcs in air at a few
  amperes), so a DC arc whose supply exceeds U_min goes out as the gap lengthens; and
  the re-ignition voltage may grow too: V_bd(d) = V_bd0 + E_bd d (``breakdown_gradient``).
  Both default to 0: a constant U_min and V_bd, no gap needed.

- Optionally (``characteristic="ayrton"``) the burning voltage follows Ayrton's form
  U = U_min + E_col d + (C + D d) / I_f instead of growing with the current: I_f is the
  arc current followed with the arc's time constant, held between accepted points like
  the state (a falling characteristic inside Newton would give two solutions per point).
- The make arc: with ``breakdown_voltage`` and ``breakdown_gradient`` a closing gap
  strikes where V_bd0 + E_bd d falls to the voltage across it (pre-strike), by the same
  re-ignition rule; the contact shorts the arc at the make.

Not modelled: arc elongation beyond the straight column (magnetic blow-out, arc
runners), erosion (coupling.laws.duty computes it from the arc energy), and the glow
discharge regime. Without ``column_gradient`` a DC arc with E > U_min and load current >
I_min burns for as long as the contact stays open.

Netlist: the arc path across the gap is one behavioural conductor, a dead zone
(conducts beyond +-U_min with slope 1/R_arc) enabled by the arc state e in {0, 1},
plus the 1 GOhm of an extinguished gap::

    Varc    a arc_p 0                                   (arc current probe)
    Barc    arc_p b I=V(arc_on)*(uramp(v-U_min)-uramp(-v-U_min))/R_arc + 1e-9*v
    Iarc_on 0 arc_on external                           (the arc state e, from Python)
    Rarc_on arc_on 0 1                                  (so V(arc_on) = e)

(an EXTERNAL current source: ngspice asks for its value through its own callback, so
the contact's EXTERNAL voltage source and the arc state need no name look-up).

The Ayrton characteristic keeps the dead zone and moves its threshold: e is 0 (out) or
1 + W with W = 1/I_f (1/A), and the path conducts min(e, 1) (|v| - U)/(R_A + dU W) beyond
U = U_min - dU + E_col d + (C + D d) W (R_A = 1e-4 ohm, dU = 1 % of U_min), so at i = I_f
the voltage is Ayrton's U(I_f) + R_A I_f and within a step the arc is a fixed, monotone
conductor as before.

With a gap dependence (``column_gradient`` or ``breakdown_gradient`` > 0) a second
EXTERNAL voltage source gives the gap distance, and U_min in the dead zone becomes
U_min + E_col V(arc_gap)::

    Varc_gap arc_gap 0 external                         (d(t) in volts = metres)
    Barc    arc_p b I=V(arc_on)*(uramp(v-U)-uramp(-v-U))/R_arc + 1e-9*v,  U = U_min+E_col*V(arc_gap)

The state is not decided inside ngspice's Newton iteration: ``ArcState`` holds it and
changes it only at accepted time points (from the accepted solution), so within a
step the arc is a fixed, monotone conductor and every time point has one solution.
An earlier version used ngspice's hysteretic switch (SW) with the control
max(K_I (|i| - I_min), K_c (armed - 1/2), |v| - V_bd); it failed in three ways
(measured, see docs/circuit.md): SW decides its state at the start of a time point from
the previous Newton solution, which after a rejected trial step is the rejected
point's, so a trial step that reached a make tens of us ahead put out a burning 1 A arc
at the retry (an extinguished arc carries no current, so "off" is then self-consistent);
SW's step control, aiming at its threshold with a control slope of 6e14 V/s at a make,
asked for 2e-16 s steps (timestep too small); and its 1 mOhm on-resistance in series
with a dead zone left the arc branch current to round-off (1e-11 A, above ABSTOL), so a
nonlinear contact (current factor) never converged while closed.

ArcState locates its own events in time, as SW's step control did: it shortens the
next step so that |i| approaches I_min (burning) or |v| approaches V_bd (extinguished)
by at most 3/4 of the remaining distance plus 1e-5 of the threshold, predicted from
the last accepted step, and lands exactly where the armed filter crosses 1/2.

A switch of the arc is a discontinuity of the circuit's equations that ngspice's error
control cannot see before it has stepped across it: the step after an extinction was as
long as the one before (12.8 ns on the free drop's 16 MHz wiring ring, a fifth of its
period), and the overshoot came out 47 V instead of 60 V. So the first step after a
switch is RESTART (1e-3) times the one before; ngspice then grows it by at most 2x per
point, as its own error estimate allows (tests/circuit/test_circuit_arc.py checks the
ringing against the series RLC closed form).
"""

from __future__ import annotations

import math
import re
from array import array
from bisect import bisect_left, insort
from dataclasses import dataclass
from typing import Callable, ClassVar, Sequence

from PySpice.Spice.Netlist import Circuit

from .contact import check_block_name, named
from .names import GROUND
from .validation import check_range, scene_key

SENSE_SOURCE = "Varc"
STATE_SOURCE = "Iarc_on"
STATE_NODE = "arc_on"
GAP_SOURCE = "Varc_gap"  # EXTERNAL: the gap distance d(t), m (volts), only with a gap dependence
GAP_NODE = "arc_gap"
OFF_CONDUCTANCE = 1e-9  # S: an extinguished gap (and the path's floor when burning)
RESOLUTION = 1e-5  # events located to this fraction of I_min or V_bd
_APPROACH = 0.75  # fraction of the remaining distance to a threshold one step may cover
RESTART = 1e-3  # the first step after the arc switches, as a fraction of the step before it
# steps whose rates an approach remembers: the fastest of them may come back (a blade ringing
# at ~100 us opens the gap at 40-75 um/ms in turn over 20-40 us steps)
_RATE_MEMORY = 3
_LEVEL_TOLERANCE = 1e-9  # of the armed filter's level, when landing on its crossing of 1/2
#: ArcState.cells: the arc's state as doubles, where ngspice's compiled step callback reads
#: and moves it too (circuit/callbacks.c's SW_ARC_*, held together by a test)
ARC_CELLS = ("t", "level", "closed", "burning", "plain", "tau", "tolerance", "idle")
_T, _LEVEL, _CLOSED, _BURNING, _PLAIN, _TAU, _TOLERANCE, _IDLE = range(len(ARC_CELLS))
_ATTRIBUTE = "_switchsim_arc"  # where add_arc records the model on a PySpice Circuit
CHARACTERISTICS = ("linear", "ayrton")
AYRTON_RESISTANCE = 1e-4  # ohm: the Ayrton arc's own slope (what stays of R_arc; 0.04 V at 400 A)
AYRTON_STEP_FRACTION = 0.01  # of U_min: the held Ayrton arc's within-step voltage span (slope dU / I_f)


@dataclass(frozen=True)
class ArcModel:
    """Arc of an opening contact. SI units.

    min_voltage: minimum arc voltage U_min, V (Ag ~12 V, Cu ~13 V, Au ~15 V).
    min_current: minimum arc current I_min, A (Ag ~0.4 A, Cu ~0.43 A, Au ~0.38 A).
    resistance: incremental resistance of the burning arc, ohm (regularisation; the
        gap voltage is U_min + resistance * |i|).
    formation_time: how long after parting the gap stays armed for the arc to form, s
        (order of the molten-bridge lifetime at ampere currents).
    breakdown_voltage: gap voltage at which an extinguished gap re-ignites, V, or None
        for a gap that never re-ignites (the voltage is then limited only by the circuit).
        With ``breakdown_gradient`` it is the value at zero gap, V_bd0.
    column_gradient: growth of the burning voltage with the gap distance d, V/m:
        U_arc = U_min + column_gradient * d + resistance * |i|. 0 (default): constant
        U_min, no gap needed. Illustrative order of magnitude for short arcs in air at a
        few amperes: 1-5 V/mm (1e3-5e3 V/m), from general contact-physics knowledge,
        not a measured value for a particular contact. With a value > 0 every run needs
        the gap d(t) (``Stepper.advance(..., gap=...)``).
    breakdown_gradient: growth of the re-ignition voltage with the gap, V/m:
        V_bd(d) = breakdown_voltage + breakdown_gradient * d (needs ``breakdown_voltage``;
        0 default). Illustrative: air breaks down at ~3 kV/mm at mm gaps (3e6 V/m); keep
        it above ``column_gradient``, else beyond d = (V_bd0 - U_min) / (E_col - E_bd) a
        re-ignited arc cannot conduct and goes out again at the next point.
    characteristic: "linear" (default: U_min + E_col d + R_arc |i|, the netlist as it always
        was) or "ayrton": U = U_min + E_col d + (C + D d) / I_f, Ayrton's form (H. Ayrton,
        The Electric Arc, 1902: U = A + B l + (C + D l) / I), A = U_min, B = E_col, with
        I_f the arc current followed with ``time_constant``; the arc voltage no longer grows
        with the current (``resistance`` is unused: the Ayrton arc's own slope is
        AYRTON_RESISTANCE, 1e-4 ohm). docs/circuit.md section 7.
    ayrton_c: C, W (V A): the falling part of the characteristic at zero gap (0: none, the
        short metal-vapour arc near U_min). Ayrton's carbon arc in air: 11.66 W.
    ayrton_d: D, W/m: its growth with the gap (needs the gap d(t)). Ayrton's carbon arc:
        10.54 W/mm = 1.054e4 W/m.
    time_constant: s, the arc's thermal time constant with which I_f follows |i| (Mayr-type
        relaxation; order 1-10 us for arcs in air). Only with "ayrton".
    """

    SECTION: ClassVar[str] = "circuit.arc"
    min_voltage: float = scene_key(12.0, unit="V", doc="minimum arc voltage")
    min_current: float = scene_key(0.4, unit="A", doc="minimum arc current")
    resistance: float = scene_key(0.05, unit="ohm")
    formation_time: float = scene_key(1e-6, unit="s")
    breakdown_voltage: float | None = scene_key(None, unit="V", doc="re-ignition across the gap; omitted: none")
    column_gradient: float = scene_key(0.0, unit="V/m", doc="arc voltage growth with the gap")
    breakdown_gradient: float = scene_key(
        0.0, unit="V/m", doc="breakdown voltage growth with the gap (needs `breakdown_voltage`)")
    characteristic: str = scene_key(
        "linear", unit="-", doc='"linear": U_min + E_col d + R_arc I; "ayrton": U_min + E_col d + (C + D d) / I')
    ayrton_c: float = scene_key(0.0, unit="W", doc='Ayrton\'s C (characteristic = "ayrton")')
    ayrton_d: float = scene_key(0.0, unit="W/m", doc="Ayrton's D: C's growth with the gap (needs the gap)")
    time_constant: float = scene_key(1e-6, unit="s", doc="how fast the Ayrton arc's voltage follows its current")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "min_voltage", self.min_voltage, "V", 0.0, 1000.0, low_open=True)
        check_range(name, "min_current", self.min_current, "A", 0.0, 100.0, low_open=True)
        check_range(name, "resistance", self.resistance, "ohm", 1e-4, 100.0)
        check_range(name, "formation_time", self.formation_time, "s", 1e-10, 1e-3)
        if self.breakdown_voltage is not None:
            check_range(
                name, "breakdown_voltage", self.breakdown_voltage, "V", self.min_voltage, 1e6, low_open=True
            )
        # Wide ranges: they catch a sign or a unit slip (V/mm is 1e3 V/m), not unusual arcs.
        check_range(name, "column_gradient", self.column_gradient, "V/m", 0.0, 1e6)
        check_range(name, "breakdown_gradient", self.breakdown_gradient, "V/m", 0.0, 1e9)
        if self.breakdown_gradient > 0 and self.breakdown_voltage is None:
            raise ValueError(
                f"{name}.breakdown_gradient = {self.breakdown_gradient:g} V/m needs breakdown_voltage "
                "(the re-ignition voltage at zero gap, V)"
            )
        if self.characteristic not in CHARACTERISTICS:
            raise ValueError(f"{name}.characteristic = {self.characteristic!r}: allowed values are "
                             f"{', '.join(map(repr, CHARACTERISTICS))}")
        check_range(name, "ayrton_c", self.ayrton_c, "W", 0.0, 1e5)
        check_range(name, "ayrton_d", self.ayrton_d, "W/m", 0.0, 1e9)
        check_range(name, "time_constant", self.time_constant, "s", 1e-10, 1e-2)
        if self.characteristic != "ayrton":
            for key in ("ayrton_c", "ayrton_d"):
                if getattr(self, key) != 0.0:
                    raise ValueError(f"{name}.{key} = {getattr(self, key):g} applies to characteristic = 'ayrton' "
                                     f"(the characteristic is {self.characteristic!r})")

    @property
    def uses_gap(self) -> bool:
        """True if the model depends on the gap distance: every run then needs d(t)."""
        return self.column_gradient > 0.0 or self.breakdown_gradient > 0.0 or self.ayrton_d > 0.0

    @property
    def gap_terms(self) -> str:
        """The model's terms that grow with the gap, for messages ("column_gradient = 2000 V/m, ...")."""
        terms = [("column_gradient", self.column_gradient, "V/m"), ("breakdown_gradient", self.breakdown_gradient,
                                                                    "V/m"), ("ayrton_d", self.ayrton_d, "V A/m")]
        return ", ".join(f"{name} = {value:g} {unit}" for name, value, unit in terms if value > 0.0)


def add_arc(circuit: Circuit, arc: ArcModel, node_a: str, node_b: str, name: str = "") -> None:
    """Add the arc path across the contact ``name`` (``node_a``, ``node_b``) of a PySpice circuit.

    The arc current (A, positive from a to b) is the branch current of ``Varc``; the arc
    state (1 burning or armed, 0 extinguished) is the voltage of node ``arc_on``, set by
    ``ArcState`` between time points through the EXTERNAL current source ``Iarc_on``. The model is recorded on the circuit, so a run
    of a PySpice ``Circuit`` finds it. With a gap dependence (``arc.uses_gap``) the gap
    distance d(t) (m) is the voltage of node ``arc_gap``, set by the EXTERNAL source
    ``Varc_gap`` (every run then needs a gap). A named contact's arc has its elements and
    nodes named as the contact's (``contact.named``: Varc_no, arc_no_on, Varc_no_gap, ...).
    """
    name = check_block_name("add_arc(name=...)", name)
    p_node, on_node, gap_node = named("arc_p", name), named(STATE_NODE, name), named(GAP_NODE, name)
    v = f"V({p_node},{node_b})"
    circuit.V(named(SENSE_SOURCE, name)[1:], node_a, p_node, 0)
    if arc.characteristic == "ayrton":
        expression = _ayrton_expression(arc, v, f"V({on_node})", f"V({gap_node})")
    else:
        u = repr(float(arc.min_voltage))
        if arc.column_gradient > 0.0:
            u = f"({u}+{float(arc.column_gradient)!r}*V({gap_node}))"
        expression = (f"V({on_node})*(uramp({v}-{u})-uramp(-{v}-{u}))/{float(arc.resistance)!r}"
                      f"+{OFF_CONDUCTANCE!r}*{v}")
    circuit.B(named("Barc", name)[1:], p_node, node_b, current_expression=expression)
    # No value after 'external' (a value segfaults ngspice 38-40 on V sources).
    circuit.I(named(STATE_SOURCE, name)[1:], circuit.gnd, on_node, "external")
    circuit.R(named("Rarc_on", name)[1:], on_node, circuit.gnd, 1)
    if arc.uses_gap:
        # No value after 'external' here either.
        circuit.V(named(GAP_SOURCE, name)[1:], gap_node, circuit.gnd, "external")
    recorded = getattr(circuit, _ATTRIBUTE, {})
    recorded[name] = (arc, str(node_a), str(node_b))
    setattr(circuit, _ATTRIBUTE, recorded)


def _ayrton_expression(arc: ArcModel, v: str, on: str, gap: str) -> str:
    """The Ayrton arc's current: a dead zone at the held voltage U = U_min - dU + E_col d +
    (C + D d) W, slope 1 / (R_A + dU W), enabled by min(e, 1); e = 0 (out) or 1 + W, W = 1/I_f
    (1/A; 0 until the arc carries I_min), set by ArcState between accepted points. At
    i = I_f the voltage is U_min + E_col d + (C + D d) / I_f + R_A I_f: Ayrton's form."""
    du = AYRTON_STEP_FRACTION * float(arc.min_voltage)
    w = f"max({on}-1,0)"
    u = repr(float(arc.min_voltage) - du)
    if arc.column_gradient > 0.0:
        u += f"+{float(arc.column_gradient)!r}*{gap}"
    c = repr(float(arc.ayrton_c))
    if arc.ayrton_d > 0.0:
        c = f"({c}+{float(arc.ayrton_d)!r}*{gap})"
    if arc.ayrton_c > 0.0 or arc.ayrton_d > 0.0:
        u += f"+{c}*{w}"
    u = f"({u})"
    return (f"min({on},1)*(uramp({v}-{u})-uramp(-{v}-{u}))/({AYRTON_RESISTANCE!r}+{du!r}*{w})"
            f"+{OFF_CONDUCTANCE!r}*{v}")


def recorded_arc(circuit: Circuit, name: str = "") -> ArcModel | None:
    """The ArcModel that ``add_arc`` put on a PySpice circuit's contact ``name``, or None."""
    found = getattr(circuit, _ATTRIBUTE, {}).get(name)
    return None if found is None else found[0]


#: Reads the last accepted values of ngspice vectors: names -> values (same order).
Reader = Callable[[Sequence[str]], Sequence[float]]


class _Cell:
    """An ArcState attribute kept in its ``cells`` (the doubles the compiled step callback
    shares) at ``index``: a float, or with ``flag`` a bool kept as 1.0 or 0.0."""

    def __init__(self, index: int, doc: str, flag: bool = False):
        self.index, self.flag, self.__doc__ = index, flag, doc

    def __get__(self, state, owner=None):
        if state is None:
            return self
        value = state.cells[self.index]
        return value != 0.0 if self.flag else value

    def __set__(self, state, value) -> None:
        state.cells[self.index] = (1.0 if value else 0.0) if self.flag else value


class ArcState:
    """The arc's on/off state, decided at ngspice's accepted time points.

    After each accepted point ngspice's step callback calls ``accepted``; the state it
    returns holds for the whole next step (the EXTERNAL source ``Iarc_on`` reads
    ``value``), so a rejected or retried trial step never changes it. Rules, at an
    accepted point t with arc current i, gap voltage v and contact conductance G:

    - armed: the closed indicator (G > 0) low-pass filtered with the time constant
      formation_time / ln 2 is above 1/2 (the filter is integrated exactly between
      accepted points; G changes only at breakpoints, so the indicator switches at the
      last breakpoint inside the interval, else right after the earlier point). A contact
      closed for a while stays armed for formation_time after parting, and a make arms
      the gap only formation_time later, once the contact has taken the current (no
      make arc);
    - burning next = armed, or (burning and |i| >= I_min), or (V_bd set and
      |v| >= V_bd(d) = V_bd0 + E_bd d, with d the gap distance at t).

    Names are ngspice vector names: ``current`` the arc current ("varc#branch"),
    ``node_a``/``node_b`` the contact nodes, ``conductance`` the node whose voltage is
    the contact conductance G(t), ``gap`` the node whose voltage is the gap distance
    (needed only with a breakdown gradient); ``conductance_source`` the EXTERNAL source
    that drives G(t), when it is one; ``gap_source`` the one that drives d(t), when the
    arc reads its gap (ngspice's session holds it while the arc cannot read it).
    """

    def __init__(self, arc: ArcModel, current: str, node_a: str, node_b: str, conductance: str,
                 gap: str = GAP_NODE, conductance_source: str | None = None, gap_source: str | None = None):
        self.arc = arc
        # the EXTERNAL source whose last value is G at an accepted point (saves a vector read)
        self.conductance_source = conductance_source
        self.gap_source = gap_source
        self._tau = arc.formation_time / math.log(2.0)
        self._conductance = (conductance.lower(),)
        self._names_on = (current.lower(),)
        nodes = tuple(n.lower() for n in (node_a, node_b) if n.lower() not in GROUND)
        self._names_off = self._names_on + nodes
        self._gap_gradient = float(arc.breakdown_gradient) if arc.breakdown_voltage is not None else 0.0
        if self._gap_gradient > 0.0:
            self._names_off += (gap.lower(),)
        self._sign_b = node_b.lower() not in GROUND  # v = V(a) - V(b); a grounded node reads 0
        self._sign_a = node_a.lower() not in GROUND
        self._ayrton = arc.characteristic == "ayrton"
        self.cell = array("d", [0.0])  # (never resized: its address is read once per load)
        # the state below as doubles (ARC_CELLS; never resized either): ngspice's compiled
        # step callback answers ``accepted`` itself where only the filter's level moves
        # (the arc stays lit and closed, or out and unarmed), which "plain" allows
        self.cells = array("d", [-math.inf, 0.0, 0.0, 0.0, 0.0, self._tau, _LEVEL_TOLERANCE, 0.0])
        self.start(False)

    # the state the compiled step callback shares (``cells``)
    level = _Cell(_LEVEL, "The filtered closed indicator (0 .. 1).")
    burning = _Cell(_BURNING, "The arc burns (or is armed).", flag=True)
    _t = _Cell(_T, "s: the last accepted point (-inf: none yet).")
    _closed = _Cell(_CLOSED, "1.0 or 0.0: the contact at that point.")
    idle = _Cell(_IDLE, "The arc was out over the step to its last point (V(arc_on) 0 in that point's "
                        "solution) and is out after it: its gap is read nowhere in the next step, as long as "
                        "it cannot arm (ngspice's session then holds its gap channel).", flag=True)

    def _publish(self) -> None:
        """Whether the compiled step callback may answer the next accepted point (its
        "plain" cell): not for the Ayrton arc (its current followed at each point), a
        breakdown to test (an arc out with a breakdown voltage), an approach under way
        (``_previous``: its rates are kept point by point) or before the first point."""
        plain = not self._ayrton and self._previous is None and self._t > -math.inf and \
            (self.arc.breakdown_voltage is None or self.burning)
        self.cells[_PLAIN] = 1.0 if plain else 0.0

    @property
    def value(self) -> float:
        """The arc's EXTERNAL current source's value (0: out, else 1 + 1/I_f, see ``_follow``),
        held in ``cell`` too, a C double that ngspice's compiled callbacks read."""
        return self._value

    @value.setter
    def value(self, value: float) -> None:
        self._value = value
        self.cell[0] = value

    def start(self, closed: bool) -> None:
        """Before the run: the state at the operating point (burning/armed iff closed at t = 0)."""
        self.burning = bool(closed)
        self.idle = not closed  # (ngspice's first iterate: all zeros)
        self.value = 1.0 if closed else 0.0
        self.level = 1.0 if closed else 0.0  # the filtered closed indicator
        self.switches = 0
        self._closed = self.level
        self._breakpoints: list[float] = []
        self._t = -math.inf
        # (t, |i| or |v|, the rate over the step before it and that step's midpoint or None) at
        # the last point, same state
        self._previous: tuple[float, float, tuple[float, float] | None] | None = None
        self._rates: list[float] = []  # the approach's last _RATE_MEMORY rates (per s)
        self.filtered_current = 0.0  # I_f of the Ayrton characteristic, A (0: not yet carrying I_min)
        self._taking_over = (-math.inf, 0.0)  # (t, |i|) at the last point before I_f is set
        self._publish()

    def add_breakpoints(self, times: Sequence[float]) -> None:
        """Instants (s) where G may change (make/break, ramp corners, PWL vertices)."""
        for b in times:
            b = float(b)
            if b > self._t:
                insort(self._breakpoints, b)

    def accepted(self, t: float, conductance: float | None, read: Reader) -> tuple[float, float]:
        """Update from the accepted point at ``t`` (s); returns (max next step s, time to land on s or inf).

        conductance: G at ``t`` (S) if the caller knows it, else None (read from ngspice).
        """
        answer = self._accepted(t, conductance, read)
        self._publish()
        return answer

    def _accepted(self, t: float, conductance: float | None, read: Reader) -> tuple[float, float]:
        arc = self.arc
        if not t > self._t:
            return math.inf, math.inf  # the same point again (a resume after a pause)
        previous_t, self._t = self._t, t
        if conductance is None:
            conductance = read(self._conductance)[0]
        closed = 1.0 if conductance > 0.0 else 0.0
        level = self.level
        if previous_t > -math.inf:
            switch = previous_t
            if closed != self._closed:
                k = bisect_left(self._breakpoints, t) - 1
                if k >= 0 and self._breakpoints[k] > previous_t:
                    switch = self._breakpoints[k]
                level = self._closed + (level - self._closed) * math.exp(-(switch - previous_t) / self._tau)
            level = closed + (level - closed) * math.exp(-(t - switch) / self._tau)
            del self._breakpoints[: bisect_left(self._breakpoints, t)]
        self.level = level
        self._closed = closed
        # Landing on a crossing of 1/2 can fall an ulp short: within 1e-9 it has crossed.
        armed = level > 0.5 - _LEVEL_TOLERANCE if closed else level > 0.5 + _LEVEL_TOLERANCE
        breakdown = arc.breakdown_voltage is not None and not self.burning
        current = voltage = 0.0
        # Armed and closed, nothing depends on the current (one vector read less).
        if (self.burning and not (armed and closed)) or breakdown:
            values = read(self._names_off if breakdown else self._names_on)
            current = abs(values[0])
            if breakdown:
                va = values[1] if self._sign_a else 0.0
                vb = values[1 + self._sign_a] if self._sign_b else 0.0
                # The margin to breakdown, |v| - E_bd d >= V_bd0: a fixed threshold, so the
                # step control below sees the gap's growth in the rate.
                voltage = abs(va - vb) - (self._gap_gradient * values[-1] if self._gap_gradient > 0.0 else 0.0)
        burning = armed or (self.burning and current >= arc.min_current) or (breakdown and voltage >= arc.breakdown_voltage)
        restart = math.inf
        if burning != self.burning:
            self.switches += 1
            self._previous = None
            if previous_t > -math.inf:
                restart = RESTART * (t - previous_t)
        self.idle = not burning and not self.burning
        self.burning = burning
        self.value = 1.0 if burning else 0.0
        if self._ayrton:
            self._follow(t, previous_t, current, burning and not (armed and closed))
        # The next crossing of 1/2 by the filter if the contact stays as it is: land on it.
        land = math.inf
        if closed and not armed:
            land = t + self._tau * math.log(2.0 * (1.0 - level))
        elif armed and not closed:
            land = t + self._tau * math.log(2.0 * level)
        floor = max(1e-12, 256.0 * math.ulp(t))
        restart = max(restart, floor)
        if armed:
            # Keep the current's history: the first step after the window needs its rate.
            if closed:
                self._previous = None
            else:
                self._approach(t, current, arc.min_current, -1.0, floor)
            return restart, land
        if burning:  # |i| falling towards I_min
            return min(restart, self._approach(t, current, arc.min_current, -1.0, floor)), land
        if breakdown:  # |v| (less E_bd d) rising towards V_bd0
            return min(restart, self._approach(t, voltage, arc.breakdown_voltage, 1.0, floor)), land
        return restart, land

    def _follow(self, t: float, previous_t: float, current: float, arcing: bool) -> None:
        """The Ayrton arc's held state: I_f relaxes towards |i| with the arc's time constant
        (exactly, |i| taken constant over the step), from the first point the arc carries
        I_min; value = 1 + 1/I_f (0 out; 1 while I_f is not yet set: the arc at U_min)."""
        arc = self.arc
        before_t, before = self._taking_over
        self._taking_over = (t, current)
        if not arcing:
            self.filtered_current = 0.0
        elif self.filtered_current > 0.0:
            decay = math.exp(-(t - previous_t) / arc.time_constant)
            self.filtered_current = current + (self.filtered_current - current) * decay
        elif current >= arc.min_current and (current - before) * arc.time_constant <= current * (t - before_t):
            # (held at U_min while its branch takes the parting contact's current over, faster
            # than the arc's own time constant: the first point above I_min, 0.404 A of a 5 A
            # arc, had set I_f, the arc's (C + D d)/I_f put it at 123 V on a 100 V supply and it
            # went out, depending on where ngspice's steps fell)
            self.filtered_current = current
        if self.burning and self.filtered_current > 0.0:
            self.value = 1.0 + 1.0 / max(self.filtered_current, arc.min_current)

    def _approach(self, t: float, x: float, threshold: float, direction: float, floor: float) -> float:
        """s: the next step's bound while x (|i| or |v|) approaches ``threshold``: it covers at
        most _APPROACH of the distance left (plus RESOLUTION of the threshold), at the fastest
        rate of the last _RATE_MEMORY steps, grown by the last step's change of rate when the
        approach speeds up.

        A rate from the last step alone lags half a step behind an approach that speeds up,
        and a slowing says nothing of the next steps: a break's arc whose gap a ringing blade
        opens unevenly while the armature accelerates went out 0.27 % below I_min (the
        changeover example: the rate halved over one step, the bound grew to 38 us and the
        next step's rate doubled), not within RESOLUTION; with the step before's rate alone
        where it slowed, and the last step's where it sped up, it still went out 0.2 % below
        where two slow steps followed a fast one (40, 39, then 75 um/ms of gap opening, the
        blade's ~100 us ringing over 22-38 us steps, ngspice's steps bounded by a coil's)."""
        previous, self._previous = self._previous, (t, x, None)
        if previous is None or not t > previous[0]:
            self._rates = []
            return math.inf
        rate = direction * (x - previous[1]) / (t - previous[0])  # > 0: moving towards the threshold
        middle = 0.5 * (t + previous[0])
        self._previous = (t, x, (rate, middle))
        self._rates = (self._rates + [rate])[-_RATE_MEMORY:]
        distance = direction * (threshold - x)
        if rate <= 0.0 or distance < 0.0:
            return math.inf
        room = _APPROACH * distance + RESOLUTION * threshold
        growth = 0.0  # d(rate)/dt, where the approach speeds up
        if previous[2] is not None:
            rate_before, middle_before = previous[2]
            if rate > rate_before and middle > middle_before:
                growth = (rate - rate_before) / (middle - middle_before)
        # a rate that fell may rise again as fast (a gap opened by a ringing blade)
        rate = max(self._rates)
        # the rate at t and its growth: the time to cover ``room``, the root of
        # rate t + growth t^2 / 2 = room (without cancellation)
        rate += growth * (t - middle)
        return max(2.0 * room / (rate + math.sqrt(rate * rate + 2.0 * growth * room)), floor)


# Element letters whose branch (between the nodes listed) gives a chopped inductor current a
# path: a finite impedance, or a voltage source. I, F, G (and a B with I=) are current sources:
# no path; L and the relay's coil block are the inductors themselves. Devices with more
# terminals count as joining all of them (their junctions); an unknown subcircuit too, so a
# netlist whose inductor sits behind one is never refused by mistake.
_PATH_NODES = {"r": 2, "c": 2, "v": 2, "d": 2, "e": 2, "h": 2, "s": 2, "w": 2,
               "q": 3, "j": 3, "m": 4, "t": 4, "o": 4, "u": 3, "z": 3}


def chopped_inductors(elements: Sequence[Sequence[str]], node_a: str, node_b: str) -> tuple[str, ...]:
    """The inductors whose current an arc going out across (node_a, node_b) would chop.

    elements: the tokens of the netlist's top-level element lines (name first), the contact's
    own line left out, the relay's coil block (``XCOIL``) included. An arc goes out at I_min
    with its current still flowing; when every other path from node_a's side of the circuit to
    node_b's runs through an inductor (or a current source) -- no capacitance, resistance or
    voltage source across the contact -- that inductor's current must jump to zero: L di/dt
    has no finite value, and ngspice, with only the open gap's 1 GOhm, rings at L * 1e-9 s
    (1e-15 s for 1 uH) and stops ('timestep too small'). Empty when the circuit is well posed.
    """
    parent: dict[str, str] = {}

    def find(node: str) -> str:
        node = "0" if node.lower() in GROUND else node.lower()
        parent.setdefault(node, node)
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    def join(nodes: Sequence[str]) -> None:
        roots = [find(n) for n in nodes]
        for root in roots[1:]:
            parent[root] = roots[0]
            find(roots[0])

    inductors: list[tuple[str, str, str]] = []
    for tokens in elements:
        if len(tokens) < 3:
            continue
        head = tokens[0].lower()
        letter = head[0]
        if letter == "l" or head == "xcoil":
            inductors.append((tokens[0], tokens[1], tokens[2]))
        elif letter == "b":
            if not re.search(r"(^|\s)i\s*=", " ".join(tokens[3:]).lower()):
                join(tokens[1:3])
        elif letter == "x":
            join([t for t in tokens[1:-1] if "=" not in t] or tokens[1:2])
        elif letter in _PATH_NODES:
            join(tokens[1:1 + _PATH_NODES[letter]])
    side_a, side_b = find(node_a), find(node_b)
    if side_a == side_b:
        return ()
    return tuple(name for name, n1, n2 in inductors if (find(n1) == side_a) != (find(n2) == side_a))
