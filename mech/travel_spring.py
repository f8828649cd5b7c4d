"""The force-travel spring's laws: its push and stored energy from a table of force against travel.

Pure functions (SI units: travel m, force N, energy J) that import nothing of mech and
call nothing but each other's arithmetic (the kernel, mech.kernel, compiles each alone).
The table is stored as tabs[0, start:start + count] (travels, strictly increasing, >= 2
points) and tabs[1, ...] (forces): linear between its points and, beyond its ends, along
its end segments (so a straight-line table is a linear spring at every travel, and the
force stays continuous wherever the bar goes). The spring's stored energy at travel x is
travel_work(x) - travel_work(0): the work of pressing it from its rest length.

With hysteresis (a press and a release table on the same travels) the push is the
branches' mean plus a stick force z (N, a state), a smooth Jenkins element of the Bouc-Wen
kind: z follows the travel x elastically, dz/dt = k_s dx/dt, while it moves back into the
band |z| <= F_h(x) (half the gap between the branches), and is drawn onto the band's edge
while it moves out, dz/dt = k_s dx/dt (1 - (z / F_h)^2), so that a press follows the press
branch (z -> +F_h) and a release the release branch (z -> -F_h) past a turn of 2 F_h / k_s.
It stores z^2 / (2 k_s) and dissipates z (dx/dt - dz/dt / k_s) >= 0, exactly what the
force's power leaves over: the energy audit closes by construction.
"""

from __future__ import annotations


def travel_force(x: float, tabs, start: int, count: int) -> float:
    """N: the spring's push away from its anchor at travel x (m, its compression from the
    rest length, positive shorter), on the line of the table's segment holding x (the end
    segments beyond the ends)."""
    lo = start
    hi = start + count - 1
    if x <= tabs[0, lo + 1]:
        hi = lo + 1
    elif x >= tabs[0, hi - 1]:
        lo = hi - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if tabs[0, mid] <= x:
            lo = mid
        else:
            hi = mid
    slope = (tabs[1, hi] - tabs[1, lo]) / (tabs[0, hi] - tabs[0, lo])
    return tabs[1, lo] + slope * (x - tabs[0, lo])


def travel_work(x: float, tabs, start: int, count: int) -> float:
    """J: the integral of travel_force from the table's first travel to x (negative below
    it): the whole segments before x's by trapezoids, then the part of x's segment."""
    lo = start
    hi = start + count - 1
    if x <= tabs[0, lo + 1]:
        hi = lo + 1
    elif x >= tabs[0, hi - 1]:
        lo = hi - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if tabs[0, mid] <= x:
            lo = mid
        else:
            hi = mid
    acc = 0.0
    for j in range(start, lo):
        acc += 0.5 * (tabs[0, j + 1] - tabs[0, j]) * (tabs[1, j] + tabs[1, j + 1])
    slope = (tabs[1, hi] - tabs[1, lo]) / (tabs[0, hi] - tabs[0, lo])
    d = x - tabs[0, lo]
    return acc + d * (tabs[1, lo] + 0.5 * slope * d)


def stick_rate(z: float, rate: float, half: float, floor: float, ks: float) -> float:
    """N/s: the stick force's rate dz/dt for the travel's rate ``rate`` (m/s), the band's
    half-width ``half`` (N, raised to ``floor`` where the branches meet: the element's
    stiffness k_s / F_h stays bounded) and the stick spring's stiffness ``ks`` (N/m)."""
    if rate * z > 0.0:
        band = half if half > floor else floor
        u = z / band
        return ks * rate * (1.0 - u * u)
    return ks * rate
