"""A magnet given as tables psi(i_j, g_k) and F(i_j, g_k), the form an FEA tool or a
measurement gives, checked on load and turned into the flux-form law of law.py.

At each tabulated gap g_k the coil current is the inverse of the tabulated psi(i):
a_k(psi), piecewise linear through the points (psi_jk, i_j) and odd (no remanence, no
hysteresis). Between the gaps the current is interpolated linearly,

    i(psi, g) = (1 - t) a_k(psi) + t a_{k+1}(psi),   t = (g - g_k) / (g_{k+1} - g_k),

(hat functions of g; linear extrapolation outside the gap range), so the stored energy is
W = (1 - t) W_k(psi) + t W_{k+1}(psi) with W_k the exact integral of a_k, and the force is
its derivative F = (W_{k+1}(psi) - W_k(psi)) / (g_{k+1} - g_k): constant in g between
tabulated gaps at constant psi (exactly so for an ideal air gap, whose force at constant
flux does not depend on g). The force table is not interpolated: it checks the flux
table. Both come from one co-energy, W'(i, g) = integral_0^i psi di, so from the smallest
gap g_0 to every other g_k the drop of W' at constant current must equal the work of the
tabulated force, integral F dg; the work is summed over the intervals by the rule exact
for power laws F = c g^-p between two neighbouring gaps (1/g^2 for an ideal gap, g^0 once
the iron saturates). A table fails on load when the mismatch exceeds ``force_tolerance``
times the co-energy drop over the whole gap range at that current.
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from coupling.laws.magnet.law import Magnet
from coupling.laws.magnet.pwl import OddPwl, number
from coupling.laws.magnet.validation import check_finite, check_increasing, check_numbers, check_positive
from mech.validation import internal, scene_key
from mech.frozen import frozen


def power_law_work(gap0: float, gap1: float, force0: float, force1: float) -> float:
    """The integral of F dg from g0 to g1 for F = c g^-p through (g0, F0) and (g1, F1), J;
    the trapezoid when either force is not positive (no power law through it)."""
    if force0 <= 0.0 or force1 <= 0.0:
        return 0.5 * (force0 + force1) * (gap1 - gap0)
    ratio = math.log(gap1 / gap0)
    q = 1.0 + math.log(force1 / force0) / ratio  # 1 - p
    if abs(q * ratio) < 1e-6:  # F ~ 1/g: the integral is F0 g0 ln(g1 / g0)
        return force0 * gap0 * ratio * (1.0 + 0.5 * q * ratio)
    return (force1 * gap1 - force0 * gap0) / q


def table_consistency(currents, gaps, flux_linkages, forces):
    """How far the force table is from -dW'/dg of the flux table: for each current i_j > 0,
    the drop of the co-energy W'(i_j, g) from the smallest gap g_0 to each g_k against the
    work of the tabulated force from g_0 to g_k, their difference over the drop across the
    whole gap range. Returns (worst mismatch, j, k, drop, work) there; (0, 0, 0, 0, 0) for a
    table without a current > 0."""
    i = np.asarray(currents, dtype=float)
    g = np.asarray(gaps, dtype=float)
    psi = np.asarray(flux_linkages, dtype=float)
    f = np.asarray(forces, dtype=float)
    # W'(i_j, g_k): the trapezoid is exact for psi(i) piecewise linear, as the law has it
    coenergy = np.concatenate((np.zeros((1, g.size)),
                               np.cumsum(np.diff(i)[:, None] * (psi[1:] + psi[:-1]) / 2.0, axis=0)))
    worst = (0.0, 0, 0, 0.0, 0.0)
    for j in range(1, i.size):
        drops = coenergy[j, 0] - coenergy[j, 1:]
        works = np.cumsum([power_law_work(g[k], g[k + 1], f[j, k], f[j, k + 1]) for k in range(g.size - 1)])
        scale = max(abs(drops[-1]), abs(works[-1]))
        if scale == 0.0:
            continue
        mismatch = np.abs(drops - works) / scale
        k = int(np.argmax(mismatch))
        if mismatch[k] > worst[0]:
            worst = (float(mismatch[k]), j, k + 1, float(drops[k]), float(works[k]))
    return worst


@frozen
class TableMagnet(Magnet):
    """A magnet from tables: ``currents`` i_j (A, from 0, increasing strictly), ``gaps`` g_k
    (m, > 0, increasing strictly), ``flux_linkages`` psi(i_j, g_k) (Wb) and ``forces``
    F(i_j, g_k) (N, >= 0 closing the gap), each a list of rows, one row per current, one
    column per gap. psi is 0 at 0 A, increases strictly with the current and does not grow
    as the gap opens. ``force_tolerance``: the allowed mismatch between the force table and
    the flux table's co-energy (module docstring), a fraction."""

    # the fields a [magnet] with model = "table" sets (docs/scene_keys.md)
    currents: tuple = scene_key(unit="A", shown="-", doc="table: the current grid")
    gaps: tuple = scene_key(unit="m", shown="-", doc="table: the gap grid")
    flux_linkages: tuple = scene_key(unit="Wb", shown="-", doc="table: psi, one row per current")
    forces: tuple = scene_key(unit="N", shown="-", doc="table: F closing the gap, one row per current")
    force_tolerance: float = scene_key(0.05, unit="-", doc="table: allowed mismatch of F against dW'/dg, checked on load")
    name: str = internal("magnet")

    def __post_init__(self):
        n = self.name
        i = check_numbers(f"{n}.currents", self.currents, "A")
        g = check_numbers(f"{n}.gaps", self.gaps, "m")
        if len(i) < 2:
            raise ValueError(f"{n}.currents: {len(i)} current(s); give at least 2, the first 0 A")
        if i[0] != 0.0:
            raise ValueError(f"{n}.currents[0] = {i[0]!r}: the table must start at 0 A, where the flux "
                             "linkage is 0 (no permanent magnet)")
        check_increasing(f"{n}.currents", i, "A")
        if len(g) < 2:
            raise ValueError(f"{n}.gaps: {len(g)} gap(s); give at least 2 (the force needs the change with the gap)")
        check_positive(f"{n}.gaps[0]", g[0], "m")
        check_increasing(f"{n}.gaps", g, "m")
        psi = self._grid("flux_linkages", self.flux_linkages, len(i), len(g), "Wb")
        f = self._grid("forces", self.forces, len(i), len(g), "N")
        tol = check_finite(f"{n}.force_tolerance", self.force_tolerance)
        if not 0.0 < tol < 1.0:
            raise ValueError(f"{n}.force_tolerance = {tol!r}: allowed range is (0, 1) (a fraction of the "
                             "co-energy change)")
        for k in range(len(g)):
            if psi[0][k] != 0.0:
                raise ValueError(f"{n}.flux_linkages[0][{k}] = {psi[0][k]!r}: the flux linkage at 0 A must be 0 "
                                 "(remanence and permanent magnets are not modelled)")
            for j in range(1, len(i)):
                if psi[j][k] <= psi[j - 1][k]:
                    raise ValueError(f"{n}.flux_linkages[{j}][{k}] = {psi[j][k]!r}: the flux linkage must increase "
                                     f"strictly with the current (at {i[j - 1]!r} A it is {psi[j - 1][k]!r} Wb; "
                                     f"gap {g[k]!r} m)")
        slack = 1e-9 * max(abs(v) for row in psi for v in row)
        for j in range(1, len(i)):
            for k in range(1, len(g)):
                if psi[j][k] > psi[j][k - 1] + slack:
                    raise ValueError(f"{n}.flux_linkages[{j}][{k}] = {psi[j][k]!r}: the flux linkage must not grow "
                                     f"as the gap opens (at {g[k - 1]!r} m it is {psi[j][k - 1]!r} Wb; current "
                                     f"{i[j]!r} A); are the gaps the armature's travel instead of the air gap?")
        f_scale = max(abs(v) for row in f for v in row)
        for j in range(len(i)):
            for k in range(len(g)):
                if f[j][k] < -tol * f_scale:
                    raise ValueError(f"{n}.forces[{j}][{k}] = {f[j][k]!r}: the force closing the gap must be >= 0 "
                                     "(a table with the opposite sign convention: negate it)")
        for key, value in (("currents", i), ("gaps", g), ("flux_linkages", psi), ("forces", f)):
            object.__setattr__(self, key, value)
        worst, j, k, drop, work = table_consistency(i, g, psi, f)
        if worst > tol:
            raise ValueError(f"{n}.forces: inconsistent with {n}.flux_linkages at {i[j]!r} A from gap {g[0]!r} "
                             f"to {g[k]!r} m: the co-energy W' drops by {drop:.4g} J, the force table's work "
                             f"is {work:.4g} J; the mismatch is {worst:.3g} of the drop over the gap range, "
                             f"allowed {tol!r} ({n}.force_tolerance; F must be -dW'/dg at constant current, "
                             "W' = integral of psi di; a finer gap grid where F changes fast brings "
                             "consistent tables within it)")

    def _grid(self, key: str, rows, n_i: int, n_g: int, unit: str) -> tuple:
        where = f"{self.name}.{key}"
        if isinstance(rows, (str, dict)) or not hasattr(rows, "__iter__"):
            raise ValueError(f"{where}: expected a list of rows, one per current, each with one value per gap ({unit})")
        rows = list(rows)
        if len(rows) != n_i:
            raise ValueError(f"{where}: {len(rows)} rows for {n_i} currents; give one row per current")
        out = []
        for j, row in enumerate(rows):
            values = check_numbers(f"{where}[{j}]", row, unit)
            if len(values) != n_g:
                raise ValueError(f"{where}[{j}]: {len(values)} values for {n_g} gaps; give one value per gap")
            out.append(values)
        return tuple(out)

    @cached_property
    def terms(self) -> tuple:
        """a_k(psi), one per tabulated gap: the inverse of psi(i, g_k), piecewise linear."""
        psi = np.asarray(self.flux_linkages)
        i = np.asarray(self.currents)
        return tuple(OddPwl(psi[:, k], i) for k in range(len(self.gaps)))

    @property
    def gap_range(self) -> tuple[float, float]:
        return (self.gaps[0], self.gaps[-1])

    def _interval(self, gap):
        gaps = np.asarray(self.gaps)
        g = np.asarray(gap, dtype=float)
        k = np.clip(np.searchsorted(gaps, g, side="right") - 1, 0, gaps.size - 2)
        return g, k, gaps[k], gaps[k + 1]

    def weights(self, gap) -> list:
        g, k, g0, g1 = self._interval(gap)
        t = (g - g0) / (g1 - g0)
        if g.ndim == 0:  # one gap (the coupling's calls): the two hats that are not zero
            return [(int(k), 1.0 - t), (int(k) + 1, t)]
        return [(m, np.where(k == m, 1.0 - t, 0.0) + np.where(k + 1 == m, t, 0.0)) for m in range(len(self.gaps))]

    def weight_slopes(self, gap) -> list:
        g, k, g0, g1 = self._interval(gap)
        s = 1.0 / (g1 - g0)
        if g.ndim == 0:
            return [(int(k), -s), (int(k) + 1, s)]
        return [(m, np.where(k == m, -s, 0.0) + np.where(k + 1 == m, s, 0.0)) for m in range(len(self.gaps))]

    def weight_expressions(self, gap: str) -> list:
        # hat m through (g_m, 1) and (g_m+-1, 0), flat 0 from g_m+-2 on, where those exist: outside
        # the gap range the two end hats then extend linearly, as ``weights`` does
        out = []
        n = len(self.gaps)
        for m in range(n):
            pts = [(self.gaps[j], 1.0 if j == m else 0.0) for j in range(max(0, m - 2), min(n, m + 3))]
            out.append(f"pwl(({gap}), " + ", ".join(f"{number(x)},{number(y)}" for x, y in pts) + ")")
        return out

    @classmethod
    def from_magnet(cls, magnet: Magnet, currents, gaps, **kw) -> TableMagnet:
        """The tables of another magnet at the currents (A) and gaps (m) given."""
        psi, force = tabulate(magnet, currents, gaps)
        return cls(tuple(currents), tuple(gaps), tuple(map(tuple, psi)), tuple(map(tuple, force)), **kw)


def tabulate(magnet: Magnet, currents, gaps) -> tuple[np.ndarray, np.ndarray]:
    """psi(i_j, g_k) (Wb) and F(i_j, g_k) (N) of ``magnet``: rows per current, columns per gap."""
    i, g = np.meshgrid(np.asarray(currents, dtype=float), np.asarray(gaps, dtype=float), indexing="ij")
    psi = np.asarray(magnet.flux_linkage(i, g))
    return psi, np.asarray(magnet.force(psi, g))
