"""Contact resistance from contact materials: Holm's constriction laws, Greenwood's multi-spot
form, a film term and a constant R_c, with a small library of contact materials.

Laws (SI: N, m, Pa, ohm, ohm m^2), as small pure functions:

- one circular a-spot between metals of resistivities rho1, rho2 (Holm, "Electric
  Contacts", 4th ed., sec. 4): R_s = (rho1 + rho2) / (4 a);
- contact radius, plastic: the softer metal's hardness H carries the load, F = H pi a^2,
  a = sqrt(F / (pi H)); elastic: Hertz's radius of a sphere of radius R on a flat,
  a = (3 F R / (4 E*))^(1/3), 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2;
- n equal spots of radius a_i spread over a cluster of radius alpha (Greenwood, "Constriction
  resistance and the real area of contact", Brit. J. Appl. Phys. 17 (1966) 1621):
  R = rho_e / (2 sum a_i) + rho_e / (pi n^2) sum_{i != j} 1 / s_ij, rho_e = (rho1 + rho2)/2;
  for spots spread uniformly over the cluster the mean 1/s is 16 / (3 pi alpha), so
  R = (rho1 + rho2) / (4 n a_i) + (16 / (3 pi^2)) (1 - 1/n) (rho1 + rho2) / (2 alpha);
  n = 1 gives the single spot back;
- a film of tunnel resistivity sigma_f (ohm m^2) over the real contact area A:
  R_f = sigma_f / A, A = pi a^2 (elastic) or F / H (plastic);
- a constant R_c.

Every law states its validity range (``validity``): the constriction formula needs contact
spots much larger than the electrons' mean free path (~0.04-0.05 um in Ag, Cu, Au at room
temperature; below it the ballistic Sharvin resistance takes over), so a_i >= 0.1 um; the
plastic real area F/H must stay inside the apparent (Hertz) area of the rivet when its
radius is given; Hertz's elastic law holds up to first yield, peak pressure
p0 = 0.57 H (p0 = 1.6 Y, H ~ 2.8 Y; Johnson, "Contact Mechanics", sec. 6).

The library also carries what the contact-duty models (coupling.laws.duty) need: thermal
data, Holm's melting and boiling voltages, the minimum arc voltage and current and the
erosion coefficients, each with value, range and source; ``Material.datum`` names the
datum and the model when one is missing.
"""

from __future__ import annotations

import marshal
import math
import os
import sys
import tomllib
from dataclasses import field
from pathlib import Path
from typing import Any

import numpy as np

from mech.validation import (
    check_choice, check_finite, check_keys, check_nonnegative, check_positive, check_whole, unknown,
)
from mech.compiled_cache import sha1
from mech.frozen import frozen

MIN_SPOT_RADIUS = 0.1e-6  # m: a >> the electron mean free path (Holm's diffusive constriction)
YIELD_PRESSURE_OVER_HARDNESS = 0.57  # Hertz peak pressure at first yield / hardness
GREENWOOD_COEFFICIENT = 16.0 / (3.0 * math.pi ** 2)  # interaction term of spots in a cluster


# --- pure laws -------------------------------------------------------------------------------


def holm_spot_resistance(rho1, rho2, radius):
    """R = (rho1 + rho2) / (4 a): one circular a-spot of radius a (m) between two metals (ohm m)."""
    return (rho1 + rho2) / (4.0 * np.asarray(radius, dtype=float))


def plastic_radius(force, hardness):
    """a = sqrt(F / (pi H)), m: F in N, H in Pa."""
    return np.sqrt(np.maximum(np.asarray(force, dtype=float), 0.0) / (math.pi * hardness))


def hertz_radius(force, sphere_radius, effective_modulus):
    """a = (3 F R / (4 E*))^(1/3), m: sphere of radius R (m) on a flat, E* in Pa."""
    return (3.0 * np.maximum(np.asarray(force, dtype=float), 0.0) * sphere_radius
            / (4.0 * effective_modulus)) ** (1.0 / 3.0)


def effective_modulus(e1, nu1, e2, nu2):
    """E*, Pa: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2."""
    return 1.0 / ((1.0 - nu1 ** 2) / e1 + (1.0 - nu2 ** 2) / e2)


def greenwood_resistance(rho1, rho2, spots, spot_radius, cluster_radius):
    """R, ohm, of n equal spots of radius a_i (m) spread uniformly over a cluster of radius
    alpha (m): (rho1 + rho2)/(4 n a_i) + 16/(3 pi^2) (1 - 1/n) (rho1 + rho2)/(2 alpha)."""
    n = float(spots)
    return ((rho1 + rho2) / (4.0 * n * np.asarray(spot_radius, dtype=float))
            + GREENWOOD_COEFFICIENT * (1.0 - 1.0 / n) * (rho1 + rho2) / (2.0 * np.asarray(cluster_radius, dtype=float)))


def film_resistance(film_resistivity, area):
    """R_f = sigma_f / A, ohm: sigma_f in ohm m^2, A (real contact area) in m^2."""
    return film_resistivity / np.asarray(area, dtype=float)


# --- the material library --------------------------------------------------------------------


@frozen
class Material:
    """A contact material: resistivity (ohm m), hardness (Pa), Young's modulus (Pa), Poisson
    ratio, and the contact-duty data (None where the library has no figure; SI units, listed
    in ``DUTY_PROPERTIES``); for each its typical range, source and note from the data file."""

    name: str
    description: str
    resistivity: float
    hardness: float
    youngs_modulus: float
    poisson_ratio: float
    thermal_conductivity: float | None = None  # W/(m K)
    temperature_coefficient: float | None = None  # of the resistivity, 1/K
    melting_point: float | None = None  # K
    boiling_point: float | None = None  # K
    melting_voltage: float | None = None  # V (Holm)
    boiling_voltage: float | None = None  # V (Holm)
    density: float | None = None  # kg/m^3
    specific_heat: float | None = None  # J/(kg K)
    latent_heat: float | None = None  # of fusion, J/kg
    min_arc_voltage: float | None = None  # V
    min_arc_current: float | None = None  # A
    erosion_anode: float | None = None  # m^3 per J of arc energy in the anodic stage
    erosion_cathode: float | None = None  # m^3 per J of arc energy in the cathodic stage
    ranges: dict = field(default_factory=dict, compare=False)
    sources: dict = field(default_factory=dict, compare=False)
    notes: dict = field(default_factory=dict, compare=False)

    def datum(self, prop: str, model: str) -> float:
        """The value of ``prop``; ValueError naming the datum and the model when the library has none."""
        value = getattr(self, prop)
        if value is None:
            raise ValueError(f"contact material {self.name!r} has no {prop} in the material library, "
                             f"needed by {model}: add it to the material's entry")
        return value


PROPERTIES = ("resistivity", "hardness", "youngs_modulus", "poisson_ratio")
DUTY_PROPERTIES = ("thermal_conductivity", "temperature_coefficient", "melting_point", "boiling_point",
                   "melting_voltage", "boiling_voltage", "density", "specific_heat", "latent_heat",
                   "min_arc_voltage", "min_arc_current", "erosion_anode", "erosion_cathode")
# Data that may be zero (an erosion-free material); every other datum must be > 0.
_MAY_BE_ZERO = {"erosion_anode", "erosion_cathode"}
_ENTRY_KEYS = {"description", "status", *PROPERTIES, *DUTY_PROPERTIES}
_DATUM_KEYS = {"value", "range", "source", "note"}


def _datum(name: str, prop: str, item) -> tuple[float, tuple[float, float], str, str]:
    """value, range, source, note of one property table, checked (one-line errors naming it)."""
    where = f"contact materials: {name}.{prop}"
    if not isinstance(item, dict):
        raise ValueError(f"{where} = {item!r}: expected a table {{ value, range, source }}")
    check_keys(where, item, sorted(_DATUM_KEYS))
    for key in ("value", "range", "source"):
        if key not in item:
            raise ValueError(f"{where}: missing {key} (each datum needs value, range and source)")
    value = check_finite(f"{where}.value", item["value"])
    if prop in _MAY_BE_ZERO:
        check_nonnegative(f"{where}.value", value)
    else:
        check_positive(f"{where}.value", value)
    rng = item["range"]
    if not (isinstance(rng, list) and len(rng) == 2):
        raise ValueError(f"{where}.range = {rng!r}: expected [low, high]")
    lo, hi = (check_finite(f"{where}.range", x) for x in rng)
    if not lo <= value <= hi:
        raise ValueError(f"contact materials: {name}.{prop} = {value!r} outside its range {[lo, hi]}")
    source = item["source"]
    if not (isinstance(source, str) and source.strip()):
        raise ValueError(f"{where}.source = {source!r}: expected where the figure comes from")
    return value, (lo, hi), source, str(item.get("note", ""))


LIBRARY = Path(__file__).parent / "data" / "contact_materials.toml"
# the parsed library, kept per version of its file (``library_document``)
DOCUMENT_CACHE = "contact_materials"


def library_document(path: Path = LIBRARY, cache: Path | None = None) -> dict:
    """The library file's TOML document (the data; ``load_materials`` checks it).

    tomllib took 3-4 ms of every run that reads the library (the default relay's start), so
    the document is kept, as marshal's bytes (read back in ~0.07 ms), in ``cache``
    (default: NUMBA_CACHE_DIR, else this package's __pycache__: where the project's other
    caches go), named by the SHA-1 of the file's bytes and the interpreter's tag: an edited
    file is parsed again, and the entries of earlier versions are removed. A cache that
    cannot be read is parsed again; one that cannot be written is left out."""
    data = path.read_bytes()
    folder = cache if cache is not None else Path(os.environ.get("NUMBA_CACHE_DIR") or Path(__file__).parent / "__pycache__")
    entry = folder / f"{DOCUMENT_CACHE}-{sha1(data).hexdigest()[:20]}.{sys.implementation.cache_tag}.marshal"
    try:
        doc = marshal.loads(entry.read_bytes())
        if type(doc) is dict:
            return doc
    except (OSError, EOFError, ValueError, TypeError):
        pass
    doc = tomllib.loads(data.decode("utf-8"))
    _keep_document(entry, doc)
    return doc


def _keep_document(entry: Path, doc: dict) -> None:
    """Write the cache entry whole (a reader sees it complete or not at all) and remove the
    other versions' entries; quietly nothing where the folder cannot be written."""
    tmp = entry.with_name(f".{entry.name}.{os.getpid()}.tmp")
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_bytes(marshal.dumps(doc))
        os.replace(tmp, entry)
        for old in entry.parent.glob(f"{DOCUMENT_CACHE}-*.marshal"):
            if old.name != entry.name:
                old.unlink(missing_ok=True)
    except (OSError, ValueError):  # (ValueError: a value marshal cannot write, none in a TOML document)
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass


def load_materials(text: str | None = None) -> dict[str, Material]:
    """The contact-material library (coupling/laws/data/contact_materials.toml, or TOML ``text``)."""
    # (a path beside this module, as builtin_scene_text's: no importlib.resources at a run's start)
    doc = library_document() if text is None else tomllib.loads(text)
    out = {}
    for name, entry in doc.items():
        if not isinstance(entry, dict):
            raise ValueError(f"contact materials: {name} = {entry!r}: expected a table of properties")
        check_keys(f"contact materials: [{name}]", entry, sorted(_ENTRY_KEYS))
        values, ranges, sources, notes = {}, {}, {}, {}
        for prop in PROPERTIES + DUTY_PROPERTIES:
            if prop not in entry:
                if prop in PROPERTIES:
                    raise ValueError(f"contact materials: [{name}] has no {prop} (every material needs "
                                     f"{', '.join(PROPERTIES)})")
                continue
            values[prop], ranges[prop], sources[prop], notes[prop] = _datum(name, prop, entry[prop])
        out[name] = Material(name, entry.get("description", ""), ranges=ranges, sources=sources, notes=notes,
                             **values)
    return out


MATERIALS = load_materials()


def material(name: str, where: str = "material") -> Material:
    """The library entry ``name``; ValueError naming the known ones."""
    if name not in MATERIALS:
        raise unknown(where, name, MATERIALS, kind="contact material")
    return MATERIALS[name]


# --- laws the coupling calls (same interface as coupling.laws.tribology.ResistanceLaw) -------------


class _ForceLaw:
    """R_c(F) without a current dependence: the coupling's interface (conductance(F, I),
    force_conductance(F), scalar_force_conductance(F), current_factor(I) = 1)."""

    def resistance_of_force(self, force):  # pragma: no cover - overridden
        raise NotImplementedError

    def force_conductance(self, normal_force_N):
        """1/R_c(F), S: exactly 0 for F <= 0."""
        f = np.asarray(normal_force_N, dtype=float)
        closed = f > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            r = self.resistance_of_force(np.where(closed, f, 1.0))
        return np.where(closed, 1.0 / r, 0.0)

    def scalar_force_conductance(self, normal_force_N: float) -> float:
        if normal_force_N <= 0.0:
            return 0.0
        return float(1.0 / self.resistance_of_force(float(normal_force_N)))

    def conductance(self, normal_force_N, current_A=0.0):
        return self.force_conductance(normal_force_N)

    def resistance(self, normal_force_N, current_A=0.0):
        g = self.force_conductance(normal_force_N)
        with np.errstate(divide="ignore"):
            return 1.0 / g

    def current_factor(self, current_A):
        """No current dependence: 1."""
        return 1.0 + 0.0 * np.asarray(current_A, dtype=float)

    def current_factor_expression(self, current: str = "I") -> str:
        return "1"


@frozen
class ConstantResistance(_ForceLaw):
    """R_c = value (ohm) whenever the contact is closed (F > 0)."""

    value: float

    def __post_init__(self):
        check_positive("tribology.resistance.value", self.value)  # ohm

    name = "constant"
    load_exponent = 0.0

    def resistance_of_force(self, force):
        return self.value + 0.0 * np.asarray(force, dtype=float)

    @property
    def validity(self) -> dict:
        return {"force_N": (0.0, math.inf), "current_A": None, "note": ""}

    def to_dict(self) -> dict[str, Any]:
        return {"law": "constant", "value": self.value}


@frozen
class HolmResistance(_ForceLaw):
    """Holm / Greenwood constriction plus film resistance between two materials (SI).

    materials: the two library names (rivet, counter-contact); regime: "plastic" (the
    softer hardness carries the load) or "elastic" (Hertz, needs ``radius``); spots: n equal
    a-spots (plastic; n > 1 needs ``radius``: the cluster is the rivet's Hertz circle);
    radius: m, the rivet's spherical radius (or None); film_resistivity: ohm m^2 (>= 0).
    """

    materials: tuple[str, str]
    regime: str = "plastic"
    spots: int = 1
    radius: float | None = None
    film_resistivity: float = 0.0

    name = "holm"

    def __post_init__(self):
        where = "tribology.resistance"
        m1, m2 = (material(m, f"{where}.materials") for m in self.materials)
        check_choice(f"{where}.regime", self.regime, ("plastic", "elastic"))
        check_whole(f"{where}.spots", self.spots, 1)
        if self.radius is not None:
            check_positive(f"{where}.radius", self.radius)  # m
        check_nonnegative(f"{where}.film_resistivity", self.film_resistivity)  # ohm m^2
        if self.radius is None and (self.regime == "elastic" or self.spots > 1):
            need = "the elastic (Hertz) regime" if self.regime == "elastic" else f"spots = {self.spots}"
            raise ValueError(f"{where}: {need} needs radius = the rivet's spherical radius (m)")
        if self.regime == "elastic" and self.spots > 1:
            raise ValueError(f"{where}: spots = {self.spots} applies to the plastic regime only")
        object.__setattr__(self, "_m", (m1, m2))
        # scalar_force_conductance's constants: rho1 + rho2 (ohm m), H and pi H (Pa)
        h = min(m1.hardness, m2.hardness)
        object.__setattr__(self, "_plastic", (m1.resistivity + m2.resistivity, h, math.pi * h))

    def scalar_force_conductance(self, normal_force_N: float) -> float:
        """``force_conductance`` for one float, S (0 for F_n <= 0): a closed contact's
        conductance channel asks it at every trial time of ngspice. The plastic single-spot
        law in plain floats, the array route's operations in its order (math.sqrt is
        correctly rounded, as np.sqrt is; ~0.15 us against ~3 us through numpy's scalars);
        the other regimes, and a force so small that a quotient underflows to 0, by the
        array route."""
        if normal_force_N <= 0.0:
            return 0.0
        if self.regime != "plastic" or self.spots != 1:
            return super().scalar_force_conductance(normal_force_N)
        f = float(normal_force_N)
        rho, h, pi_h = self._plastic
        try:
            a = math.sqrt(f / pi_h)  # plastic_radius
            return 1.0 / (rho / (4.0 * a) + self.film_resistivity / (f / h))
        except ZeroDivisionError:
            return super().scalar_force_conductance(normal_force_N)

    @property
    def rho(self) -> tuple[float, float]:
        return self._m[0].resistivity, self._m[1].resistivity

    @property
    def hardness(self) -> float:
        """Pa: the softer material's hardness."""
        return min(m.hardness for m in self._m)

    @property
    def modulus(self) -> float:
        """E*, Pa."""
        m1, m2 = self._m
        return float(effective_modulus(m1.youngs_modulus, m1.poisson_ratio, m2.youngs_modulus, m2.poisson_ratio))

    @property
    def load_exponent(self) -> float:
        """m of the constriction term R ~ F^-m (1/2 plastic, 1/3 elastic)."""
        return 0.5 if self.regime == "plastic" else 1.0 / 3.0

    def resistance_of_force(self, force):
        """R_c(F), ohm, for F > 0 (N)."""
        rho1, rho2 = self.rho
        f = np.asarray(force, dtype=float)
        if self.regime == "elastic":
            a = hertz_radius(f, self.radius, self.modulus)
            return holm_spot_resistance(rho1, rho2, a) + film_resistance(self.film_resistivity, math.pi * a * a)
        h = self.hardness
        if self.spots == 1:
            r = holm_spot_resistance(rho1, rho2, plastic_radius(f, h))
        else:
            spot = plastic_radius(f / self.spots, h)
            r = greenwood_resistance(rho1, rho2, self.spots, spot, hertz_radius(f, self.radius, self.modulus))
        return r + film_resistance(self.film_resistivity, f / h)

    @property
    def validity(self) -> dict:
        """force_N: (F_min, F_max) in N where the law holds (module docstring); current_A: None
        (no current dependence); note: for the warnings."""
        h, n = self.hardness, self.spots
        if self.regime == "elastic":
            lo = 4.0 * self.modulus * MIN_SPOT_RADIUS ** 3 / (3.0 * self.radius)
            p = YIELD_PRESSURE_OVER_HARDNESS * h
            hi = math.pi ** 3 * self.radius ** 2 * p ** 3 / (6.0 * self.modulus ** 2)
            note = "; Hertz holds up to first yield, p0 = 0.57 H: use regime = 'plastic' above it"
        else:
            lo = n * math.pi * h * MIN_SPOT_RADIUS ** 2
            hi = math.pi * h * self.radius ** 2 if self.radius is not None else math.inf
            note = "; the real area F/H outgrows the rivet's face"
        return {"force_N": (lo, hi), "current_A": None, "note": note}

    def to_dict(self) -> dict[str, Any]:
        return {"law": "holm", "materials": list(self.materials), "regime": self.regime, "spots": self.spots,
                "radius": self.radius, "film_resistivity": self.film_resistivity,
                "validity_force_N": [f if math.isfinite(f) else None for f in self.validity["force_N"]]}


HOLM_KEYS = {"law", "materials", "regime", "spots", "radius", "film_resistivity"}
CONSTANT_KEYS = {"law", "value"}


def resistance_law_from_table(table: dict, where: str = "tribology.resistance"):
    """A material or constant R_c law from a scene table (``law = "holm"`` or ``"constant"``)."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table, got {table!r}")
    law = check_choice(f"{where}.law", table.get("law"), ("holm", "constant"))
    check_keys(f"{where} (law = {law!r})", table, CONSTANT_KEYS if law == "constant" else HOLM_KEYS)
    if law == "constant":
        if "value" not in table:
            raise ValueError(f"{where}: law = 'constant' needs value = R_c (ohm)")
        return ConstantResistance(table["value"])
    mats = table.get("materials")
    if isinstance(mats, str):
        mats = [mats, mats]
    if not (isinstance(mats, list) and len(mats) == 2 and all(isinstance(m, str) for m in mats)):
        raise ValueError(f"{where}.materials = {table.get('materials')!r}: expected two names "
                         f"[\"rivet\", \"counter-contact\"] (or one for both) from: {', '.join(MATERIALS)}")
    kw = {k: table[k] for k in ("regime", "spots", "radius", "film_resistivity") if k in table}
    return HolmResistance(tuple(mats), **kw)
