"""A relay coil's drive: the supply switched on and off by a low-side driver, with the coil's suppression.

Netlist (``CoilDrive.add_to``; nodes ``coil_supply``, ``coil_drv``)::

    Vcoil_supply coil_supply 0 V                     (the coil supply, V)
    <the coil block between coil_supply and coil_drv> (circuit.blocks.CoilBlock)
    Vcoil_switch coil_switch 0 PWL(...)              (the driver's conductance, S, as a voltage)
    Bcoil_switch coil_drv 0 I=V(coil_drv)*(V(coil_switch)+1e-9)
    Ccoil_switch coil_drv 0 C_sw                     (the driver's output capacitance)
    Dcoil_clamp  0 coil_drv (BV = V_br)              (the driver's avalanche: what stops an unsuppressed coil)
    suppression across the coil:
      "diode": Dcoil_supp coil_drv coil_supply       (freewheeling: the coil voltage held near -0.7 V)
      "zener": Dcoil_supp coil_drv coil_z ; Dcoil_zener coil_supply coil_z (BV = V_z)
                                                     (clamped at -(V_z + 0.7 V): fast release, driver safe)
      "rc":    Rcoil_supp coil_supply coil_rc R ; Ccoil_supp coil_rc coil_drv C
      "none":  the driver's capacitance, then its avalanche clamp, take the coil's current

The driver is off at t = 0 (the operating point has the coil unpowered), switches on at
``on_time`` and off at ``off_time`` (s), its conductance ramping linearly over
``edge_time`` between 1e-9 S and 1/``switch_resistance``. Known from relay
application notes and reproduced here: a diode holds the coil current, which decays with
the coil's L/R, so the armature releases late and slowly (and the contact's break arc
burns longer); a zener (in series with a diode) clamps the coil at -(V_z + V_d), the
current falls ~(V_z + V_d)/L, fast; an RC rings.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

from PySpice.Spice.Netlist import Circuit

from .blocks import CoilBlock
from .probes import Probes
from .validation import check_range, internal, scene_key

SUPPRESSIONS = ("none", "diode", "zener", "rc")
SUPPLY_NODE = "coil_supply"
DRIVER_NODE = "coil_drv"
OFF_CONDUCTANCE = 1e-9  # S: the open driver
DIODE_MODEL = "switchsim_coil_diode"
ZENER_MODEL = "switchsim_coil_zener"
CLAMP_MODEL = "switchsim_coil_clamp"


@dataclass(frozen=True)
class CoilDrive:
    """A coil, its supply and its low-side driver, and the suppression across it (SI units).

    coil: the coil (circuit.blocks.CoilBlock; its nodes are set here: coil_supply, coil_drv).
    voltage: V, the coil supply.
    on_time, off_time: s, when the driver switches on and off (off_time None: it stays on).
    suppression: "none", "diode", "zener" (a diode in series with a zener) or "rc".
    zener_voltage: V, the zener's breakdown ("zener").
    rc_resistance, rc_capacitance: ohm, F ("rc").
    switch_resistance: ohm, the driver on; switch_capacitance: F, its output capacitance;
    switch_breakdown: V, its avalanche voltage; edge_time: s, its switching time.
    diode_saturation_current: A, IS of the suppression diodes (N = 1.8, RS = 0.05 ohm).
    """

    SECTION: ClassVar[str] = "coil"  # the scene section of its keys: [coil] voltage, ... (errors name coil.<key>)
    coil: CoilBlock = scene_key(keys=(  # [coil] resistance and turns make the coil (with [magnet])
        ("resistance", "ohm", 'the winding; needed except with `magnet.model = "plunger_solenoid"` (10)'),
        ("turns", "-", 'the winding; needed with `magnet.model = "flux_tubes"` (plunger_solenoid: 957); not with '
                       '"table"')))
    voltage: float = scene_key(12.0, unit="V", doc="the coil supply")
    on_time: float = scene_key(0.0, unit="s", doc="the driver switches on (0: a step at the start)")
    off_time: Optional[float] = scene_key(None, unit="s", doc="the driver switches off; omitted: stays on")
    suppression: str = scene_key(
        "none", unit="-",
        doc='"none" (the driver avalanches at `switch_breakdown`), "diode" (freewheeling), "zener" (a diode in '
            'series with a zener), "rc"')
    zener_voltage: float = scene_key(
        24.0, unit="V", doc='"zener" only; < `switch_breakdown` - `voltage` (else the driver avalanches before it clamps)')
    rc_resistance: float = scene_key(100.0, unit="ohm", doc='"rc" only')
    rc_capacitance: float = scene_key(100e-9, unit="F", doc='"rc" only')
    switch_resistance: float = scene_key(0.1, unit="ohm", doc="the driver when on")
    switch_capacitance: float = scene_key(100e-12, unit="F", doc="the driver's output capacitance")
    switch_breakdown: float = scene_key(100.0, unit="V", doc="the driver's avalanche voltage, > `voltage`")
    edge_time: float = scene_key(1e-6, unit="s", doc="the driver's switching time")
    diode_saturation_current: float = internal(1e-9)

    def __post_init__(self) -> None:
        name = self.SECTION
        if not isinstance(self.coil, CoilBlock):
            raise ValueError(f"{name}.coil = {self.coil!r}: must be a CoilBlock")
        if (self.coil.node_p, self.coil.node_n) != (SUPPLY_NODE, DRIVER_NODE):
            raise ValueError(f"{name}.coil: its nodes are {SUPPLY_NODE!r} and {DRIVER_NODE!r} (got "
                             f"{self.coil.node_p!r}, {self.coil.node_n!r})")
        check_range(name, "voltage", self.voltage, "V", 0.0, 1e4, low_open=True)
        check_range(name, "on_time", self.on_time, "s", 0.0, 1e3)
        check_range(name, "edge_time", self.edge_time, "s", 0.0, 1e-2, low_open=True)  # (off_time needs it)
        if self.off_time is not None:
            check_range(name, "off_time", self.off_time, "s", 0.0, 1e3)
            if self.off_time < self.on_time + self.edge_time:
                raise ValueError(f"{name}.off_time = {self.off_time:g} s: must come after on_time + edge_time = "
                                 f"{self.on_time + self.edge_time:g} s")
        if self.suppression not in SUPPRESSIONS:
            raise ValueError(f"{name}.suppression = {self.suppression!r}: allowed values are "
                             f"{', '.join(repr(s) for s in SUPPRESSIONS)}")
        check_range(name, "zener_voltage", self.zener_voltage, "V", 0.0, 1e4, low_open=True)
        check_range(name, "rc_resistance", self.rc_resistance, "ohm", 0.0, 1e7, low_open=True)
        check_range(name, "rc_capacitance", self.rc_capacitance, "F", 0.0, 1e-2, low_open=True)
        check_range(name, "switch_resistance", self.switch_resistance, "ohm", 1e-6, 1e6)
        check_range(name, "switch_capacitance", self.switch_capacitance, "F", 0.0, 1e-3, low_open=True)
        check_range(name, "switch_breakdown", self.switch_breakdown, "V", 0.0, 1e5, low_open=True)
        if self.switch_breakdown <= self.voltage:
            raise ValueError(f"{name}.switch_breakdown = {self.switch_breakdown:g} V: must exceed the supply "
                             f"{name}.voltage = {self.voltage:g} V (the driver would conduct while off)")
        if self.suppression == "zener" and self.voltage + self.zener_voltage >= self.switch_breakdown:
            # the driver's node reaches voltage + V_z + V_d before the zener conducts: the
            # driver's avalanche clamps first and the zener is never in the circuit
            raise ValueError(f"{name}.zener_voltage = {self.zener_voltage:g} V: the driver avalanches at "
                             f"{name}.switch_breakdown = {self.switch_breakdown:g} V before the zener clamps "
                             f"(supply {name}.voltage = {self.voltage:g} V); allowed zener_voltage < "
                             f"switch_breakdown - voltage = {self.switch_breakdown - self.voltage:g} V")
        check_range(name, "diode_saturation_current", self.diode_saturation_current, "A", 1e-20, 1e-3,
                    low_open=True)

    def switch_vertices(self) -> list[tuple[float, float]]:
        """(time s, conductance S) of the driver's PWL (it holds its last value after the last):
        off at t = 0 (the circuit's operating point has the coil unpowered), switched on at
        ``on_time`` (0: a step at the start) and off at ``off_time``, each over ``edge_time``."""
        on = 1.0 / self.switch_resistance
        points = [(0.0, OFF_CONDUCTANCE)]
        if self.on_time > 0.0:
            points.append((self.on_time, OFF_CONDUCTANCE))
        points.append((self.on_time + self.edge_time, on))
        if self.off_time is not None:
            points += [(self.off_time, on), (self.off_time + self.edge_time, OFF_CONDUCTANCE)]
        return points

    @property
    def contacts(self) -> tuple:
        """A coil's drive alone holds no contact (an actuator)."""
        return ()

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        return (self.coil,)

    @property
    def probes(self) -> Probes:
        return Probes((), coils=self.coils)

    def build(self, title: str = "switchsim coil drive") -> Circuit:
        """The coil's drive alone as a PySpice circuit (an actuator without a contact circuit)."""
        circuit = Circuit(title)
        self.add_to(circuit)
        return circuit

    def add_to(self, circuit: Circuit) -> None:
        """Place the supply, the coil, the driver and the suppression on a PySpice circuit."""
        gnd = circuit.gnd
        circuit.V("coil_supply", SUPPLY_NODE, gnd, float(self.voltage))
        self.coil.add_to(circuit)
        pwl = " ".join(f"{t!r} {g!r}" for t, g in self.switch_vertices())
        circuit.V("coil_switch", "coil_switch", gnd, f"PWL({pwl})")
        circuit.B("coil_switch", DRIVER_NODE, gnd,
                  current_expression=f"V({DRIVER_NODE})*(V(coil_switch)+{OFF_CONDUCTANCE!r})")
        circuit.C("coil_switch", DRIVER_NODE, gnd, float(self.switch_capacitance))
        circuit.D("coil_clamp", gnd, DRIVER_NODE, model=CLAMP_MODEL)
        circuit.model(CLAMP_MODEL, "D", IS=1e-14, N=1.0, BV=float(self.switch_breakdown), IBV=1e-3, RS=0.1)
        diode = dict(IS=float(self.diode_saturation_current), N=1.8, RS=0.05)
        if self.suppression == "diode":
            circuit.D("coil_supp", DRIVER_NODE, SUPPLY_NODE, model=DIODE_MODEL)
            circuit.model(DIODE_MODEL, "D", **diode)
        elif self.suppression == "zener":
            circuit.D("coil_supp", DRIVER_NODE, "coil_z", model=DIODE_MODEL)
            circuit.D("coil_zener", SUPPLY_NODE, "coil_z", model=ZENER_MODEL)
            circuit.model(DIODE_MODEL, "D", **diode)
            circuit.model(ZENER_MODEL, "D", IS=1e-14, N=1.0, BV=float(self.zener_voltage), IBV=1e-3, RS=0.5)
        elif self.suppression == "rc":
            circuit.R("coil_supp", SUPPLY_NODE, "coil_rc", float(self.rc_resistance))
            circuit.C("coil_supp", "coil_rc", DRIVER_NODE, float(self.rc_capacitance))
