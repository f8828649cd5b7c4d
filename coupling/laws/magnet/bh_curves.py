"""B-H curves of the magnet's iron: a linear permeability, and tabulated curves H(B)
interpolated linearly and continued beyond their last point with the vacuum slope
dH/dB = 1/mu0 (the iron fully saturated), so that the field energy density, the integral
of H dB, is exact and ngspice's pwl evaluates the same curve.

The built-in saturating steel is the free-cutting steel 9SMnPb28 (1.0718; AISI 12L14 is
its US counterpart): the approximation of its relative permeability

    mu_r(B) = 1 + (mu_i - 1 + c_a B_N) / (1 + c_b B_N + B_N^n),  B_N = |B| / B_mumax

with mu_i = 400, B_mumax = 1.488 T, c_a = 1200, c_b = 3, n = 12.5, fitted to measured
commutation curves by T. Roschke ("Entwurf geregelter elektromagnetischer Antriebe für
Luftschütze", Fortschritt-Berichte VDI, Reihe 21, Nr. 293, VDI-Verlag 2000) and published with those
parameters in the Modelica Standard Library (Modelica.Magnetic.FluxTubes.Material.
SoftMagnetic.Steel.Steel_9SMnPb28). The table samples H = B / (mu0 mu_r(B)) at the points
STEEL_9SMNPB28_POINTS up to 2.2 T; the approximation itself turns unphysical above
~2.3 T (its differential permeability falls below mu0), so the table's vacuum slope takes
over at 2.2 T, where the steel's polarization B - mu0 H is 2.07 T. docs/magnet.md gives the
curve and how far the sampled table lies from the approximation.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from mech.frozen import frozen
from coupling.laws.magnet.pwl import Linear, OddPwl
from coupling.laws.magnet.validation import check_finite, check_numbers, unknown

MU0 = 1.25663706212e-6  # N/A^2, vacuum permeability (CODATA 2018)
SATURATED_EXTENSION = 1.0  # T: the table's last, vacuum-slope segment spans this much B


def roschke_relative_permeability(flux_density, mu_i, b_mumax, c_a, c_b, n):
    """mu_r(B) of Roschke's approximation for soft-magnetic materials (B in T)."""
    b = np.abs(np.asarray(flux_density, dtype=float)) / b_mumax
    return 1.0 + (mu_i - 1.0 + c_a * b) / (1.0 + c_b * b + b ** n)


@frozen
class LinearMaterial:
    """Iron of constant relative permeability ``relative_permeability`` (>= 1): H = B / (mu0 mu_r)."""

    relative_permeability: float
    name: str = "magnet.material"

    def __post_init__(self):
        mu_r = check_finite(f"{self.name}.relative_permeability", self.relative_permeability)
        if mu_r < 1.0:
            raise ValueError(f"{self.name}.relative_permeability = {mu_r!r}: must be >= 1 "
                             "(iron is magnetised along the field; mu_r < 1 is a diamagnet)")

    linear = True

    @cached_property
    def curve(self) -> Linear:
        """H(B) = B / (mu0 mu_r)."""
        return Linear(1.0 / (MU0 * self.relative_permeability))

    def field_strength_at(self, flux_density):
        """H (A/m) at B (T)."""
        return self.curve(flux_density)

    def energy_density(self, flux_density):
        """The integral of H dB from 0 to B, J/m^3."""
        return self.curve.integral(flux_density)


@frozen
class TabulatedMaterial:
    """Iron given by its B-H curve: ``flux_density`` (T) and ``field_strength`` (A/m), both
    starting at 0 and increasing strictly, each segment's differential permeability dB/dH
    at least mu0; H(B) linear between the points and, beyond the last, along the vacuum
    slope 1/mu0. The curve is odd: H(-B) = -H(B) (no remanence, no hysteresis)."""

    flux_density: tuple
    field_strength: tuple
    label: str = ""
    name: str = "magnet.material"

    def __post_init__(self):
        n = self.name
        b = check_numbers(f"{n}.flux_density", self.flux_density, "T")
        h = check_numbers(f"{n}.field_strength", self.field_strength, "A/m")
        if len(b) != len(h):
            raise ValueError(f"{n}: {len(b)} flux densities for {len(h)} field strengths; give one H per B")
        if len(b) < 2:
            raise ValueError(f"{n}.flux_density: {len(b)} point(s); give at least 2 (the first B = 0, H = 0)")
        if b[0] != 0.0 or h[0] != 0.0:
            raise ValueError(f"{n}: the curve starts at B = {b[0]!r} T, H = {h[0]!r} A/m; it must start "
                             "at B = 0, H = 0 (no remanence)")
        for key, values, unit in (("flux_density", b, "T"), ("field_strength", h, "A/m")):
            for j in range(1, len(values)):
                if values[j] <= values[j - 1]:
                    raise ValueError(f"{n}.{key}[{j}] = {values[j]!r}: the B-H curve must increase strictly "
                                     f"(previous {values[j - 1]!r} {unit})")
        for j in range(1, len(b)):
            mu_d = (b[j] - b[j - 1]) / (h[j] - h[j - 1]) / MU0
            if mu_d < 1.0 - 1e-9:
                raise ValueError(f"{n}.field_strength[{j}] = {h[j]!r}: the differential permeability from "
                                 f"B = {b[j - 1]!r} to {b[j]!r} T is {mu_d:.3g} mu0; it must be >= mu0 "
                                 "(the polarization B - mu0 H cannot fall as H grows)")
        object.__setattr__(self, "flux_density", tuple(b))
        object.__setattr__(self, "field_strength", tuple(h))

    linear = False

    @cached_property
    def curve(self) -> OddPwl:
        """H(B) as an odd piecewise-linear function, its vacuum-slope segment included."""
        b = np.array(self.flux_density + (self.flux_density[-1] + SATURATED_EXTENSION,))
        h = np.array(self.field_strength + (self.field_strength[-1] + SATURATED_EXTENSION / MU0,))
        return OddPwl(b, h)

    @property
    def saturation_polarization(self) -> float:
        """B - mu0 H at and beyond the last point, T: what the iron adds to the vacuum's B."""
        return self.flux_density[-1] - MU0 * self.field_strength[-1]

    def field_strength_at(self, flux_density):
        """H (A/m) at B (T)."""
        return self.curve(flux_density)

    def energy_density(self, flux_density):
        """The integral of H dB from 0 to B, J/m^3 (exact on the piecewise-linear curve)."""
        return self.curve.integral(flux_density)


def sampled_material(label: str, flux_density, relative_permeability) -> TabulatedMaterial:
    """A tabulated material sampled from a relative permeability mu_r(B) at the points
    ``flux_density`` (T, starting at 0)."""
    b = np.asarray(flux_density, dtype=float)
    h = b / (MU0 * relative_permeability(b))
    return TabulatedMaterial(tuple(float(x) for x in b), tuple(float(x) for x in h), label=label)


STEEL_9SMNPB28_PARAMETERS = {"mu_i": 400.0, "b_mumax": 1.488, "c_a": 1200.0, "c_b": 3.0, "n": 12.5}
# every 0.25 T where mu_r stays near mu_i, every 0.05 T through the knee to 2.2 T
STEEL_9SMNPB28_POINTS = tuple(np.round(np.concatenate((np.arange(0.0, 1.0, 0.25), np.arange(1.0, 2.2001, 0.05))), 10))

STEEL_9SMNPB28 = sampled_material(
    "9SMnPb28", STEEL_9SMNPB28_POINTS,
    lambda b: roschke_relative_permeability(b, **STEEL_9SMNPB28_PARAMETERS))

MAGNETIC_MATERIALS = {"9SMnPb28": STEEL_9SMNPB28}


def magnetic_material(label: str, where: str = "magnet.material") -> TabulatedMaterial:
    """The built-in material ``label``; ValueError naming the known ones."""
    if label not in MAGNETIC_MATERIALS:
        raise unknown(where, label, MAGNETIC_MATERIALS, kind="magnetic material")
    return MAGNETIC_MATERIALS[label]


def check_material(name: str, material):
    """``material`` when it is a LinearMaterial or a TabulatedMaterial, else a one-line error."""
    if not isinstance(material, (LinearMaterial, TabulatedMaterial)):
        raise ValueError(f"{name} = {material!r}: expected a LinearMaterial or a TabulatedMaterial "
                         f"(or the name of a built-in: {', '.join(MAGNETIC_MATERIALS)})")
    return material


