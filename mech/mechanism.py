"""Switch mechanisms: a held bar, its rivets, actuator forces and springs, as kernel arrays.

A scene that is a plain free bar with its two end caps keeps the analytic free-free
basis (mech.modal_basis). Anything else -- a clamp or a pivot, rivets (contact caps
anywhere on the bar, with mass), forces or springs -- takes its modes from the
finite-element beam (mech.beam_fe) of the bar as held, with the rivets' masses on it,
and its invariants about the frame origin: the support for a held bar, the composite
centroid for a free one.

Geometry (body frame): b1 along the bar, origin at ``x0`` m from tip 0; a point at
``position`` s m from tip 0 with ``offset`` h m along b3 sits at (s - x0, 0, h).

Contact pairs: a contact point of the bar (a rivet or an end cap) and the fixed contact it
strikes. With [block], every contact point strikes the block (a pair per point, at most
two); with [[fixed]] entries, each is a pair with the point it names (at most
kernel_layout.MAX_PAIRS). The pairs' points are the first rows of the point arrays, at
least kernel_layout.CONTACT_ROWS of them (a missing second one is switched off); load
points follow.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .contact_laws import hertz_stiffness
from .kernel_layout import (
    C_C, C_K, C_N, C_ON, C_R, C_Z, CONTACT_ROWS, L_AX, L_AY, L_AZ, L_BODY, L_C, L_DX, L_DY, L_DZ, L_FLOOR, L_K,
    L_KIND, L_KS, L_R0, L_ZBACK,
    L_ARM, L_POINT, L_Q0, L_S0, L_SN, L_T0, L_TN, LOAD_FORCE, LOAD_SPRING, LOAD_TRAVEL_SPRING, N_CPAR, N_LOAD,
)
from .modal_basis import ModalBasis
from .parameters import MechScene
from .frozen import frozen, record

if TYPE_CHECKING:
    from .beam_fe import FEBeam


@frozen
class ContactPoint:
    """One contact cap: ``position`` m from tip 0, ``offset`` m along b3, cap ``radius`` m,
    its material (Pa, -), and a name for messages and results."""

    name: str
    position: float
    offset: float
    radius: float
    youngs_modulus: float
    poisson_ratio: float


@frozen
class ContactPair:
    """A contact point and the fixed contact it strikes (SI). fixed: the fixed contact's
    name ("block" for [block]); key: where the scene gives it ("block", "fixed[1]"), for
    messages; shape "plane" or "sphere" (radius m; offset m of its top from the point's
    start along the bar's horizontal direction); normal: +1.0 facing up (below the bar),
    -1.0 facing down (above it); height (m, world z of its surface) or gap (m from the
    point's cap at the start), one of them None; its material (Pa, -); electrical: a
    contact the circuit sees (False: a mechanical stop)."""

    point: ContactPoint
    fixed: str
    key: str
    shape: str
    radius: float | None
    offset: float
    normal: float
    height: float | None
    gap: float | None
    youngs_modulus: float
    poisson_ratio: float
    electrical: bool

    @property
    def effective_radius(self) -> float:
        """m: the Hertz radius of the point's cap against the fixed contact, R1 R2 / (R1 + R2)
        against a sphere."""
        r = self.point.radius
        return r if self.shape != "sphere" else r * self.radius / (r + self.radius)


def needs_mechanism(scene: MechScene) -> bool:
    """True when the scene is more than the free bar on its two end caps over the plane
    block (an armature's card is a load point on the bar)."""
    return bool(scene.mount.held or scene.rivets or scene.forces or scene.springs or scene.fixed
                or scene.block.shape != "plane" or scene.armature.has_card)


def contact_points(scene: MechScene) -> list[ContactPoint]:
    """The contact caps: the rivets, or else the end caps not inside a clamp or hinge, named
    as MechScene.contact_point_names says."""
    bar = scene.bar
    names = scene.contact_point_names()
    if scene.rivets:
        return [ContactPoint(name, rv.position, rv.offset, rv.radius,
                             rv.youngs_modulus or bar.youngs_modulus,
                             rv.poisson_ratio if rv.poisson_ratio is not None else bar.poisson_ratio)
                for name, rv in zip(names, scene.rivets)]
    ends = {"tip0": bar.tip_radius, "tip1": bar.length - bar.tip_radius}
    return [ContactPoint(name, ends[name], 0.0, bar.tip_radius, bar.youngs_modulus, bar.poisson_ratio)
            for name in names]


def contact_pairs(scene: MechScene) -> list[ContactPair]:
    """The contact pairs, in the order of their contact rows: one per [[fixed]] entry (in
    its order) with the point it names; with [block], one per contact point."""
    cps = contact_points(scene)
    if not scene.fixed:
        b = scene.block
        return [ContactPair(cp, "block", "block", b.shape, b.radius, b.offset, 1.0, 0.0, None,
                            b.youngs_modulus, b.poisson_ratio, True) for cp in cps]
    by_name = {cp.name: cp for cp in cps}
    return [ContactPair(by_name[fx.point], name, fx.key, fx.shape, fx.radius, fx.offset, fx.normal, fx.height,
                        fx.gap, fx.youngs_modulus, fx.poisson_ratio, fx.electrical)
            for name, fx in zip(scene.fixed_names(), scene.fixed)]


def fe_beam(scene: MechScene) -> FEBeam:
    """The finite-element beam of the bar as held, with the rivets as point masses.

    A rivet's rotary inertia about the section's bending axis: a sphere's 2/5 m r^2 plus
    m h^2 for its offset h from the axis (it is carried on the axis point it sits above).
    """
    from .beam_fe import FEBeam, PointMass  # (here: see build_arrays)

    bar = scene.bar
    i22, i33 = bar.second_moments
    masses = tuple(PointMass(rv.position, rv.mass, rv.mass * (0.4 * rv.radius**2 + rv.offset**2))
                   for rv in scene.rivets if rv.mass > 0.0)
    mnt = scene.mount
    return FEBeam(length=bar.length, youngs_modulus=bar.youngs_modulus, density=bar.density,
                  area=bar.area, i22=i22, i33=i33, support=mnt.kind,
                  support_position=mnt.position if mnt.held else 0.0, point_masses=masses)


@record
class MechanismArrays:
    """Everything the kernel needs beyond the free bar (SI units, body frame)."""

    basis: ModalBasis
    x0: float  # m from tip 0: the body frame's origin
    points: tuple  # (psi (P, n, 3), theta (P, n, 3), xc (P, 3))
    pairs: list  # ContactPair per enabled contact row
    first_moments: np.ndarray  # (3, 2n + 1): c, L_j, H_j
    load: np.ndarray  # (n_loads, N_LOAD)
    tables: np.ndarray  # (2, k)
    spring_points: list  # (load row, spring) for the rest-length set-up
    card_row: int = -1  # the armature card's point row (-1: no card)
    rows: int = CONTACT_ROWS  # contact rows (the pairs', at least CONTACT_ROWS): the load points' rows follow

    @property
    def contacts(self) -> list:
        """The ContactPoint of each enabled contact row."""
        return [p.point for p in self.pairs]


def build_arrays(scene: MechScene, planar: bool) -> MechanismArrays:
    """Modes, invariants and point arrays of a mechanism scene."""
    # (imported here, not at the top: a free bar's scene or an armature's alone never
    # builds a beam, and the module's start, its classes and reference matrices, cost
    # the plunger example ~1.5 ms)
    from .beam_fe import beam_basis, beam_invariants, point_shapes

    bar = scene.bar
    if bar.bending != "euler_bernoulli":
        raise ValueError(f"bar.bending = {bar.bending!r}: switch mechanisms (mount, rivets, forces, springs) "
                         "use Euler-Bernoulli finite-element modes; use 'euler_bernoulli'")
    beam = fe_beam(scene)
    modes = beam_basis(beam, bar.axial_modes, bar.bending_modes, planar=planar)
    inv = beam_invariants(beam, modes, modal_damping=bar.modal_damping)
    x0 = inv.x0
    n = inv.n

    pairs = contact_pairs(scene)
    cps = [p.point for p in pairs]
    s_pts = [cp.position for cp in cps]
    h_pts = [cp.offset for cp in cps]
    loads = list(scene.forces) + list(scene.springs)
    s_pts += [ld.position for ld in loads]
    h_pts += [0.0 for _ in loads]
    if scene.armature.has_card:  # the card's point on the axis, after the loads'
        s_pts.append(scene.armature.card_position)
        h_pts.append(0.0)
    # CONTACT_ROWS contact rows at least; a missing second contact is a switched-off dummy row
    rows = max(len(cps), CONTACT_ROWS)
    if len(cps) < CONTACT_ROWS:
        s_pts.insert(len(cps), s_pts[0] if s_pts else 0.0)
        h_pts.insert(len(cps), 0.0)
    if len(cps) == 0:
        raise ValueError("no contact point: every end cap is held by the mount; add a [[rivet]]")
    s_arr = np.array(s_pts, dtype=float)
    h_arr = np.array(h_pts, dtype=float)
    if n:
        psi, theta = point_shapes(modes, s_arr, h_arr)
    else:
        psi = np.zeros((len(s_arr), 0, 3))
        theta = np.zeros((len(s_arr), 0, 3))
    xc = np.zeros((len(s_arr), 3))
    xc[:, 0] = s_arr - x0
    xc[:, 2] = h_arr

    first = np.zeros((3, 2 * n + 1))
    first[:, 0] = inv.first_moment
    first[:, 1:n + 1] = inv.translational_coupling
    first[:, n + 1:] = inv.rotational_coupling

    load = np.zeros((len(loads), N_LOAD))
    times, values = [], []
    for k, ld in enumerate(loads):
        row = load[k]
        row[L_POINT] = rows + k
        if k < len(scene.forces):
            row[L_KIND] = LOAD_FORCE
            row[L_BODY] = 1.0 if ld.frame == "body" else 0.0
            row[L_DX], row[L_DY], row[L_DZ] = ld.direction
            ts, vs = ld.table()
            row[L_T0] = len(times)
            row[L_TN] = len(ts)
            times += list(ts)
            values += list(vs)
        else:
            row[L_KIND] = LOAD_TRAVEL_SPRING if ld.from_table else LOAD_SPRING
            row[L_AX], row[L_AY], row[L_AZ] = ld.anchor
            row[L_K] = 0.0 if ld.from_table else ld.stiffness
            row[L_C] = ld.damping
            if ld.between == "armature":  # its anchor end moves with the armature
                row[L_ARM] = 1.0 if ld.lever is None else ld.lever
                row[L_Q0] = scene.armature.start_position
    for k, f in enumerate(scene.forces):  # share tables of forces that follow their travel, after the time tables
        if f.follows_travel:
            load[k, L_S0] = len(times)
            load[k, L_SN] = len(f.travel)
            times += list(f.travel)
            values += list(f.share)
    hysteretic = [k for k, ld in enumerate(loads) if k >= len(scene.forces) and ld.hysteretic]
    for k, ld in enumerate(loads):  # force-travel tables after every time table
        if k >= len(scene.forces) and ld.from_table:
            load[k, L_T0] = len(times)
            load[k, L_TN] = len(ld.travel)
            times += list(ld.travel)
            values += list(ld.force)
            if ld.hysteretic:  # its release branch on the same travels, its stick force's state
                load[k, L_R0] = len(times)
                times += list(ld.travel)
                values += list(ld.release_force)
                load[k, L_KS], load[k, L_FLOOR] = ld.stick_stiffness()
                load[k, L_ZBACK] = len(hysteretic) - hysteretic.index(k)
    tables = np.array([times, values], dtype=float) if times else np.zeros((2, 1))

    basis = ModalBasis(
        families=inv.families, orders=inv.orders, frequencies=inv.frequencies, mass=inv.mass,
        J0=inv.J0, J1=inv.J1, J2=inv.J2, S=inv.S, stiffness=inv.stiffness, damping=inv.damping,
        psi_tip=psi[:2], theta_tip=theta[:2], x_centre=xc[:2, 0].copy(),
    )
    springs = [(len(scene.forces) + k, sp) for k, sp in enumerate(scene.springs)]
    card = rows + len(loads) if scene.armature.has_card else -1
    return MechanismArrays(basis, x0, (psi, theta, xc), pairs, first, load, tables, springs, card, rows)


def contact_parameters(pairs, rows: int, stiffness_override, dampings, planes=None) -> np.ndarray:
    """cpar (rows, N_CPAR) of the contact pairs (kernel_layout C_*): Hertz stiffness
    (N/m^1.5) of the point's cap against its fixed contact (the effective radius R1 R2 /
    (R1 + R2) against a sphere), damping c, cap radius m, on, and the fixed contact's
    plane: ``planes`` (height m, normal +-1) per pair (None: z = 0 facing up, the block's);
    rows without a pair are switched off."""
    cpar = np.zeros((rows, N_CPAR))
    for i, pair in enumerate(pairs):
        cp = pair.point
        k = stiffness_override or hertz_stiffness(pair.effective_radius, cp.youngs_modulus, cp.poisson_ratio,
                                                  pair.youngs_modulus, pair.poisson_ratio)
        cpar[i, [C_K, C_C, C_R, C_ON]] = (k, dampings[i] if i < len(dampings) else dampings[0], cp.radius, 1.0)
        cpar[i, [C_Z, C_N]] = planes[i] if planes is not None else (0.0, 1.0)
    return cpar


def fixed_planes(pairs, xc: np.ndarray, R0: np.ndarray, z0: float) -> list[tuple[float, float]]:
    """(height m, normal +-1) of each pair's fixed contact, its surface placed where the
    scene says: ``height``, or ``gap`` from its point's cap in the initial pose (frame
    height z0 m, rotation R0, no deflection). A fixed contact facing up above its point's
    cap centre, or one its point starts inside of (deeper than 1e-9 of the cap's radius,
    a round-off of a hand-computed height), is an error naming its key."""
    out = []
    for i, pair in enumerate(pairs):
        r = pair.point.radius
        z = z0 + float((R0 @ xc[i])[2])  # the cap's centre
        n = pair.normal
        height = z - n * (r + pair.gap) if pair.height is None else pair.height
        if pair.height is None:  # (round-off must not put the point a hair inside it)
            while r - n * (z - height) > 0.0:
                height = float(np.nextafter(height, -n * math.inf))
        where = "height" if pair.height is not None else "gap"
        value = pair.height if pair.height is not None else pair.gap
        if n > 0.0 and height > z:
            raise ValueError(f"{pair.key}.{where} = {value!r}: it faces up, but its surface (z = {height:.6g} m) "
                             f"lies above its point {pair.point.name!r} (cap centre at z = {z:.6g} m); a fixed "
                             "contact above the point faces down (facing = 'down')")
        pen = r - n * (z - height)
        if pen > 1e-9 * r:
            side = "top" if n < 0.0 else "bottom"
            edge = z - n * r
            raise ValueError(f"{pair.key}.{where} = {value!r}: its point {pair.point.name!r} would start {pen:.3g} m "
                             f"inside it (the cap's {side} is at z = {edge:.6g} m); place its surface at or "
                             f"{'above' if n < 0.0 else 'below'} that (or give gap >= 0)")
        out.append((height, n))
    return out


def frame_height(scene: MechScene, xc: np.ndarray, cps, R0: np.ndarray) -> float:
    """z of the frame origin that puts the lowest contact cap ``initial.height`` above z = 0."""
    lowest = min(float((R0 @ xc[i])[2]) - cp.radius for i, cp in enumerate(cps))
    return scene.initial.height - lowest


def effective_contact_mass(arr: MechanismArrays, scene: MechScene) -> float:
    """kg: the mass the first contact point presents to a normal impact.

    Pivot: the rigid rotation about the hinge, I / r^2; clamp: the fundamental bending
    mode's mass at the point, m / phi_1(x)^2; free: the rigid bar with its inertia.
    """
    b = arr.basis
    xc = arr.points[2]
    m = b.mass
    if scene.mount.kind == "pivot":
        r = float(np.hypot(xc[0, 0], xc[0, 2]))
        return b.J0[1, 1] / max(r * r, 1e-30)
    if scene.mount.kind == "clamp":
        bend = [j for j, f in enumerate(b.families) if f == "bend3"]
        if not bend:
            raise ValueError("bar.modes: a clamped blade needs at least one bending mode to move")
        phi = abs(float(b.psi_tip[0, bend[0], 2]))
        return m / max(phi * phi, 1e-30)
    # free bar: the rigid bar's normal mass at its lowest contact, the lever arm being
    # the horizontal distance from the centroid (tilt angle_deg)
    lowest = min(range(len(arr.contacts)), key=lambda i: math.sin(math.radians(scene.initial.angle_deg)) * xc[i, 0])
    r = float(xc[lowest, 0]) * math.cos(math.radians(scene.initial.angle_deg))
    return m / (1.0 + m * r * r / b.J0[1, 1])


def impulse_mass(arr: MechanismArrays, scene: MechScene) -> float:
    """kg: the mass a held bar's first contact point presents to an impulse along the
    normal, 1/m = sum_j (Psi_j . n)^2 / m (+ r^2 / I for a pivot's rotation): the lightest
    mass any impact can meet there, with every mode of the basis taking part."""
    b = arr.basis
    th = math.radians(scene.initial.angle_deg)
    normal_body = np.array([-math.sin(th), 0.0, math.cos(th)])  # world z in the body frame
    mobility = float(np.sum((b.psi_tip[0] @ normal_body) ** 2)) / b.mass
    if scene.mount.kind == "pivot":
        xc = arr.points[2][0]
        arm = xc[0] * math.cos(th) - xc[2] * math.sin(th)  # horizontal lever of the point
        mobility += arm * arm / b.J0[1, 1]
    return 1.0 / max(mobility, 1e-300)


def _lever(arr: MechanismArrays, scene: MechScene, row: int) -> float:
    """How far load point ``row`` moves per unit motion of the first contact point in the
    bar's slowest way of moving (the rigid rotation of a pivot, the fundamental mode of
    a clamp; 1 for a free bar)."""
    xc = arr.points[2]
    if scene.mount.kind == "pivot":
        return abs(xc[row, 0]) / max(abs(xc[0, 0]), 1e-12)
    if scene.mount.kind == "clamp":
        b = arr.basis
        bend = [j for j, f in enumerate(b.families) if f == "bend3"]
        if bend:
            psi = arr.points[0]
            return abs(psi[row, bend[0], 2]) / max(abs(psi[0, bend[0], 2]), 1e-12)
    return 1.0


def closing_work(scene: MechScene, arr: MechanismArrays) -> float:
    """J: an upper estimate of the work available to close the gap (forces, preloads,
    gravity over the initial gap); a scale for the error control, not a prediction."""
    gap = scene.initial.height
    # each load's largest force times how far its point travels while the contact closes
    force = sum(max(abs(v) for v in f.table()[1]) * _lever(arr, scene, arr.rows + k)
                for k, f in enumerate(scene.forces))
    nf = len(scene.forces)
    force += sum((max(abs(v) for v in sp.force) if sp.from_table else abs(sp.preload or 0.0) + sp.stiffness * gap)
                 * _lever(arr, scene, arr.rows + nf + k) for k, sp in enumerate(scene.springs))
    xc = arr.points[2]
    if scene.mount.kind == "pivot":
        r = max(float(np.hypot(xc[0, 0], xc[0, 2])), 1e-9)
        force += abs(scene.mount.preload_torque) / r + scene.mount.stiffness * gap / (r * r)
    force += arr.basis.mass * scene.gravity
    return force * max(gap, 1e-6)


def base_velocity_jumps(scene: MechScene) -> list[tuple[float, np.ndarray]]:
    """(time s, world velocity jump m/s) at each breakpoint of a piecewise-linear base
    travel; the velocity is zero before the first and after the last point."""
    table = scene.mount.base_table()
    if table is None:
        return []
    ts = np.array(table[0], dtype=float)
    ds = np.array(table[1], dtype=float)
    vel = np.zeros((len(ts) + 1, 3))
    if len(ts) > 1:
        vel[1:-1] = np.diff(ds, axis=0) / np.diff(ts)[:, None]
    jumps = []
    for k, t in enumerate(ts):
        dv = vel[k + 1] - vel[k]
        if np.any(dv != 0.0):
            jumps.append((float(t), dv))
    return jumps
