"""Contact duty: what current and arcs do to a contact, as small pure functions (SI units).

- Holm's electrodynamic repulsion of a constriction, F = mu0 I^2 / (4 pi) ln(R / a), and the
  blow-off current where it equals the contact force;
- the a-spot temperature from the contact voltage (Holm's voltage-temperature relation with
  the Wiedemann-Franz law, T^2 - T0^2 = U^2 / (4 L)) and the melting-voltage criterion,
  with the constriction's own heating (R = R0 (1 + 2/3 alpha theta)) when the voltage comes
  from a room-temperature resistance law;
- Slade's threshold welding current of a closed contact against its force;
- the molten bridge at a separation under current, the molten pool a bounce arc leaves, and a
  weld verdict "none" / "possible" / "likely" with the numbers behind it;
- arc erosion per operation from the arc energy in each electrode's own arc stage (anodic
  below the transition gap, cathodic beyond it), and a rivet cap's height and radius after
  an eroded volume.

docs/contact_duty.md gives each model's source, validity and what it leaves out.
"""

from __future__ import annotations

import math

import numpy as np

from mech.validation import check_finite, check_nonnegative, check_positive
from mech.frozen import frozen

from .materials import Material, material

MU0 = 4e-7 * math.pi  # N/A^2, vacuum permeability (the classical value; CODATA 2018 differs by 5.5e-10)
LORENZ = 2.45e-8  # V^2/K^2, the Lorenz number of the Wiedemann-Franz law (Holm's value)
AMBIENT = 293.15  # K, the bulk temperature T0 of the contact members (20 C, Holm's tables)
RESISTANCE_RISE = 2.0 / 3.0  # Holm: a constriction at supertemperature theta has R = R0 (1 + 2/3 alpha theta)
SLADE_BLOW_OFF = 4.45e-7  # N/A^2: Slade's blow-off force k i^2 (mu0/(4 pi) ln(R/a) with ln(R/a) = 4.45)
HOT_HARDNESS = 0.1  # Slade: the hardness near the melting point, as a fraction of the room-temperature one
TRANSITION_GAP = 20e-6  # m: anodic -> cathodic arc stage (Ben Jemaa et al. 1998: 15-30 um)
MELT_FRACTION = 0.1  # of a bounce arc's energy that melts metal at each root (order of magnitude)
TENSILE_OVER_HARDNESS = 1.0 / 3.0  # a weld's strength ~ the yield stress ~ H/3 (Tabor)


# --- Holm's repulsion and the blow-off current -------------------------------------------------


def constriction_repulsion(current, spot_radius, conductor_radius):
    """Holm's electrodynamic repulsion of one circular a-spot, N: F = mu0 I^2 / (4 pi) ln(R / a).

    current: A (either sign); spot_radius a and conductor_radius R (the contact member's
    radius, where the current lines run parallel again): m. Valid for a << R; 0 where a >= R
    (no constriction)."""
    a = np.asarray(spot_radius, dtype=float)
    ratio = np.asarray(conductor_radius, dtype=float) / a
    log = np.log(np.where(ratio > 1.0, ratio, 1.0))
    return MU0 / (4.0 * math.pi) * np.asarray(current, dtype=float) ** 2 * log


def spot_radius_from_resistance(resistance, rho1, rho2):
    """The a-spot radius a = (rho1 + rho2) / (4 R_c), m, that a measured constriction
    resistance R_c (ohm) implies between metals of resistivities rho1, rho2 (ohm m)."""
    return (rho1 + rho2) / (4.0 * np.asarray(resistance, dtype=float))


def blow_off_current(force, spot_radius, conductor_radius):
    """The current (A) whose Holm repulsion equals the contact force F (N) at the spot radius
    a and conductor radius R (m): I_b = sqrt(4 pi F / (mu0 ln(R / a))); inf where a >= R."""
    a = np.asarray(spot_radius, dtype=float)
    ratio = np.asarray(conductor_radius, dtype=float) / a
    with np.errstate(divide="ignore"):
        k = np.where(ratio > 1.0, MU0 / (4.0 * math.pi) * np.log(np.where(ratio > 1.0, ratio, 2.0)), 0.0)
        return np.where(k > 0.0, np.sqrt(np.maximum(np.asarray(force, dtype=float), 0.0) / np.where(k > 0, k, 1.0)),
                        math.inf)


def shrinking_blow_off_current(force: float, hardness: float, conductor_radius: float) -> float:
    """The current (A) that opens a contact held at force F0 (N) by its own Holm repulsion
    when its a-spot follows the force it still carries (plastic, a = sqrt(F / (pi H)), H in
    Pa; member radius R, m).

    The force left, F = F0 - k I^2 (L0 - ln(F / F0) / 2) with k = mu0 / (4 pi) and L0 =
    ln(R / a0), a0 the spot at F0, has an equilibrium for as long as the line meets the
    logarithm: with x = F / F0 and q = k I^2 / F0 the equilibria solve x - 1 + q L0 -
    (q / 2) ln x = 0, which is convex in x with its least value at x = q / 2; the last
    equilibrium is there, at q (1/2 + L0 - ln(q / 2) / 2) = 1. Returns I = sqrt(q F0 / k)
    (below ``blow_off_current`` at the held spot, which keeps a0: 0.83 of it for Ag on Ag
    at 1.6 N, R = 1.5 mm); inf where a0 >= R."""
    f0 = check_positive("shrinking_blow_off_current(force)", force)
    h = check_positive("shrinking_blow_off_current(hardness)", hardness)
    r = check_positive("shrinking_blow_off_current(conductor_radius)", conductor_radius)
    l0 = math.log(r / math.sqrt(f0 / (math.pi * h)))
    if l0 <= 0.0:
        return math.inf

    def excess(q: float) -> float:
        return q * (0.5 + l0 - 0.5 * math.log(q / 2.0)) - 1.0

    # excess rises monotonically on (0, 2 e^(2 L0)); it is -1 at 0+ and > 0 at 2 / (1 + 2 L0)
    lo, hi = 0.0, 2.0 / (1.0 + 2.0 * l0)
    while excess(hi) < 0.0:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0.0 else (lo, mid)
        if hi - lo <= 1e-15 * hi:
            break
    q = 0.5 * (lo + hi)
    return math.sqrt(q * f0 / (MU0 / (4.0 * math.pi)))


# --- a-spot temperature (Holm) -----------------------------------------------------------------


def spot_temperature(contact_voltage, ambient: float = AMBIENT):
    """The hottest point of a constriction (K) carrying the contact voltage U (V) between
    members at ``ambient`` (K): T^2 = T0^2 + U^2 / (4 L) (Holm, Wiedemann-Franz, steady state)."""
    u = np.asarray(contact_voltage, dtype=float)
    return np.sqrt(ambient ** 2 + u * u / (4.0 * LORENZ))


def constriction_voltage(temperature, ambient: float = AMBIENT):
    """The contact voltage (V) at which the constriction's hottest point reaches ``temperature``
    (K): U = 2 sqrt(L (T^2 - T0^2)); at the melting (boiling) point, the melting (boiling) voltage."""
    t = np.asarray(temperature, dtype=float)
    return 2.0 * np.sqrt(LORENZ * np.maximum(t * t - ambient ** 2, 0.0))


@frozen
class ContactPair:
    """The two contact materials (library names; rivet and counter-contact, or the electrodes a
    and b of a circuit contact) and the bulk temperature ``ambient`` (K), with the pair's figures
    the duty models use. A material without a datum a model needs: ValueError naming both."""

    materials: tuple[str, str]
    ambient: float = AMBIENT

    def __post_init__(self):
        mats = self.materials
        if isinstance(mats, str):
            mats = (mats, mats)
        if not (isinstance(mats, (tuple, list)) and len(mats) == 2 and all(isinstance(m, str) for m in mats)):
            raise ValueError(f"ContactPair.materials = {self.materials!r}: expected two material names (or one for both)")
        object.__setattr__(self, "materials", tuple(mats))
        check_positive("ContactPair.ambient", self.ambient)
        object.__setattr__(self, "_m", tuple(material(m, "ContactPair.materials") for m in mats))

    @property
    def pair(self) -> tuple[Material, Material]:
        return self._m

    def _melting(self, model: str) -> Material:
        """The member whose a-spot melts first: the lower melting voltage."""
        return min(self._m, key=lambda m: m.datum("melting_voltage", model))

    def melting_voltage(self, model: str = "the melting-voltage criterion") -> float:
        """V: the lower of the two melting voltages (the constriction melts where it first can)."""
        return self._melting(model).melting_voltage

    def boiling_voltage(self, model: str = "the molten-bridge model") -> float:
        """V: the lower of the two boiling voltages."""
        return min(m.datum("boiling_voltage", model) for m in self._m)

    def hardness(self) -> float:
        """Pa: the softer member's hardness (it carries the load)."""
        return min(m.hardness for m in self._m)

    def temperature_coefficient(self, model: str) -> float:
        """1/K: the constriction resistance's, each member weighted by its resistivity."""
        m1, m2 = self._m
        a1, a2 = m1.datum("temperature_coefficient", model), m2.datum("temperature_coefficient", model)
        return (m1.resistivity * a1 + m2.resistivity * a2) / (m1.resistivity + m2.resistivity)

    def hot_resistivity_sum(self, temperature: float, model: str) -> float:
        """rho1(T) + rho2(T), ohm m, each rho0 (1 + 2/3 alpha (T - T0)): the resistivities that set
        a constriction's resistance when its hottest point is at ``temperature`` (Holm)."""
        return sum(m.resistivity * (1.0 + RESISTANCE_RISE * m.datum("temperature_coefficient", model)
                                    * (temperature - self.ambient)) for m in self._m)


def hot_contact_voltage(cold_voltage, pair: ContactPair):
    """The contact voltage (V) a constriction really carries when a room-temperature resistance
    law gives ``cold_voltage`` = I R0 (V): U = U0 (1 + 2/3 alpha (T(U) - T0)), T(U) Holm's
    spot temperature; solved in closed form (a quadratic in U). inf where no steady state
    exists (the heating runs away: the spot melts)."""
    alpha = pair.temperature_coefficient("the a-spot temperature from a room-temperature contact voltage")
    t0 = pair.ambient
    u0 = np.abs(np.asarray(cold_voltage, dtype=float))
    c1 = u0 * (1.0 - RESISTANCE_RISE * alpha * t0)
    c2 = u0 * RESISTANCE_RISE * alpha
    # (U - c1)^2 = c2^2 (T0^2 + U^2 / (4 L)), U >= c1
    qa = 1.0 - c2 * c2 / (4.0 * LORENZ)
    disc = c1 * c1 - qa * (c1 * c1 - c2 * c2 * t0 * t0)
    with np.errstate(divide="ignore", invalid="ignore"):
        root = (c1 + np.sqrt(np.maximum(disc, 0.0))) / qa
    return np.where(qa > 0.0, root, math.inf)


def cold_melting_voltage(pair: ContactPair) -> float:
    """The room-temperature contact voltage I R0 (V) at which the spot reaches the melting
    voltage: U_m / (1 + 2/3 alpha (T(U_m) - T0)); compare a simulated contact voltage with it."""
    um = pair.melting_voltage()
    alpha = pair.temperature_coefficient("the melting-voltage criterion")
    return um / (1.0 + RESISTANCE_RISE * alpha * (float(spot_temperature(um, pair.ambient)) - pair.ambient))


# --- welding ---------------------------------------------------------------------------------


def welding_current(force, pair: ContactPair, blow_off_coefficient: float = SLADE_BLOW_OFF):
    """Slade's threshold welding current (A) of a closed contact at force F (N), for a current
    pulse of a few ms (an AC half cycle):

        i_W = 2 U_m sqrt(F) / sqrt(rho_T^2 pi (0.1 H0) + 4 k U_m^2),

    the current at which one a-spot, its hardness softened to 0.1 H0 near melting and its
    force reduced by the blow-off k i^2, carries the melting voltage U_m; rho_T = (rho1(T_m) +
    rho2(T_m)) / 2 with rho(T) = rho0 (1 + 2/3 alpha (T - T0)). ``blow_off_coefficient`` k in
    N/A^2 (Slade's 4.45e-7, or MU0/(4 pi) ln(R/a) for a known geometry)."""
    check_nonnegative("welding_current(blow_off_coefficient)", blow_off_coefficient)
    model = "Slade's threshold welding current"
    melting = pair._melting(model)
    um = melting.melting_voltage
    rho = pair.hot_resistivity_sum(melting.datum("melting_point", model), model) / 2.0
    f = np.maximum(np.asarray(force, dtype=float), 0.0)
    return 2.0 * um * np.sqrt(f) / math.sqrt(rho * rho * math.pi * HOT_HARDNESS * pair.hardness()
                                             + 4.0 * blow_off_coefficient * um * um)


def molten_bridge(current, cold_voltage, pair: ContactPair) -> dict:
    """The molten bridge of a separation under current: at parting the force and the spot
    shrink and the contact voltage rises through the melting voltage (Holm), so the spot melts
    while it still carries ``current`` (A). cold_voltage: the contact voltage (V) of the
    room-temperature resistance law just before parting. Returns molten (the hot voltage
    reached U_m), boiling (it reached the boiling voltage), hot_voltage (V), spot_temperature (K)
    and bridge_radius (m): the spot radius at which this current melts it,
    |I| (rho1(T_m) + rho2(T_m)) / (4 U_m)."""
    model = "the molten-bridge model"
    melting = pair._melting(model)
    um = melting.melting_voltage
    rho_sum = pair.hot_resistivity_sum(melting.datum("melting_point", model), model)
    radius = abs(float(current)) * rho_sum / (4.0 * um)
    if cold_voltage is None:  # a force law's R_c grows without bound as F -> 0: the voltage passes U_m
        return {"molten": bool(current != 0.0), "boiling": bool(current != 0.0), "hot_voltage": None,
                "spot_temperature": None, "melting_voltage": um, "bridge_radius": radius}
    hot = float(hot_contact_voltage(cold_voltage, pair))
    return {"molten": bool(hot >= um), "boiling": bool(hot >= pair.boiling_voltage(model)),
            "hot_voltage": hot, "spot_temperature": float(spot_temperature(hot, pair.ambient)),
            "melting_voltage": um, "bridge_radius": radius}


def arc_pool_radius(arc_energy, mat: Material, melt_fraction: float = MELT_FRACTION, ambient: float = AMBIENT):
    """Radius (m) of the hemispherical pool a fraction ``melt_fraction`` of an arc's energy
    (J) melts at one root: V = f E / (d (c_p (T_m - T0) + L_f)), r = (3 V / (2 pi))^(1/3)."""
    check_positive("arc_pool_radius(melt_fraction)", melt_fraction)
    model = "the bounce-arc weld (molten pool)"
    per_volume = mat.datum("density", model) * (mat.datum("specific_heat", model)
                                                * (mat.datum("melting_point", model) - ambient)
                                                + mat.datum("latent_heat", model))
    volume = melt_fraction * np.maximum(np.asarray(arc_energy, dtype=float), 0.0) / per_volume
    return np.cbrt(3.0 * volume / (2.0 * math.pi))


def weld_strength(radius, pair: ContactPair):
    """Force (N) to break a weld of radius r (m): (H / 3) pi r^2 with the softer member's H
    (a weld's strength taken as the yield stress, H ~ 3 Y: Tabor)."""
    return TENSILE_OVER_HARDNESS * pair.hardness() * math.pi * np.asarray(radius, dtype=float) ** 2


def weld_verdict(pair: ContactPair, *, held_force: float, peak_current: float, held_voltage: float = 0.0,
                 separations=(), opening_force: float | None = None, margin: float = 2.0,
                 melt_fraction: float = MELT_FRACTION) -> dict:
    """The weld risk of one make: "likely", "possible" or "none", with the numbers behind it.

    held_force: N, the contact force of the held (closed) contact; peak_current: A, the
    largest |current| the closed contact carried; held_voltage: V, the largest room-
    temperature contact voltage while held at that force; separations: one entry per bounce
    separation under current, each a mapping with current (A at parting), voltage (V, the
    cold contact voltage at parting, or absent: the spot melts), arc_energy (J, of that opening's arc) and
    arc_at_remake (bool: the arc still burned when the contact made again, so it closed on
    molten metal); opening_force: N, what must break a weld (None: the held force).

    Ratios (each >= 1 means a weld at least as strong as the criterion): static =
    peak_current / Slade's i_W(held_force); held_spot = the held contact's hot voltage / U_m;
    for each separation the weld a bridge (bridge_radius) or a bounce arc's pool (if the arc
    burned at the re-make) would leave, over the opening force. "likely" if any ratio >= 1,
    "possible" if any >= 1 / margin, else "none"."""
    check_positive("weld_verdict(held_force)", held_force)
    check_finite("weld_verdict(peak_current)", peak_current)
    check_positive("weld_verdict(margin)", margin)
    opening = held_force if opening_force is None else check_positive("weld_verdict(opening_force)", opening_force)
    i_w = float(welding_current(held_force, pair))
    um = pair.melting_voltage()
    held_hot = float(hot_contact_voltage(held_voltage, pair))
    ratios = {"static": abs(peak_current) / i_w, "held_spot": held_hot / um}
    details = []
    for k, sep in enumerate(separations):
        current = check_finite(f"weld_verdict(separations[{k}].current)", sep["current"])
        bridge = molten_bridge(current, sep.get("voltage"), pair)
        bridge_force = float(weld_strength(bridge["bridge_radius"], pair)) if bridge["molten"] else 0.0
        pool = 0.0
        if sep.get("arc_at_remake", False):
            energy = check_nonnegative(f"weld_verdict(separations[{k}].arc_energy)", sep.get("arc_energy", 0.0))
            pool = max(float(arc_pool_radius(energy, m, melt_fraction, pair.ambient)) for m in pair.pair)
        pool_force = float(weld_strength(pool, pair))
        details.append({"current": current, "molten_bridge": bridge["molten"],
                        "bridge_radius": bridge["bridge_radius"], "bridge_weld_force": bridge_force,
                        "pool_radius": pool, "pool_weld_force": pool_force,
                        "ratio": max(bridge_force, pool_force) / opening})
    ratios["separation"] = max((d["ratio"] for d in details), default=0.0)
    worst = max(ratios, key=ratios.get)
    top = ratios[worst]
    verdict = "likely" if top >= 1.0 else "possible" if top >= 1.0 / margin else "none"
    return {"weld_risk": verdict, "criterion": worst, "ratios": ratios, "welding_current": i_w,
            "melting_voltage": um, "held_hot_voltage": held_hot, "opening_force": opening,
            "margin": margin, "separations": details}


# --- erosion ---------------------------------------------------------------------------------


def arc_stage_energies(time, voltage, current, gap, transition_gap: float = TRANSITION_GAP) -> dict:
    """The arc energy (J) each electrode takes in its own eroding stage, from waveforms.

    time (s), voltage (V, the gap voltage, electrode a minus b), current (A, the arc current,
    positive from a to b: then a is the anode) and gap (m) at the same samples; each interval
    is integrated by the trapezoid rule and classed by its midpoint: anodic stage while the
    gap is below ``transition_gap`` (metal-vapour arc: the anode erodes), cathodic beyond it
    (gas arc: the cathode erodes; Ben Jemaa et al. 1998). Returns {"a": {"anodic": J with a
    the anode below the transition, "cathodic": J with a the cathode beyond it}, "b": {...},
    "total": J}."""
    check_positive("arc_stage_energies(transition_gap)", transition_gap)
    t = np.asarray(time, dtype=float)
    arrays = [np.asarray(x, dtype=float) for x in (voltage, current, gap)]
    if any(x.shape != t.shape for x in arrays) or t.ndim != 1:
        raise ValueError("arc_stage_energies: time, voltage, current and gap must be 1-D arrays of one length")
    v, i, d = arrays
    p = v * i
    dt = np.diff(t)
    if np.any(dt < 0):
        raise ValueError("arc_stage_energies: time must not decrease")
    e = 0.5 * (p[1:] + p[:-1]) * dt
    i_mid, d_mid = 0.5 * (i[1:] + i[:-1]), 0.5 * (d[1:] + d[:-1])
    anodic = d_mid < transition_gap
    a_anode = i_mid > 0.0
    b_anode = i_mid < 0.0
    return {"a": {"anodic": float(e[anodic & a_anode].sum()), "cathodic": float(e[~anodic & b_anode].sum())},
            "b": {"anodic": float(e[anodic & b_anode].sum()), "cathodic": float(e[~anodic & a_anode].sum())},
            "total": float(e.sum())}


def erosion(stage_energies: dict, pair: ContactPair, transfer_fraction: float = 0.0,
            coefficients: tuple[float, float] | None = None) -> dict:
    """Volume (m^3) and mass (kg) each electrode loses in one operation: electrode x loses
    k_anode(x) E_x,anodic + k_cathode(x) E_x,cathodic (``arc_stage_energies``; the pair's
    materials are electrodes a and b); ``transfer_fraction`` of what one loses lands on the
    other (0: all lost, 1: all transferred). ``coefficients``: (k_anode, k_cathode) in m^3/J
    for both electrodes instead of the library's (a coefficient calibrated on a life test).
    Returns {"a": {"loss_volume", "net_volume", "net_mass"}, "b": {...}}: net = own loss -
    transfer_fraction x the other's loss."""
    check_nonnegative("erosion(transfer_fraction)", transfer_fraction)
    if transfer_fraction > 1.0:
        raise ValueError(f"erosion(transfer_fraction) = {transfer_fraction!r}: must be <= 1")
    if coefficients is not None:
        coefficients = tuple(check_nonnegative(f"erosion(coefficients[{k}])", c) for k, c in enumerate(coefficients))
    model = "arc erosion"
    loss = {}
    for side, mat in zip(("a", "b"), pair.pair):
        energies = stage_energies[side]
        k_anode, k_cathode = coefficients if coefficients is not None else (
            mat.datum("erosion_anode", model), mat.datum("erosion_cathode", model))
        loss[side] = k_anode * max(energies["anodic"], 0.0) + k_cathode * max(energies["cathodic"], 0.0)
    out = {}
    for side, other, mat in (("a", "b", pair.pair[0]), ("b", "a", pair.pair[1])):
        net = loss[side] - transfer_fraction * loss[other]
        out[side] = {"loss_volume": loss[side], "net_volume": net, "net_mass": net * mat.datum("density", model)}
    return out


# --- the rivet's cap after erosion -----------------------------------------------------------


def cap_volume(height, sphere_radius):
    """Volume (m^3) of a spherical cap of height h and sphere radius R (m): pi h^2 (3R - h) / 3."""
    h = np.asarray(height, dtype=float)
    return math.pi * h * h * (3.0 * np.asarray(sphere_radius, dtype=float) - h) / 3.0


def eroded_cap(height: float, sphere_radius: float, volume: float) -> tuple[float, float]:
    """A rivet cap (height h, sphere radius R, m; h <= R) after losing ``volume`` (m^3) from its
    top, its base (radius c = sqrt(h (2R - h)), where it sits on the carrier) kept: the new
    height h' solves pi h' (3 c^2 + h'^2) / 6 = V - volume, the new radius is
    R' = (c^2 + h'^2) / (2 h') (the worn dome is flatter). Returns (h', R'); the height lost
    h - h' is what the gap grows by."""
    h = check_positive("eroded_cap(height)", height)
    r = check_positive("eroded_cap(sphere_radius)", sphere_radius)
    dv = check_nonnegative("eroded_cap(volume)", volume)
    if h > r:
        raise ValueError(f"eroded_cap(height) = {h!r}: must be <= sphere_radius = {r!r} (a cap, not more than a hemisphere)")
    total = float(cap_volume(h, r))
    if dv >= total:
        raise ValueError(f"eroded_cap(volume) = {dv!r} m^3: the cap holds only {total!r} m^3 (worn through)")
    if dv == 0.0:
        return h, r
    c2 = h * (2.0 * r - h)
    target = total - dv
    # V(h') = pi h' (3 c^2 + h'^2) / 6 increases monotonically: Newton from h converges from above.
    x = h
    for _ in range(100):
        f = math.pi * x * (3.0 * c2 + x * x) / 6.0 - target
        step = f / (math.pi * (c2 + x * x) / 2.0)
        x -= step
        if abs(step) <= 1e-15 * h:
            break
    return x, (c2 + x * x) / (2.0 * x)
