"""Switch-circuit templates: validated parameter dataclasses that build a PySpice ``Circuit``.

Topology of ``SwitchCircuit`` (the contact on the supply side, the load to ground)::

    src --Rsource-- wire --Rwire-- wire_l --Lwire-- contact_a =CONTACT= contact_b --Vload-- load --LOAD-- 0
                                                    |--Ccontact--|    (parasitic, across the contact)
                                                    |--Rsnubber--snubber--Csnubber--|  (optional)
                                                    |--arc path--|    (optional ArcModel)
    flyback diode (optional): anode 0, cathode contact_b (across Vload + load)

Loads: ``ResistiveLoad`` (R), ``InductiveLoad`` (R + L in series: relay coil, motor),
``CapacitiveLoad`` (series R, then C with a bleed resistor across it: lamp or
supply-input inrush). ``Vload`` is a 0 V probe: its current is the load current, which
keeps flowing through it when the flyback diode freewheels.

Sources: ``DCSource`` (a voltage source E behind its internal resistance; AC, E the RMS
value, with ``frequency`` > 0) or
``CurrentSource`` (a supply in constant-current mode: I_set with its output resistance
and capacitance and a compliance clamp; see its docstring for the netlist)::

    Isource 0 src I_set ; Rsource_out src 0 ; Csource_out src 0
    Dclamp src clamp (switchsim_clamp) ; Vclamp clamp 0 V_comp - (diode drop at I_set)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar, Union

from PySpice.Spice.Netlist import Circuit

from ..arc import ArcModel, add_arc
from ..blocks import CoilBlock, ContactBlock
from ..coil_drive import CoilDrive
from ..contact import DEFAULT_LEAKAGE, add_contact, check_current_factor
from ..names import check_block_name
from ..probes import Probes
from ..validation import check_range, internal, scene_key

BOLTZMANN_OVER_CHARGE = 8.617333262e-5  # V/K
CLAMP_TEMPERATURE = 27.0  # degC: the clamp diode's instance temperature (fixed, whatever TEMP)
CLAMP_SATURATION_CURRENT = 1e-12  # A
CLAMP_MODEL = "switchsim_clamp"

NODE_A = "contact_a"
NODE_B = "contact_b"
LOAD_PROBE = "Vload"


@dataclass(frozen=True)
class DCSource:
    """A voltage source behind its internal resistance ``source_resistance`` (ohm): DC, or AC
    with ``frequency`` > 0.

    voltage: V (positive): the DC open-circuit voltage, or with ``frequency`` > 0 the RMS
        value of the sine (a relay's load is rated in V AC): amplitude sqrt(2) * voltage.
    frequency: Hz; 0 (default): DC. > 0: v(t) = sqrt(2) voltage sin(2 pi frequency t + phase).
    phase_deg: the sine's phase at t = 0, degrees (only with ``frequency`` > 0; 0: the source
        starts at its rising zero, 90: at its positive peak).
    """

    SECTION: ClassVar[str] = "circuit"  # the scene section of its keys: [circuit] voltage, ...
    voltage: float = scene_key(
        24.0, unit="V", doc="source: DC, or RMS with `frequency` > 0; mcu_input: the logic supply Vcc")
    source_resistance: float = scene_key(0.01, unit="ohm")
    frequency: float = scene_key(0.0, unit="Hz", doc="source: 0 DC; > 0 a sine of RMS `voltage`")
    phase_deg: float = scene_key(0.0, unit="deg", doc="source: the sine's phase at t = 0 (`frequency` > 0)")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "voltage", self.voltage, "V", 0.0, 1e5, low_open=True)
        check_range(self.SECTION, "source_resistance", self.source_resistance, "ohm", 0.0, 1e6)
        # mains and aircraft supplies (50-400 Hz) up to ultrasound; a slip of units (rad/s, kHz) shows
        check_range(self.SECTION, "frequency", self.frequency, "Hz", 0.0, 1e6)
        check_range(self.SECTION, "phase_deg", self.phase_deg, "deg", -360.0, 360.0)
        if self.frequency == 0.0 and self.phase_deg != 0.0:
            raise ValueError(f"{self.SECTION}.phase_deg = {self.phase_deg:g} deg applies to an AC source: set "
                             f"{self.SECTION}.frequency (Hz, > 0), or leave phase_deg out for DC")

    @property
    def amplitude(self) -> float:
        """V: the largest voltage the source puts out (sqrt(2) voltage for AC, voltage for DC)."""
        return math.sqrt(2.0) * self.voltage if self.frequency > 0.0 else self.voltage

    def spice_value(self) -> float | str:
        """The source's SPICE value: the DC volts, or ``SIN(0 amplitude frequency 0 0 phase)``."""
        if self.frequency == 0.0:
            return float(self.voltage)
        return f"SIN(0 {self.amplitude!r} {float(self.frequency)!r} 0 0 {float(self.phase_deg)!r})"


@dataclass(frozen=True)
class CurrentSource:
    """DC supply in constant-current mode (SI units).

    current: the set current I_set, A (> 0).
    compliance_voltage: V_comp, the most the supply puts out, V: with the load open it
        leaves constant-current mode and holds V_comp (constant-voltage mode).
    output_capacitance: C_out across the output terminals, F (> 0: output filter
        capacitor, lead capacitance). It sets how fast the voltage rises when the load
        opens (I_set / C_out at first) and discharges into the contact at each make.
    output_resistance: R_out across the output, ohm: the finite output impedance of the
        current regulator; a closed loop of resistance R gets I_set R_out / (R_out + R).

    The netlist (``SwitchCircuit.build``)::

        Isource     0 src I_set                 (the regulated current, into src)
        Rsource_out src 0 R_out
        Csource_out src 0 C_out
        Dclamp      src clamp switchsim_clamp temp=27   (IS = 1e-12 A, N = 1, RS = 0)
        Vclamp      clamp 0 V_comp - V_T ln(1 + I_set/IS)

    The compliance limit is a diode clamp onto a voltage source, not a behavioural
    min(I_set, ...) law: ngspice limits a junction's voltage between Newton iterations
    (pnjlim), so the clamp's exponential knee converges from any operating point, while
    a piecewise-linear clamp has a kink that Newton and the truncation-error control must
    find by step rejection at every break. Vclamp is offset by the diode's drop at I_set,
    so with the load open the output sits at V_comp when the clamp takes the whole set
    current, and at V_comp + V_T ln(I_clamp / I_set) when it takes less (V_T = k T / q =
    25.9 mV at the clamp's fixed 27 degC: -60 mV per decade). Below V_comp - 0.3 V the
    clamp carries less than 1e-5 I_set: constant-current mode.
    """

    SECTION: ClassVar[str] = "circuit"
    current: float = scene_key(1.0, unit="A", doc="current_source: set current")
    compliance_voltage: float = scene_key(20.0, unit="V", doc="current_source: the most the supply puts out")
    output_capacitance: float = scene_key(1e-6, unit="F", doc="current_source")
    output_resistance: float = scene_key(1e4, unit="ohm", doc="current_source")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "current", self.current, "A", 0.0, 1e3, low_open=True)
        check_range(name, "compliance_voltage", self.compliance_voltage, "V", 0.0, 1e5, low_open=True)
        check_range(name, "output_capacitance", self.output_capacitance, "F", 0.0, 1.0, low_open=True)
        check_range(name, "output_resistance", self.output_resistance, "ohm", 1e-3, 1e12)

    @property
    def thermal_voltage(self) -> float:
        """V: k T / q of the clamp diode at its fixed temperature."""
        return BOLTZMANN_OVER_CHARGE * (CLAMP_TEMPERATURE + 273.15)

    @property
    def clamp_source_voltage(self) -> float:
        """V: the clamp's voltage source, V_comp less the diode's drop at I_set."""
        return self.compliance_voltage - self.thermal_voltage * math.log1p(self.current / CLAMP_SATURATION_CURRENT)

    def open_voltage(self, load_conductance: float = 0.0) -> float:
        """V: the steady output voltage with the contact open (CV mode if the clamp conducts).

        load_conductance: S, whatever else draws current from the output (leakage).
        Solves I_set = V (1/R_out + G) + IS (exp((V - V_clamp)/V_T) - 1) by bisection.
        """
        g = 1.0 / self.output_resistance + load_conductance
        vt, vc, i_s = self.thermal_voltage, self.clamp_source_voltage, CLAMP_SATURATION_CURRENT
        lo, hi = 0.0, min(self.current / g, self.compliance_voltage + 1.0)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            excess = mid * g + i_s * math.expm1(min((mid - vc) / vt, 700.0)) - self.current
            lo, hi = (mid, hi) if excess < 0 else (lo, mid)
        return 0.5 * (lo + hi)


Source = Union[DCSource, CurrentSource]


@dataclass(frozen=True)
class Wiring:
    """Loop wiring between source and contact: wiring_resistance (ohm) and wiring_inductance
    (H, ~1 uH per metre of loop)."""

    SECTION: ClassVar[str] = "circuit"
    wiring_resistance: float = scene_key(0.01, unit="ohm")
    wiring_inductance: float = scene_key(1e-6, unit="H")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "wiring_resistance", self.wiring_resistance, "ohm", 0.0, 1e3)
        check_range(self.SECTION, "wiring_inductance", self.wiring_inductance, "H", 0.0, 1.0)


@dataclass(frozen=True)
class ResistiveLoad:
    """Resistive load: load_resistance, ohm."""

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(12.0, unit="ohm", doc="changeover: NO's load")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)


@dataclass(frozen=True)
class InductiveLoad:
    """Series R-L load (relay coil, motor winding): load_resistance (ohm), load_inductance (H)."""

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(24.0, unit="ohm")
    load_inductance: float = scene_key(
        10e-3, unit="H", doc="inductive; bridge: the load's inductance, changeover: NO's, in series with "
        "`load_resistance` (0: resistive)")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0, low_open=True)


@dataclass(frozen=True)
class CapacitiveLoad:
    """Inrush load: series load_resistance (ohm), then load_capacitance (F) with bleed_resistance (ohm) across it.

    The bleed resistor is the load's steady consumption and gives the capacitor a DC
    path, so the operating point is defined with the contact open.
    """

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(0.5, unit="ohm")
    load_capacitance: float = scene_key(100e-6, unit="F", doc="capacitive")
    bleed_resistance: float = scene_key(1e3, unit="ohm", doc="capacitive")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)
        check_range(name, "load_capacitance", self.load_capacitance, "F", 0.0, 1.0, low_open=True)
        check_range(name, "bleed_resistance", self.bleed_resistance, "ohm", 1e-3, 1e12)


Load = Union[ResistiveLoad, InductiveLoad, CapacitiveLoad]


@dataclass(frozen=True)
class Snubber:
    """RC snubber across the contact: resistance (ohm) in series with capacitance (F)."""

    SECTION: ClassVar[str] = "circuit.snubber"
    resistance: float = scene_key(100.0, unit="ohm", shown="-")
    capacitance: float = scene_key(100e-9, unit="F", shown="-")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "resistance", self.resistance, "ohm", 0.0, 1e6, low_open=True)
        check_range(self.SECTION, "capacitance", self.capacitance, "F", 0.0, 1e-3, low_open=True)


@dataclass(frozen=True)
class FlybackDiode:
    """Freewheeling diode across an inductive load (ngspice D model: IS in A, N, RS in ohm)."""

    SECTION: ClassVar[str] = "circuit.flyback"
    saturation_current: float = scene_key(1e-9, unit="A", doc="diode I_s")
    emission_coefficient: float = scene_key(1.8, unit="-", doc="diode n")
    series_resistance: float = scene_key(0.05, unit="ohm")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "saturation_current", self.saturation_current, "A", 1e-20, 1e-3, low_open=True)
        check_range(name, "emission_coefficient", self.emission_coefficient, "", 0.5, 5.0)
        check_range(name, "series_resistance", self.series_resistance, "ohm", 0.0, 100.0)


@dataclass(frozen=True)
class SwitchCircuit:
    """A DC switch circuit around one contact. SI units throughout.

    contact_capacitance: parasitic capacitance across the contact, F (contact plus
        wiring stray capacitance). It bounds the opening dv/dt; 0 is refused when an
        inductance is in series with the contact (wiring, or an inductive load without
        a flyback diode) and there is no snubber: the opening would then abort.
    leakage_conductance: conductance of the open contact, S (insulation).
    contact_current_factor: optional ngspice expression g(I) of the contact current I
        (A): the contact conductance is then G(t)/g(I), solved by ngspice (see contact.py).
    coil: the relay's own coil with its drive and suppression (``CoilDrive``), in the same
        ngspice circuit as the contact's loop, or None.

    Example::

        circuit = SwitchCircuit(DCSource(24.0), InductiveLoad(24.0, 10e-3), arc=ArcModel())
        print(circuit.build())        # the netlist
    """

    SECTION: ClassVar[str] = "circuit"
    source: Source = internal(default_factory=DCSource)  # its keys are the source's fields
    load: Load = internal(default_factory=ResistiveLoad)
    wiring: Wiring = internal(default_factory=Wiring)
    contact_capacitance: float = scene_key(
        100e-12, unit="F", doc="across the contact (bridge, changeover: across each of its two)")
    snubber: Snubber | None = scene_key(
        None, unit="-", doc="RC across the contact (changeover: one across each contact), `{resistance = 100.0, capacitance = 100e-9}` (ohm, F; give "
        "both): [circuit.snubber]; omitted or false: none")
    flyback: FlybackDiode | None = scene_key(
        None, unit="-", doc="a diode across an inductive load: true (its defaults) or a table: [circuit.flyback]; "
        "omitted or false: none (bridge: across its inductive load; changeover: one across each inductive throw's load)")
    arc: ArcModel | None = scene_key(
        None, unit="-", doc="the arc model: true (its defaults) or a table: [circuit.arc]; omitted or false: none")
    leakage_conductance: float = scene_key(DEFAULT_LEAKAGE, unit="S", doc="open-contact insulation")
    contact_current_factor: str | None = internal(None)  # from [tribology]'s resistance law
    title: str = internal("switchsim contact circuit")
    coil: CoilDrive | None = internal(None)  # from [coil]

    def __post_init__(self) -> None:
        name = self.SECTION
        if not isinstance(self.source, (DCSource, CurrentSource)):
            raise ValueError(f"SwitchCircuit.source = {self.source!r}: must be a DCSource or CurrentSource")
        if not isinstance(self.wiring, Wiring):
            raise ValueError(f"SwitchCircuit.wiring = {self.wiring!r}: must be a Wiring")
        if not isinstance(self.load, (ResistiveLoad, InductiveLoad, CapacitiveLoad)):
            raise ValueError(
                f"SwitchCircuit.load = {self.load!r}: must be a ResistiveLoad, InductiveLoad or CapacitiveLoad"
            )
        for attr, kind in (("snubber", Snubber), ("flyback", FlybackDiode), ("arc", ArcModel), ("coil", CoilDrive)):
            value = getattr(self, attr)
            if value is not None and not isinstance(value, kind):
                raise ValueError(f"SwitchCircuit.{attr} = {value!r}: must be a {kind.__name__} or None")
        self._check_own_keys()
        if self.flyback is not None and not self._inductive_load:
            raise ValueError(self._flyback_refusal)
        if isinstance(self.source, CurrentSource):
            if not isinstance(self.load, ResistiveLoad):
                raise ValueError(f"SwitchCircuit.load is {type(self.load).__name__}: a CurrentSource drives a "
                                 "ResistiveLoad (the rest of the loop: leads, specimen)")
            closed = self.wiring.wiring_resistance + self.load.load_resistance
            if self.source.compliance_voltage < self.source.current * closed:
                raise ValueError(
                    f"{name}.compliance_voltage = {self.source.compliance_voltage:g} V is below "
                    f"{name}.current x ({name}.wiring_resistance + {name}.load_resistance) = "
                    f"{self.source.current:g} A x {closed:g} ohm = {self.source.current * closed:g} V: the "
                    "supply could not drive the set current even through the closed contact"
                )
        check_range(name, "contact_capacitance", self.contact_capacitance, "F", 0.0, 1e-6)
        series_l = self.wiring.wiring_inductance + (self._load_inductance if self.flyback is None else 0.0)
        if self.contact_capacitance == 0.0 and series_l > 0.0 and self.snubber is None:
            raise ValueError(
                f"{name}.contact_capacitance = 0 F with {series_l!r} H in series with the contact and no snubber: "
                "opening the contact would stop an inductor current in zero time (ngspice aborts, 'timestep too "
                "small'); give the contact's stray capacitance (> 0 F, default 1e-10 F) or a snubber"
            )
        check_range(name, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor(type(self).__name__, self.contact_current_factor)
        if not isinstance(self.title, str) or "\n" in self.title:
            raise ValueError(f"SwitchCircuit.title = {self.title!r}: must be a one-line string")

    def _check_own_keys(self) -> None:
        """A subclass's own keys, checked before the checks here read them."""

    @property
    def _inductive_load(self) -> bool:
        """Whether a flyback diode has an inductive load to go across."""
        return isinstance(self.load, InductiveLoad)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but load is {type(self.load).__name__}: "
                "a flyback diode belongs across an InductiveLoad")

    @property
    def _load_inductance(self) -> float:
        """H: the largest load inductance in series with a contact."""
        return float(self.load.load_inductance) if isinstance(self.load, InductiveLoad) else 0.0

    def _place_flyback(self, c: Circuit, node: str, name: str = "flyback") -> None:
        """The flyback diode from ground to ``node`` (the load's top), its model once."""
        d = self.flyback
        c.D(name, c.gnd, node, model="switchsim_flyback")
        if "switchsim_flyback" not in c.model_names:
            c.model("switchsim_flyback", "D", IS=float(d.saturation_current), N=float(d.emission_coefficient),
                    RS=float(d.series_resistance))

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The circuit's one contact, as a block (unnamed: its elements keep their names)."""
        return (ContactBlock("", NODE_A, NODE_B, self.leakage_conductance, self.contact_current_factor, self.arc),)

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        """The relay's own coil, when the circuit drives it (``coil``)."""
        return () if self.coil is None else (self.coil.coil,)

    @property
    def probes(self) -> Probes:
        return Probes(self.contacts, load_current=f"{LOAD_PROBE}#branch", coils=self.coils)

    def build(self) -> Circuit:
        """The PySpice circuit (``print`` it for the netlist)."""
        c = Circuit(self.title)
        gnd = c.gnd
        self._place_supply(c, NODE_A)
        self._place_switch(c)
        c.V(LOAD_PROBE[1:], NODE_B, "load", 0)
        load = self.load
        if isinstance(load, ResistiveLoad):
            c.R("load", "load", gnd, float(load.load_resistance))
        elif isinstance(load, InductiveLoad):
            c.R("load", "load", "load_l", float(load.load_resistance))
            c.L("load", "load_l", gnd, float(load.load_inductance))
        else:
            c.R("load", "load", "load_c", float(load.load_resistance))
            c.C("load", "load_c", gnd, float(load.load_capacitance))
            c.R("bleed", "load_c", gnd, float(load.bleed_resistance))
        if self.flyback is not None:
            self._place_flyback(c, NODE_B)
        if self.coil is not None:
            self.coil.add_to(c)
        return c

    def _place_supply(self, c: Circuit, end: str, probe: str | None = None) -> None:
        """The source and the wiring in series, from the supply to node ``end``; with ``probe``
        (a voltage source's name), a 0 V probe of the supply's current right at the source."""
        gnd = c.gnd
        source = self.source
        if isinstance(source, CurrentSource):
            c.I("source", gnd, "src", float(source.current))
            c.R("source_out", "src", gnd, float(source.output_resistance))
            c.C("source_out", "src", gnd, float(source.output_capacitance))
            c.D("clamp", "src", "clamp", model=CLAMP_MODEL, temperature=CLAMP_TEMPERATURE)
            c.model(CLAMP_MODEL, "D", IS=CLAMP_SATURATION_CURRENT, N=1.0, RS=0.0)
            c.V("clamp", "clamp", gnd, float(source.clamp_source_voltage))
            r_source = 0.0
        else:
            c.V("source", "src", gnd, source.spice_value())
            r_source = source.source_resistance
        series = [
            (kind, name, value)
            for kind, name, value in (
                ("R", "source", r_source),
                ("R", "wire", self.wiring.wiring_resistance),
                ("L", "wire", self.wiring.wiring_inductance),
            )
            if value > 0
        ]
        if not series:
            # ngspice rejects a 0 ohm resistor; a 0 V source keeps the node names.
            series = [("V", "wire_short", 0.0)]
        inner_nodes = iter(("wire", "wire_l"))
        node = "src"
        if probe is not None:
            c.V(probe[1:], node, SUPPLY_NODE, 0)
            node = SUPPLY_NODE
        for i, (kind, name, value) in enumerate(series):
            next_node = end if i == len(series) - 1 else next(inner_nodes)
            getattr(c, kind)(name, node, next_node, float(value))
            node = next_node

    def _place_switch(self, c: Circuit) -> None:
        """What sits between NODE_A and NODE_B: the contact, its capacitance, the snubber, the arc."""
        add_contact(c, NODE_A, NODE_B, self.leakage_conductance, self.contact_current_factor)
        if self.contact_capacitance > 0:
            c.C("contact", NODE_A, NODE_B, float(self.contact_capacitance))
        if self.snubber is not None:
            c.R("snubber", NODE_A, "snubber", float(self.snubber.resistance))
            c.C("snubber", "snubber", NODE_B, float(self.snubber.capacitance))
        if self.arc is not None:
            add_arc(c, self.arc, NODE_A, NODE_B)



# --- a double-break bridge: two contacts in series in one loop ------------------------------

BRIDGE_NODE = "bridge"  # the moving bridge itself, between its two contacts


@dataclass(frozen=True)
class BridgeCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose switch is a double-break bridge: two contacts in series in
    the one loop, the moving bridge between them (SI units)::

        ... Lwire -- contact_a =CONTACT_<n0>= bridge =CONTACT_<n1>= contact_b --Vload-- load ...
                   |--Ccontact_<n0>--|      |--Ccontact_<n1>--|    (each contact's stray capacitance)
                   |--arc path <n0>--|      |--arc path <n1>--|    (each its own arc, optional)
                   |--Rsnubber--snubber--Csnubber-------------|    (optional, across the whole bridge)

    contact_names: the two contacts' names, in the loop's order from the supply (each a
        block name, circuit.names: the coupled scene gives its two electrical [[fixed]]
        contacts' names); each is its own ``ContactBlock`` with its own conductance and gap
        inputs, arc and result columns (``contact_voltage_<name>``, ...).
    contact_capacitance: F, across each contact (not across the bridge: in series two
        such give half of it across the whole).
    load_inductance: H, the load's inductance in series with its resistance (0: resistive; a
        contactor's motor or coil, AC-3/DC-3 duty): Lload below Rload (node ``load_l``), as
        an ``InductiveLoad``'s; ``flyback`` is then a diode from ground to ``contact_b``,
        across the load and its probe (as the one-contact template's: below the probe, the
        probe's nA open current would come out of a node where the diode carries amperes).
    Every other field is SwitchCircuit's; the arc model (``arc``) is each contact's, so at
    a break the two arcs in series hold twice its burning voltage and share the inductor's
    energy.
    """

    contact_names: tuple = internal(("a", "b"))  # the scene's two electrical [[fixed]] contacts
    load_inductance: float = scene_key(
        0.0, unit="H", doc="bridge: the load's inductance, in series with `load_resistance` (0: resistive)")

    def __post_init__(self) -> None:
        super().__post_init__()
        names = self.contact_names
        if not isinstance(names, (tuple, list)) or len(names) != 2:
            raise ValueError(f"BridgeCircuit.contact_names = {names!r}: the bridge's two contacts, two names")
        for name in names:
            check_block_name("BridgeCircuit.contact_names", name)
            if not name:
                raise ValueError("BridgeCircuit.contact_names: each of the bridge's contacts is named")
        if names[0].lower() == names[1].lower():
            raise ValueError(f"BridgeCircuit.contact_names = {tuple(names)!r}: two distinct names (SPICE ignores case)")
        object.__setattr__(self, "contact_names", tuple(names))

    def _check_own_keys(self) -> None:
        # (before SwitchCircuit's checks read the load's inductance)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0)
        if self.load_inductance > 0.0 and not isinstance(self.load, ResistiveLoad):
            raise ValueError(f"{self.SECTION}.load_inductance = {self.load_inductance!r} with a "
                             f"{type(self.load).__name__}: the bridge's load_inductance goes in series with a "
                             "ResistiveLoad (or give the InductiveLoad alone)")

    @property
    def _inductive_load(self) -> bool:
        return self.load_inductance > 0.0 or isinstance(self.load, InductiveLoad)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but the bridge's load is resistive (load_inductance = "
                f"{self.load_inductance!r}): a flyback diode belongs across an inductive load")

    @property
    def _load_inductance(self) -> float:
        return float(self.load_inductance) if self.load_inductance > 0.0 else super()._load_inductance

    def build(self) -> Circuit:
        if self.load_inductance > 0.0:  # the one-contact template's R-L load, the same netlist
            load = InductiveLoad(self.load.load_resistance, self.load_inductance)
            return replace(self, load=load, load_inductance=0.0).build()
        return super().build()

    #: how the contacts are arranged in the loop: the current flows only while both are closed
    arrangement = "series"

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The bridge's two contacts, in the loop's order."""
        (n0, n1), args = self.contact_names, (self.leakage_conductance, self.contact_current_factor, self.arc)
        return (ContactBlock(n0, NODE_A, BRIDGE_NODE, *args), ContactBlock(n1, BRIDGE_NODE, NODE_B, *args))

    def _place_switch(self, c: Circuit) -> None:
        for block in self.contacts:
            add_contact(c, block.node_a, block.node_b, self.leakage_conductance, self.contact_current_factor,
                        block.name)
            if self.contact_capacitance > 0:
                c.C(block.element("Ccontact")[1:], block.node_a, block.node_b, float(self.contact_capacitance))
            if self.arc is not None:
                add_arc(c, self.arc, block.node_a, block.node_b, block.name)
        if self.snubber is not None:
            c.R("snubber", NODE_A, "snubber", float(self.snubber.resistance))
            c.C("snubber", "snubber", NODE_B, float(self.snubber.capacitance))


# --- a changeover (form C): the moving contact between a normally-open and a normally-closed ---

SUPPLY_NODE = "supply"  # between a probe at the source and the series elements (_place_supply)


@dataclass(frozen=True)
class ChangeoverCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose switch is a changeover (form C): the supply feeds the moving
    contact (the common), which connects it to the normally-open (NO) or the normally-closed
    (NC) fixed contact, each throw with its own resistive load to ground, as a relay's form C
    contact is wired and tested (SI units)::

        Vsource src 0; src --Vload-- supply --Rsource-- ... Lwire -- contact_a =CONTACT_<no>= throw_<no> --Vload_<no>-- load_<no> --Rload_<no>-- [load_<no>_l --Lload_<no>--] 0
                                                                   |       =CONTACT_<nc>= throw_<nc> --Vload_<nc>-- load_<nc> --Rload_<nc>-- [load_<nc>_l --Lload_<nc>--] 0
        (an inductive throw: Lload_<n> below its resistor, the flyback Dflyback_<n> from 0 to throw_<n>)
        across each contact: Ccontact_<n>, its arc path, the snubber (Rsnubber_<n>, Csnubber_<n>) when given

    contact_names: (NO's name, NC's name): each contact a block name (circuit.names; the
        coupled scene gives its two electrical [[fixed]] contacts named NO and NC, as
        written), each its own ``ContactBlock`` with its own conductance and gap inputs, arc
        and result columns (``contact_voltage_<name>``, ...). NO is the first contact.
    load: NO's load, a ResistiveLoad (ohm).
    nc_load_resistance: ohm, NC's load; None: the same as NO's.
    load_inductance: H, NO's load inductance in series with its resistance (0: resistive;
        a valve or motor winding, a contactor's coil).
    nc_load_inductance: H, NC's; None: the same as NO's.
    flyback: a diode across each inductive throw's load (``FlybackDiode``), or None; only
        with an inductive throw.
    contact_capacitance: F, across each contact; the snubber, when given, across each too.
    The load probe ``Vload`` sits at the source (in series with the supply, the wiring
    ending on the common, contact_a): ``load_current`` is the supply's current through the
    moving contact, NO's and NC's together; each throw's own load current
    is ``i(Vload_<name>)`` (a probe). Every other field is SwitchCircuit's; the arc model is
    each contact's. Both throws open: the supply sees only the contacts' leakage and stray
    capacitance.
    """

    contact_names: tuple = internal(("NO", "NC"))  # the scene's electrical [[fixed]] contacts NO and NC
    nc_load_resistance: float | None = scene_key(
        None, unit="ohm", doc="changeover: NC's load (> 0); omitted: the same as `load_resistance`")
    load_inductance: float = scene_key(
        0.0, unit="H", doc="changeover: NO's load inductance, in series with `load_resistance` (0: resistive)")
    nc_load_inductance: float | None = scene_key(
        None, unit="H", doc="changeover: NC's load inductance (0: resistive); omitted: the same as `load_inductance`")

    #: how the contacts are arranged: each in its own branch, each closed while it touches
    arrangement = "changeover"

    def __post_init__(self) -> None:
        super().__post_init__()
        name = "ChangeoverCircuit"
        names = self.contact_names
        if not isinstance(names, (tuple, list)) or len(names) != 2:
            raise ValueError(f"{name}.contact_names = {names!r}: the changeover's two contacts, (NO, NC)")
        for n in names:
            check_block_name(f"{name}.contact_names", n)
            if not n:
                raise ValueError(f"{name}.contact_names: each of the changeover's contacts is named")
        if names[0].lower() == names[1].lower():
            raise ValueError(f"{name}.contact_names = {tuple(names)!r}: two distinct names (SPICE ignores case)")
        object.__setattr__(self, "contact_names", tuple(names))
        if not isinstance(self.load, ResistiveLoad):
            raise ValueError(f"{name}.load is {type(self.load).__name__}: a changeover's throws each drive a "
                             "ResistiveLoad")
        if isinstance(self.source, CurrentSource):
            raise ValueError(f"{name}.source is a CurrentSource: a changeover is fed by a voltage source (DCSource)")
        if self.nc_load_resistance is not None:
            check_range(self.SECTION, "nc_load_resistance", self.nc_load_resistance, "ohm", 0.0, 1e9, low_open=True)

    def _check_own_keys(self) -> None:
        # (the load inductances are checked before SwitchCircuit's checks read them)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0)
        if self.nc_load_inductance is not None:
            check_range(self.SECTION, "nc_load_inductance", self.nc_load_inductance, "H", 0.0, 100.0)

    @property
    def load_inductances(self) -> tuple[float, float]:
        """H: (NO's load inductance, NC's)."""
        nc = self.load_inductance if self.nc_load_inductance is None else self.nc_load_inductance
        return float(self.load_inductance), float(nc)

    @property
    def _inductive_load(self) -> bool:
        return any(x > 0.0 for x in self.load_inductances)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but both throws are resistive (load_inductance = "
                f"{self.load_inductance!r}, nc_load_inductance = {self.nc_load_inductance!r}): a flyback diode belongs "
                "across an inductive load")

    @property
    def _load_inductance(self) -> float:
        return max(self.load_inductances)

    @property
    def load_resistances(self) -> tuple[float, float]:
        """ohm: (NO's load, NC's load)."""
        nc = self.load.load_resistance if self.nc_load_resistance is None else self.nc_load_resistance
        return float(self.load.load_resistance), float(nc)

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """(NO, NC): each from the common to its throw."""
        args = (self.leakage_conductance, self.contact_current_factor, self.arc)
        # each throw's own load current (its probe Vload_<name>, build): its mu(I), its columns
        return tuple(ContactBlock(n, NODE_A, f"throw_{n.lower()}", *args, load_probe=f"Vload_{n.lower()}")
                     for n in self.contact_names)

    def build(self) -> Circuit:
        c = Circuit(self.title)
        gnd = c.gnd
        # The load probe sits at the source, not between the wiring and the common: there the
        # node between it and Lwire carried no conductance, only the two branch currents, and
        # in the pivot order ngspice fixes at the first time point (it reorders only at an
        # exactly zero pivot) the factors grew at the femtosecond steps of a make (Lwire's L/h
        # 1e9 ohm): an entry of 3.8e15, the probe's 0 V violated by up to 32 mV, Newton's test
        # failed at node "common" and a 5 V make at RELTOL 1e-6 aborted (docs/circuit.md,
        # section 7). The wiring now ends on the common, as in the one-contact template.
        self._place_supply(c, NODE_A, probe=LOAD_PROBE)
        for block, resistance, inductance in zip(self.contacts, self.load_resistances, self.load_inductances):
            add_contact(c, block.node_a, block.node_b, self.leakage_conductance, self.contact_current_factor,
                        block.name)
            n = block.name.lower()
            if self.contact_capacitance > 0:
                c.C(block.element("Ccontact")[1:], block.node_a, block.node_b, float(self.contact_capacitance))
            if self.snubber is not None:
                c.R(f"snubber_{n}", block.node_a, f"snubber_{n}", float(self.snubber.resistance))
                c.C(f"snubber_{n}", f"snubber_{n}", block.node_b, float(self.snubber.capacitance))
            if self.arc is not None:
                add_arc(c, self.arc, block.node_a, block.node_b, block.name)
            c.V(f"load_{n}", block.node_b, f"load_{n}", 0)
            if inductance > 0.0:
                c.R(f"load_{n}", f"load_{n}", f"load_{n}_l", resistance)
                c.L(f"load_{n}", f"load_{n}_l", gnd, inductance)
                if self.flyback is not None:
                    # across the load and its probe (as the one-contact template's): below the
                    # probe, the probe's branch current, a few nA, came out of the KCL of a node
                    # where the diode carries amperes, and its Newton noise (~1e-7 A) never met
                    # ABSTOL: "timestep too small" at the freewheeling throw's break
                    self._place_flyback(c, block.node_b, f"flyback_{n}")
            else:
                c.R(f"load_{n}", f"load_{n}", gnd, resistance)
        if self.coil is not None:
            self.coil.add_to(c)
        return c


# --- a switch read by a microcontroller input ---------------------------------------------

PULLS = ("up", "down")
MCU_PIN = "pin"  # the input pin's node
MCU_SWITCH_NODE = "sw"  # the switch node, between the pull resistor and the contact
MCU_SUPPLY_NODE = "vcc"


@dataclass(frozen=True)
class McuInput:
    """A pushbutton or switch read by a microcontroller input pin, with its RC filter. SI units.

    voltage: the logic supply Vcc, V (an ideal rail: its impedance is far below any pull
        resistor).
    pull: "up": a pull resistor from Vcc to the switch node and the contact from the switch
        node to ground (active low, the usual wiring); "down": the contact from Vcc to the
        switch node and the pull resistor to ground (active high).
    pull_resistance: ohm, the pull-up (or pull-down) resistor, > 0.
    series_resistance: ohm, from the switch node to the pin (0: none); it sets how fast the
        closing contact discharges the input capacitor and limits that current.
    input_capacitance: F, from the pin to ground: the filter capacitor plus the pin's own.
    logic_low, logic_high: V, the input's Schmitt thresholds (0 < low < high < Vcc): the
        input reads low once the pin falls below logic_low and high once it rises above
        logic_high (defaults 0.3 and 0.7 of 3.3 V, the CMOS V_IL / V_IH); the scene's logic
        metric reads them (coupling.core.logic).
    contact_capacitance: F, across the contact (stray capacitance of the switch and leads).
    leakage_conductance: S, the open contact's conductance.
    contact_current_factor: optional ngspice expression g(I) of the contact current (A).

    The netlist (pull = "up"; "down" swaps the contact and the pull resistor's places)::

        Vsource vcc 0 Vcc
        Vload   vcc pull 0                 (0 V probe: the pull resistor's current, the loop current)
        Rpull   pull sw R_pull
        contact sw 0                       (circuit.contact; Ccontact sw 0 across it)
        Rseries sw pin R_series            (Vseries sw pin 0 when R_series = 0)
        Cinput  pin 0 C_in

    With the contact's closed resistance R_c, the pin relaxes exponentially after each make
    and break (contact capacitance neglected, C_contact << C_in): after a break towards the
    open level (Vcc pulled up, 0 pulled down) with tau = (R_pull + R_series) C_in; after a
    make towards the divider R_pull : R_c (Vcc R_c / (R_pull + R_c) pulled up) with
    tau = (R_series + R_pull R_c / (R_pull + R_c)) C_in (``break_time_constant``,
    ``make_time_constant``).
    """

    SECTION: ClassVar[str] = "circuit"
    voltage: float = scene_key(3.3, unit="V")
    pull: str = scene_key(
        "up", unit="-", doc='mcu_input: "up" (pull resistor to Vcc, the contact to ground: active low) or "down" '
        "(pull resistor to ground, the contact to Vcc)")
    pull_resistance: float = scene_key(10e3, unit="ohm", doc="mcu_input: the pull-up (pull-down) resistor, > 0")
    series_resistance: float = scene_key(1e3, unit="ohm", doc="mcu_input: from the switch node to the pin (0: none)")
    input_capacitance: float = scene_key(
        100e-9, unit="F", doc="mcu_input: from the pin to ground (the filter C plus the pin's own)")
    logic_low: float = scene_key(
        0.99, unit="V", doc="mcu_input: the input reads low below it (Schmitt threshold; the default of "
        "`[metrics] logic`)")
    logic_high: float = scene_key(
        2.31, unit="V", doc="mcu_input: the input reads high above it (> `logic_low`, < `voltage`)")
    contact_capacitance: float = scene_key(5e-12, unit="F")
    leakage_conductance: float = scene_key(DEFAULT_LEAKAGE, unit="S")
    contact_current_factor: str | None = internal(None)
    title: str = internal("switchsim mcu input")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "voltage", self.voltage, "V", 0.0, 1e3, low_open=True)
        if isinstance(self.pull, (list, dict)) or self.pull not in PULLS:
            raise ValueError(f"{name}.pull = {self.pull!r}: allowed values are 'up' (pull-up to Vcc, contact "
                             "to ground) and 'down' (pull-down to ground, contact to Vcc)")
        check_range(name, "pull_resistance", self.pull_resistance, "ohm", 0.0, 1e9, low_open=True)
        check_range(name, "series_resistance", self.series_resistance, "ohm", 0.0, 1e9)
        check_range(name, "input_capacitance", self.input_capacitance, "F", 0.0, 1e-2)
        check_range(name, "logic_low", self.logic_low, "V", 0.0, 1e3, low_open=True)
        check_range(name, "logic_high", self.logic_high, "V", 0.0, 1e3, low_open=True)
        if self.logic_low >= self.logic_high:
            raise ValueError(f"{name}.logic_low = {self.logic_low:g} V must be below {name}.logic_high = "
                             f"{self.logic_high:g} V (the Schmitt thresholds: low < high)")
        if self.logic_high >= self.voltage:
            raise ValueError(f"{name}.logic_high = {self.logic_high:g} V must be below {name}.voltage = "
                             f"{self.voltage:g} V: the pin never rises above the supply")
        check_range(name, "contact_capacitance", self.contact_capacitance, "F", 0.0, 1e-6)
        check_range(name, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor(type(self).__name__, self.contact_current_factor)
        if not isinstance(self.title, str) or "\n" in self.title:
            raise ValueError(f"McuInput.title = {self.title!r}: must be a one-line string")

    @property
    def nodes(self) -> tuple[str, str]:
        """(node_a, node_b) of the contact: (sw, 0) pulled up, (vcc, sw) pulled down."""
        return (MCU_SWITCH_NODE, "0") if self.pull == "up" else (MCU_SUPPLY_NODE, MCU_SWITCH_NODE)

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The switch, as the circuit's one (unnamed) contact."""
        return (ContactBlock("", *self.nodes, self.leakage_conductance, self.contact_current_factor),)

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        return ()

    @property
    def probes(self) -> Probes:
        return Probes(self.contacts, load_current=f"{LOAD_PROBE}#branch")

    @property
    def break_time_constant(self) -> float:
        """s: the pin's time constant while the contact is open, (R_pull + R_series) C_in."""
        return (self.pull_resistance + self.series_resistance) * self.input_capacitance

    def make_time_constant(self, closed_resistance: float) -> float:
        """s: the pin's time constant while the contact is closed with ``closed_resistance``
        (ohm): (R_series + R_pull || R_c) C_in."""
        parallel = self.pull_resistance * closed_resistance / (self.pull_resistance + closed_resistance)
        return (self.series_resistance + parallel) * self.input_capacitance

    def build(self) -> Circuit:
        """The PySpice circuit (``print`` it for the netlist)."""
        c = Circuit(self.title)
        gnd = c.gnd
        c.V("source", MCU_SUPPLY_NODE, gnd, float(self.voltage))
        node_a, node_b = self.nodes
        if self.pull == "up":
            c.V(LOAD_PROBE[1:], MCU_SUPPLY_NODE, "pull", 0)
            c.R("pull", "pull", MCU_SWITCH_NODE, float(self.pull_resistance))
        else:
            c.R("pull", MCU_SWITCH_NODE, "pull", float(self.pull_resistance))
            c.V(LOAD_PROBE[1:], "pull", gnd, 0)
        add_contact(c, node_a, node_b, self.leakage_conductance, self.contact_current_factor)
        if self.contact_capacitance > 0:
            c.C("contact", node_a, node_b, float(self.contact_capacitance))
        if self.series_resistance > 0:
            c.R("series", MCU_SWITCH_NODE, MCU_PIN, float(self.series_resistance))
        else:  # ngspice rejects a 0 ohm resistor
            c.V("series", MCU_SWITCH_NODE, MCU_PIN, 0)
        if self.input_capacitance > 0:
            c.C("input", MCU_PIN, gnd, float(self.input_capacitance))
        return c


# --- a fault: the load shorted at a time ---------------------------------------------------

FAULT_NODE = "fault_g"
FAULT_OFF = 1e-9  # S: the fault path before the fault (an insulation's leakage)


@dataclass(frozen=True)
class ShortCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose load terminals are shorted at a time: the fault current that
    flows through a closed contact when the load side fails (SI units).

    fault_time: s, when the short starts; fault_resistance: ohm, the short's resistance (the
    fault loop is then source, wiring, contact and this, the load in parallel); fault_rise: s,
    over which the short's conductance ramps from 1e-9 S to 1/fault_resistance (a bolted
    fault: a short rise; the wiring's L/R shapes the current as well). The steady fault
    current through a closed contact of resistance R_c is E / (R_source + R_wire + R_c +
    R_fault || R_load) (``fault_current``). Every other field is SwitchCircuit's.

    The netlist adds, across the load (node ``load`` to ground, after the load probe, so the
    load current is the loop current with the fault's share)::

        Vfault_g fault_g 0 PWL(0 1e-9 t_f 1e-9 t_f+rise 1/R_f)   (the short's conductance, S, as a voltage)
        Bfault   load 0 I=V(load)*V(fault_g)
    """

    fault_time: float = scene_key(1e-3, unit="s", doc="short_circuit: when the load is shorted")
    fault_resistance: float = scene_key(
        0.01, unit="ohm", doc="short_circuit: the short's resistance (the fault current E / (R_source + R_wire + "
        "R_c + R_fault || R_load))")
    fault_rise: float = scene_key(
        1e-6, unit="s", doc="short_circuit: over which the short's conductance ramps in (> 0)")

    def __post_init__(self) -> None:
        super().__post_init__()
        name = self.SECTION
        check_range(name, "fault_time", self.fault_time, "s", 0.0, 1e3)
        check_range(name, "fault_resistance", self.fault_resistance, "ohm", 1e-6, 1e6)
        check_range(name, "fault_rise", self.fault_rise, "s", 0.0, 10.0, low_open=True)
        if isinstance(self.source, CurrentSource):
            raise ValueError(f"ShortCircuit.source is a CurrentSource: a fault is a short behind a voltage source "
                             "(DCSource), whose current only the loop's impedance limits")

    def fault_current(self, contact_resistance: float = 0.0) -> float:
        """A: the steady current through the closed contact (``contact_resistance``, ohm) with
        the short in place (inductances carry no voltage then; an inductive load's L is a short);
        with an AC source the amplitude its peak voltage drives, the inductances neglected."""
        load = self.load.load_resistance
        parallel = load * self.fault_resistance / (load + self.fault_resistance)
        loop = self.source.source_resistance + self.wiring.wiring_resistance + contact_resistance + parallel
        return self.source.amplitude / loop

    def fault_vertices(self) -> list[tuple[float, float]]:
        """(time s, conductance S) of the short's PWL."""
        on = 1.0 / self.fault_resistance
        if self.fault_time <= 0.0:
            return [(0.0, FAULT_OFF), (self.fault_rise, on)]
        return [(0.0, FAULT_OFF), (self.fault_time, FAULT_OFF), (self.fault_time + self.fault_rise, on)]

    def build(self) -> Circuit:
        c = super().build()
        pwl = " ".join(f"{t!r} {g!r}" for t, g in self.fault_vertices())
        c.V(FAULT_NODE, FAULT_NODE, c.gnd, f"PWL({pwl})")
        c.B("fault", "load", c.gnd, current_expression=f"V(load)*V({FAULT_NODE})")
        return c
