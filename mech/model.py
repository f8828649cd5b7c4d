"""From a scene to the compiled model: arrays, initial state, error scales, step bound.

Leaves out what the scene does not need: a scene whose motion stays in one vertical
plane gets the planar model (x, z, pitch, axial and in-plane bending modes), zero modes
give the rigid bar, and zero friction switches the tangential machinery off.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import field, replace

import numpy as np

from .armature import gain_table
from .contact_laws import damping_formula, hertz_impact, hertz_stiffness
from .damping_calibration import calibrate_damping
from .drives import ARMATURE_DRIVE, DriveKind, kind_of
from .kernel_layout import (
    C_N, C_Z, CONTACT_ROWS, N_CPAR, NEV_TIP, NQ_PAIR, event_count, quadrature_rows,
    CONTACT_DRIVES, D_VALUE, F_BAUM, F_BETA, F_C, F_G, F_GAMMA, F_VBOUND, F_K, F_MASS, F_MAX_RATIO, F_RTIP,
    N_DRIVE, AP_CARD_C, AP_CARD_K, AP_CARD_Z0, AP_DAMPING, AP_FREE, AP_LEVER, AP_MASS, AP_PRELOAD, AP_RATE,
    AP_HMAX, AP_STOP_C, AP_STOP_K, AP_TRAVEL, I_ARMATURE, I_ARM_CARD, I_ARM_DRIVE, I_ARM_NGAIN, MOUNT_NONE, N_APAR,
    N_ARM,
    N_ACLOSED,
    armature_offset,
    F_VREG, FRICTION_EXACT, FRICTION_NONE, FRICTION_REGULARIZED, I_FRICTION, I_N,
    I_PLANAR, I_MOUNT, I_NLOAD, MOUNT_CLAMP, MOUNT_FREE, MOUNT_PIVOT, N_FPAR,
    F_PIV_C, F_PIV_K, F_PIV_PHI0, F_PIV_SIGN, F_PIV_T0, L_L0, I_INERTIA, INERTIA_GRAM, INERTIA_SPARSE, N_IPAR, N_LOAD, NQ, NQ_FREE, C_C, C_K, C_ON, C_R, state_sizes,
    L_AX, L_AZ, L_BODY, L_DX, L_DZ, L_KIND, L_POINT, L_R0, L_T0, L_TN, L_ZBACK, LOAD_FORCE,
)
from .mechanism import (
    MechanismArrays, build_arrays, closing_work, contact_pairs, contact_parameters,
    effective_contact_mass, fe_beam, fixed_planes, frame_height, impulse_mass, needs_mechanism,
)
from .modal_basis import ModalBasis, _quadrature, build_modal_basis, sparse_invariants
from .mode_count import CAP, SAFETY, choose_mode_count
from .modes import axial_frequencies, bending_frequencies, bending_shape, free_free_roots
from .parameters import MechScene
from .travel_spring import travel_force
from .rotations import matrix_to_quaternion, quat_to_matrix, rotation_y, rotation_z  # noqa: F401
from .frozen import frozen


def is_planar(scene: MechScene, tol: float = 1e-12) -> bool:
    """True when the initial state keeps the motion in the bar's vertical plane.

    Gravity, the plane block and isotropic friction keep such a motion planar; what
    must hold initially is a centre-of-mass velocity in the plane and an angular
    velocity normal to it.
    """
    ini = scene.initial
    psi = math.radians(ini.azimuth_deg)
    normal = np.array([-math.sin(psi), math.cos(psi), 0.0])
    v = np.array(ini.velocity)
    w = np.array(ini.angular_velocity)
    scale_v = max(1.0, np.linalg.norm(v))
    scale_w = max(1.0, np.linalg.norm(w))
    return abs(v @ normal) <= tol * scale_v and np.linalg.norm(w - (w @ normal) * normal) <= tol * scale_w


@frozen
class ContactScales:
    """Contact constants and the scales the error control and step bound use (SI)."""

    stiffness: float  # N/m^1.5
    damping: float  # c
    beta: float
    reference_speed: float  # m/s
    reference_mass: float  # kg, effective normal mass of the first-impacting tip
    penetration_scale: float  # m, Hertz delta_max at the reference impact
    shortest_contact: float  # s, Hertz contact time lower bound
    energy_scale: float  # J
    speed_bound: float  # m/s, no tip approaches the block faster (energy available, lightest mass)
    dampings: tuple = ()  # c of each contact point (mechanism scenes)


def _first_impact(scene: MechScene) -> tuple[float, float]:
    """Normal speed (m/s) and effective normal mass (kg) of the first tip impact, from a
    rigid-bar free flight of the initial state (gravity only)."""
    bar, ini = scene.bar, scene.initial
    m = bar.mass
    theta = math.radians(ini.angle_deg)
    a = 0.5 * bar.length - bar.tip_radius
    # tip normal speed from translation and rotation about the horizontal axis
    psi = math.radians(ini.azimuth_deg)
    axis = np.array([math.cos(theta) * math.cos(psi), math.cos(theta) * math.sin(psi), math.sin(theta)])
    low_sign = -1.0 if theta > 0 else 1.0
    w = np.array(ini.angular_velocity)
    v_tip = np.array(ini.velocity) + np.cross(w, low_sign * a * axis)
    vn = -v_tip[2]
    g = scene.gravity
    speed = math.sqrt(max(vn, 0.0) ** 2 + 2.0 * g * ini.height)
    if speed <= 0.0:
        # nothing approaches the block yet: the scale of the motion there is instead
        motion = float(np.linalg.norm(ini.velocity)) + float(np.linalg.norm(w)) * 0.5 * bar.length
        speed = max(motion, 1e-3)
    i_t = bar.density * bar.length * bar.second_moments[0] + m * bar.length**2 / 12.0
    m_eff = m / (1.0 + m * (a * math.cos(theta)) ** 2 / i_t)
    return speed, m_eff


def contact_damping(con, v_ref: float, k: float, m_eff: float) -> float:
    """c of the contact law: given, the law's closed form, or calibrated so a single impact
    of m_eff (kg) at v_ref (m/s) on stiffness k (N/m^1.5) rebounds with the target restitution."""
    if con.damping is not None:
        return con.damping
    if con.calibration == "formula":
        return damping_formula(con.law, con.restitution, v_ref, k)
    return calibrate_damping(con.law, con.restitution, v_ref, k, m_eff)


def contact_scales(scene: MechScene, n_modes: int) -> ContactScales:
    bar, blk, con = scene.bar, scene.block, scene.contact
    k = con.stiffness or hertz_stiffness(bar.tip_radius, bar.youngs_modulus, bar.poisson_ratio,
                                         blk.youngs_modulus, blk.poisson_ratio)
    speed_est, m_eff = _first_impact(scene)
    v_ref = con.reference_speed or speed_est
    c = contact_damping(con, v_ref, k, m_eff)
    ini = scene.initial
    m = bar.mass
    ke0 = 0.5 * m * float(np.dot(ini.velocity, ini.velocity)) + 0.5 * m * bar.length**2 / 12.0 * float(
        np.dot(ini.angular_velocity, ini.angular_velocity))
    # fastest normal approach any tip can reach: all energy into one tip's normal motion
    e_avail = ke0 + m * scene.gravity * (ini.height + bar.length)
    m_min = m / (4.0 * (1.0 + n_modes))  # 1/m_eff <= (1 + 3 + 4 n)/m: |phi_j| <= 2 at the tips
    v_max = math.sqrt(2.0 * e_avail / m_min) + v_ref
    t_short = hertz_impact(m_min, k, v_max).contact_time
    return ContactScales(
        stiffness=k, damping=c, beta=con.beta, reference_speed=v_ref, reference_mass=m_eff,
        penetration_scale=hertz_impact(m_eff, k, v_ref).max_penetration,
        shortest_contact=t_short, energy_scale=max(e_avail, 1e-12), speed_bound=v_max,
    )


def mechanism_scales(scene: MechScene, arr: MechanismArrays, n_modes: int) -> ContactScales:
    """Contact constants and scales of a mechanism scene (held bar, rivets, loads).

    The reference impact is the first contact pair's: its point's effective mass
    (mechanism.effective_contact_mass) at the speed the closing work could give it (held
    bars) or the free-flight speed (free bars); ``contact.reference_speed`` overrides.
    Each pair's damping is calibrated on its own stiffness; the shortest contact (the
    step bound) is the stiffest pair's.
    """
    con = scene.contact
    ks = contact_parameters(arr.pairs, arr.rows, con.stiffness, (0.0,))[: len(arr.pairs), C_K]
    m_eff = effective_contact_mass(arr, scene)
    work = closing_work(scene, arr)
    if scene.mount.held:
        # nothing may drive the contact closed (a free vibration): the scale of the motion
        # the scene starts with then, and 1 mm/s at least, as for the free bar
        r = float(np.hypot(arr.points[2][0, 0], arr.points[2][0, 2]))
        spin = float(np.linalg.norm(scene.initial.angular_velocity)) * r
        v_est = max(math.sqrt(2.0 * work / m_eff), spin, 1e-3)
        e_avail = work + 0.5 * m_eff * spin * spin
    else:
        v_est, _ = _first_impact(scene)
        ini = scene.initial
        m = arr.basis.mass
        e_avail = (0.5 * m * float(np.dot(ini.velocity, ini.velocity)) + work
                   + m * scene.gravity * (ini.height + scene.bar.length))
    v_ref = con.reference_speed or v_est
    dampings = [contact_damping(con, v_ref, k, m_eff) for k in ks]
    # lightest mass an impact can meet: a held bar's impulse mass from its modes; a free
    # bar's bound as in contact_scales (|phi_j| <= 2 at a point)
    m_min = impulse_mass(arr, scene) if scene.mount.held else m_eff / (4.0 * (1.0 + n_modes))
    v_max = math.sqrt(2.0 * e_avail / m_min) + v_ref
    k0 = float(ks[0])
    return ContactScales(
        stiffness=k0, damping=dampings[0], beta=con.beta, reference_speed=v_ref, reference_mass=m_eff,
        penetration_scale=hertz_impact(m_eff, k0, v_ref).max_penetration,
        shortest_contact=hertz_impact(m_min, float(np.max(ks)), v_max).contact_time,
        energy_scale=max(e_avail, 1e-12), speed_bound=v_max, dampings=tuple(dampings),
    )


# --- the energy the scene's steady loads can release (the audit's yardstick) ------------

def load_work_bound(model: "BarModel", energy: float, forces: bool = True) -> float:
    """J: the most work the steady loads can do on a held bar (clamp or pivot) within its
    range of motion, from the scene alone, before the run: gravity, a pivot's preload
    torque (with its torsion spring) and, with ``forces``, every actuator force at the
    largest magnitude its table reaches (a world or a body direction). ``energy`` (J): what
    the scene brings besides (initial kinetic, elastic, contact and spring energy), which
    can carry the bar further.

    - Rigid rotation (pivot): the loads' potential Phi(phi) about the hinge, lowest over
      the arc of angles the bar can reach from its start without a contact cap going into
      the block (deeper than the Hertz penetration that energy could make): Phi(phi0) -
      min Phi. A pendulum released above the block: m g times its centre's drop until the
      cap meets the block; a preload torque T: T times the angle to the block.
    - Elastic modes: a load f (modal forces, N) on stiffness K releases f.q, at most
      a (1 + sqrt(1 + 2 e / a)) with a = f K^-1 f (2a from rest: twice the static work) for
      the energy e otherwise present; a clamped blade's contact point cannot go below the
      block (its gap and the penetration), which bounds q further
      (``_elastic_bound``).
    Free bars are bounded in mech.results (their centre's drop to the block)."""
    scene = model.scene
    if not scene.mount.held:
        return 0.0
    y0 = model.initial_state()
    loads = _steady_loads(model) if forces else []
    rigid = 0.0
    if scene.mount.kind == "pivot":
        rigid = _pivot_arc_bound(model, y0, loads, energy)
    if model.n == 0:
        return rigid
    phis = [float(y0[2])]
    if scene.mount.kind == "pivot":  # the modal loads turn with the bar: their largest over a turn
        phis += list(float(y0[2]) + np.linspace(-math.pi, math.pi, 64, endpoint=False))
    constrained = scene.mount.kind == "clamp"
    return rigid + max(_elastic_bound(model, y0, loads, phi, energy + rigid, constrained) for phi in phis)


def _steady_loads(model: "BarModel") -> list:
    """(point index, direction (3,), body frame?, magnitude N) of each actuator force, at
    the value of largest magnitude its table reaches."""
    out = []
    for row in model.load:
        if int(row[L_KIND]) != LOAD_FORCE:
            continue
        values = model.tables[1, int(row[L_T0]):int(row[L_T0]) + int(row[L_TN])]
        f = float(values[np.argmax(np.abs(values))]) if len(values) else 0.0
        out.append((int(row[L_POINT]), np.array(row[L_DX:L_DZ + 1]), bool(row[L_BODY]), f))
    return out


def _pivot_arc_bound(model: "BarModel", y0: np.ndarray, loads: list, energy: float) -> float:
    """J: Phi(phi0) - min Phi over the arc of the rigid rotation the block allows (see
    load_work_bound); Phi: gravity, the forces, the preload torque and torsion spring."""
    fp = model.fpar
    m = model.basis.mass
    c = model.first_moments[:, 0]  # kg m, about the hinge (the frame origin)
    psi, _, xc = model.points
    phi0 = float(y0[2])
    cp = model.cpar
    caps = [(xc[i], cp[i, C_R], cp[i, C_Z], cp[i, C_N]) for i in range(model.rows) if cp[i, C_ON] != 0.0]

    def potential(phi):
        phi = np.asarray(phi, dtype=float)
        cos, sin = np.cos(phi), np.sin(phi)
        v = fp[F_G] * (m * y0[1] + (-sin * c[0] + cos * c[2]))
        th = fp[F_PIV_SIGN] * (phi - fp[F_PIV_PHI0])
        v = v + 0.5 * fp[F_PIV_K] * th * th - fp[F_PIV_T0] * th
        for point, d, body, f in loads:
            p = xc[point]
            if body:  # a force turning with the bar: a constant torque about the hinge
                v = v - f * (d[0] * p[2] - d[2] * p[0]) * (phi - phi0)
            else:
                x = y0[0] + cos * p[0] + sin * p[2]
                z = y0[1] - sin * p[0] + cos * p[2]
                v = v - f * (d[0] * x + d[2] * z)
        return v

    def clearance(phi, depth):
        """m: the nearest cap's gap to its fixed contact at angle(s) phi, plus ``depth``."""
        phi = np.asarray(phi, dtype=float)
        z = [sg * (y0[1] - np.sin(phi) * p[0] + np.cos(phi) * p[2] - zf) - r for p, r, zf, sg in caps]
        return np.min(z, axis=0) + depth

    def limit(direction, depth):
        """The angle where a cap first meets the block turning from phi0 (at most a turn)."""
        grid = phi0 + direction * np.linspace(0.0, 2.0 * math.pi, 4097)
        below = np.flatnonzero(clearance(grid, depth) < 0.0)
        if not len(below) or below[0] == 0:
            return float(grid[-1] if not len(below) else phi0)
        lo, hi = float(grid[below[0] - 1]), float(grid[below[0]])
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if clearance(mid, depth) >= 0.0 else (lo, mid)
        return lo

    def bound(depth):
        lo, hi = limit(-1.0, depth), limit(1.0, depth)
        phis = np.concatenate([np.linspace(lo, hi, 20001), [lo, hi]])
        return max(float(potential(phi0) - np.min(potential(phis))), 0.0)

    k = float(np.max(model.cpar[:, C_K]))
    first = bound(0.0)
    # the caps may sink in by the Hertz penetration the energy makes: (5/2 E / k)^(2/5)
    depth = (2.5 * (first + energy) / k) ** 0.4 if k > 0.0 else 0.0
    return bound(depth)


def _elastic_bound(model: "BarModel", y0: np.ndarray, loads: list, phi: float, energy: float,
                   constrained: bool) -> float:
    """J: the most work the steady loads do on the elastic modes at the bar's angle phi
    (see load_work_bound): max f.q over {1/2 q K q - f.q <= e}, and with ``constrained``
    (clamp) over the part where contact point 0 stays above the block less the penetration
    depth, a ball cut by a half-space, in closed form."""
    psi, _, xc = model.points
    K = model.basis.stiffness
    R = rotation_y(phi)
    g = model.fpar[F_G]
    L = model.first_moments[:, 1:model.n + 1]  # kg: the modes' first moments
    f = -g * (R[2] @ L)
    for point, d, body, mag in loads:
        dir_body = d if body else R.T @ d
        f = f + mag * (psi[point] @ dir_body)
    free = load_release_bound(K, f, energy)
    if not constrained or free <= 0.0:
        return free
    sg, zf = float(model.cpar[0, C_N]), float(model.cpar[0, C_Z])
    c = -sg * (psi[0] @ R[2])  # displacement of contact pair 0's point towards its fixed contact per unit q (m)
    gap = sg * (float(y0[1] + R[2] @ xc[0]) - zf) - float(model.cpar[0, C_R])  # its gap at the start
    k = float(model.cpar[0, C_K])
    depth = (2.5 * (free + max(energy, 0.0)) / k) ** 0.4 if k > 0.0 else 0.0
    return load_release_bound(K, f, energy, c, max(gap, 0.0) + depth)


def load_release_bound(K: np.ndarray, f: np.ndarray, energy: float, c: np.ndarray | None = None,
                       room: float = math.inf) -> float:
    """J: the most work f.q a steady load f (N, modal) can do on a linear elastic system of
    stiffness K (N/m, symmetric positive definite) starting at q = 0 with ``energy`` (J)
    besides: max f.q over {1/2 q K q - f.q <= energy}, and with c (m per unit q) over
    the part where c.q <= ``room`` (m: a contact point that may move that far towards the
    block). A ball in the coordinates u = K^(1/2) (q - K^-1 f) of radius
    rho = sqrt(2 energy + a), a = f K^-1 f: f.q = a + rho sqrt(a) at its best, 2a from rest
    (twice the static work); cut by the half-space, the best lies on the cut:
    a + f_c alpha + sqrt(a - f_c^2) sqrt(rho^2 - alpha^2), alpha = beta / |c~|,
    beta = room - c K^-1 f, f_c = f K^-1 c / |c~|, |c~|^2 = c K^-1 c."""
    Kinv_f = np.linalg.solve(K, f)
    a = float(f @ Kinv_f)
    if a <= 0.0:
        return 0.0
    rho = math.sqrt(2.0 * max(energy, 0.0) + a)
    free = a + rho * math.sqrt(a)
    if c is None or not math.isfinite(room):
        return free
    Kinv_c = np.linalg.solve(K, c)
    cc = float(c @ Kinv_c)
    if cc <= 0.0:
        return free
    beta = room - float(c @ Kinv_f)
    fc = float(f @ Kinv_c) / math.sqrt(cc)
    if rho * fc * math.sqrt(cc) <= beta * math.sqrt(a):  # the ball's best point lies in the half-space
        return free
    alpha = min(max(beta / math.sqrt(cc), -rho), rho)
    return a + fc * alpha + math.sqrt(max(a - fc * fc, 0.0)) * math.sqrt(max(rho * rho - alpha * alpha, 0.0))


def _pivot_parameters(fpar: np.ndarray, scene: MechScene, xc: np.ndarray) -> None:
    """The pivot's torsion spring into fpar (before the model is built from it)."""
    mnt = scene.mount
    # the free end is the side of the first contact point; with kernel.unpack's rotation
    # a point at body x moves by dz/dphi = -x cos(phi), so turning it down, towards the
    # block, is -phi when it lies at body -x
    fpar[F_PIV_SIGN] = -1.0 if xc[0, 0] < 0.0 else 1.0
    fpar[F_PIV_K] = mnt.stiffness
    fpar[F_PIV_C] = mnt.damping
    fpar[F_PIV_T0] = mnt.preload_torque
    fpar[F_PIV_PHI0] = -math.radians(scene.initial.angle_deg)


def _spring_rest_lengths(model: "BarModel") -> np.ndarray:
    """The load table with each spring's rest length (m) from its preload or rest_length,
    and each force that follows its travel with its point's start along its direction (m),
    measured on the model's initial state."""
    scene = model.scene
    load = model.load.copy()
    xc = model.points[2]
    y0 = model.initial_state()
    R0 = rotation_y(-math.radians(scene.initial.angle_deg))
    r0 = np.array([y0[0], 0.0, y0[1]]) if model.planar else y0[0:3]
    for row, sp in model.mechanism.spring_points:
        p = int(load[row, 1])
        x = r0 + R0 @ xc[p]
        length = float(np.linalg.norm(x - np.array(sp.anchor)))
        if sp.rest_length is not None:
            rest = sp.rest_length
        elif sp.from_table:
            rest = length  # a force-travel spring's travel 0 at the start
        elif sp.preload is not None:
            rest = length - sp.preload / sp.stiffness
            if rest < 0.0:
                raise ValueError(f"{sp.name}.preload = {sp.preload!r}: more than the spring's stiffness times "
                                 f"its length ({sp.stiffness * length!r} N) can give")
        else:
            rest = length
        load[row, L_L0] = rest
    for row, f in enumerate(scene.forces):  # a force that follows its travel: its point's start along d
        if f.follows_travel:
            x = r0 + R0 @ xc[int(load[row, 1])]
            load[row, L_L0] = float(np.dot(f.direction, x))
    return load


def _stick_start(model: "BarModel", y: np.ndarray) -> None:
    """Each spring with hysteresis starts on its press branch: its stick force z the band's
    half-width at its travel in state y (the point placed rigidly, as _spring_rest_lengths
    measures its rest length)."""
    load = model.load
    xc = model.points[2]
    R0 = rotation_y(-math.radians(model.scene.initial.angle_deg))
    r0 = np.array([y[0], 0.0, y[1]]) if model.planar else y[0:3]
    for row in np.flatnonzero(load[:, L_ZBACK] > 0):
        ld = load[row]
        x = r0 + R0 @ xc[int(ld[L_POINT])]
        travel = float(ld[L_L0] - np.linalg.norm(x - ld[L_AX:L_AZ + 1]))
        t0, tn = int(ld[L_T0]), int(ld[L_TN])
        press = travel_force(travel, model.tables, t0, tn)
        release = travel_force(travel, model.tables, int(ld[L_R0]), tn)
        y[len(y) - int(ld[L_ZBACK])] = 0.5 * (press - release)


def state_slices(n: int, planar: bool, nq: int, armature: bool = False, bar: bool = True, nh: int = 0) -> dict:
    """Named slices of the state vector for n modes and nq quadratures; with an armature,
    "armature" (its q and rate) between the bar's speeds and the quadratures; without a
    bar, only "armature" and "quad"; with nh springs with hysteresis, "hysteresis" (their
    stick forces, N, in the order of the springs) after the quadratures, closing the vector."""
    if not bar:
        return {"armature": slice(0, N_ARM), "quad": slice(N_ARM, N_ARM + nq)}
    if planar:
        out = {"pos": slice(0, 2), "angle": slice(2, 3), "q": slice(3, 3 + n),
               "vel": slice(3 + n, 5 + n), "omega": slice(5 + n, 6 + n),
               "eta": slice(6 + n, 6 + 2 * n), "quad": slice(6 + 2 * n, 6 + 2 * n + nq)}
    else:
        out = {"pos": slice(0, 3), "quat": slice(3, 7), "q": slice(7, 7 + n),
               "vel": slice(7 + n, 10 + n), "omega": slice(10 + n, 13 + n),
               "eta": slice(13 + n, 13 + 2 * n), "quad": slice(13 + 2 * n, 13 + 2 * n + nq)}
    if armature:
        a0 = out["quad"].start
        out["armature"] = slice(a0, a0 + N_ARM)
        out["quad"] = slice(a0 + N_ARM, a0 + N_ARM + nq)
    if nh:
        out["hysteresis"] = slice(out["quad"].stop, out["quad"].stop + nh)
    return out


# the armature's speed scale where nothing else sets one (no return spring, no initial
# speed): its travel in this time. A relay's armature or a small solenoid closes in
# milliseconds; the error control needs only the order of magnitude (it is relative to the
# armature's own q and speed once it moves; this scale sets their absolute floor)
ARMATURE_TIME_SCALE = 1e-3  # s


@frozen
class ArmatureScales:
    """The armature's scales (SI; m or rad for a clapper): its reference speed, the stops'
    penetration at that speed, an energy, and the shortest contact time of its stops and
    card (the undamped half period on the armature's mass)."""

    speed: float
    penetration: float
    energy: float
    contact_time: float


def armature_scales(arm) -> ArmatureScales:
    """Scales of the armature (a present mech.parameters.Armature) for the error control and
    the step after a stop or card contact starts: the reference speed is the largest of the
    speed the return spring's energy over the travel gives (the least the drive must put in
    to close it, preload d + rate d^2 / 2), the initial speed and travel / ARMATURE_TIME_SCALE."""
    m = arm.inertia_value
    d = arm.travel
    w_spring = arm.spring_preload * d + 0.5 * arm.spring_rate * d * d
    speed = max(math.sqrt(2.0 * w_spring / m), abs(arm.initial_speed), d / ARMATURE_TIME_SCALE)
    k = arm.stop_stiffness
    if arm.has_card:
        k = max(k, arm.card_lever ** 2 * arm.card_stiffness)  # the card's stiffness along q
    return ArmatureScales(speed=speed, penetration=speed * math.sqrt(m / arm.stop_stiffness),
                          energy=0.5 * m * speed * speed, contact_time=math.pi * math.sqrt(m / k))


def armature_parameters(arm, card_z0: float = 0.0, card_mobility: float = 0.0) -> np.ndarray:
    """The kernel's apar (kernel_layout AP_*) of an armature (zeros if none); card_z0: the
    world height (m) of the bar's card point at the start; card_mobility (1/kg): that
    point's, along z (model.point_mobility). The step bound while a stop or the card is
    closed, AP_HMAX, is 1 / their highest rate: sqrt(k_stop / m) and, for the card between
    the armature and the bar's point, sqrt(k_card (lever^2 / m + card_mobility))."""
    apar = np.zeros(N_APAR)
    if not arm.present:
        return apar
    m = arm.inertia_value
    rate2 = arm.stop_stiffness / m
    if arm.has_card:
        rate2 = max(rate2, arm.card_stiffness * (arm.card_lever ** 2 / m + card_mobility))
    apar[AP_HMAX] = 1.0 / math.sqrt(rate2)
    apar[AP_MASS] = arm.inertia_value
    apar[AP_TRAVEL] = arm.travel
    apar[AP_RATE] = arm.spring_rate
    apar[AP_PRELOAD] = arm.spring_preload
    apar[AP_STOP_K] = arm.stop_stiffness
    apar[AP_STOP_C] = arm.stop_damping
    apar[AP_DAMPING] = arm.damping
    if arm.has_card:
        apar[AP_LEVER] = arm.card_lever
        apar[AP_FREE] = arm.card_free_travel
        apar[AP_CARD_K] = arm.card_stiffness
        apar[AP_CARD_C] = arm.card_damping
        apar[AP_CARD_Z0] = card_z0
    return apar


@frozen
class BarModel:
    """The compiled model's arrays plus what Python needs to interpret the state.

    Built whole by ``build_model`` and never changed afterwards (frozen; its arrays are
    not written after the build): what changes during a run -- each contact point's
    friction coefficient and repulsion, the named channels ``drive_names`` -- is the
    solver's drive, passed beside the arrays (``kernel_arrays``).
    """

    scene: MechScene
    planar: bool
    basis: ModalBasis
    contact: ContactScales
    fpar: np.ndarray
    ipar: np.ndarray
    azimuth: float  # rad: planar models are solved in the plane rotated by -azimuth
    atol: np.ndarray
    relmask: np.ndarray
    max_step: float
    sparse: tuple  # the sparse inertia invariants (mech.modal_basis.sparse_invariants)
    points: tuple  # (psi, theta, xc): the contact pairs' points (``rows`` rows) then load points
    cpar: np.ndarray  # (rows, N_CPAR) per contact pair (kernel_layout C_*): k, c, cap radius, on, plane
    first_moments: np.ndarray  # (3, 2n + 1): c (kg m), L_j (kg), H_j (kg m), body frame
    load: np.ndarray  # (n_loads, N_LOAD) actuator forces and springs
    tables: np.ndarray  # (2, n) concatenated time tables of the loads
    mechanism: MechanismArrays | None = None  # set for mechanism scenes (mech.mechanism)
    mode_count: object = None  # ModeCount when bar.modes = "auto" chose the counts, else None
    # the drive channels: their names (rows of the drive, kernel_layout D_*), and per
    # contact row the drive row of each of its kinds (kernel_layout K_*; -1: no such point)
    drive_names: tuple = ()
    cdrive: np.ndarray = None
    input_work: bool = False  # the input-work quadrature kept although nothing of the scene needs it
    # the armature (kernel_layout AP_*; zeros without one) and its gain table (3, knots)
    apar: np.ndarray = field(default_factory=lambda: np.zeros(N_APAR))
    again: np.ndarray = field(default_factory=lambda: np.zeros((3, 0)))
    # the contact pairs (mech.mechanism.ContactPair: the point, the fixed contact it strikes,
    # its plane and whether the circuit sees it), in the order of their contact rows
    pairs: tuple = ()

    # What follows from the built arrays alone is cached (functools.cached_property: the
    # model is never changed after the build): the solver asks for these at every macro
    # step, and a slices() map built anew cost ~9 us a call.

    @functools.cached_property
    def rows(self) -> int:
        """Contact rows of the kernel's arrays (cpar, aux, regimes): the pairs' and, for a
        single pair, a switched-off second (kernel_layout.CONTACT_ROWS)."""
        return int(self.cpar.shape[0])

    @property
    def event_count(self) -> int:
        """Event functions: NEV_TIP per contact row, then the armature's."""
        return event_count(self.rows)

    @property
    def armature_event_base(self) -> int:
        """Index of the armature's first event (kernel_layout EA_* follow it)."""
        return self.rows * NEV_TIP

    @functools.cached_property
    def n(self) -> int:
        return self.basis.n

    def initial_drive(self) -> np.ndarray:
        """A new drive array (one row per channel of ``drive_names``, columns kernel_layout
        D_*): every friction coefficient at the scene's value at zero current, every other
        channel 0, all constant in time."""
        drive = np.zeros((len(self.drive_names), N_DRIVE))
        fr = self.scene.friction
        drive[self.drive_rows("mu"), D_VALUE] = fr.mu_at(0.0) if fr.active else 0.0
        return drive

    @functools.cached_property
    def drive_kinds(self) -> tuple[DriveKind, ...]:
        """The kind (mech.drives) of each drive channel, in the order of ``drive_names``."""
        return tuple(kind_of(name) for name in self.drive_names)

    def drive_rows(self, kind: str) -> np.ndarray:
        """The drive rows of channel ``kind`` (kernel_layout CONTACT_DRIVES) of every
        contact point, in the order of the points."""
        k = CONTACT_DRIVES.index(kind)
        return np.array([row for row in self.cdrive[:, k] if row >= 0], dtype=np.int64)

    @functools.cached_property
    def arrays(self) -> tuple:
        """The compiled kernel's model argument (one tuple, see kernel.dynamics) with the
        scene's constant friction coefficient as its drive: the same tuple object on every
        call, so the compiled route's argument check (mech.aot) validates it once rather
        than at each of thousands of calls. A solver passes its own drive instead
        (``kernel_arrays``)."""
        return self.kernel_arrays(self.initial_drive())

    def kernel_arrays(self, drive: np.ndarray) -> tuple:
        """The kernel's model argument with ``drive`` (float64[len(drive_names), N_DRIVE],
        C order, kernel_layout D_*) as the driven quantities over time."""
        b = self.basis
        ptr, idx, val = self.sparse
        psi, theta, xc = self.points
        return (self.fpar, self.ipar, b.J0, ptr, idx, val, psi, theta, xc, self.cpar,
                self.first_moments, self.load, self.tables, self.cdrive, drive)

    def kernel_armature(self, closed: np.ndarray):
        """The kernel's armature argument (kernel.dynamics: ``arm``): None without an
        armature, else (apar, again, closed) with ``closed`` (float64[N_ACLOSED], kernel_layout
        EA_* and BAR_HELD) the states of its stops and card, and the bar's hold in flight,
        that the solver keeps."""
        if not self.has_armature:
            return None
        return (self.apar, self.again, closed)

    @functools.cached_property
    def armature_arrays(self):
        """``kernel_armature`` with every stop and the card open, the same tuple on every call
        (for what follows from the state alone: energies, the armature's table)."""
        return self.kernel_armature(np.zeros(N_ACLOSED))

    @functools.cached_property
    def has_bar(self) -> bool:
        """False for an armature alone (no bar, no contact point)."""
        return int(self.ipar[I_MOUNT]) != MOUNT_NONE

    @functools.cached_property
    def has_armature(self) -> bool:
        return bool(self.ipar[I_ARMATURE])

    @functools.cached_property
    def armature_index(self) -> int:
        """The armature's q in the state (its rate follows); -1 without an armature."""
        if not self.has_armature:
            return -1
        return armature_offset(self.n, self.planar, int(self.ipar[I_MOUNT]))

    @functools.cached_property
    def state_size(self) -> int:
        npos, nvel = state_sizes(self.n, self.planar) if self.has_bar else (0, 0)
        return npos + nvel + (N_ARM if self.has_armature else 0) + self.nq + self.hysteresis_count

    @functools.cached_property
    def hysteresis_count(self) -> int:
        """The force-travel springs with hysteresis, one state each (their stick forces)."""
        return int(np.count_nonzero(self.load[:, L_ZBACK] > 0)) if len(self.load) else 0

    @property
    def cap_axes(self) -> list:
        """Per contact row: (outward body axis of its cap, cap half-angle rad), or (None, 0)
        where no cap limit applies (a rivet on the axis of the bar)."""
        bar = self.scene.bar
        ends = {"tip0": np.array([-1.0, 0.0, 0.0]), "tip1": np.array([1.0, 0.0, 0.0])}
        if self.mechanism is None:
            return [(ends["tip0"], bar.cap_half_angle), (ends["tip1"], bar.cap_half_angle)]
        out = []
        for cp in self.mechanism.contacts:
            if cp.name in ends and not self.scene.rivets:
                out.append((ends[cp.name], bar.cap_half_angle))
            elif cp.offset != 0.0:
                out.append((np.array([0.0, 0.0, math.copysign(1.0, cp.offset)]), 0.5 * math.pi))
            else:
                out.append((None, 0.0))
        return out + [(None, 0.0)] * (self.rows - len(out))

    @functools.cached_property
    def rest_window(self) -> float:
        """s: how long a contact must stay quiet before the solver holds it at rest: two
        periods of the slowest oscillation it could still hide (the lowest elastic mode,
        the contact's own rebound on its reference mass, a pivot's torsion spring)."""
        if not self.has_bar:
            return 0.0  # an armature alone is never held (docs/mechanics.md, "The armature")
        cs = self.contact
        k_lin = 1.5 * cs.stiffness * math.sqrt(cs.penetration_scale)
        periods = [2.0 * math.pi * math.sqrt(cs.reference_mass / k_lin)]
        f = self.basis.frequencies
        if len(f) and np.min(f) > 0.0:
            periods.append(1.0 / float(np.min(f)))
        mnt = self.scene.mount
        if mnt.kind == "pivot" and mnt.stiffness > 0.0:
            periods.append(2.0 * math.pi * math.sqrt(self.basis.J0[1, 1] / mnt.stiffness))
        # (an armature is watched only while a stop or its card holds it, where its own
        # periods are those of these stiff contacts: mech.solver, _watch_rest)
        return 2.0 * max(periods)

    @property
    def load_change_times(self) -> list:
        """s: the breakpoints of the actuator force tables (a held state must end there)."""
        out = []
        for f in self.scene.forces:
            if f.time is not None:
                out += list(f.table()[0])
        return sorted(out)

    def rotation(self, y: np.ndarray) -> np.ndarray:
        """Body -> solver-frame rotation matrix of state y (planar: about y by the angle)."""
        sl = self.slices()
        if self.planar:
            return rotation_y(float(y[sl["angle"]][0]))
        R = np.empty((3, 3))
        quat_to_matrix(*y[sl["quat"]], R)
        return R

    def contact_point_x(self, y: np.ndarray, i: int) -> float:
        """m: world x of contact point i's cap centre in state y (modal deflection included)."""
        sl = self.slices()
        psi, _, xc = self.points
        s_body = xc[i] + (psi[i].T @ y[sl["q"]] if self.n else 0.0)
        return float(y[sl["pos"]][0] + self.rotation(y)[0] @ s_body)

    @functools.cached_property
    def sphere_tops(self) -> tuple:
        """m per contact pair: world x of its spherical fixed contact's top (None: a plane):
        [block]'s below the first contact point at the start, a [[fixed]] sphere's below (or
        above) its own, each shifted by its offset."""
        y0 = self.initial_state()
        out = []
        for i, pair in enumerate(self.pairs):
            if pair.shape != "sphere":
                out.append(None)
                continue
            out.append(self.contact_point_x(y0, 0 if pair.key == "block" else i) + pair.offset)
        return tuple(out)

    @functools.cached_property
    def armature_springs(self) -> bool:
        """True if a spring joins the armature to the bar (``between = "armature"``): the bar's
        loads then move with the armature, card open or not."""
        return any(sp.between == "armature" for sp in self.scene.springs)

    def loads_ramping(self, t: float) -> bool:
        """True if some actuator force changes right after t (s): t lies inside a table
        interval whose two ends differ, so the loads are not constant until the next
        breakpoint and no hold at rest may start."""
        for f in self.scene.forces:
            if f.time is None:
                continue
            ts, vs = f.table()
            for k in range(len(ts) - 1):
                if ts[k] <= t < ts[k + 1] and vs[k] != vs[k + 1]:
                    return True
        return False

    @functools.cached_property
    def nq(self) -> int:
        """Number of quadratures: the input-work and load-dissipation ones only when the
        scene has loads or a mount, or the model was built with ``input_work``."""
        return quadrature_count(self.ipar, self.input_work, self.rows)

    def slices(self) -> dict:
        """Named slices of the state vector (a new dict: the caller may change it)."""
        return dict(self._slice_map)

    @functools.cached_property
    def _slice_map(self) -> dict:
        return state_slices(self.n, self.planar, self.nq, self.has_armature, self.has_bar, self.hysteresis_count)

    @functools.cached_property
    def armature_drive_row(self) -> int:
        """The drive row of "armature.force" (-1: no armature)."""
        return int(self.ipar[I_ARM_DRIVE]) if self.has_armature else -1

    def _resting(self, R0: np.ndarray) -> tuple[float, np.ndarray]:
        """Centre height (m) and modal coordinates (m) of the bar resting on the block.

        The weight is carried by both tips (lying flat) or by the lower one (standing);
        each loaded tip is pressed in by the Hertz penetration (F/k)^(2/3), and the tip
        forces bend the modes statically: K q = sum_i Psi_i . (R0^T F_i). Gravity itself
        loads no mode (their mean is zero), so this is the whole static equilibrium.
        """
        ini, bar = self.scene.initial, self.scene.bar
        weight = bar.mass * self.scene.gravity
        if abs(ini.angle_deg) < 1e-9:
            loads = {0: 0.5 * weight, 1: 0.5 * weight}
        else:
            loads = {0 if ini.angle_deg > 0 else 1: weight}
        b = self.basis
        q = np.zeros(b.n)
        if b.n:
            Q = np.zeros(b.n)
            for i, f in loads.items():
                Q += b.psi_tip[i] @ (R0.T @ np.array([0.0, 0.0, f]))
            q = np.linalg.solve(b.stiffness, Q)
        k = self.contact.stiffness
        i, f = next(iter(loads.items()))
        pen = (f / k) ** (2.0 / 3.0) if f > 0 else 0.0
        s_i = np.array([b.x_centre[i], 0.0, 0.0]) + (b.psi_tip[i].T @ q if b.n else 0.0)
        z0 = self.scene.bar.tip_radius - pen - float((R0 @ s_i)[2])
        return z0, q

    def initial_state(self) -> np.ndarray:
        if not self.has_bar:
            y = np.zeros(self.state_size)
            arm = self.scene.armature
            y[self.slices()["armature"]] = (arm.start_position, arm.initial_speed)
            return y
        y = self._bar_initial_state()
        if self.has_armature:
            arm = self.scene.armature
            y[self.slices()["armature"]] = (arm.start_position, arm.initial_speed)
        if self.hysteresis_count:
            _stick_start(self, y)
        return y

    def _bar_initial_state(self) -> np.ndarray:
        ini, bar = self.scene.initial, self.scene.bar
        theta = math.radians(ini.angle_deg)
        a = 0.5 * bar.length - bar.tip_radius
        z0 = ini.height + bar.tip_radius + a * abs(math.sin(theta))
        if self.mechanism is not None:
            R0 = rotation_z(self.azimuth) @ rotation_y(-theta)
            z0 = frame_height(self.scene, self.points[2], self.mechanism.contacts, R0)
        y = np.zeros(self.state_size)
        if ini.resting:
            z0, q_rest = self._resting(rotation_z(self.azimuth) @ rotation_y(-theta))
            y[self.slices()["q"]] = q_rest
        sl = self.slices()
        v = np.array(ini.velocity, dtype=float)
        w_world = np.array(ini.angular_velocity, dtype=float)
        if self.planar:
            Rz = rotation_z(self.azimuth)
            v_p = Rz.T @ v
            w_p = Rz.T @ w_world
            y[sl["pos"]] = [0.0, z0]
            y[sl["angle"]] = -theta
            y[sl["vel"]] = [v_p[0], v_p[2]]
            y[sl["omega"]] = w_p[1]  # body y = world y' for rotations about y'
        else:
            R0 = rotation_z(self.azimuth) @ rotation_y(-theta)
            y[sl["pos"]] = [0.0, 0.0, z0]
            y[sl["quat"]] = matrix_to_quaternion(R0)
            y[sl["vel"]] = v
            y[sl["omega"]] = R0.T @ w_world
        return y


def quadrature_count(ipar: np.ndarray, input_work: bool, rows: int = CONTACT_ROWS) -> int:
    """NQ with the input-work and load-dissipation quadratures (a mount, loads, an armature,
    or asked for: a driven force on a free bar), NQ_FREE without them (a plain free bar
    keeps the state and error norm it always had); a model of more than CONTACT_ROWS
    contact rows has NQ and NQ_PAIR more per row beyond them (kernel_layout.quadrature_rows)."""
    if rows > CONTACT_ROWS:
        return NQ + NQ_PAIR * (rows - CONTACT_ROWS)
    held = ipar[I_MOUNT] != MOUNT_FREE or ipar[I_NLOAD] > 0 or ipar[I_ARMATURE] != 0
    return NQ if held or input_work else NQ_FREE


def contact_drives(n_points: int, n_rows: int) -> tuple[tuple, np.ndarray]:
    """(channel names, cdrive) for ``n_points`` contact points in ``n_rows`` contact rows:
    one channel of each kind of kernel_layout CONTACT_DRIVES per point, named
    "<kind>.<point>", ordered by kind, then point."""
    names = tuple(f"{kind}.{i}" for kind in CONTACT_DRIVES for i in range(n_points))
    cdrive = np.full((n_rows, len(CONTACT_DRIVES)), -1, dtype=np.int64)
    for k in range(len(CONTACT_DRIVES)):
        cdrive[:n_points, k] = k * n_points + np.arange(n_points)
    return names, cdrive


def build_model(scene: MechScene, *, input_work: bool = False) -> BarModel:
    """Assemble the compiled model of ``scene`` (planar or 3D as the scene needs).

    input_work: keep the input-work quadrature (``work_in`` of the energy audit) even for
    a free bar without loads, so that a driven force (``repulsion.<i>``) may act on it.
    """
    if scene.bar is None:
        return armature_model(scene)
    scene, mode_count = resolve_auto_modes(scene)
    mode = scene.solver.model
    planar_ok = is_planar(scene)
    if mode == "planar" and not planar_ok:
        raise ValueError(
            "solver.model = 'planar': the initial velocity or angular velocity leaves the bar's "
            "vertical plane; use 'auto' or '3d'"
        )
    planar = planar_ok if mode == "auto" else mode == "planar"
    if scene.mount.held and not planar:
        raise ValueError("mount.kind: a held bar is solved in its plane (x-z); its initial motion must stay there")
    arr = build_arrays(scene, planar) if needs_mechanism(scene) else None
    basis = arr.basis if arr is not None else build_modal_basis(scene.bar, planar)
    n = basis.n
    cs = contact_scales(scene, n) if arr is None else mechanism_scales(scene, arr, n)
    fr = scene.friction
    fpar = np.zeros(N_FPAR)
    fpar[F_MASS] = basis.mass
    fpar[F_G] = scene.gravity
    fpar[F_K] = cs.stiffness
    fpar[F_C] = cs.damping
    fpar[F_BETA] = cs.beta
    fpar[F_GAMMA] = fr.gamma
    fpar[F_MAX_RATIO] = fr.max_ratio if math.isfinite(fr.max_ratio) else 1e300
    fpar[F_RTIP] = scene.bar.tip_radius
    # the friction's speed scale: the regularized law's v_s; for the exact law the slip
    # speed it resolves (below it the slip direction blends from the reference, and a
    # reversal is recognised past a thousandth of it: kernel slip_direction, events)
    fpar[F_VREG] = fr.regularization_speed if fr.model == "regularized" else scene.solver.stick_velocity_tol
    # Stick drift correction: slip velocity decays on a time scale of a few contact times.
    fpar[F_BAUM] = 1.0 / cs.shortest_contact
    fpar[F_VBOUND] = cs.speed_bound
    if not fr.active:
        fmodel = FRICTION_NONE
    elif fr.model == "regularized":
        fmodel = FRICTION_REGULARIZED
    else:
        fmodel = FRICTION_EXACT
    ipar = np.zeros(N_IPAR, dtype=np.int64)
    ipar[I_N] = n
    ipar[I_PLANAR] = int(planar)
    ipar[I_FRICTION] = fmodel
    ipar[I_INERTIA] = INERTIA_SPARSE if arr is not None else INERTIA_GRAM
    if arr is not None:
        ipar[I_MOUNT] = {"free": MOUNT_FREE, "clamp": MOUNT_CLAMP, "pivot": MOUNT_PIVOT}[scene.mount.kind]
        ipar[I_NLOAD] = len(arr.load)
    arm = scene.armature
    pairs = tuple(contact_pairs(scene)) if arr is None else tuple(arr.pairs)
    rows = CONTACT_ROWS if arr is None else arr.rows
    n_points = len(pairs)
    if arm.present:
        ipar[I_ARMATURE] = 1
        ipar[I_ARM_DRIVE] = 2 * n_points  # after the contact points' channels
        ipar[I_ARM_CARD] = arr.card_row if arr is not None else -1
        ipar[I_ARM_NGAIN] = len(arm.force_gain["position"]) if arm.force_gain else 0

    # Error scales: positions and angles absolutely, against the Hertz penetration, so
    # the contact geometry is resolved at every height; speeds and energies relatively.
    rtol = scene.solver.rtol
    L = scene.bar.length
    dstar = cs.penetration_scale
    vstar = cs.reference_speed
    npos, nvel = state_sizes(n, planar)
    nq = quadrature_count(ipar, input_work, rows)
    nh = int(np.count_nonzero(arr.load[:, L_ZBACK] > 0)) if arr is not None and len(arr.load) else 0
    atol = np.empty(npos + nvel + (N_ARM if arm.present else 0) + nq + nh)
    rel = np.zeros_like(atol)
    sl = state_slices(n, planar, nq, arm.present, nh=nh)
    if nh:  # the stick forces against their springs' largest force
        atol[sl["hysteresis"]] = rtol * max(max(abs(f) for f in sp.force) for sp in scene.springs if sp.hysteretic)
        rel[sl["hysteresis"]] = 1.0
    atol[sl["pos"]] = rtol * dstar
    atol[sl["angle" if planar else "quat"]] = rtol * dstar / L
    atol[sl["q"]] = rtol * dstar
    atol[sl["vel"]] = rtol * vstar
    atol[sl["omega"]] = rtol * vstar / L
    atol[sl["eta"]] = rtol * vstar
    atol[sl["quad"]] = rtol * cs.energy_scale
    rel[sl["q"]] = 1.0
    rel[sl["vel"]] = 1.0
    rel[sl["omega"]] = 1.0
    rel[sl["eta"]] = 1.0
    rel[sl["quad"]] = 1.0
    if arm.present:
        # the armature's energy belongs to the scene's scale (its drive's work is most of it)
        ascales = armature_scales(arm)
        cs = replace(cs, energy_scale=cs.energy_scale + ascales.energy)
        _armature_tolerances(atol, rel, sl["armature"], ascales, rtol)
        atol[sl["quad"]] = rtol * cs.energy_scale
    # Quadrature of the impulse is in N s, not J: scale it by the reference momentum.
    quad0 = sl["quad"].start
    for i in range(rows):
        atol[quad0 + quadrature_rows(i)[2]] = rtol * cs.reference_mass * vstar
    max_step = 0.25 * cs.shortest_contact
    if scene.solver.max_step is not None:
        max_step = min(max_step, scene.solver.max_step)
    if arr is None:
        xc = np.zeros((2, 3))
        xc[:, 0] = basis.x_centre
        cpar = np.zeros((CONTACT_ROWS, N_CPAR))
        cpar[:, C_K] = cs.stiffness
        cpar[:, C_C] = cs.damping
        cpar[:, C_R] = scene.bar.tip_radius
        cpar[:, C_ON] = 1.0
        cpar[:, C_N] = 1.0  # the block: the plane z = 0 facing up
        parts = dict(points=(basis.psi_tip, basis.theta_tip, xc), cpar=cpar,
                     first_moments=np.zeros((3, 2 * n + 1)), load=np.zeros((0, N_LOAD)), tables=np.zeros((2, 1)))
    else:
        if scene.mount.kind == "pivot":
            _pivot_parameters(fpar, scene, arr.points[2])
        parts = dict(points=arr.points, mechanism=arr, first_moments=arr.first_moments, load=arr.load.copy(),
                     tables=arr.tables,
                     cpar=contact_parameters(arr.pairs, rows, scene.contact.stiffness, cs.dampings,
                                             _fixed_planes(scene, arr, planar)))
    names, cdrive = contact_drives(n_points, len(parts["cpar"]))
    if arm.present:
        names += (ARMATURE_DRIVE,)
        parts.update(apar=armature_parameters(arm),
                     again=gain_table(*(arm.force_gain[k] for k in ("position", "gain"))) if arm.force_gain
                     else gain_table(None, None))
    model = BarModel(scene, planar, basis, cs, fpar, ipar, math.radians(scene.initial.azimuth_deg), atol, rel,
                     max_step, sparse_invariants(basis), mode_count=mode_count, drive_names=names, cdrive=cdrive,
                     input_work=input_work, pairs=pairs, **parts)
    if arr is not None and (arr.spring_points or any(f.follows_travel for f in scene.forces)):
        # the springs' rest lengths (and where a force that follows its travel starts) are
        # measured on the initial state, which the other arrays define: a second, complete
        # model with them
        model = replace(model, load=_spring_rest_lengths(model))
    if arm.has_card:
        # so is the height of the bar's card point, which places the card
        card = int(model.ipar[I_ARM_CARD])
        model = replace(model, apar=armature_parameters(arm, _card_height(model), point_mobility(model, card)))
    return model


def _fixed_planes(scene: MechScene, arr: MechanismArrays, planar: bool):
    """(height m, normal) of each pair's fixed contact ([[fixed]]; None for [block]: z = 0
    facing up), placed in the initial pose as BarModel.initial_state places the bar."""
    if not scene.fixed:
        return None
    R0 = rotation_z(math.radians(scene.initial.azimuth_deg)) @ rotation_y(-math.radians(scene.initial.angle_deg))
    z0 = frame_height(scene, arr.points[2], arr.contacts, R0)
    return fixed_planes(arr.pairs, arr.points[2], R0, z0)


def point_mobility(model: "BarModel", p: int) -> float:
    """1/kg: how a point (row p of the model's points) of the bar at rest answers an impulse
    along world z, sum_j (Psi_j . z)^2 / m over the modes, with the rigid motions a free bar
    or a pivot allows (1/m and r^2/I about the centroid, r^2/I about the hinge)."""
    psi, _, xc = model.points
    b = model.basis
    mobility = float(np.sum(psi[p, :, 2] ** 2)) / b.mass if model.n else 0.0
    mount = int(model.ipar[I_MOUNT])
    if mount in (MOUNT_FREE, MOUNT_PIVOT):
        mobility += xc[p, 0] ** 2 / b.J0[1, 1]
    if mount == MOUNT_FREE:
        mobility += 1.0 / b.mass
    return mobility


def _armature_tolerances(atol: np.ndarray, rel: np.ndarray, where: slice, scales: "ArmatureScales",
                         rtol: float) -> None:
    """The armature's error scales: q absolutely, to rtol x the stops' penetration at the
    reference speed (so a stop's contact is resolved at either end of the travel, as the
    bar's positions are against the Hertz penetration); its speed to rtol x the reference
    speed and rtol x itself."""
    atol[where] = (rtol * scales.penetration, rtol * scales.speed)
    rel[where] = (0.0, 1.0)


def _card_height(model: "BarModel") -> float:
    """m: world z of the bar's card point in the model's initial state (modal deflection included)."""
    y = model.initial_state()
    sl = model.slices()
    psi, _, xc = model.points
    p = int(model.ipar[I_ARM_CARD])
    s_body = xc[p] + (psi[p].T @ y[sl["q"]] if model.n else 0.0)
    z0 = float(y[sl["pos"]][-1])
    return z0 + float(model.rotation(y)[2] @ s_body)


def armature_model(scene: MechScene) -> BarModel:
    """The model of an armature alone (no bar): the same kernel and solver with a bar-less
    model (kernel_layout MOUNT_NONE: no bar states, no contact point, the armature's two
    states and the quadratures). Its ContactScales are the armature's stops' (stiffness
    N/m or N m/rad, the reference speed, the stops' penetration and contact time, its
    energy scale); no step bound but solver.max_step (no contact point to step over: the
    events find the stops, the error control their stiffness)."""
    arm = scene.armature
    sc = armature_scales(arm)
    rtol = scene.solver.rtol
    basis = ModalBasis(families=(), orders=(), frequencies=np.zeros(0), mass=0.0, J0=np.zeros((3, 3)),
                       J1=np.zeros((0, 3, 3)), J2=np.zeros((0, 3, 3)), S=np.zeros((0, 0, 3)),
                       stiffness=np.zeros((0, 0)), damping=np.zeros((0, 0)), psi_tip=np.zeros((2, 0, 3)),
                       theta_tip=np.zeros((2, 0, 3)), x_centre=np.zeros(2))
    cs = ContactScales(stiffness=arm.stop_stiffness, damping=arm.stop_damping, beta=1.0, reference_speed=sc.speed,
                       reference_mass=arm.inertia_value, penetration_scale=sc.penetration,
                       shortest_contact=sc.contact_time, energy_scale=sc.energy, speed_bound=sc.speed)
    fpar = np.zeros(N_FPAR)
    fpar[F_VBOUND] = sc.speed
    fpar[F_VREG] = scene.solver.stick_velocity_tol
    fpar[F_BAUM] = 1.0 / sc.contact_time
    ipar = np.zeros(N_IPAR, dtype=np.int64)
    ipar[I_PLANAR] = 1
    ipar[I_FRICTION] = FRICTION_NONE
    ipar[I_INERTIA] = INERTIA_SPARSE
    ipar[I_MOUNT] = MOUNT_NONE
    ipar[I_ARMATURE] = 1
    ipar[I_ARM_DRIVE] = 0
    ipar[I_ARM_CARD] = -1
    ipar[I_ARM_NGAIN] = len(arm.force_gain["position"]) if arm.force_gain else 0
    sl = state_slices(0, True, NQ, True, False)
    atol = np.empty(N_ARM + NQ)
    rel = np.ones_like(atol)
    _armature_tolerances(atol, rel, sl["armature"], sc, rtol)
    atol[sl["quad"]] = rtol * sc.energy
    max_step = scene.solver.max_step if scene.solver.max_step is not None else math.inf
    again = (gain_table(arm.force_gain["position"], arm.force_gain["gain"]) if arm.force_gain
             else gain_table(None, None))
    return BarModel(scene, True, basis, cs, fpar, ipar, 0.0, atol, rel, max_step, sparse_invariants(basis),
                    points=(np.zeros((2, 0, 3)), np.zeros((2, 0, 3)), np.zeros((2, 3))),
                    cpar=np.zeros((CONTACT_ROWS, N_CPAR)),
                    first_moments=np.zeros((3, 1)), load=np.zeros((0, N_LOAD)), tables=np.zeros((2, 1)),
                    drive_names=(ARMATURE_DRIVE,), cdrive=np.full((2, len(CONTACT_DRIVES)), -1, dtype=np.int64),
                    apar=armature_parameters(arm), again=again)


# --- bar.modes = "auto" (issue 9): counts from the contact time -----------------------

def family_frequencies(bar, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Hz: the first ``count`` axial and bending frequencies of ``bar`` (bending in the
    more flexible plane). Euler-Bernoulli closed forms; for the paper's shear-type bending,
    sqrt(K_jj/m) of its stiffness on the free-free shapes (its K is full within a family)."""
    axial = axial_frequencies(count, bar.length, bar.youngs_modulus, bar.density)
    if bar.bending == "euler_bernoulli":
        bend = bending_frequencies(count, bar.length, bar.youngs_modulus, min(bar.second_moments),
                                   bar.area, bar.density)
    else:
        xi, w = _quadrature(400)
        k = np.array([np.sum(bar.shear_modulus / bar.poisson_ratio * bar.area
                             * (bending_shape(b, xi, 1) / bar.length) ** 2 * w * bar.length)
                      for b in free_free_roots(count)])
        bend = np.sqrt(k / bar.mass) / (2.0 * math.pi)
    return axial, bend


def resolve_auto_modes(scene: MechScene, safety: float | None = None, impact_speed: float | None = None):
    """(scene with explicit mode counts, ModeCount or None). "auto" counts are chosen by
    mech.mode_count.choose_mode_count from the Hertz contact time of the first impact
    (rigid-bar effective mass and impact speed of ``contact_scales``); safety: the
    factor of f_cut = safety / t_c (None: mode_count.SAFETY). impact_speed: m/s, an impact
    speed known better than the scene's estimate (a run's own largest, see
    refined_mode_count): t_c scales as v^(-1/5) on the same effective mass (Hertz)."""
    bar = scene.bar
    if bar.axial_modes != "auto" and bar.bending_modes != "auto":
        return scene, None
    factor = SAFETY if safety is None else safety
    if needs_mechanism(scene):
        mass, stiffness, speed = _mechanism_impact(scene)
        if impact_speed is not None:
            speed = impact_speed
        t_c = hertz_impact(mass, stiffness, speed).contact_time
        axial, bend = _mechanism_frequencies(scene, CAP, factor / t_c)
    else:
        cs = contact_scales(scene, 0)
        speed = cs.reference_speed if impact_speed is None else impact_speed
        t_c = hertz_impact(cs.reference_mass, cs.stiffness, speed).contact_time
        axial, bend = family_frequencies(bar, CAP)
    # a bar lying along the surface (a blade, a lever) is struck across its axis: the normal
    # gives its axial modes no force, so the floor does not raise them (mech/mode_count.py)
    unloaded = ("axial",) if abs(scene.initial.angle_deg) < 1e-9 else ()
    choice = choose_mode_count(axial, bend, t_c, impact_speed=speed,
                               safety=SAFETY if safety is None else safety, unloaded=unloaded)
    bar = dataclasses.replace(
        bar,
        axial_modes=choice.axial if bar.axial_modes == "auto" else bar.axial_modes,
        bending_modes=choice.bending if bar.bending_modes == "auto" else bar.bending_modes,
    )
    return dataclasses.replace(scene, bar=bar), choice


def _mechanism_impact(scene: MechScene) -> tuple[float, float, float]:
    """(effective mass kg, Hertz stiffness N/m^1.5, impact speed m/s) of a mechanism's first
    contact point's impact (mechanism_scales, from a small basis)."""
    bar = scene.bar
    small = dataclasses.replace(scene, bar=dataclasses.replace(bar, axial_modes=1, bending_modes=3))
    arr = build_arrays(small, True)
    cs = mechanism_scales(small, arr, arr.basis.n)
    return cs.reference_mass, cs.stiffness, cs.reference_speed


def _mechanism_frequencies(scene: MechScene, cap: int, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(axial Hz, bending Hz) of the bar as held (finite-element modes, rivets' masses on
    it; bending in its more flexible plane), every one below ``cutoff`` (Hz) at least."""
    beam = fe_beam(scene)
    i22, i33 = scene.bar.second_moments
    axial = frequencies_below(beam, "axial", cutoff, cap)
    bend = frequencies_below(beam, "bend3" if i22 <= i33 else "bend2", cutoff, cap)
    return axial, bend


def refined_mode_count(scene: MechScene, chosen, impact_speeds) -> object | None:
    """The "auto" count a run's own impacts ask for, or None when the chosen one holds.

    scene: the MechScene as written (its "auto" families); chosen: the ModeCount the run
    used (its estimate of the impact speed); impact_speeds: m/s, the normal speeds of the
    run's impacts. The fastest impact is the shortest (t_c ~ v^(-1/5)) and so sets the
    cutoff: where it was faster than the estimate and its count is larger in a family,
    the run under-resolved its own impacts (a driven blade arriving at a few tenths of a
    m/s where the estimate took a floor of 1 mm/s), and that count is returned."""
    speeds = np.abs(np.asarray(impact_speeds, dtype=float))
    speeds = speeds[np.isfinite(speeds)]
    if chosen is None or not len(speeds) or not float(speeds.max()) > chosen.impact_speed:
        return None
    # the cutoff at the fastest impact (t_c ~ v^(-1/5)) against the first mode left out of
    # each family: below both, the count holds (no eigen-solve needed to know it)
    cutoff = chosen.cutoff * (float(speeds.max()) / chosen.impact_speed) ** 0.2
    if cutoff < min(chosen.next_frequencies):
        return None
    _, refined = resolve_auto_modes(scene, safety=chosen.safety, impact_speed=float(speeds.max()))
    if refined is None or (refined.axial <= chosen.axial and refined.bending <= chosen.bending):
        return None
    return refined


def frequencies_below(beam, family: str, cutoff: float, cap: int, first: int = 8) -> np.ndarray:
    """Frequencies (Hz, ascending) of the lowest modes of ``family`` of a held bar (a
    mech.beam_fe.FEBeam), enough of them that the last lies at or above ``cutoff`` (Hz),
    or ``cap`` of them.

    Solved on the mesh the count needs (beam_fe.default_elements), not on the mesh of
    ``cap`` modes: a first solve of ``first`` modes, then, if needed, the count the
    family's growth of frequency with mode number (bending ~ (n + 1/2)^2, axial ~ n)
    predicts for the cutoff, with a fifth more. The highest mode of a solve is within
    about 4e-5 of its converged frequency (default_elements), so a count of modes below
    the cutoff differs from the finest mesh's only for a mode that close to the cutoff;
    the cap's mesh (255 elements, ~0.3 s of eigen-solves for a blade's two families)
    was most of the start of a held bar's run. The frequencies are the eigenvalues alone
    (beam_fe.beam_frequencies: no shapes, a third of the cost), which the shapes' Rayleigh
    quotients of beam_modes match to their round-off.
    """
    from .beam_fe import beam_frequencies  # (here: a held bar's alone, mech.mechanism.build_arrays)

    count = max(1, min(first, cap))
    while True:
        f = beam_frequencies(beam, family, count)
        if count >= cap or f[-1] >= cutoff:
            return f
        top = f[-1]
        if family == "axial":
            needed = count * cutoff / top
        else:
            needed = (count + 0.5) * math.sqrt(cutoff / top) - 0.5
        count = min(cap, max(count + 1, math.ceil(1.2 * needed) + 1))
