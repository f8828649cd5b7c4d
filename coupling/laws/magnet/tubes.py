"""Flux tubes: the pieces a magnet is drawn from, each one formula with its geometry (SI).

Iron tubes carry the coil's whole flux Phi and need Phi's magnetomotive force
l H(Phi / A) from their B-H curve: a prism (``IronPath``: length, cross-section), an axially
magnetised cylinder or tube (``AxialIron``) and a radially magnetised disc or annulus
(``RadialIron``). Air tubes are linear, permeance G (H = Wb/A):

- ``AxialGap``: G = mu0 A / l, a gap of length l over the area A;
- ``RadialGap``: G = 2 pi mu0 l / ln(1 + t / r), the hollow cylinder of inner radius r,
  radial thickness t and axial length l that a slide guiding leaves around a plunger;
- ``QuarterCylinder``: G = 0.52 mu0 l, leakage from an edge to the perpendicular face,
  l the edge's length;
- ``QuarterHollowCylinder``: G = 2 mu0 l ln(1 + t / r) / pi, leakage through a quarter
  annulus of inner radius r and thickness t (given as ratio = t / r), l its length;

(the last two from H. C. Roters, "Electromagnetic Devices", Wiley 1941, as given in the
Modelica Standard Library, Modelica.Magnetic.FluxTubes.Shapes.Leakage). Air tubes in
parallel at one place of the path make a ``FixedGap``. The working air gap over the pole
face, G_w = mu0 A / g, and the leakage flux around the poles in parallel with it,

    G_l(g) = (mu0 w / pi) ln(1 + pi r / g)

(w the mean circumference of the leakage field, r its radius; E. Kallenbach et al.,
"Elektromagnete", 3rd ed., Vieweg+Teubner 2008, with the correction of the Modelica
Standard Library, Modelica.Magnetic.FluxTubes.Shapes.Force.LeakageAroundPoles, which
notes that the book swaps this formula with a neighbouring one), depend on the gap g.
"""

from __future__ import annotations

import math

import numpy as np

from mech.frozen import frozen
from coupling.laws.magnet.bh_curves import MU0, LinearMaterial, TabulatedMaterial
from coupling.laws.magnet.pwl import Linear, OddPwl
from coupling.laws.magnet.validation import check_instance, check_nonnegative, check_positive

QUARTER_CYLINDER_FACTOR = 0.52  # Roters: permeance of a quarter cylinder per mu0 and length


def _check_material(name: str, material):
    return check_instance(name, material, (LinearMaterial, TabulatedMaterial),
                          "a LinearMaterial or a TabulatedMaterial")


class _Iron:
    """What every iron tube gives the magnet: its share of the coil current, a function of
    the flux linkage psi = N Phi."""

    def current_term(self, turns: float):
        """l H(psi / (N A)) / N, A, as a function of psi (Wb): a Linear or an OddPwl."""
        length, area = self.path_length, self.path_area
        curve = self.material.curve
        if isinstance(curve, Linear):
            return Linear(curve.slope * length / (turns * turns * area))
        return OddPwl(curve.xs * (turns * area), curve.ys * (length / turns))

    def reluctance(self) -> float:
        """l / (mu0 mu_r A), A/Wb, of a linear material (at B = 0 for a tabulated one)."""
        return self.material.curve.initial_slope * self.path_length / self.path_area


@frozen
class IronPath(_Iron):
    """Iron of ``length`` (m, along the flux) and uniform cross-section ``area`` (m^2)."""

    length: float
    area: float
    material: LinearMaterial | TabulatedMaterial
    name: str = "magnet.iron"

    def __post_init__(self):
        check_positive(f"{self.name}.length", self.length, "m")
        check_positive(f"{self.name}.area", self.area, "m^2")
        _check_material(f"{self.name}.material", self.material)

    shape = "prism"

    @property
    def path_length(self) -> float:
        return self.length

    @property
    def path_area(self) -> float:
        return self.area


@frozen
class AxialIron(_Iron):
    """A cylinder (``inner_radius`` = 0) or tube magnetised along its axis: flux area
    pi (r_o^2 - r_i^2), path ``length`` (m)."""

    outer_radius: float
    length: float
    material: LinearMaterial | TabulatedMaterial
    inner_radius: float = 0.0
    name: str = "magnet.iron"

    def __post_init__(self):
        n = self.name
        check_positive(f"{n}.outer_radius", self.outer_radius, "m")
        check_positive(f"{n}.length", self.length, "m")
        check_nonnegative(f"{n}.inner_radius", self.inner_radius, "m")
        if self.inner_radius >= self.outer_radius:
            raise ValueError(f"{n}.inner_radius = {self.inner_radius!r}: must be < outer_radius "
                             f"= {self.outer_radius!r} m")
        _check_material(f"{n}.material", self.material)

    shape = "axial"

    @property
    def path_length(self) -> float:
        return self.length

    @property
    def path_area(self) -> float:
        return math.pi * (self.outer_radius ** 2 - self.inner_radius ** 2)


@frozen
class RadialIron(_Iron):
    """A disc or annulus of axial ``thickness`` t magnetised radially from ``inner_radius``
    r_i to ``outer_radius`` r_o (the bottom of a pot-shaped yoke). Its linear reluctance
    ln(r_o / r_i) / (2 pi mu t) is kept exactly; B is taken at the mean radius:
    area pi t (r_i + r_o), path length ((r_i + r_o) / 2) ln(r_o / r_i)."""

    inner_radius: float
    outer_radius: float
    thickness: float
    material: LinearMaterial | TabulatedMaterial
    name: str = "magnet.iron"

    def __post_init__(self):
        n = self.name
        check_positive(f"{n}.inner_radius", self.inner_radius, "m")
        check_positive(f"{n}.outer_radius", self.outer_radius, "m")
        check_positive(f"{n}.thickness", self.thickness, "m")
        if self.outer_radius <= self.inner_radius:
            raise ValueError(f"{n}.outer_radius = {self.outer_radius!r}: must be > inner_radius "
                             f"= {self.inner_radius!r} m")
        _check_material(f"{n}.material", self.material)

    shape = "radial"

    @property
    def path_length(self) -> float:
        return 0.5 * (self.inner_radius + self.outer_radius) * math.log(self.outer_radius / self.inner_radius)

    @property
    def path_area(self) -> float:
        return math.pi * self.thickness * (self.inner_radius + self.outer_radius)


IRON_SHAPES = {"prism": IronPath, "axial": AxialIron, "radial": RadialIron}


@frozen
class AxialGap:
    """An air gap of ``length`` (m) over ``area`` (m^2): G = mu0 A / l."""

    length: float
    area: float
    name: str = "magnet.fixed_gap.tube"

    def __post_init__(self):
        check_positive(f"{self.name}.length", self.length, "m")
        check_positive(f"{self.name}.area", self.area, "m^2")

    shape = "axial"

    @property
    def permeance(self) -> float:
        return MU0 * self.area / self.length


@frozen
class RadialGap:
    """The radial air gap of a slide guiding: a hollow cylinder of ``inner_radius`` r (m),
    radial ``thickness`` t (m) and axial ``length`` l (m): G = 2 pi mu0 l / ln(1 + t / r)."""

    inner_radius: float
    thickness: float
    length: float
    name: str = "magnet.fixed_gap.tube"

    def __post_init__(self):
        check_positive(f"{self.name}.inner_radius", self.inner_radius, "m")
        check_positive(f"{self.name}.thickness", self.thickness, "m")
        check_positive(f"{self.name}.length", self.length, "m")

    shape = "radial"

    @property
    def permeance(self) -> float:
        return 2.0 * math.pi * MU0 * self.length / math.log1p(self.thickness / self.inner_radius)


@frozen
class QuarterCylinder:
    """Leakage from an edge to the perpendicular face along ``length`` l (m; 2 pi r around a
    round pole): G = 0.52 mu0 l (Roters)."""

    length: float
    name: str = "magnet.fixed_gap.tube"

    def __post_init__(self):
        check_positive(f"{self.name}.length", self.length, "m")

    shape = "quarter_cylinder"

    @property
    def permeance(self) -> float:
        return QUARTER_CYLINDER_FACTOR * MU0 * self.length


@frozen
class QuarterHollowCylinder:
    """Leakage through a quarter annulus of inner radius r and thickness t, ``ratio`` = t / r,
    along ``length`` l (m): G = 2 mu0 l ln(1 + t / r) / pi (Roters)."""

    length: float
    ratio: float
    name: str = "magnet.fixed_gap.tube"

    def __post_init__(self):
        check_positive(f"{self.name}.length", self.length, "m")
        check_positive(f"{self.name}.ratio", self.ratio)

    shape = "quarter_hollow_cylinder"

    @property
    def permeance(self) -> float:
        return 2.0 * MU0 * self.length * math.log1p(self.ratio) / math.pi


AIR_SHAPES = {cls.shape: cls for cls in (AxialGap, RadialGap, QuarterCylinder, QuarterHollowCylinder)}


@frozen
class FixedGap:
    """One place of the flux path where it crosses air that does not move with the
    armature: its air tubes ``tube`` (a list) in parallel. Reluctance 1 / (sum of permeances)."""

    tube: tuple
    name: str = "magnet.fixed_gap"

    def __post_init__(self):
        tubes = tuple(self.tube) if not isinstance(self.tube, (str, dict)) and hasattr(self.tube, "__iter__") else None
        if not tubes:
            raise ValueError(f"{self.name}.tube: a fixed gap needs at least one air tube "
                             f"({', '.join(AIR_SHAPES)})")
        for k, tube in enumerate(tubes):
            check_instance(f"{self.name}.tube[{k}]", tube, tuple(AIR_SHAPES.values()),
                           f"an air tube ({', '.join(cls.__name__ for cls in AIR_SHAPES.values())})")
        object.__setattr__(self, "tube", tubes)

    @property
    def reluctance(self) -> float:
        """A/Wb."""
        return 1.0 / sum(t.permeance for t in self.tube)


def working_gap_permeance(area: float, gap):
    """G_w = mu0 A / g, H: an air gap of length g (m) over the pole face A (m^2)."""
    return MU0 * area / np.asarray(gap, dtype=float)


def working_gap_permeance_slope(area: float, gap):
    """dG_w/dg, H/m."""
    g = np.asarray(gap, dtype=float)
    return -MU0 * area / (g * g)


def pole_leakage_permeance(width: float, radius: float, gap):
    """G_l = (mu0 w / pi) ln(1 + pi r / g), H (Kallenbach et al. 2008, as corrected in
    Modelica FluxTubes' LeakageAroundPoles)."""
    g = np.asarray(gap, dtype=float)
    return (MU0 * width / math.pi) * np.log1p(math.pi * radius / g)


def pole_leakage_permeance_slope(width: float, radius: float, gap):
    """dG_l/dg = -mu0 w r / (g (g + pi r)), H/m."""
    g = np.asarray(gap, dtype=float)
    return -MU0 * width * radius / (g * (g + math.pi * radius))


@frozen
class WorkingGap:
    """The working air gap over the pole face of ``area`` (m^2); its length g (m) follows
    the armature. Below ``minimum`` (m, default 1 um: pole faces touch at their roughness)
    g is held at ``minimum``, so that the gap's reluctance stays finite."""

    area: float
    minimum: float = 1e-6
    name: str = "magnet.working_gap"

    def __post_init__(self):
        check_positive(f"{self.name}.area", self.area, "m^2")
        check_positive(f"{self.name}.minimum", self.minimum, "m")


@frozen
class PoleLeakage:
    """The leakage flux around the poles, in parallel with the working gap: ``width`` w (m,
    the leakage field's mean circumference around a round pole) and ``radius`` r (m, its
    radial reach); G_l(g) = (mu0 w / pi) ln(1 + pi r / g). Its radius is taken constant:
    the formula's authors note the field shrinks for gaps below r, where the working gap
    dominates anyway."""

    width: float
    radius: float
    name: str = "magnet.pole_leakage"

    def __post_init__(self):
        check_positive(f"{self.name}.width", self.width, "m")
        check_positive(f"{self.name}.radius", self.radius, "m")
