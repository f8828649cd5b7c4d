"""Indices and codes of the compiled kernel's arrays and state, readable without numba.

The compiled mechanics (mech.kernel, mech.integrator) and the Python around it (the
solver, the model builder, the results) share these numbers; keeping them in a module
that imports nothing lets the Python side run without loading the compiler.
"""

from __future__ import annotations


# fpar indices (F_K, F_C, F_RTIP: the first contact pair's values, kept for the scales;
# the kernel reads each contact pair's own from cpar, its fixed contact's plane too)
(F_MASS, F_G, F_K, F_C, F_BETA, F_GAMMA, F_MAX_RATIO, F_RTIP, F_VREG, F_BAUM,
 F_VBOUND, F_PIV_K, F_PIV_C, F_PIV_T0, F_PIV_PHI0, F_PIV_SIGN) = range(16)
N_FPAR = 16
# the armature's one-sided contacts (its rest stop, pole stop and card, EA_* below) that
# the solver has found closed at its events (1.0) or open (0.0), and whether it is seated:
# their forces act only while closed, so a step never integrates across the jump c v of a
# dashpot's force at touchdown (the solver's own array, beside the drive in the kernel's
# model tuple).
# the drive: what the caller changes during a run, passed beside the model's arrays (the
# last element of the kernel's model tuple) so that the model itself never changes. One
# row per named channel (mech.model.BarModel.drive_names), each linear in time within a
# step: its value at D_T0 (s), its slope (per s) and D_T0
D_VALUE, D_SLOPE, D_T0 = range(3)
N_DRIVE = 3
# what drives each contact point: the columns of the model's contact-drive index array
# (cdrive[i, K_MU] is the drive row of contact point i's friction coefficient, N^gamma;
# cdrive[i, K_REPULSION] of the force that pushes it away from the block while it touches,
# N), and the names of those channels ("mu.<i>", "repulsion.<i>"); the kernel reads the
# rows through cdrive only, never by name
K_MU, K_REPULSION = range(2)
CONTACT_DRIVES = ("mu", "repulsion")
# ipar indices; the armature's (mech/armature.py): 1 when the model has one, the drive
# row of "armature.force", the card's point row (in psi/theta/xc, after the loads; -1:
# no card), the number of knots of its gain table (0: gain 1)
I_N, I_PLANAR, I_FRICTION, I_MOUNT, I_NLOAD, I_INERTIA, I_ARMATURE, I_ARM_DRIVE, I_ARM_CARD, I_ARM_NGAIN = range(10)
N_IPAR = 10
# inertia route (mech/inertia.py): Gram products (analytic free-free basis) or sparse list
INERTIA_GRAM, INERTIA_SPARSE = 0, 1
FRICTION_NONE, FRICTION_EXACT, FRICTION_REGULARIZED = 0, 1, 2
# how the bar is held: free (6 rigid degrees of freedom), clamped at a base that moves
# with a piecewise-constant velocity (none), pivoted about body y (rotation only, planar);
# MOUNT_NONE: no bar at all, an armature alone (its state only)
MOUNT_FREE, MOUNT_CLAMP, MOUNT_PIVOT, MOUNT_NONE = 0, 1, 2, 3
# per contact pair (cpar rows: a contact point of the bar and the fixed contact it strikes;
# at least CONTACT_ROWS rows, the model's own pairs first, a row without a pair switched
# off): Hertz stiffness N/m^1.5, damping c, cap radius m, 1.0 when the pair exists, the
# world height of the fixed contact's surface m (the plane z = C_Z) and its normal, +1.0
# facing up (below the bar: the block) or -1.0 facing down (above it: the NC contact of a
# changeover), along which the point's penetration, the normal force and a repulsion act
C_K, C_C, C_R, C_ON, C_Z, C_N = range(6)
N_CPAR = 6
# contact rows of every model: a model of one pair (a single contact) carries a second,
# switched-off row, so that the one- and two-point models of before the pairs keep their
# arrays, events and state; beyond them a model has one row per pair, at most MAX_PAIRS
# (a changeover's NO and NC, a bridge's two points, the two of a double-break
# changeover): the stick constraint's matrix (2 per pair in 3D) stays small, and each
# pair adds NEV_TIP events and 3 quadratures
CONTACT_ROWS = 2
MAX_PAIRS = 4
# per load (rows of ``load``): actuator force (a time table of magnitude times a unit
# direction, world or body frame), linear spring-dashpot to a world anchor, or force-travel
# spring (a table of its push against its travel, L_T0/L_TN its columns in ``tabs``, after
# every force's time table; mech/travel_spring.py) with a dashpot, to a world anchor; with
# hysteresis also its release table (L_R0, same travels), the stick spring's stiffness L_KS
# (N/m), the floor of the band's half-width L_FLOOR (N) and its state, the stick force z
# (N), at y[len(y) - L_ZBACK] (the springs' states close the state vector, after the
# quadratures; L_ZBACK 0: none). An actuator force that follows its travel: its share
# table (travels m, shares 1) at L_S0 (L_SN points; 0: none) and its point's start along
# its world direction, d . x_P(0), at L_L0 (m; its travel is d . x_P - L_L0). A spring
# whose anchor end is on the armature: the lever L_ARM (m of the anchor's travel down,
# world -z, per unit of q; 0: on the frame) and q at the start L_Q0, its anchor at
# (L_AX, L_AY, L_AZ - L_ARM (q - L_Q0))
LOAD_FORCE, LOAD_SPRING, LOAD_TRAVEL_SPRING = 0, 1, 2
(L_KIND, L_POINT, L_BODY, L_DX, L_DY, L_DZ, L_T0, L_TN, L_AX, L_AY, L_AZ, L_K, L_C, L_L0,
 L_R0, L_KS, L_FLOOR, L_ZBACK, L_S0, L_SN, L_ARM, L_Q0) = range(22)
N_LOAD = 22
# the armature (mech/armature.py): a rigid body with one coordinate q (m or rad, the travel
# from its rest stop), its parameters in ``apar`` (SI: kg or kg m^2; m or rad; N/m or
# N m/rad; N or N m; N s/m or N m s/rad; the card's lever m per unit q, free travel m,
# stiffness N/m, damping N s/m, and the world height of the bar's card point at the
# start, m). Its two states (q, dq/dt) follow the bar's positions and speeds, before
# the quadratures. Gain table ``again`` (3, knots): positions, gains, PCHIP slopes.
(AP_MASS, AP_TRAVEL, AP_RATE, AP_PRELOAD, AP_STOP_K, AP_STOP_C, AP_DAMPING,
 AP_LEVER, AP_FREE, AP_CARD_K, AP_CARD_C, AP_CARD_Z0, AP_HMAX) = range(13)
N_APAR = 13  # AP_HMAX: s, the longest step while a stop or the card is closed (1 / their highest rate)
N_ARM = 2  # its states
# regimes of a tip
FREE, SLIP, STICK = 0, 1, 2
# quadratures: dissipations; per contact row i < 2, compression work at Q_WCOMP + 2i,
# restitution work at Q_WCOMP + 2i + 1, normal impulse at Q_IMPULSE + i; work put in by
# actuators and by a moving clamp (Q_WIN); dashpot dissipation of springs and pivot
# (Q_DLOAD) (the last two exist only in models with loads or a mount: NQ_FREE quadratures
# otherwise, so a plain free bar's state and error norm are what they were); rows i >= 2
# (models of more than two pairs) have their three after Q_DLOAD (quadrature_rows)
Q_DNORMAL, Q_DFRICTION, Q_DMODAL, Q_WCOMP, Q_IMPULSE, Q_WIN, Q_DLOAD = 0, 1, 2, 3, 7, 9, 10
NQ_FREE = 9
NQ = 11
NQ_PAIR = 3  # per contact row beyond the first two: compression work, restitution work, impulse
# aux columns per tip
A_Y, A_YDOT, A_FN, A_FTX, A_FTY, A_VTX, A_VTY, A_MARGIN = range(8)
NAUX = 8
# events per tip: contact (y), force clip, slip direction, stick margin, compression
# turn (dy/dt = 0: splits the normal work into compression and restitution exactly)
EV_CONTACT, EV_CLIP, EV_SLIP, EV_STICK, EV_COMPRESSION = range(5)
NEV_TIP = 5
# the armature's events, after the contact rows' (index rows x NEV_TIP + EA_*): the rest stop (q), the
# pole stop (travel - q) and the card (its gap to the bar), each positive while open; the
# turn (its speed, watched while a stop is closed and it is not seated) and the seat (the
# force pressing it onto the stop it is seated on, watched while seated). The same indices
# in the solver's array of the contacts' states (``aclosed``): 1.0 where the rest stop,
# pole stop, card is closed; at EA_SEAT, 1.0 while the armature is seated on its closed
# stop (held there, its stop's force the reaction; docs/mechanics.md, "The armature")
EA_REST, EA_POLE, EA_CARD, EA_TURN, EA_SEAT = range(5)
NEV_ARM = 5
# one more entry of that array, after the events' (``aclosed[BAR_HELD]``): 1.0 while the bar
# is held at its static equilibrium in flight, nothing touching it, while the armature moves
# (the kernel then gives the bar's positions and speeds zero rates; mech.solver, "held in
# flight"); N_ACLOSED: the array's length
BAR_HELD = NEV_ARM
N_ACLOSED = NEV_ARM + 1
NEV = CONTACT_ROWS * NEV_TIP + NEV_ARM  # events of a model of CONTACT_ROWS rows (event_count)


# what one call of the integrator ended with (mech.integrator.integrate)
DONE, EVENT, BUFFER_FULL, STEP_TOO_SMALL, NOT_FINITE, MAX_STEPS = range(6)
STATUS_TEXT = ("done", "event", "buffer full", "step size too small", "non-finite state", "too many steps")


def quadrature_rows(i: int) -> tuple[int, int, int]:
    """Offsets in the quadratures of contact row i's compression work, restitution work
    (J) and normal impulse (N s): Q_WCOMP + 2i, + 1 and Q_IMPULSE + i for the first two
    rows, NQ + NQ_PAIR (i - 2) + 0, 1, 2 beyond them."""
    if i < 2:
        return Q_WCOMP + 2 * i, Q_WCOMP + 2 * i + 1, Q_IMPULSE + i
    base = NQ + NQ_PAIR * (i - 2)
    return base, base + 1, base + 2


def event_count(rows: int) -> int:
    """Events of a model with ``rows`` contact rows: NEV_TIP per row, then the armature's
    (at rows x NEV_TIP + EA_*)."""
    return rows * NEV_TIP + NEV_ARM


def state_sizes(n: int, planar: bool) -> tuple[int, int]:
    """(position size, velocity size) of the bar's state for n modes (see mech.kernel's layout)."""
    if planar:
        return 3 + n, 3 + n
    return 7 + n, 6 + n


def armature_offset(n: int, planar: bool, mount: int) -> int:
    """Index of the armature's q in the state: after the bar's positions and speeds (0: no bar)."""
    if mount == MOUNT_NONE:
        return 0
    return 6 + 2 * n if planar else 13 + 2 * n  # (state_sizes, written out: compiled alone)
