"""Indices and codes of the compiled kernel's arrays and state, readable without numba.

The compiled mechanics (mech.kernel, mech.integrator) and the Python around it (the
solver, the model builder, the results) share these numbers; keeping them in a module
that imports nothing lets the Python side run without loading the compiler.
"""

from __future__ import annotations


# fpar indices (F_K, F_C, F_RTIP: the first contact point's values, kept for the scales;
# the kernel reads each contact point's own from cpar)
(F_MASS, F_G, F_K, F_C, F_BETA, F_GAMMA, F_MAX_RATIO, F_RTIP, F_VREG, F_BAUM,
 F_VBOUND, F_BLOCK_Z, F_PIV_K, F_PIV_C, F_PIV_T0, F_PIV_PHI0, F_PIV_SIGN) = range(17)
N_FPAR = 17
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
# ipar indices
I_N, I_PLANAR, I_FRICTION, I_MOUNT, I_NLOAD, I_INERTIA = range(6)
N_IPAR = 6
# inertia route (mech/inertia.py): Gram products (analytic free-free basis) or sparse list
INERTIA_GRAM, INERTIA_SPARSE = 0, 1
FRICTION_NONE, FRICTION_EXACT, FRICTION_REGULARIZED = 0, 1, 2
# how the bar is held: free (6 rigid degrees of freedom), clamped at a base that moves
# with a piecewise-constant velocity (none), pivoted about body y (rotation only, planar)
MOUNT_FREE, MOUNT_CLAMP, MOUNT_PIVOT = 0, 1, 2
# per contact point (cpar rows 0, 1): Hertz stiffness N/m^1.5, damping c, cap radius m,
# 1.0 when the point exists
C_K, C_C, C_R, C_ON = range(4)
# per load (rows of ``load``): actuator force (a time table of magnitude times a unit
# direction, world or body frame) or linear spring-dashpot to a world anchor
LOAD_FORCE, LOAD_SPRING = 0, 1
(L_KIND, L_POINT, L_BODY, L_DX, L_DY, L_DZ, L_T0, L_TN, L_AX, L_AY, L_AZ, L_K, L_C, L_L0) = range(14)
N_LOAD = 14
# regimes of a tip
FREE, SLIP, STICK = 0, 1, 2
# quadratures: dissipations; per tip i, compression work at Q_WCOMP + 2i, restitution
# work at Q_WCOMP + 2i + 1, normal impulse at Q_IMPULSE + i; work put in by actuators
# and by a moving clamp (Q_WIN); dashpot dissipation of springs and pivot (Q_DLOAD)
# (the last two exist only in models with loads or a mount: NQ_FREE quadratures otherwise,
# so a plain free bar's state and error norm are what they were)
Q_DNORMAL, Q_DFRICTION, Q_DMODAL, Q_WCOMP, Q_IMPULSE, Q_WIN, Q_DLOAD = 0, 1, 2, 3, 7, 9, 10
NQ_FREE = 9
NQ = 11
# aux columns per tip
A_Y, A_YDOT, A_FN, A_FTX, A_FTY, A_VTX, A_VTY, A_MARGIN = range(8)
NAUX = 8
# events per tip: contact (y), force clip, slip direction, stick margin, compression
# turn (dy/dt = 0: splits the normal work into compression and restitution exactly)
EV_CONTACT, EV_CLIP, EV_SLIP, EV_STICK, EV_COMPRESSION = range(5)
NEV_TIP = 5


# what one call of the integrator ended with (mech.integrator.integrate)
DONE, EVENT, BUFFER_FULL, STEP_TOO_SMALL, NOT_FINITE, MAX_STEPS = range(6)
STATUS_TEXT = ("done", "event", "buffer full", "step size too small", "non-finite state", "too many steps")


def state_sizes(n: int, planar: bool) -> tuple[int, int]:
    """(position size, velocity size) of the state for n modes (see mech.kernel's layout)."""
    if planar:
        return 3 + n, 3 + n
    return 7 + n, 6 + n
