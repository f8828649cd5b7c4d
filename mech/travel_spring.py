"""The force-travel spring's laws: its push and stored energy from a table of force against travel.

Pure functions (SI units: travel m, force N, energy J) that import nothing of mech and
call nothing but each other's arithmetic (the kernel, mech.kernel, compiles each alone).
The table is stored as tabs[0, start:start + count] (travels, strictly increasing, >= 2
points) and tabs[1, ...] (forces): linear between its points and, beyond its ends, along
its end segments (so a straight-line table is a linear spring at every travel, and the
force stays continuous wherever the bar goes). The spring's stored energy at travel x is
travel_work(x) - travel_work(0): the work of pressing it from its rest length.
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
