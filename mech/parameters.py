"""Validated, frozen parameter sets of the impact problem (SI units).

Every dataclass checks its fields once, where it is built, with the checks of
mech/validation.py, and raises ``ValueError`` naming the field, the value and what is
allowed. Nothing downstream re-validates. The defaults of the fields are the defaults of
the scene keys (docs/scene_keys.md, tested against it).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Callable, Literal, Union

import numpy as np

from .table_smoothing import INTERPOLATIONS, smooth_samples
from .travel_spring import travel_work
from .validation import (
    check_bool, check_choice, check_count, check_finite, check_magnitude, check_name, check_nonnegative,
    check_position, check_positive, check_range, check_table, check_vector3, check_whole, internal, scene_key,
)
from .frozen import frozen

MuLike = Union[float, Callable[[float], float]]

# Bounds of the values a scene may give (docs/scene_keys.md, "Bounds"). Far beyond any
# switch contact, they keep every product the model forms finite (bar.length = 1e300 made
# the inertia overflow to inf, initial.velocity = 1e300 the kinetic energy) and bound the
# work and memory a run can be asked for.
LENGTH_MAX = 10.0  # m: lengths, radii, heights, offsets, anchors, a clamp's travel
SPEED_MAX = 1e3  # m/s: initial speeds, reference and resolution speeds
ANGULAR_SPEED_MAX = 1e5  # rad/s
MODULUS_MAX = 1e13  # Pa: ten times diamond's
DENSITY_MIN, DENSITY_MAX = 1.0, 1e5  # kg/m^3: from air (nothing solid is lighter) to four times osmium
MASS_MAX = 1e3  # kg: a rivet's mass
GRAVITY_MAX = 1e3  # m/s^2: a hundred g
FORCE_MAX = 1e9  # N: actuator forces, spring preloads
TORQUE_MAX = 1e10  # N m: a pivot's preload (FORCE_MAX at LENGTH_MAX)
STIFFNESS_MAX = 1e12  # N/m of a spring, N m/rad of a pivot
CONTACT_STIFFNESS_MAX = 1e16  # N/m^1.5 (Hertz for steel on steel, 5 mm caps: 1.1e10)
DAMPING_MAX = 1e15  # of springs (N s/m), a pivot (N m s/rad) and the contact law
MU_MAX = 1e3  # N^gamma
T_END_MAX = 1e3  # s: the longest run (a switch's motion lasts milliseconds)
MAX_STEPS_MAX = 100_000_000  # accepted + rejected steps: minutes to hours of integration
HISTORY_ROWS_MIN, HISTORY_ROWS_MAX = 100, 10_000_000  # rows of the history a run keeps in memory
HISTORY_ROWS = 100_000  # the default: twice what history.csv keeps at most by default ([output])
ENERGY_TOLERANCE_MAX = 5e-3  # a larger audit residual is an energy error of the size a bounce dissipates
TABLE_POINTS_MAX = 100_000  # points of a force table or a clamp's travel
LOADS_MAX = 100  # [[force]] and [[spring]] entries together
FIXED_MAX = 4  # [[fixed]] entries: contact pairs (kernel_layout.MAX_PAIRS)
RIVETS_WITH_BLOCK = 2  # [[rivet]] entries with the one fixed contact [block] (each a contact pair)
DIRECTION_MAX = 1e6  # components of a force's direction before it is normalized


@frozen
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

    length: float = scene_key(0.3, unit="m", doc="tip to tip")
    diameter: float | None = scene_key(0.01, unit="m", doc="round section (or `width` and `thickness`)")
    width: float | None = scene_key(None, unit="m", doc="rectangular section, with `thickness`")
    thickness: float | None = scene_key(None, unit="m", doc="rectangular section, bending direction")
    tip_radius: float = scene_key(0.005, unit="m", doc="spherical tip caps, >= half the section")
    youngs_modulus: float = scene_key(210e9, unit="Pa")
    poisson_ratio: float = scene_key(0.3, unit="-", doc="in (-1, 0.5)")
    density: float = scene_key(7850.0, unit="kg/m^3")
    axial_modes: int | str = scene_key(
        "auto", unit="-",
        doc='elastic modes per family (0-40), or `{axial = n, bending = n}` (a family left out: "auto"); "auto": '
            "every mode below 3 / contact time (docs/mechanics.md)",
        name="modes")
    bending_modes: int | str = scene_key(
        "auto", unit="-",
        doc='elastic modes per family (0-40), or `{axial = n, bending = n}` (a family left out: "auto"); "auto": '
            "every mode below 3 / contact time (docs/mechanics.md)",
        name="modes")
    bending: Literal["euler_bernoulli", "paper_shear"] = scene_key(
        "euler_bernoulli", unit="-", doc='or "paper_shear"')
    modal_damping: float = scene_key(0.0, unit="-", doc="damping ratio of every elastic mode")

    def __post_init__(self):
        check_positive("bar.length", self.length, high=LENGTH_MAX)
        if self.diameter is not None:
            if self.width is not None or self.thickness is not None:
                raise ValueError(
                    "bar.diameter and bar.width/bar.thickness: give either bar.diameter (round section) "
                    "or bar.width and bar.thickness (rectangular section), not both"
                )
            check_positive("bar.diameter", self.diameter, high=LENGTH_MAX)
        else:
            if self.width is None or self.thickness is None:
                raise ValueError("bar.diameter: a section is needed: bar.diameter, or bar.width and bar.thickness")
            check_positive("bar.width", self.width, high=LENGTH_MAX)
            check_positive("bar.thickness", self.thickness, high=LENGTH_MAX)
        check_positive("bar.tip_radius", self.tip_radius, high=LENGTH_MAX)
        check_positive("bar.youngs_modulus", self.youngs_modulus, high=MODULUS_MAX)
        check_range("bar.poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        check_range("bar.density", self.density, DENSITY_MIN, DENSITY_MAX, closed_low=True, closed_high=True)
        check_count("bar.axial_modes", self.axial_modes, auto=True)
        check_count("bar.bending_modes", self.bending_modes, auto=True)
        check_choice("bar.bending", self.bending, ("euler_bernoulli", "paper_shear"))
        check_range("bar.modal_damping", self.modal_damping, 0.0, 1.0, closed_low=True)
        half = self.section_half_width
        if self.tip_radius < half * (1.0 - 1e-12):
            what = "half the diameter" if self.diameter is not None else "half the section's diagonal"
            raise ValueError(
                f"bar.tip_radius = {self.tip_radius!r}: must be >= {half!r} m ({what}) so the spherical "
                "cap covers the section"
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


@frozen
class Block:
    """The fixed contact: a massive elastic body. youngs_modulus: Pa; poisson_ratio: -.

    shape: "plane" (a half-space, its surface the plane z = 0) or "sphere" (a fixed
    spherical rivet of ``radius`` m whose top is at z = 0, right below the striking
    contact at the start, shifted by ``offset`` m along the bar's horizontal direction).
    The sphere is treated by its tangent plane at the top with the curvature in the Hertz
    stiffness (effective radius R1 R2 / (R1 + R2)): exact while the contact stays within a
    small fraction of the radius from the top: the run flags a contact where the sphere lies
    more than a tenth of the Hertz penetration scale below that plane (``block.offset``
    misaligns the two contacts and is what such a flag usually means).
    """

    youngs_modulus: float = scene_key(210e9, unit="Pa")
    poisson_ratio: float = scene_key(0.3, unit="-")
    shape: str = scene_key(
        "plane", unit="-", doc='"plane" (surface z = 0) or "sphere" (a fixed rivet, its top at z = 0)')
    radius: float | None = scene_key(None, unit="m", doc="sphere only: the fixed rivet's radius")
    offset: float = scene_key(
        0.0, unit="m", doc="sphere only: shift of its top from below the striking contact, along the bar")

    def __post_init__(self):
        check_positive("block.youngs_modulus", self.youngs_modulus, high=MODULUS_MAX)
        check_range("block.poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        check_choice("block.shape", self.shape, ("plane", "sphere"))
        if self.shape == "sphere":
            if self.radius is None:
                raise ValueError("block.radius: needed for block.shape = 'sphere' (m)")
            check_positive("block.radius", self.radius, high=LENGTH_MAX)
        elif self.radius is not None:
            raise ValueError("block.radius: only a spherical block has a radius; set block.shape = 'sphere'")
        check_magnitude("block.offset", self.offset, LENGTH_MAX)


CONTACT_LAWS = ("paper", "hunt_crossley", "lankarani_nikravesh", "flores")


@frozen
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

    law: str = scene_key(
        "paper", unit="-", doc='normal damping law: "paper", "hunt_crossley", ... (docs/mechanics.md)')
    damping: float | None = scene_key(None, unit="N s/m^2(.5)", doc="damping coefficient given directly")
    restitution: float | None = scene_key(0.8, unit="-", doc="target restitution at `reference_speed` (or `damping`)")
    reference_speed: float | None = scene_key(
        None, unit="m/s", doc="where `restitution` is calibrated; omitted: the first impact's normal speed")
    calibration: Literal["exact", "formula"] = scene_key("exact", unit="-", doc='or "formula"')
    stiffness: float | None = scene_key(
        None, unit="N/m^1.5", doc="override of the Hertz stiffness; omitted: Hertz from the materials and radii")

    def __post_init__(self):
        check_choice("contact.law", self.law, CONTACT_LAWS)
        check_choice("contact.calibration", self.calibration, ("exact", "formula"))
        if self.damping is not None and self.restitution is not None:
            raise ValueError("contact.damping and contact.restitution: give one of them, not both")
        if self.damping is not None:
            check_nonnegative("contact.damping", self.damping, high=DAMPING_MAX)
        elif self.restitution is not None:
            check_range("contact.restitution", self.restitution, 0.0, 1.0, closed_high=True)
        else:
            raise ValueError("contact.restitution: give contact.damping (c) or contact.restitution (target e)")
        if self.reference_speed is not None:
            check_positive("contact.reference_speed", self.reference_speed, high=SPEED_MAX)
        if self.stiffness is not None:
            check_positive("contact.stiffness", self.stiffness, high=CONTACT_STIFFNESS_MAX)
        if self.calibration == "formula" and self.law == "paper" and self.damping is None:
            raise ValueError(
                "contact.calibration = 'formula': the paper law has no closed form; use 'exact'"
            )

    @property
    def beta(self) -> float:
        """Exponent of y in the damping term."""
        return 1.0 if self.law == "paper" else 1.5


@frozen
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

    mu: MuLike = scene_key(0.0, unit="N^gamma", doc="friction coefficient (not with `[tribology]`)")
    gamma: float = scene_key(0.0, unit="-", doc="|F_t| = mu F_n^(1-gamma) (not with `[tribology]`)")
    model: Literal["exact", "regularized"] = scene_key(
        "exact", unit="-", doc='stick/slip by events, or "regularized"')
    max_ratio: float = scene_key(1.0, unit="-", doc="largest |F_t|/F_n")
    regularization_speed: float = scene_key(1e-4, unit="m/s", doc="regularized model only")

    def __post_init__(self):
        if not callable(self.mu):
            check_nonnegative("friction.mu", self.mu, high=MU_MAX)
        check_range("friction.gamma", self.gamma, 0.0, 1.0, closed_low=True)
        check_choice("friction.model", self.model, ("exact", "regularized"))
        check_positive("friction.max_ratio", self.max_ratio, allow_inf=True)
        check_positive("friction.regularization_speed", self.regularization_speed, high=SPEED_MAX)

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


@frozen
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

    height: float = scene_key(1e-3, unit="m", doc="lowest tip above the block (the contact gap)")
    angle_deg: float = scene_key(
        30.0, unit="deg",
        doc="bar axis to the surface, [-90, 90]; a bar with a `[mount]` clamp or pivot starts level",
        shown="30 (held bar: 0)")
    azimuth_deg: float = scene_key(0.0, unit="deg", doc="direction of the bar's horizontal projection")
    velocity: tuple[float, float, float] = scene_key(
        (0.2, 0.0, -1.0), unit="m/s", doc="centre of mass, world frame (z up); a held bar starts at rest",
        shown="[0.2, 0, -1] (held bar: [0, 0, 0])")
    angular_velocity: tuple[float, float, float] = scene_key((0.0, 0.0, 0.0), unit="rad/s", doc="world frame")
    resting: bool = scene_key(False, unit="-", doc="start in static equilibrium on the block")

    def __post_init__(self):
        h = check_finite("initial.height", self.height)
        if h < 0.0:
            raise ValueError(
                f"initial.height = {h!r}: the bar would start inside the block; must be >= 0"
            )
        check_nonnegative("initial.height", h, high=LENGTH_MAX)
        check_range("initial.angle_deg", self.angle_deg, -90.0, 90.0, closed_low=True, closed_high=True)
        check_magnitude("initial.azimuth_deg", self.azimuth_deg, 360.0)
        object.__setattr__(self, "velocity", check_vector3("initial.velocity", self.velocity, SPEED_MAX))
        object.__setattr__(self, "angular_velocity", check_vector3(
            "initial.angular_velocity", self.angular_velocity, ANGULAR_SPEED_MAX))
        check_bool("initial.resting", self.resting)
        if self.resting and not (abs(self.angle_deg) < 1e-9 or abs(abs(self.angle_deg) - 90.0) < 1e-9):
            raise ValueError(
                f"initial.resting with angle_deg = {self.angle_deg!r}: a bar rests in static equilibrium only "
                "lying flat (angle_deg = 0, on both tips) or standing (angle_deg = 90 or -90, on one tip)"
            )


# The loosest rtol shown to give a sound run: at 1e-5 the default coupled and mechanics
# scenes keep their energy audit within tolerance, at 2e-5 the mechanics default already
# fails it (benchmarks/bench_rtol_soundness.py; its table, with the figures, in
# docs/coupling.md, "The rtol range").
RTOL_MAX = 1e-5


@frozen
class SolverOptions:
    """Integration settings.

    rtol: relative tolerance of the DOPRI5 error control (error scales are set from the
    problem: Hertz penetration, impact speed, total energy), in (1e-13, RTOL_MAX]. t_end: s.
    model: "auto" (planar when the motion stays in a vertical plane), "planar" or "3d".
    max_step: s, upper bound on the step (None: a quarter of the shortest contact time
    estimated from the Hertz closed form, so no contact can be stepped over).
    stick_velocity_tol: m/s, slip speeds below this at a slip-direction event are stops.
    energy_tolerance: relative energy residual above which the result is flagged, in
    (0, ENERGY_TOLERANCE_MAX].
    max_steps: accepted and rejected steps before the run stops unfinished.
    history_rows: rows of the history a run keeps in memory: beyond them the older rows are
    thinned to a uniform time grid, every event and regime change kept (mech.recorder);
    the memory a run takes grows with this, not with its steps.
    """

    rtol: float = scene_key(1e-6, unit="-", doc="DOPRI5 relative tolerance")
    t_end: float = scene_key(
        0.05, unit="s",
        doc="length of the run (the built-in scenes set their own). A `[circuit.schedule]` scene keeps "
            "`[solver]` for this key alone; without it the run lasts 0.05 s")
    model: Literal["auto", "planar", "3d"] = scene_key("auto", unit="-", doc='"planar", "3d"')
    max_step: float | None = scene_key(
        None, unit="s", doc="omitted: a quarter of the shortest contact time (Hertz estimate)")
    stick_velocity_tol: float = scene_key(1e-6, unit="m/s")
    energy_tolerance: float = scene_key(
        1e-3, unit="-",
        doc="energy residual (relative to the scene's energy scale) above which the result is flagged and "
            "unsound; at most 5e-3")
    max_steps: int = scene_key(
        5_000_000, unit="-", doc="accepted and rejected steps before the run stops unfinished; at most 1e8")
    history_rows: int = scene_key(
        HISTORY_ROWS, unit="-",
        doc="rows of the history a run keeps in memory (besides one stepper's room, at most 16 384 rows); beyond "
            "them older rows are thinned to a uniform time grid, every event and regime change kept, the steps "
            'unchanged (docs/mechanics.md, "Memory"); 100 to 1e7')

    def __post_init__(self):
        check_range("solver.rtol", self.rtol, 1e-13, RTOL_MAX, closed_high=True)
        check_positive("solver.t_end", self.t_end, high=T_END_MAX)
        check_choice("solver.model", self.model, ("auto", "planar", "3d"))
        if self.max_step is not None:
            check_positive("solver.max_step", self.max_step, high=T_END_MAX)
        check_positive("solver.stick_velocity_tol", self.stick_velocity_tol, high=SPEED_MAX)
        check_positive("solver.energy_tolerance", self.energy_tolerance, high=ENERGY_TOLERANCE_MAX)
        check_whole("solver.max_steps", self.max_steps, 1, MAX_STEPS_MAX)
        check_whole("solver.history_rows", self.history_rows, HISTORY_ROWS_MIN, HISTORY_ROWS_MAX)


MOUNT_KINDS = ("free", "clamp", "pivot")


@frozen
class Mount:
    """Where the bar is held.

    kind: "free" (no support), "clamp" (a cantilever blade clamped at ``position``) or
    "pivot" (a hinge at ``position`` about the horizontal axis normal to the bar's plane).
    position: m along the bar from tip 0 (``length`` holds it at the tip-1 end, so tip 0 or
    a rivet strikes). base_motion (clamp only): prescribed travel of the clamp,
    ``{time = [...] s, displacement = [[x, y, z], ...] m}`` in the world frame, linear
    between points (constant before the first and after the last), or with
    ``interpolation = "pchip"`` a monotone cubic through them (mech.table_smoothing).
    stiffness: N m/rad, torsion spring of the pivot; preload_torque: N m, its torque at
    the initial position, turning the free end towards the block; damping: N m s/rad.
    """

    kind: str = scene_key("free", unit="-", doc='"free", "clamp" (cantilever blade) or "pivot" (hinge about y)')
    position: float | None = scene_key(
        None, unit="m", doc="clamp or hinge, along the bar from tip 0 (`length`: at the tip-1 end)")
    base_motion: dict | None = scene_key(
        None, unit="s, m",
        doc="clamp only: `{time = [...], displacement = [[x, y, z], ...]}` travel of the clamp, linear between "
            'points; with `interpolation = "pchip"` a monotone cubic through them (docs/mechanics.md, "Smooth '
            'tables")')
    stiffness: float = scene_key(0.0, unit="N m/rad", doc="pivot only: torsion spring")
    preload_torque: float = scene_key(
        0.0, unit="N m", doc="pivot only: the spring's torque at the start, turning the free end towards the block")
    damping: float = scene_key(0.0, unit="N m s/rad", doc="pivot only")

    def __post_init__(self):
        check_choice("mount.kind", self.kind, MOUNT_KINDS)
        if self.kind == "free":
            for key in ("position", "base_motion"):
                if getattr(self, key) is not None:
                    raise ValueError(f"mount.{key}: a free bar is not held; set mount.kind = "
                                     "'clamp' or 'pivot', or remove the key")
        elif self.position is None:
            raise ValueError(f"mount.position: needed for mount.kind = {self.kind!r} "
                             "(m along the bar from tip 0)")
        else:
            check_finite("mount.position", self.position)
        if self.kind != "pivot":
            for key in ("stiffness", "preload_torque", "damping"):
                if getattr(self, key) != 0.0:
                    raise ValueError(f"mount.{key}: a torsion spring belongs to a pivot; "
                                     f"mount.kind = {self.kind!r}")
        check_nonnegative("mount.stiffness", self.stiffness, high=STIFFNESS_MAX)
        check_magnitude("mount.preload_torque", self.preload_torque, TORQUE_MAX)
        check_nonnegative("mount.damping", self.damping, high=DAMPING_MAX)
        if self.base_motion is not None:
            if self.kind != "clamp":
                raise ValueError("mount.base_motion: only a clamped bar has a moving base "
                                 f"(mount.kind = {self.kind!r})")
            bm = self.base_motion
            if not isinstance(bm, dict) or not {"time", "displacement"} <= set(bm) <= {
                    "time", "displacement", "interpolation"}:
                raise ValueError(f"mount.base_motion = {bm!r}: expected "
                                 "{time = [...], displacement = [[x, y, z], ...]} (and interpolation)")
            ts, ds = check_table("mount.base_motion", bm["time"], bm["displacement"], width=3, time_high=T_END_MAX,
                                 value_high=LENGTH_MAX, max_points=TABLE_POINTS_MAX)
            how = check_choice("mount.base_motion.interpolation", bm.get("interpolation", "linear"), INTERPOLATIONS)
            object.__setattr__(self, "base_motion", {"time": ts, "displacement": ds, "interpolation": how})

    def base_table(self) -> tuple[tuple, tuple] | None:
        """(times s, displacements m) the mechanics follows, linear between them: the table as
        given, or densely sampled from its monotone cubic (interpolation = "pchip"); None
        without a base motion."""
        bm = self.base_motion
        if bm is None:
            return None
        if bm["interpolation"] == "linear":
            return bm["time"], bm["displacement"]
        ts, ds = smooth_samples(bm["time"], bm["displacement"])
        return tuple(float(t) for t in ts), tuple(tuple(float(v) for v in d) for d in ds)

    @property
    def held(self) -> bool:
        return self.kind != "free"


@frozen
class PointForce:
    """An actuator force on the bar (an armature, a finger).

    position: m along the bar from tip 0. direction: a vector (normalized here) in the
    ``frame`` "world" (fixed) or "body" (turning with the bar's frame). magnitude: N,
    constant; or ``time`` (s) and ``value`` (N) tables, linear between points, or with
    ``interpolation = "pchip"`` a monotone cubic through them (mech.table_smoothing).
    ``travel`` (m, strictly increasing) and ``share`` (1, in [0, 1], one per travel): the
    force follows the travel of its point, the magnitude times share(travel), linear
    between the points and held beyond the ends; the travel is the point's displacement
    along ``direction`` from its start (world frame only): a finger that presses to its
    force and no further than the key's travel (docs/mechanics.md, "Forces that follow
    their travel").
    """

    position: float = scene_key(0.0, unit="m", doc="along the bar from tip 0")
    direction: tuple[float, float, float] = scene_key((0.0, 0.0, -1.0), unit="-", doc="normalized; in `frame`")
    frame: str = scene_key("world", unit="-", doc='"world" (fixed) or "body" (turns with the bar)')
    magnitude: float | None = scene_key(None, unit="N", doc="constant force ...")
    time: tuple | None = scene_key(None, unit="s", doc="... or a table of times")
    value: tuple | None = scene_key(None, unit="N", doc="... and magnitudes, linear between points")
    interpolation: str = scene_key(
        "linear", unit="-",
        doc='"linear" or "pchip": a monotone cubic through the table\'s points, held flat at its ends '
            '(docs/mechanics.md, "Smooth tables")')
    travel: tuple | None = scene_key(
        None, unit="m",
        doc="with `share`: the force follows the travel of its point (its displacement along `direction` from its "
            "start), >= 2 points, strictly increasing; world frame only (docs/mechanics.md, \"Forces that follow "
            "their travel\")")
    share: tuple | None = scene_key(
        None, unit="-",
        doc="in [0, 1], one per `travel`: the force is its magnitude times the share at its point's travel, linear "
            "between points, held beyond the ends")
    name: str = internal("force")

    def __post_init__(self):
        n = self.name
        check_finite(f"{n}.position", self.position)
        d = check_vector3(f"{n}.direction", self.direction, DIRECTION_MAX)
        norm = math.sqrt(sum(v * v for v in d))
        if norm == 0.0:
            raise ValueError(f"{n}.direction = {list(d)!r}: must not be the zero vector")
        object.__setattr__(self, "direction", tuple(v / norm for v in d))
        check_choice(f"{n}.frame", self.frame, ("world", "body"))
        if self.magnitude is not None:
            if self.time is not None or self.value is not None:
                raise ValueError(f"{n}: give magnitude (constant) or time and value (a table), not both")
            check_magnitude(f"{n}.magnitude", self.magnitude, FORCE_MAX)
        else:
            if self.time is None or self.value is None:
                raise ValueError(f"{n}: give magnitude (N) or both time (s) and value (N) tables")
            ts, vs = check_table(f"{n}", self.time, self.value, time_high=T_END_MAX, value_high=FORCE_MAX,
                                 max_points=TABLE_POINTS_MAX)
            object.__setattr__(self, "time", ts)
            object.__setattr__(self, "value", vs)
        check_choice(f"{n}.interpolation", self.interpolation, INTERPOLATIONS)
        if self.travel is not None or self.share is not None:
            if self.frame != "world":
                raise ValueError(f"{n}.travel: a force that follows its travel acts along a fixed direction; "
                                 f"{n}.frame = {self.frame!r} is not allowed with it (use \"world\")")
            xs, ss = share_table(n, self.travel, self.share)
            object.__setattr__(self, "travel", xs)
            object.__setattr__(self, "share", ss)

    @property
    def follows_travel(self) -> bool:
        """True for a force scaled by a table over its point's travel (travel and share)."""
        return self.travel is not None

    def table(self) -> tuple[tuple, tuple]:
        """(times s, values N) of the magnitude the mechanics follows, linear between them
        (one point for a constant; interpolation = "pchip": sampled from its monotone cubic)."""
        if self.magnitude is not None:
            return (0.0,), (float(self.magnitude),)
        if self.interpolation == "linear":
            return self.time, self.value
        return self._smoothed

    @functools.cached_property
    def _smoothed(self) -> tuple[tuple, tuple]:
        # sampled once: the solver asks for the table at every rest window it watches
        # (mech.model.loads_ramping, load_change_times)
        ts, vs = smooth_samples(self.time, self.value)
        return tuple(float(t) for t in ts), tuple(float(v) for v in vs)


def share_table(name: str, travel, share) -> tuple[tuple, tuple]:
    """(travels m, shares 1) of force ``name``'s travel table checked: both lists of finite
    numbers, at least two and at most TABLE_POINTS_MAX travels, strictly increasing and
    within LENGTH_MAX, one share in [0, 1] per travel. Errors name the key."""
    return _travel_table(
        name, travel, share, "share",
        lambda where, v: check_range(where, v, 0.0, 1.0, closed_low=True, closed_high=True),
        needs=f"a force that follows its travel needs both {name}.travel (m) and {name}.share (1, in [0, 1])",
        noun="share", table="the table")


# what a spring's ``anchor`` end is fixed to: the frame, or the armature's point that moves
# with it (mech.kernel: its anchor moves down along world -z by lever x (q - q0))
SPRING_ENDS = ("frame", "armature")


@frozen
class Spring:
    """A spring and dashpot from a fixed world ``anchor`` (m) to the bar at ``position`` (m
    from tip 0); damping: N s/m. Either linear: stiffness N/m (> 0), with ``preload`` (N,
    the spring's pull towards the anchor at the initial position; negative pushes) or
    ``rest_length`` (m), neither: unstressed at the start. Or a force-travel spring (a
    dome, a snap-action spring: mech/travel_spring.py): ``travel`` (m, strictly
    increasing, its compression from the rest length: positive shorter) and ``force`` (N,
    one per travel, its push away from the anchor; any sign of slope), linear between the
    points and along the end segments beyond them; its rest length ``rest_length`` (m) or,
    without it, its length at the start (travel 0 there). ``release_force`` (N, one per
    travel, at or below ``force``): the release branch of a spring with hysteresis, which
    follows the press table while pressed, the release table while released
    (mech/travel_spring.py; it starts on the press branch). ``between``: "frame" (the
    anchor fixed) or "armature" (the anchor is the armature's point at the start and moves
    with it down, along world -z, by ``lever`` (m per unit of q; default 1 for a plunger,
    needed for a clapper) times q - q0: a spring between the actuator and the moving part,
    its reaction on the armature)."""

    anchor: tuple[float, float, float] = scene_key((0.0, 0.0, 0.0), unit="m", doc="world point")
    position: float = scene_key(0.0, unit="m", doc="along the bar from tip 0")
    stiffness: float | None = scene_key(None, unit="N/m", doc="> 0, a linear spring (or `travel` and `force`)")
    preload: float | None = scene_key(
        None, unit="N", doc="linear: pull towards the anchor at the start (or `rest_length`; neither: unstressed)")
    rest_length: float | None = scene_key(
        None, unit="m", doc="travel 0 of a force-travel spring (default: its length at the start)")
    damping: float = scene_key(0.0, unit="N s/m")
    travel: tuple | None = scene_key(
        None, unit="m", doc="compression from the rest length (positive: shorter), >= 2 points, strictly increasing")
    force: tuple | None = scene_key(
        None, unit="N",
        doc="push away from the anchor at each `travel`, any sign of slope; linear between points, along the end "
            "segments beyond them")
    release_force: tuple | None = scene_key(
        None, unit="N",
        doc="with hysteresis: the release branch at each `travel`, at or below `force` (the spring follows "
            "`force` while pressed, `release_force` while released)")
    between: str = scene_key(
        "frame", unit="-",
        doc='what the `anchor` end is fixed to: "frame", or "armature": the anchor is the armature\'s point at the '
            "start and moves down (world -z) with it by `lever` x (q - q0), the spring's reaction acting on the "
            'armature (docs/mechanics.md, "Springs between the armature and the bar")')
    lever: float | None = scene_key(
        None, unit="m per m or rad",
        doc='with `between = "armature"`: the anchor\'s travel per unit of the armature\'s q; omitted: 1 for a '
            "plunger, needed for a clapper")
    name: str = internal("spring")

    def __post_init__(self):
        n = self.name
        object.__setattr__(self, "anchor", check_vector3(f"{n}.anchor", self.anchor, LENGTH_MAX))
        check_choice(f"{n}.between", self.between, SPRING_ENDS)
        if self.lever is not None:
            if self.between != "armature":
                raise ValueError(f"{n}.lever = {self.lever!r}: the lever moves a spring's end with the armature; "
                                 f"it needs {n}.between = \"armature\"")
            check_positive(f"{n}.lever", self.lever, high=LENGTH_MAX)
        check_finite(f"{n}.position", self.position)
        check_nonnegative(f"{n}.damping", self.damping, high=DAMPING_MAX)
        if self.preload is not None and self.rest_length is not None:
            raise ValueError(f"{n}: give preload or rest_length, not both")
        if self.rest_length is not None:
            check_nonnegative(f"{n}.rest_length", self.rest_length, high=LENGTH_MAX)
        if self.travel is None and self.force is None:
            if self.release_force is not None:
                raise ValueError(f"{n}.release_force: a release branch needs its press branch, {n}.travel (m) and "
                                 f"{n}.force (N)")
            if self.stiffness is None:
                raise ValueError(f"{n}: give stiffness (N/m, a linear spring) or travel (m) and force (N) tables "
                                 "(a force-travel spring)")
            check_positive(f"{n}.stiffness", self.stiffness, high=STIFFNESS_MAX)
            if self.preload is not None:
                check_magnitude(f"{n}.preload", self.preload, FORCE_MAX)
            return
        for key in ("stiffness", "preload"):
            if getattr(self, key) is not None:
                raise ValueError(f"{n}.{key} = {getattr(self, key)!r}: a force-travel spring (travel and force "
                                 f"tables) takes its force from its table; remove {n}.{key}")
        xs, fs = force_travel_table(n, self.travel, self.force)
        object.__setattr__(self, "travel", xs)
        object.__setattr__(self, "force", fs)
        if self.release_force is not None:
            _, rs = force_travel_table(n, xs, self.release_force, force_key="release_force")
            for k, (f, r) in enumerate(zip(fs, rs)):
                if r > f:
                    raise ValueError(f"{n}.release_force[{k}] = {r!r}: above the press branch there ({n}.force[{k}] "
                                     f"= {f!r} N); the release branch lies at or below it (a loop dissipates)")
            if rs == fs:
                raise ValueError(f"{n}.release_force: equal to {n}.force at every travel (no hysteresis); remove it")
            object.__setattr__(self, "release_force", rs)

    @property
    def hysteretic(self) -> bool:
        """True for a force-travel spring with a release branch."""
        return self.release_force is not None

    def stick_stiffness(self) -> tuple[float, float]:
        """(N/m, N): the stick spring's stiffness k_s and the floor of the band's half-width
        of a spring with hysteresis (mech/travel_spring.py). k_s = 1000 F_h,max / span: a
        turn leaves one branch for the other within 2 F_h / k_s, 0.2 % of the table's
        span; the press follows its branch to 1 % within 2.6 F_h / k_s. The floor, 1e-3
        F_h,max, keeps the element's stiffness k_s / F_h bounded where the branches meet
        (the force there within 1e-3 F_h,max of them)."""
        half = max(0.5 * (f - r) for f, r in zip(self.force, self.release_force))
        span = self.travel[-1] - self.travel[0]
        return 1000.0 * half / span, 1e-3 * half
    @property
    def from_table(self) -> bool:
        """True for a force-travel spring (travel and force tables)."""
        return self.travel is not None

    def releasable_energy(self) -> float:
        """J: the most energy a force-travel spring can give up from its start (travel 0,
        energy 0) anywhere in its table's travel: -min U, U(x) the integral of its force
        from 0, whose least lies at a table point or where the force crosses zero going up;
        with hysteresis the larger of its two branches' (its force lies between them). 0 for
        a linear spring (its stored energy at the start counts as the scene's)."""
        if not self.from_table:
            return 0.0
        branches = (self.force,) if self.release_force is None else (self.force, self.release_force)
        return max(_releasable(self.travel, fs) for fs in branches)


def _releasable(travel, force) -> float:
    """J: -min of the integral of the table (travel, force) from 0, 0 if never negative."""
    tabs = np.array([travel, force], dtype=float)
    n = len(travel)
    xs = list(travel)
    for k in range(n - 1):
        f0, f1 = force[k], force[k + 1]
        if f0 < 0.0 < f1:
            xs.append(travel[k] + (travel[k + 1] - travel[k]) * f0 / (f0 - f1))
    base = travel_work(0.0, tabs, 0, n)
    return max(0.0, -min(travel_work(x, tabs, 0, n) - base for x in xs))


def force_travel_table(name: str, travel, force, force_key: str = "force") -> tuple[tuple, tuple]:
    """(travels m, forces N) of the force-travel spring ``name`` checked: both lists of
    finite numbers, at least two and at most TABLE_POINTS_MAX travels, strictly increasing
    and within LENGTH_MAX, one force (within FORCE_MAX) per travel. Errors name the key."""
    return _travel_table(
        name, travel, force, force_key, lambda where, v: check_magnitude(where, v, FORCE_MAX),
        needs=f"a force-travel spring needs both {name}.travel (m) and {name}.{force_key} (N)",
        noun="force", table="a force-travel table")


def _travel_table(name: str, travel, values, key: str, check_value, *, needs: str, noun: str,
                  table: str) -> tuple[tuple, tuple]:
    """(travels m, values) of a table over travel (``name``.travel and ``name``.``key``)
    checked as share_table and force_travel_table say; ``check_value(where, v)`` checks one
    value, ``needs``, ``noun`` and ``table`` word the one-line errors."""
    for k, items in (("travel", travel), (key, values)):
        if items is None:
            other = key if k == "travel" else "travel"
            raise ValueError(f"{name}.{k}: missing; {needs}, one {noun} per travel (it has {name}.{other})")
        if isinstance(items, (str, dict)) or not hasattr(items, "__iter__") or \
                any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in items):
            raise ValueError(f"{name}.{k} = {items!r:.80}: expected a list of numbers")
    if len(travel) > TABLE_POINTS_MAX:
        raise ValueError(f"{name}.travel: {len(travel)} points; at most {TABLE_POINTS_MAX} allowed")
    xs = tuple(check_magnitude(f"{name}.travel[{k}]", v, LENGTH_MAX) for k, v in enumerate(travel))
    vs = tuple(check_value(f"{name}.{key}[{k}]", v) for k, v in enumerate(values))
    if len(xs) < 2:
        raise ValueError(f"{name}.travel = {list(xs)!r}: {len(xs)} point(s); give at least two travels")
    if len(vs) != len(xs):
        raise ValueError(f"{name}.{key}: {len(vs)} {noun}s for {len(xs)} travels; give one {noun} per travel")
    for k in range(1, len(xs)):
        if xs[k] <= xs[k - 1]:
            raise ValueError(f"{name}.travel[{k}] = {xs[k]!r}: travels must increase strictly (previous "
                             f"{xs[k - 1]!r} m); {table} gives one {noun} per travel")
    return xs, vs


@frozen
class Rivet:
    """A spherical contact cap on the bar (a contact rivet): a contact point.

    position: m along the bar from tip 0; offset: m from the bar's axis along body b3 (the
    face normal of a blade; negative: the underside, towards the block when the blade
    lies flat above it; positive: the top, towards a fixed contact above it). radius: m, of
    the cap; mass: kg, carried by the bar at that point. youngs_modulus (Pa) and
    poisson_ratio: the rivet's own material (None: the bar's). name: how [[fixed]] entries,
    the results and a circuit refer to it (None: "rivet<k>", k its place among the rivets).
    key: the entry's place in the scene ("rivet[1]"), for messages; not a scene key.
    """

    position: float = scene_key(0.0, unit="m", doc="along the bar from tip 0")
    offset: float = scene_key(0.0, unit="m", doc="from the axis along the face normal b3 (negative: underside)")
    radius: float = scene_key(1e-3, unit="m", doc="of the cap")
    mass: float = scene_key(0.0, unit="kg", doc="carried by the bar at that point")
    youngs_modulus: float | None = scene_key(None, unit="Pa", doc="the rivet's material; omitted: the bar's")
    poisson_ratio: float | None = scene_key(None, unit="-", doc="omitted: the bar's")
    name: str | None = scene_key(
        None, unit="-",
        doc="how `[[fixed]]`, the results and a circuit refer to it (a letter, then letters, digits, `_`); "
            'omitted: "rivet<k>", k its place from 0')
    key: str = internal("rivet")

    def __post_init__(self):
        n = self.key
        check_finite(f"{n}.position", self.position)
        check_magnitude(f"{n}.offset", self.offset, LENGTH_MAX)
        check_positive(f"{n}.radius", self.radius, high=LENGTH_MAX)
        check_nonnegative(f"{n}.mass", self.mass, high=MASS_MAX)
        if self.youngs_modulus is not None:
            check_positive(f"{n}.youngs_modulus", self.youngs_modulus, high=MODULUS_MAX)
        if self.poisson_ratio is not None:
            check_range(f"{n}.poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        if self.name is not None:
            check_name(f"{n}.name", self.name)


FIXED_SHAPES = ("plane", "sphere")
FACINGS = ("up", "down")


@frozen
class FixedContact:
    """A fixed contact struck by one contact point of the moving part: a counter-contact
    (the NO or NC contact of a changeover, one of a bridge's two) or, with
    ``electrical = false``, a mechanical stop only.

    point: the name of the contact point that strikes it: a [[rivet]]'s ``name`` (default
    "rivet<k>") or, on a bar without rivets, "tip0" / "tip1" (its end caps). name: its own
    (None: "fixed<k>", k its place among the fixed contacts). shape: "plane" or "sphere"
    (a fixed rivet of ``radius`` m, taken as its tangent plane at the point nearest the
    bar, its curvature in the Hertz stiffness, as [block]'s; ``offset`` m shifts its top
    from its point's start along the bar's horizontal direction). facing: "up" (below the
    moving part, its surface facing up, as [block]) or "down" (above it, facing down: the
    NC contact of a changeover). Where its surface is: ``height`` (m, world z; [block]'s
    surface is at 0) or ``gap`` (m, >= 0: from its point's cap at the start, along its
    facing; 0: touching); one of them. youngs_modulus (Pa), poisson_ratio: its material.
    electrical: true for a contact the circuit sees, false for a stop.
    key: the entry's place in the scene ("fixed[1]"), for messages; not a scene key.
    """

    point: str | None = scene_key(
        None, unit="-",
        doc='the contact point that strikes it: a `[[rivet]]`\'s `name`, or "tip0" / "tip1" (the end caps of a '
            "bar without rivets)")
    name: str | None = scene_key(
        None, unit="-", doc='its name in the results and for a circuit; omitted: "fixed<k>", k its place from 0')
    shape: str = scene_key("plane", unit="-", doc='"plane" or "sphere" (a fixed rivet, taken as its tangent plane)')
    radius: float | None = scene_key(None, unit="m", doc="sphere only")
    offset: float = scene_key(
        0.0, unit="m", doc="sphere only: shift of its top from its point's start, along the bar")
    facing: str = scene_key(
        "up", unit="-",
        doc='"up": below the moving part, facing up (as `[block]`); "down": above it (the NC contact of a '
            "changeover)")
    height: float | None = scene_key(
        None, unit="m",
        doc="world z of its surface (`[block]`'s is 0; the bar is placed by `initial.height` above z = 0) ...")
    gap: float | None = scene_key(
        None, unit="m",
        doc="... or its distance from its point's cap at the start, along its facing (>= 0; 0: touching); one of "
            "the two")
    youngs_modulus: float = scene_key(210e9, unit="Pa")
    poisson_ratio: float = scene_key(0.3, unit="-")
    electrical: bool = scene_key(True, unit="-", doc="false: a mechanical stop, which the circuit does not see")
    key: str = internal("fixed")

    def __post_init__(self):
        n = self.key
        if self.point is None:
            raise ValueError(f"{n}.point: needed: the name of the contact point that strikes it (a [[rivet]]'s "
                             "name, or 'tip0' / 'tip1' for the bar's end caps)")
        check_name(f"{n}.point", self.point)
        if self.name is not None:
            check_name(f"{n}.name", self.name)
        check_choice(f"{n}.shape", self.shape, FIXED_SHAPES)
        if self.shape == "sphere":
            if self.radius is None:
                raise ValueError(f"{n}.radius: needed for {n}.shape = 'sphere' (m)")
            check_positive(f"{n}.radius", self.radius, high=LENGTH_MAX)
        else:
            if self.radius is not None:
                raise ValueError(f"{n}.radius: only a spherical fixed contact has a radius; set {n}.shape = 'sphere'")
            if self.offset != 0.0:
                raise ValueError(f"{n}.offset: shifts a spherical fixed contact's top; set {n}.shape = 'sphere'")
        check_magnitude(f"{n}.offset", self.offset, LENGTH_MAX)
        check_choice(f"{n}.facing", self.facing, FACINGS)
        if self.height is None and self.gap is None:
            raise ValueError(f"{n}.height: needed: give height (m, world z of its surface) or gap (m from its "
                             "point at the start), one of them")
        if self.height is not None and self.gap is not None:
            raise ValueError(f"{n}.height = {self.height!r} and {n}.gap = {self.gap!r}: give height (m, world z of "
                             "its surface) or gap (m from its point at the start), not both")
        if self.height is not None:
            check_magnitude(f"{n}.height", self.height, LENGTH_MAX)
        else:
            check_nonnegative(f"{n}.gap", self.gap, high=LENGTH_MAX)
        check_positive(f"{n}.youngs_modulus", self.youngs_modulus, high=MODULUS_MAX)
        check_range(f"{n}.poisson_ratio", self.poisson_ratio, -1.0, 0.5)
        check_bool(f"{n}.electrical", self.electrical)

    @property
    def normal(self) -> float:
        """+1.0 facing up (below the moving part), -1.0 facing down (above it): world z of its outward normal."""
        return 1.0 if self.facing == "up" else -1.0


ARMATURE_KINDS = ("none", "plunger", "clapper")


@frozen
class Armature:
    """The relay's armature: a rigid body on one coordinate q, its travel from the rest stop
    (m for a plunger, rad for a clapper; 0 <= q <= travel between its stops), driven by the
    drive channel "armature.force" times ``force_gain(q)``, positive towards the pole.

    kind: "none" (no armature: the default), "plunger" (translation) or "clapper" (rotation
    about its hinge). mass: kg (plunger); inertia: kg m^2 about the hinge (clapper).
    travel: m or rad, from the rest stop to the pole stop (> 0).
    spring_rate: N/m or N m/rad (>= 0) and spring_preload: N or N m (>= 0) of the return
    spring, which pushes towards the rest stop with preload + rate q (a preload > 0 holds
    the armature on its rest stop). stop_stiffness (N/m or N m/rad, > 0) and stop_damping
    (N s/m or N m s/rad) of both stops: linear spring-dashpots that only push (k pen +
    c dpen/dt clipped at 0), so the armature bounces on them. damping: viscous, N s/m or
    N m s/rad. initial_position: q at the start (m or rad, in [0, travel]; None: 0, on the
    rest stop); initial_speed: m/s or rad/s. At rest on a stop it is pressed onto, the
    armature starts seated there (mech.solver).
    The card, which pushes the contact spring (needs a [bar]): card_position, m along the
    bar from tip 0 (None: no card); card_lever, m of card travel per unit of q (> 0);
    card_free_travel, m of card travel before it touches the bar at rest (>= 0);
    card_stiffness, N/m (> 0); card_damping, N s/m: a one-sided spring-dashpot like the
    stops, pressing the bar's point towards the fixed contact (world -z), its reaction on
    the armature. force_gain: {position = [...] (m or rad, strictly increasing, covering
    [0, travel]), gain = [...]}, interpolated by monotone cubics (PCHIP); None: gain 1.
    """

    kind: str = scene_key(
        "none", unit="-", doc='"plunger" (translation), "clapper" (rotation about a hinge); "none": no armature')
    mass: float | None = scene_key(None, unit="kg", doc="plunger only")
    inertia: float | None = scene_key(None, unit="kg m^2", doc="clapper only, about the hinge")
    travel: float | None = scene_key(None, unit="m or rad", doc="from the rest stop (q = 0) to the pole stop")
    spring_rate: float = scene_key(0.0, unit="N/m or N m/rad", doc="return spring, pushing towards the rest stop")
    spring_preload: float = scene_key(
        0.0, unit="N or N m", doc="return spring at q = 0 (> 0 holds the armature on its rest stop)")
    stop_stiffness: float | None = scene_key(None, unit="N/m or N m/rad", doc="both stops: one-sided spring-dashpots")
    stop_damping: float = scene_key(0.0, unit="N s/m or N m s/rad", doc="both stops")
    damping: float = scene_key(0.0, unit="N s/m or N m s/rad", doc="viscous, on q")
    initial_position: float | None = scene_key(
        None, unit="m or rad", doc="in [0, travel]; omitted: 0, on the rest stop")
    initial_speed: float = scene_key(0.0, unit="m/s or rad/s")
    card_position: float | None = scene_key(
        None, unit="m",
        doc="along the bar from tip 0: the card that pushes the bar down (world -z), towards the fixed contact; "
            "omitted: no card")
    card_lever: float | None = scene_key(None, unit="m/m or m/rad", doc="card travel per unit of q (with a card)")
    card_free_travel: float = scene_key(0.0, unit="m", doc="card travel before it touches the bar at rest")
    card_stiffness: float | None = scene_key(None, unit="N/m", doc="the card's one-sided contact (with a card)")
    card_damping: float = scene_key(0.0, unit="N s/m")
    force_gain: dict | None = scene_key(
        None, unit="m or rad, -",
        doc='`{position = [...], gain = [...]}`: the armature\'s force is the drive "armature.force" times this '
            "(monotone cubic) over q; omitted: 1")

    def __post_init__(self):
        check_choice("armature.kind", self.kind, ARMATURE_KINDS)
        if self.kind == "none":
            for f in dataclasses.fields(self):
                if f.name != "kind" and getattr(self, f.name) != f.default:
                    raise ValueError(f"armature.{f.name}: an armature needs armature.kind = 'plunger' "
                                     "(translation) or 'clapper' (rotation about a hinge)")
            return
        own, other = ("mass", "inertia") if self.kind == "plunger" else ("inertia", "mass")
        if getattr(self, other) is not None:
            has = "a mass (kg)" if own == "mass" else "an inertia (kg m^2)"
            raise ValueError(f"armature.{other}: a {self.kind} has {has}; give armature.{own} instead")
        if getattr(self, own) is None:
            raise ValueError(f"armature.{own}: needed for armature.kind = {self.kind!r} "
                             f"({'kg' if own == 'mass' else 'kg m^2 about the hinge'})")
        check_positive(f"armature.{own}", getattr(self, own))
        if self.travel is None:
            raise ValueError("armature.travel: needed (m or rad, from the rest stop to the pole stop)")
        travel = check_positive("armature.travel", self.travel)
        check_nonnegative("armature.spring_rate", self.spring_rate)
        check_nonnegative("armature.spring_preload", self.spring_preload)
        if self.stop_stiffness is None:
            raise ValueError("armature.stop_stiffness: needed (N/m or N m/rad, the stops' contact stiffness)")
        check_positive("armature.stop_stiffness", self.stop_stiffness)
        check_nonnegative("armature.stop_damping", self.stop_damping)
        check_nonnegative("armature.damping", self.damping)
        if self.initial_position is not None:
            q0 = check_finite("armature.initial_position", self.initial_position)
            if not 0.0 <= q0 <= travel:
                raise ValueError(f"armature.initial_position = {q0!r}: must lie between the rest stop (0) and "
                                 f"the pole stop (armature.travel = {travel!r})")
        check_finite("armature.initial_speed", self.initial_speed)
        self._check_card(travel)
        if self.force_gain is not None:
            object.__setattr__(self, "force_gain", _gain_table(self.force_gain, travel))

    def _check_card(self, travel: float) -> None:
        card = {"card_lever": None, "card_free_travel": 0.0, "card_stiffness": None, "card_damping": 0.0}
        if self.card_position is None:
            for key, default in card.items():
                if getattr(self, key) != default:
                    raise ValueError(f"armature.{key}: a card needs armature.card_position "
                                     "(m along the bar from tip 0)")
            return
        check_finite("armature.card_position", self.card_position)
        for key in ("card_lever", "card_stiffness"):
            if getattr(self, key) is None:
                raise ValueError(f"armature.{key}: needed with armature.card_position "
                                 f"({'m of card travel per unit of q' if key == 'card_lever' else 'N/m'})")
        lever = check_positive("armature.card_lever", self.card_lever)
        free = check_nonnegative("armature.card_free_travel", self.card_free_travel)
        check_positive("armature.card_stiffness", self.card_stiffness)
        check_nonnegative("armature.card_damping", self.card_damping)
        if free >= lever * travel:
            raise ValueError(f"armature.card_free_travel = {free!r}: the card would never reach the bar; it must "
                             f"be less than card_lever x travel = {lever * travel!r} m")

    @property
    def present(self) -> bool:
        return self.kind != "none"

    @property
    def has_card(self) -> bool:
        return self.card_position is not None

    @property
    def inertia_value(self) -> float:
        """kg (plunger) or kg m^2 (clapper): what the drive accelerates."""
        return self.mass if self.kind == "plunger" else self.inertia

    @property
    def start_position(self) -> float:
        """m or rad: q at the start (on the rest stop, unless given)."""
        return 0.0 if self.initial_position is None else float(self.initial_position)


def _gain_table(table, travel: float) -> dict:
    """armature.force_gain checked: {position: tuple, gain: tuple}, at least two points,
    positions strictly increasing and covering [0, travel] (to 1e-9 of it), finite gains."""
    name = "armature.force_gain"
    if not isinstance(table, dict) or set(table) != {"position", "gain"}:
        raise ValueError(f"{name} = {table!r}: expected {{position = [...], gain = [...]}}")
    out = {}
    for key in ("position", "gain"):
        items = table[key]
        if isinstance(items, (str, dict)) or not hasattr(items, "__iter__"):
            raise ValueError(f"{name}.{key} = {items!r}: expected a list of numbers")
        out[key] = tuple(check_finite(f"{name}.{key}[{k}]", v) for k, v in enumerate(items))
    xs, gs = out["position"], out["gain"]
    if len(xs) < 2:
        raise ValueError(f"{name}.position: {len(xs)} point(s); give at least two")
    if len(gs) != len(xs):
        raise ValueError(f"{name}.gain: {len(gs)} gains for {len(xs)} positions; give one gain per position")
    for k in range(1, len(xs)):
        if xs[k] <= xs[k - 1]:
            raise ValueError(f"{name}.position[{k}] = {xs[k]!r}: positions must increase strictly "
                             f"(previous {xs[k - 1]!r})")
    slack = 1e-9 * travel
    if xs[0] > slack or xs[-1] < travel - slack:
        raise ValueError(f"{name}.position = [{xs[0]!r} ... {xs[-1]!r}]: must cover the travel, from 0 to "
                         f"armature.travel = {travel!r}")
    return out


@frozen
class MechScene:
    """Everything the impact solver needs. gravity: m/s^2 (>= 0), acting along -z.

    bar: None is an armature alone (no contact spring, no contact): then ``armature`` is
    given and no mount, force, spring, rivet or fixed contact.
    The fixed contacts: ``block`` (one, below the bar, struck by every contact point) or
    ``fixed`` (FixedContact entries, each struck by the contact point it names; every
    contact point strikes at least one), not both."""

    bar: Bar | None = internal(default_factory=Bar)
    block: Block = internal(default_factory=Block)
    contact: Contact = internal(default_factory=Contact)
    friction: Friction = internal(default_factory=Friction)
    initial: Initial = internal(default_factory=Initial)
    solver: SolverOptions = internal(default_factory=SolverOptions)
    gravity: float = scene_key(9.80665, unit="m/s^2")
    mount: Mount = internal(default_factory=Mount)
    forces: tuple = internal(())
    springs: tuple = internal(())
    rivets: tuple = internal(())
    armature: Armature = internal(default_factory=Armature)
    fixed: tuple = internal(())

    def __post_init__(self):
        check_nonnegative("environment.gravity", self.gravity, high=GRAVITY_MAX)
        for name, cls in (("bar", Bar), ("block", Block), ("contact", Contact),
                          ("friction", Friction), ("initial", Initial), ("solver", SolverOptions),
                          ("mount", Mount), ("armature", Armature)):
            if not isinstance(getattr(self, name), cls) and not (name == "bar" and self.bar is None):
                raise ValueError(f"{name}: expected a {cls.__name__}, got {type(getattr(self, name)).__name__}")
        for name, cls in (("forces", PointForce), ("springs", Spring), ("rivets", Rivet), ("fixed", FixedContact)):
            items = tuple(getattr(self, name))
            object.__setattr__(self, name, items)
            for item in items:
                if not isinstance(item, cls):
                    raise ValueError(f"{name}: expected {cls.__name__} entries, got {type(item).__name__}")
        if len(self.forces) + len(self.springs) > LOADS_MAX:
            raise ValueError(f"[[force]], [[spring]]: {len(self.forces)} forces and {len(self.springs)} springs; "
                             f"at most {LOADS_MAX} together")
        if self.bar is None:
            self._check_armature_alone()
            return
        self._check_mechanism()
        arm = self.armature
        if arm.has_card:
            check_position("armature.card_position", arm.card_position, self.bar.length)
            if self.initial.resting:
                raise ValueError("initial.resting: the resting start is for the free bar on its tips; "
                                 "this scene has an armature card")

    def _check_armature_alone(self) -> None:
        """A scene without a bar: an armature alone, nothing that needs a bar."""
        if not self.armature.present:
            raise ValueError("bar: a scene without a bar is an armature alone; give [armature] with "
                             "kind = 'plunger' or 'clapper', or a [bar]")
        for name, shown in (("forces", "force"), ("springs", "spring"), ("rivets", "rivet"), ("fixed", "fixed")):
            if getattr(self, name):
                raise ValueError(f"[[{shown}]]: acts on the bar, and this scene has none (an armature alone)")
        if self.mount.held:
            raise ValueError("mount.kind: holds the bar, and this scene has none (an armature alone)")
        if self.armature.has_card:
            raise ValueError("armature.card_position: the card pushes the contact spring, and this scene has "
                             "no [bar] (an armature alone); add the [bar] or remove the card keys")

    @property
    def has_bar(self) -> bool:
        return self.bar is not None

    def contact_point_names(self) -> tuple[str, ...]:
        """The names of the bar's contact points, in their order: its rivets' (``name``, or
        "rivet<k>"), or without rivets its end caps "tip0" and "tip1", but for a cap within
        its radius of a clamp or hinge (held, not a contact)."""
        if self.rivets:
            return tuple(rv.name or f"rivet{k}" for k, rv in enumerate(self.rivets))
        bar = self.bar
        caps = (("tip0", bar.tip_radius), ("tip1", bar.length - bar.tip_radius))
        if self.mount.held:
            caps = tuple(c for c in caps if abs(c[1] - self.mount.position) > bar.tip_radius)
        return tuple(name for name, _ in caps)

    def fixed_names(self) -> tuple[str, ...]:
        """The names of the [[fixed]] entries (``name``, or "fixed<k>"), in their order."""
        return tuple(fx.name or f"fixed{k}" for k, fx in enumerate(self.fixed))

    def _check_mechanism(self) -> None:
        """Cross-section checks: points on the bar, held bars in one plane, rivets apart."""
        L = self.bar.length
        mnt = self.mount
        if mnt.held:
            check_position("mount.position", mnt.position, L)
        for f in self.forces:
            check_position(f"{f.name}.position", f.position, L)
            if f.frame == "world" and abs(f.direction[1]) > 1e-12 and mnt.held:
                raise ValueError(f"{f.name}.direction = {list(f.direction)!r}: a held bar moves in the "
                                 "x-z plane; the force must have no y component")
        for sp in self.springs:
            check_position(f"{sp.name}.position", sp.position, L)
            if sp.between == "armature":
                if not self.armature.present:
                    raise ValueError(f"{sp.name}.between = 'armature': needs an [armature] (kind = 'plunger' or "
                                     "'clapper') to carry the spring's anchor end")
                if self.armature.kind == "clapper" and sp.lever is None:
                    raise ValueError(f"{sp.name}.lever: needed for a spring on a clapper (m of the anchor's travel "
                                     "per rad of the armature)")
            if mnt.held and sp.anchor[1] != 0.0:
                raise ValueError(f"{sp.name}.anchor = {list(sp.anchor)!r}: a held bar moves in the "
                                 "x-z plane; the anchor must have y = 0")
        seen = set()
        for rv, name in zip(self.rivets, self.contact_point_names()):
            if name in seen:
                raise ValueError(f"{rv.key}.name: its name {name!r} is another rivet's too; give each its own")
            seen.add(name)
        if self.fixed:
            self._check_fixed()
        elif len(self.rivets) > RIVETS_WITH_BLOCK:
            raise ValueError(f"[[rivet]]: {len(self.rivets)} rivets given; the one fixed contact [block] takes at "
                             f"most {RIVETS_WITH_BLOCK} (a single or a bridge contact); for more, give each "
                             "its fixed contact in [[fixed]] entries")
        half_t = 0.5 * (self.bar.thickness if self.bar.thickness is not None else self.bar.diameter)
        for rv in self.rivets:
            check_position(f"{rv.key}.position", rv.position, L)
            if abs(rv.offset) > half_t + rv.radius:
                raise ValueError(f"{rv.key}.offset = {rv.offset!r}: the rivet's cap centre must lie within "
                                 f"its radius of the bar's face (|offset| <= {half_t + rv.radius!r} m)")
            if mnt.kind == "clamp" and abs(rv.position - mnt.position) < rv.radius:
                raise ValueError(f"{rv.key}.position = {rv.position!r}: the rivet sits in the clamp "
                                 f"(mount.position = {mnt.position!r}); it must be at least its radius away")
        for k, b in enumerate(self.rivets):
            for a in self.rivets[:k]:
                if abs(a.position - b.position) < a.radius + b.radius and a.offset == b.offset:
                    raise ValueError(f"{b.key}.position: the rivets {a.key} and {b.key} overlap; place them at "
                                     "least the sum of their radii apart")
        if mnt.held:
            if self.initial.azimuth_deg != 0.0:
                raise ValueError(f"initial.azimuth_deg = {self.initial.azimuth_deg!r}: a held bar lies in "
                                 "the x-z plane; use 0")
            if any(v != 0.0 for v in self.initial.velocity):
                raise ValueError(f"initial.velocity = {list(self.initial.velocity)!r}: a held bar starts at rest "
                                 "with its mount; move a clamp with mount.base_motion")
            w = self.initial.angular_velocity
            if mnt.kind == "clamp" and any(v != 0.0 for v in w):
                raise ValueError(f"initial.angular_velocity = {list(w)!r}: a clamped bar cannot turn")
            if mnt.kind == "pivot" and (w[0] != 0.0 or w[2] != 0.0):
                raise ValueError(f"initial.angular_velocity = {list(w)!r}: a pivoted bar turns about y only")
            if self.solver.model == "3d":
                raise ValueError("solver.model = '3d': held bars are solved in their plane (x-z); "
                                 "use 'auto' or 'planar'")
            if self.initial.resting:
                raise ValueError("initial.resting: a held bar is placed by initial.height (gap of its "
                                 "contact) and closed by its forces; remove initial.resting")
        if self.initial.resting and (self.rivets or self.forces or self.springs or self.fixed):
            raise ValueError("initial.resting: the resting start is for the free bar on its tips on [block] "
                             "without rivets, forces, springs or [[fixed]] contacts")

    def _check_fixed(self) -> None:
        """[[fixed]] against the contact points: at most FIXED_MAX, not with [block], names
        unique, each naming a contact point, every contact point struck; on a held bar
        (its b3 the world's z but for its tilt) a rivet on the underside strikes only
        below it, one on the top only above it."""
        if len(self.fixed) > FIXED_MAX:
            raise ValueError(f"[[fixed]]: {len(self.fixed)} fixed contacts given; at most {FIXED_MAX} contact pairs "
                             "are supported (a changeover's NO and NC, a bridge's two points)")
        if self.block != Block():
            raise ValueError("[block]: this scene gives its fixed contacts as [[fixed]] entries; describe the "
                             "block as one of them (facing = 'up', height = 0) and remove [block]")
        points = self.contact_point_names()
        names = self.fixed_names()
        for k, fx in enumerate(self.fixed):
            if names.index(names[k]) < k:
                raise ValueError(f"{fx.key}.name: its name {names[k]!r} is another fixed contact's too; give each "
                                 "its own")
            if fx.point not in points:
                where = "rivets" if self.rivets else "end caps (with rivets only rivets touch)"
                raise ValueError(f"{fx.key}.point = {fx.point!r}: no such contact point; the bar's {where}: "
                                 f"{', '.join(map(repr, points)) or 'none'}")
            if self.rivets and self.mount.held:
                rv = self.rivets[points.index(fx.point)]
                if rv.offset * fx.normal > 0.0:
                    side, other = ("top", "above") if rv.offset > 0.0 else ("underside", "below")
                    raise ValueError(f"{fx.key}.facing = {fx.facing!r}: its point {fx.point!r} is a rivet on the "
                                     f"blade's {side} ({rv.key}.offset = {rv.offset!r}), which strikes only a "
                                     f"fixed contact {other} it (facing = {'down' if fx.normal > 0 else 'up'!r})")
        struck = {fx.point for fx in self.fixed}
        ends = {"tip0": self.bar.tip_radius, "tip1": self.bar.length - self.bar.tip_radius}
        for k, p in enumerate(points):
            if not self.rivets and self.mount.held and abs(ends[p] - self.mount.position) <= (
                    self.bar.tip_radius * (1.0 + 1e-9)):
                continue  # (an end cap at the mount, to round-off: held there, nothing to strike)
            if p not in struck:
                where = f"rivet[{k}]" if self.rivets else f"end cap {p!r}"
                raise ValueError(f"{where}: the contact point {p!r} strikes no fixed contact; name it as the "
                                 "point of a [[fixed]] entry (a mechanical stop: electrical = false)"
                                 + ("" if self.rivets else ", or hold that end in the mount"))
