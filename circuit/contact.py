"""The contact element: a conductance G(t) >= 0 (S) given from Python, as ngspice netlist lines.

In the netlist the contact between nodes a and b is three elements::

    Vcontact   a contact_s 0                                  (0 V: contact current probe)
    Bcontact   contact_s b  I=V(contact_s,b)*(V(contact_g)+G_leak)
    Vcontact_g contact_g 0  external                          (G(t) in volts = siemens)

``G = 0`` is an open contact: the element then carries only the leakage conductance
(default 1e-12 S, an insulation resistance of 1 TOhm) and there is no division by
zero. The conductance source is written ``external`` without a value: ngspice 38-40
segfault on an EXTERNAL source that also has a DC value. For a one-shot reference the
same source is written as a PWL instead (see ``deck.py``).

Every make/break instant must be a breakpoint: ngspice does not know the value of an
EXTERNAL source jumps, and lands exactly on breakpoints, restarting there with a small
first-order step. At a breakpoint the conductance used is the left limit ``G(t_b-)``
(the state before the event), so a jump acts from the breakpoint on; see
``left_limited``.

Current-dependent contacts: a contact resistance that also depends on the current
through it (film breakdown, heating) is given as a factor g(I) > 0, an ngspice
expression of the contact current ``I`` (A). The element is then::

    Bcontact_geff contact_geff 0 V=V(contact_g)/(g(i(Vcontact)))
    Bcontact      contact_s b   I=V(contact_s,b)*(V(contact_geff)+G_leak)

so Python supplies only the time-dependent part G(t) and ngspice's Newton iteration
solves I = V G(t)/g(I) within each time point: no lag between current and resistance.
The effective conductance G(t)/g(I) is node ``contact_geff``.
"""

from __future__ import annotations

import math
import re
from bisect import bisect_right
from typing import Callable, Iterable, Sequence

from PySpice.Spice.Netlist import Circuit

from .channels import ConstantChannel, TableChannel
from .names import check_block_name, named

CONDUCTANCE_SOURCE = "Vcontact_g"
CONDUCTANCE_NODE = "contact_g"
EFFECTIVE_NODE = "contact_geff"
SENSE_SOURCE = "Vcontact"
SENSE_NODE = "contact_s"
ELEMENT = "Bcontact"
DEFAULT_LEAKAGE = 1e-12  # S

Conductance = Callable[[float], float]

_CURRENT_TOKEN = re.compile(r"\bI\b")


def check_current_factor(where: str, expression: str | None) -> str | None:
    """Validate a current-factor expression: a one-line ngspice expression using ``I``."""
    if expression is None:
        return None
    if not isinstance(expression, str) or not expression.strip() or "\n" in expression:
        raise ValueError(f"{where}.contact_current_factor = {expression!r}: must be a one-line ngspice "
                         "expression of the contact current I (A), e.g. '0.6+0.4*exp(-abs(I)/1.7)'")
    if expression.count("(") != expression.count(")"):
        raise ValueError(f"{where}.contact_current_factor = {expression!r}: unbalanced parentheses")
    return expression


def add_contact(circuit: Circuit, node_a: str, node_b: str, leakage_conductance: float = DEFAULT_LEAKAGE,
                current_factor: str | None = None, name: str = "") -> str:
    """Add the contact ``name`` between ``node_a`` and ``node_b`` to a PySpice circuit.

    The contact current (A, positive from a to b) is the branch current of
    ``Vcontact`` (``Vcontact_<name>`` for a named contact); the prescribed conductance
    G(t) (S) is the voltage of node ``contact_g`` (``contact_<name>_g``). With
    ``current_factor`` (an ngspice expression of the contact current ``I``, see the
    module docstring) the conductance is G(t)/g(I). Returns the node whose voltage is
    the effective conductance (S). A PySpice circuit may hold several named contacts.
    """
    name = check_block_name("add_contact(name=...)", name)
    sense, sense_node = named(SENSE_SOURCE, name), named(SENSE_NODE, name)
    g_node, g_source = named(CONDUCTANCE_NODE, name), named(CONDUCTANCE_SOURCE, name)
    circuit.V(sense[1:], node_a, sense_node, 0)
    conductance = g_node
    if current_factor is not None:
        effective = named(EFFECTIVE_NODE, name)
        g = _CURRENT_TOKEN.sub(f"i({sense})", current_factor)
        circuit.B(effective, effective, circuit.gnd, voltage_expression=f"V({g_node})/({g})")
        conductance = effective
    circuit.B(
        named(ELEMENT, name)[1:],
        sense_node,
        node_b,
        current_expression=f"V({sense_node},{node_b})*(V({conductance})+{float(leakage_conductance)!r})",
    )
    circuit.V(g_source[1:], g_node, circuit.gnd, "external")
    placed = getattr(circuit, _PLACED, {})
    placed[name] = (str(node_a), str(node_b), float(leakage_conductance), current_factor)
    setattr(circuit, _PLACED, placed)
    return conductance


_PLACED = "_switchsim_contacts"  # where add_contact records the contacts it placed on a PySpice Circuit


def placed_contacts(circuit: Circuit) -> dict[str, tuple[str, str, float, str | None]]:
    """The contacts ``add_contact`` put on a PySpice circuit: name -> (node_a, node_b,
    leakage conductance S, current factor or None)."""
    return dict(getattr(circuit, _PLACED, {}))


#: ngspice lands on a macro time when its step is within this fraction of the remaining
#: step of it (ngspice.py); a breakpoint that close before the macro time is moved onto it.
LANDING_TOLERANCE = 1e-9


def snapped(breakpoints: Sequence[float], t_stop: float, span: float, merge: float = 0.0) -> list[float]:
    """Breakpoints as ngspice will land on them: those within ``LANDING_TOLERANCE * span``,
    or ``merge`` (s), before ``t_stop`` (s) are moved onto it (sorted, de-duplicated).

    ngspice would otherwise clip its step to the breakpoint and the landing rule would
    lengthen it to ``t_stop`` again, so the breakpoint would be stepped over: measured, a
    make 77 ulp before a 2 us macro time was never landed on (no restart at the make).
    ``merge`` (``SimulationOptions.sliver``): a breakpoint that close before the pause's
    target would leave a sliver step after ngspice's restart at it (order 1, Newton from
    the jump), and with an inductor in the loop its companion L/h made that step's Newton
    fail until the step fell below ngspice's smallest: measured, a make 1.1e-13 s and
    another 3e-15 s before a macro time aborted two changeover runs with "timestep too
    small" (100 mH and 10 mH loads with flyback diodes).
    """
    tolerance = max(LANDING_TOLERANCE * span, merge)
    return sorted({t_stop if 0.0 <= t_stop - b <= tolerance else float(b) for b in breakpoints})


def left_limited(conductance: Conductance, breakpoints: Sequence[float], span: float,
                 t_stop: float | None = None, merge: float = 0.0) -> Conductance:
    """``conductance`` evaluated as its left limit at each breakpoint.

    ngspice evaluates the source at the breakpoint time itself, and that value closes
    the step that ends there. Using the value after a jump would apply the new contact
    state over the whole preceding step (measured on an RC charge: 3.3 % of the
    final voltage wrong, against 0.025 % with the left limit). Times within 1e-12
    relative (at least 64 ulp) of a breakpoint count as the breakpoint: ngspice lands on
    it up to rounding, and ends a run at t_end (1 - 2.2e-13) whatever t_end (measured),
    so a make at t_end was otherwise missed. The left limit is taken ``1e-9 * span``
    before it (``span``: the macro step length, s). With
    ``t_stop`` (the macro time), breakpoints moved onto it by ``snapped`` (with ``merge``)
    keep their own left limit.
    """
    befores: dict[float, float] = {}
    for b in sorted(float(b) for b in breakpoints):
        at = snapped((b,), t_stop, span, merge)[0] if t_stop is not None else b
        before = b - max(1e-9 * span, 64.0 * math.ulp(b))
        befores[at] = min(before, befores.get(at, math.inf))
    if not befores or isinstance(conductance, ConstantChannel):  # (a constant's left limit is itself)
        return conductance
    points = sorted(befores)
    # Nearest breakpoint by bisection: one comparison per call whatever their number.
    lows = [b - _same_instant(b) for b in points]
    highs = [b + _same_instant(b) for b in points]
    values = [befores[b] for b in points]
    function = conductance.function if isinstance(conductance, TableChannel) else conductance

    def source(t: float) -> float:
        i = bisect_right(lows, t) - 1
        if i >= 0 and t <= highs[i]:
            return function(values[i])
        return function(t)

    if isinstance(conductance, TableChannel) and conductance.windows is None:
        # the same windows, evaluated by the compiled callbacks (this comparison, this bisection)
        return conductance.with_windows(source, lows, highs, values)
    return source


def _same_instant(b: float) -> float:
    """Half-width (s) of the window of times that ngspice's landing on ``b`` may hit."""
    return max(1e-12 * abs(b), 64.0 * math.ulp(b)) + 1e-300


def checked_breakpoints(breakpoints: Iterable[float], t_start: float, t_stop: float) -> tuple[float, ...]:
    """Sorted, de-duplicated breakpoints, each required in (t_start, t_stop] (s)."""
    result = sorted({float(b) for b in breakpoints})
    for b in result:
        if not math.isfinite(b) or not (t_start < b <= t_stop):
            raise ValueError(
                f"breakpoint {b!r} s is outside the step ({t_start!r}, {t_stop!r}] s; "
                "pass only the make/break instants inside the step being advanced"
            )
    return tuple(result)
