"""Validated, frozen parameter sets of the impact problem (SI units).

Every dataclass checks its fields once, where it is built, and raises ``ValueError``
naming the field, the value and what is allowed. Nothing downstream re-validates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Literal, Union

import numpy as np

MuLike = Union[float, Callable[[float], float]]


def check_finite(name: str, value) -> float:
    """Return ``value`` as float, or raise naming the field when it is not a finite number."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value!r}: expected a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r}: expected a finite number")
    return value


def check_positive(name: str, value) -> float:
    value = check_finite(name, value)
    if value <= 0.0:
        raise ValueError(f"{name} = {value!r}: must be > 0")
    return value


def check_nonnegative(name: str, value) -> float:
    value = check_finite(name, value)
    if value < 0.0:
        raise ValueError(f"{name} = {value!r}: must be >= 0")
    return value


def check_range(name: str, value, low: float, high: float, *, closed_low=False, closed_high=False) -> float:
    """A number inside (low, high); ``closed_*`` makes that end inclusive."""
    value = check_finite(name, value)
    ok_low = value >= low if closed_low else value > low
    ok_high = value <= high if closed_high else value < high
    if not (ok_low and ok_high):
        lo, hi = ("[" if closed_low else "("), ("]" if closed_high else ")")
        raise ValueError(f"{name} = {value!r}: allowed range is {lo}{low}, {high}{hi}")
    return value


def check_choice(name: str, value, choices) -> str:
    if value not in choices:
        raise ValueError(f"{name} = {value!r}: allowed values are {', '.join(map(repr, choices))}")
    return value


def check_vector3(name: str, value) -> tuple[float, float, float]:
    try:
        items = list(value)
    except TypeError:
        raise ValueError(f"{name} = {value!r}: expected a list of 3 numbers") from None
    if len(items) != 3:
        raise ValueError(f"{name} = {value!r}: expected a list of 3 numbers")
    return tuple(check_finite(f"{name}[{i}]", v) for i, v in enumerate(items))


def _check_count(name: str, value, high: int = 40, auto: bool = False):
    if auto and value == "auto":  # chosen from the scene (mech/mode_count.py)
        return value
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} = {value!r}: expected a whole number in [0, {high}]"
                         + (' or "auto"' if auto else ""))
    if not 0 <= value <= high:
        raise ValueError(f"{name} = {value!r}: allowed range is [0, {high}]")
    return int(value)


@dataclass(frozen=True)
class Bar:
    """The slender bar with rounded (spherical-cap) tips at both ends.

    length: m, tip to tip. Section: round (``diameter``, m) or rectangular
    (``width`` x ``thickness``, m; width along body b2, thickness along b3).
    tip_radius: m, radius of the spherical tip caps; must be at least half the
    section's largest half-width so the cap spans the section.
    youngs_modulus: Pa. poisson_ratio: -, in (-1, 0.5). density: kg/m^3.
    axial_modes, bending_modes: free-free modes per family (bending counts per plane);
    0 and 0 is the rigid bar; "auto" (default): chosen from the scene's contact time
    (mech/mode_count.py), resolved when the model is built.
    bending: "euler_bernoulli" (default, U = 1/2 int E I (d2 delta/dx2)^2 dx) or
    "paper_shear" (the source paper's U = 1/2 int (G/nu) A (d delta/dx)^2 dx).
    modal_damping: damping ratio of every elastic mode (default 0: none).
    """

    length: float = 0.3
    diameter: float | None = 0.01
    width: float | None = None
    thickness: float | None = None
    tip_radius: float = 0.005
    youngs_modulus: float = 210e9
    poisson_ratio: float = 0.3
    density: float = 7850.0
    axial_modes: int | str = "auto"
    bending_modes: int | str = "auto"
    bending: Literal["euler_bernoulli", "paper_shear"] = "euler_bernoulli"
    modal_damping: float = 0.0

    def __post_init__(self):
        check_positive("bar.length", self.length)
        if self.diameter is not None:
            if self.width is not None or self.thickness is not None:
                raise ValueError(
                    "bar: give either diameter (round section) or width and thickness "
                    "(rectangular section), not both"
                )
            check_positive("bar.diameter", self.diameter)
        else:
            if self.width is None or self.thickness is None:
                raise ValueError("bar: a section is needed: diameter, or width and thickness")
            check_positive("bar.width", self.width)
            check_positive("bar.thickness", self.thickness)
        check_positive("bar.tip_radius", self.tip_radius)
        check_positive("bar.youngs_modulus", self.youngs_modulus)
        check_range("bar.poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        check_positive("bar.density", self.density)
        _check_count("bar.axial_modes", self.axial_modes, auto=True)
        _check_count("bar.bending_modes", self.bending_modes, auto=True)
        check_choice("bar.bending", self.bending, ("euler_bernoulli", "paper_shear"))
        check_range("bar.modal_damping", self.modal_damping, 0.0, 1.0, closed_low=True)
        half = self.section_half_width
        if self.tip_radius < half * (1.0 - 1e-12):
            raise ValueError(
                f"bar.tip_radius = {self.tip_radius!r}: must be >= {half!r} m (half the section "
                "width) so the spherical cap covers the section"
            )
        if 2.0 * self.tip_radius >= self.length:
            raise ValueError(
                f"bar.tip_radius = {self.tip_radius!r}: must be < length/2 = {self.length / 2!r} m"
            )

    @property
    def section_half_width(self) -> float:
        """m: the largest distance of the section's edge from the axis."""
        if self.diameter is not None:
            return 0.5 * self.diameter
        return 0.5 * math.hypot(self.width, self.thickness)

    @property
    def area(self) -> float:
        """m^2."""
        if self.diameter is not None:
            return math.pi * self.diameter**2 / 4.0
        return self.width * self.thickness

    @property
    def second_moments(self) -> tuple[float, float]:
        """m^4: (I_22, I_33) = (int x3^2 dA, int x2^2 dA): bending of delta3 uses I_22, of delta2 I_33."""
        if self.diameter is not None:
            i = math.pi * self.diameter**4 / 64.0
            return i, i
        b, h = self.width, self.thickness
        return b * h**3 / 12.0, h * b**3 / 12.0

    @property
    def mass(self) -> float:
        """kg (the caps are treated as part of a uniform prismatic bar)."""
        return self.density * self.area * self.length

    @property
    def shear_modulus(self) -> float:
        """Pa."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def cap_half_angle(self) -> float:
        """rad: half-angle of the spherical cap; contact normals beyond it would leave the cap."""
        return math.asin(min(1.0, self.section_half_width / self.tip_radius))


@dataclass(frozen=True)
class Block:
    """The massive block (an elastic half-space). youngs_modulus: Pa; poisson_ratio: -."""

    youngs_modulus: float = 210e9
    poisson_ratio: float = 0.3

    def __post_init__(self):
        check_positive("block.youngs_modulus", self.youngs_modulus)
        check_range("block.poisson_ratio", self.poisson_ratio, -1.0, 0.5)


CONTACT_LAWS = ("paper", "hunt_crossley", "lankarani_nikravesh", "flores")


@dataclass(frozen=True)
class Contact:
    """Normal contact law F_n = k y^1.5 + c y^beta dy/dt, clipped at F_n >= 0.

    law: "paper" (beta = 1, the source paper's c y dy/dt), "hunt_crossley",
    "lankarani_nikravesh" or "flores" (beta = 1.5).
    damping: c given directly (paper: N s/m^2; the others: N s/m^2.5), or
    restitution: target coefficient of restitution in (0, 1] at reference_speed (m/s;
    None = the first impact's normal speed estimated from the initial conditions),
    calibrated by ``calibration``: "exact" (root-find on the single-impact problem) or
    "formula" (the law's own closed form; not available for "paper").
    stiffness: N/m^1.5; None = Hertz from the materials and tip radius.
    """

    law: str = "paper"
    damping: float | None = None
    restitution: float | None = 0.8
    reference_speed: float | None = None
    calibration: Literal["exact", "formula"] = "exact"
    stiffness: float | None = None

    def __post_init__(self):
        check_choice("contact.law", self.law, CONTACT_LAWS)
        check_choice("contact.calibration", self.calibration, ("exact", "formula"))
        if self.damping is not None and self.restitution is not None:
            raise ValueError("contact: give damping or restitution, not both")
        if self.damping is not None:
            check_nonnegative("contact.damping", self.damping)
        elif self.restitution is not None:
            check_range("contact.restitution", self.restitution, 0.0, 1.0, closed_high=True)
        else:
            raise ValueError("contact: give damping (c) or restitution (target e)")
        if self.reference_speed is not None:
            check_positive("contact.reference_speed", self.reference_speed)
        if self.stiffness is not None:
            check_positive("contact.stiffness", self.stiffness)
        if self.calibration == "formula" and self.law == "paper" and self.damping is None:
            raise ValueError(
                "contact.calibration = 'formula': the paper law has no closed form; use 'exact'"
            )

    @property
    def beta(self) -> float:
        """Exponent of y in the damping term."""
        return 1.0 if self.law == "paper" else 1.5


@dataclass(frozen=True)
class Friction:
    """Generalized friction |F_t| = mu F_n^(1-gamma) (gamma = 0: Coulomb).

    mu: N^gamma, a number or a callable mu(I) of the contact current I (A) that the
    coupling evaluates; 0 switches the tangential machinery off.
    gamma: -, in [0, 1). model: "exact" (stick/slip switching by events) or
    "regularized" (F_t = -mu F_n^(1-gamma) v_t / sqrt(|v_t|^2 + v_s^2), for comparison).
    max_ratio: the largest |F_t|/F_n the law may reach; below the load
    F_0 = (mu / max_ratio)^(1/gamma) friction is proportional to F_n with that ratio
    (docs/mechanics.md gives the reasons). inf keeps the bare power law.
    regularization_speed: v_s, m/s (regularized model only).
    """

    mu: MuLike = 0.0
    gamma: float = 0.0
    model: Literal["exact", "regularized"] = "exact"
    max_ratio: float = 1.0
    regularization_speed: float = 1e-4

    def __post_init__(self):
        if not callable(self.mu):
            check_nonnegative("friction.mu", self.mu)
        check_range("friction.gamma", self.gamma, 0.0, 1.0, closed_low=True)
        check_choice("friction.model", self.model, ("exact", "regularized"))
        if not (isinstance(self.max_ratio, (int, float)) and self.max_ratio > 0):
            raise ValueError(f"friction.max_ratio = {self.max_ratio!r}: must be > 0 (inf allowed)")
        if math.isnan(self.max_ratio):
            raise ValueError(f"friction.max_ratio = {self.max_ratio!r}: must be > 0 (inf allowed)")
        check_positive("friction.regularization_speed", self.regularization_speed)

    @property
    def active(self) -> bool:
        """False when friction is identically zero (mu = 0 constant)."""
        return callable(self.mu) or self.mu > 0.0

    def mu_at(self, current: float = 0.0) -> float:
        """mu (N^gamma) at contact current ``current`` (A)."""
        if callable(self.mu):
            value = float(self.mu(current))
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"friction.mu({current!r}) = {value!r}: must be a finite number >= 0")
            return value
        return float(self.mu)


@dataclass(frozen=True)
class Initial:
    """Initial state at release.

    height: m, gap between the lowest tip and the block surface (>= 0).
    angle_deg: deg, bar axis to the surface, in [-90, 90]; > 0 puts tip 1 (body +x end) up.
    azimuth_deg: deg, direction of the bar's horizontal projection about the vertical.
    velocity: m/s, centre of mass, world frame (x, y horizontal, z up).
    angular_velocity: rad/s, world frame.
    resting: start in static equilibrium on the block (a contact already closed): lying
    flat on both tips (angle_deg = 0) or standing on one (angle_deg = +-90), pressed in by
    its weight, with the static sag of its modes; height is then not used.
    """

    height: float = 1e-3
    angle_deg: float = 30.0
    azimuth_deg: float = 0.0
    velocity: tuple[float, float, float] = (0.2, 0.0, -1.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    resting: bool = False

    def __post_init__(self):
        h = check_finite("initial.height", self.height)
        if h < 0.0:
            raise ValueError(
                f"initial.height = {h!r}: the bar would start inside the block; must be >= 0"
            )
        check_range("initial.angle_deg", self.angle_deg, -90.0, 90.0, closed_low=True, closed_high=True)
        check_finite("initial.azimuth_deg", self.azimuth_deg)
        object.__setattr__(self, "velocity", check_vector3("initial.velocity", self.velocity))
        object.__setattr__(
            self, "angular_velocity", check_vector3("initial.angular_velocity", self.angular_velocity)
        )
        if not isinstance(self.resting, bool):
            raise ValueError(f"initial.resting = {self.resting!r}: expected true or false")
        if self.resting and not (abs(self.angle_deg) < 1e-9 or abs(abs(self.angle_deg) - 90.0) < 1e-9):
            raise ValueError(
                f"initial.resting with angle_deg = {self.angle_deg!r}: a bar rests in static equilibrium only "
                "lying flat (angle_deg = 0, on both tips) or standing (angle_deg = 90 or -90, on one tip)"
            )


@dataclass(frozen=True)
class SolverOptions:
    """Integration settings.

    rtol: relative tolerance of the DOPRI5 error control (error scales are set from the
    problem: Hertz penetration, impact speed, total energy). t_end: s.
    model: "auto" (planar when the motion stays in a vertical plane), "planar" or "3d".
    max_step: s, upper bound on the step (None: a quarter of the shortest contact time
    estimated from the Hertz closed form, so no contact can be stepped over).
    stick_velocity_tol: m/s, slip speeds below this at a slip-direction event are stops.
    energy_tolerance: relative energy residual above which the result is flagged.
    """

    rtol: float = 1e-6
    t_end: float = 0.05
    model: Literal["auto", "planar", "3d"] = "auto"
    max_step: float | None = None
    stick_velocity_tol: float = 1e-6
    energy_tolerance: float = 1e-3
    max_steps: int = 5_000_000

    def __post_init__(self):
        check_range("solver.rtol", self.rtol, 1e-13, 0.1, closed_high=True)
        check_positive("solver.t_end", self.t_end)
        check_choice("solver.model", self.model, ("auto", "planar", "3d"))
        if self.max_step is not None:
            check_positive("solver.max_step", self.max_step)
        check_positive("solver.stick_velocity_tol", self.stick_velocity_tol)
        check_positive("solver.energy_tolerance", self.energy_tolerance)
        if isinstance(self.max_steps, bool) or not isinstance(self.max_steps, int) or self.max_steps < 1:
            raise ValueError(f"solver.max_steps = {self.max_steps!r}: must be a whole number >= 1")


@dataclass(frozen=True)
class MechScene:
    """Everything the impact solver needs. gravity: m/s^2 (>= 0), acting along -z."""

    bar: Bar = field(default_factory=Bar)
    block: Block = field(default_factory=Block)
    contact: Contact = field(default_factory=Contact)
    friction: Friction = field(default_factory=Friction)
    initial: Initial = field(default_factory=Initial)
    solver: SolverOptions = field(default_factory=SolverOptions)
    gravity: float = 9.80665

    def __post_init__(self):
        check_nonnegative("environment.gravity", self.gravity)
        for name, cls in (("bar", Bar), ("block", Block), ("contact", Contact),
                          ("friction", Friction), ("initial", Initial), ("solver", SolverOptions)):
            if not isinstance(getattr(self, name), cls):
                raise ValueError(f"{name}: expected a {cls.__name__}, got {type(getattr(self, name)).__name__}")
