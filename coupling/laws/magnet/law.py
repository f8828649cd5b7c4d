"""The magnet as a law between the circuit and the mechanics, in flux form.

The coil's flux linkage psi (Wb) is the circuit's state; the working air gap g (m) is the
mechanics'. Every magnet gives its coil current as a sum of separable terms

    i(psi, g) = sum_k w_k(g) a_k(psi),

each a_k odd and piecewise linear (or linear) in psi, so that i is explicit (no root
solve), ngspice evaluates the same sum from one expression, and the stored magnetic energy

    W(psi, g) = integral_0^psi i dpsi' = sum_k w_k(g) A_k(psi),   A_k = integral a_k,

is exact (piecewise quadratic in psi). The force closing the gap is its derivative at
constant flux linkage,

    F(psi, g) = dW/dg = sum_k w_k'(g) A_k(psi)   (N, >= 0 attracting),

so the energy balance v i = R i^2 + dW/dt + F (-dg/dt) holds identically: i dpsi + F dg is
the exact differential of W. In co-energy form, W'(i, g) = psi i - W and F = -dW'/dg at
constant current. At fixed g, i is piecewise linear and increasing in psi, so psi(i, g)
is its exact inverse.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from coupling.laws.magnet.bh_curves import MU0
from coupling.laws.magnet.pwl import Linear, OddPwl, merged, number, union
from coupling.laws.magnet.tubes import (
    FixedGap, PoleLeakage, WorkingGap, _Iron, pole_leakage_permeance, pole_leakage_permeance_slope,
    working_gap_permeance, working_gap_permeance_slope,
)
from coupling.laws.magnet.validation import check_instance, check_positive
from mech.validation import internal, scene_key
from mech.frozen import frozen


def _out(x):
    x = np.asarray(x, dtype=float)
    return float(x) if x.ndim == 0 else x


class Magnet:
    """What the coil block and the coupling call (SI; psi in Wb, g in m, i in A, F in N, W in J).

    Subclasses give ``terms`` (the a_k: psi -> A), ``weights(g)`` and ``weight_slopes(g)``
    (the w_k and dw_k/dg that are not zero at g, as (k, value) pairs) and
    ``weight_expressions(gap)`` (ngspice text of every w_k, None for a constant 1).
    """

    terms: tuple

    def weights(self, gap) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    def weight_slopes(self, gap) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    def weight_expressions(self, gap: str) -> list:  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def gap_range(self) -> tuple[float, float]:
        """(g_low, g_high), m: where the magnet's description holds; outside it the law is
        extended (held, or linearly: see the subclass), not invalid."""
        raise NotImplementedError  # pragma: no cover

    def current(self, psi, gap):
        """i(psi, g), A: the coil current at flux linkage psi (Wb) and working gap g (m);
        odd in psi. Arrays broadcast."""
        psi = np.asarray(psi, dtype=float)
        terms = self.terms
        return _out(sum(w * terms[k](psi) for k, w in self.weights(gap)) + 0.0 * psi)

    def energy(self, psi, gap):
        """W(psi, g) = integral_0^psi i dpsi' at constant g, J (>= 0, even in psi)."""
        psi = np.asarray(psi, dtype=float)
        terms = self.terms
        return _out(sum(w * terms[k].integral(psi) for k, w in self.weights(gap)) + 0.0 * psi)

    def force(self, psi, gap):
        """F(psi, g) = dW/dg at constant psi, N: the magnetic force on the armature that
        closes the gap (>= 0: attraction)."""
        psi = np.asarray(psi, dtype=float)
        terms = self.terms
        f = sum(s * terms[k].integral(psi) for k, s in self.weight_slopes(gap))
        return _out(f + 0.0 * psi + 0.0 * np.asarray(gap, dtype=float))

    def flux_linkage(self, current, gap):
        """psi(i, g), Wb: the inverse of ``current`` at fixed g (one root: i is increasing
        and piecewise linear in psi, so the root is explicit)."""
        i = np.asarray(current, dtype=float)
        g = np.asarray(gap, dtype=float)
        i, g = np.broadcast_arrays(i, g)
        shape = i.shape
        a, g = np.abs(i).ravel(), g.ravel()
        xs = self.breakpoints
        ys = np.asarray(self.current(xs[:, None], g[None, :]), dtype=float).reshape(xs.size, g.size)
        if np.any(np.diff(ys, axis=0) <= 0.0):
            bad = g[np.any(np.diff(ys, axis=0) <= 0.0, axis=0)][0]
            raise ValueError(f"flux_linkage: i(psi) is not increasing at g = {bad!r} m, outside the "
                             f"magnet's gap range {self.gap_range!r} m")
        k = np.clip((ys <= a[None, :]).sum(axis=0) - 1, 0, xs.size - 2)
        cols = np.arange(g.size)
        y0, y1 = ys[k, cols], ys[k + 1, cols]
        psi = xs[k] + (xs[k + 1] - xs[k]) * (a - y0) / (y1 - y0)
        return _out((np.sign(i.ravel()) * psi).reshape(shape))

    def coenergy(self, current, gap):
        """W'(i, g) = integral_0^i psi di' = psi i - W, J."""
        psi = self.flux_linkage(current, gap)
        return _out(psi * np.asarray(current, dtype=float) - self.energy(psi, gap))

    def force_at_current(self, current, gap):
        """F at coil current i (A) and gap g (m), N: F(psi(i, g), g) = -dW'/dg at constant i."""
        return self.force(self.flux_linkage(current, gap), gap)

    def inductance(self, gap):
        """L(g) = psi / i as i -> 0, H: the inductance of a linear magnet, the unsaturated
        (initial) inductance of a saturating one."""
        slope = sum(w * self.terms[k].initial_slope for k, w in self.weights(gap))
        return _out(1.0 / np.asarray(slope, dtype=float))

    @cached_property
    def breakpoints(self) -> np.ndarray:
        """The psi >= 0 (Wb) where some term's slope changes: i is linear in psi between them."""
        xs = union([t.xs for t in self.terms])
        return xs if xs.size >= 2 else np.array([0.0, 1.0])

    def current_expression(self, psi: str, gap: str) -> str:
        """i(psi, g) as ONE ngspice B-source expression of the expressions ``psi`` (Wb) and
        ``gap`` (m), e.g. ``current_expression("V(coil_psi)", "V(coil_gap)")``: only + - * /,
        ln, max and pwl; odd in psi and linear through psi = 0. It equals ``current`` to
        round-off (ngspice's pwl is evaluated as here). It begins with ``pwl(``: put it first
        on the B-source line (``I = <expression>``), since ngspice reads the numbers of a line
        that does not begin so to ~11 significant digits only (benchmarks/magnet_ngspice.py)."""
        parts = []
        for w, a in zip(self.weight_expressions(gap), self.terms):
            text = a.expression(psi)
            parts.append(text if w is None else f"{text}*({w})")
        return " + ".join(parts)


@frozen
class FluxTubeMagnet(Magnet):
    """A magnet drawn from flux tubes: the coil of ``turns`` N drives its flux through the
    ``iron`` tubes and the ``fixed_gap`` places in series with the ``working_gap`` and, in
    parallel with it, the ``pole_leakage`` (None: none). With Phi = psi / N,

        N i = sum_iron l H(Phi / A) + Phi R_fixed + Phi / (G_w(g) + G_l(g)).

    The gap g is held at ``working_gap.minimum`` below it (force 0 there)."""

    # the fields a [magnet] with model = "flux_tubes" sets (docs/scene_keys.md; turns is coil.turns)
    turns: float = internal()
    working_gap: WorkingGap = scene_key(unit="-", shown="-", doc="flux_tubes: `{area, minimum}` (m^2, m)")
    iron: tuple = scene_key((), unit="-", shown="-",
                            doc="flux_tubes: `[[magnet.iron]]` tubes, each a shape with its material")
    fixed_gap: tuple = scene_key(
        (), unit="-", shown="-", doc="flux_tubes: `[[magnet.fixed_gap]]`, each with `[[magnet.fixed_gap.tube]]` in parallel")
    pole_leakage: PoleLeakage | None = scene_key(
        None, unit="-", doc="flux_tubes: `{width, radius}` (m); omitted: no leakage")
    name: str = internal("magnet")

    def __post_init__(self):
        n = self.name
        check_positive(f"{n}.turns", self.turns)
        check_instance(f"{n}.working_gap", self.working_gap, WorkingGap, "a WorkingGap")
        for key, classes, what in (("iron", _Iron, "iron tubes (IronPath, AxialIron, RadialIron)"),
                                   ("fixed_gap", FixedGap, "FixedGap entries")):
            value = getattr(self, key)
            if isinstance(value, (str, dict)) or not hasattr(value, "__iter__"):
                raise ValueError(f"{n}.{key}: expected a list of {what}")
            items = tuple(value)
            for k, item in enumerate(items):
                check_instance(f"{n}.{key}[{k}]", item, classes, what)
            object.__setattr__(self, key, items)
        if self.pole_leakage is not None:
            check_instance(f"{n}.pole_leakage", self.pole_leakage, PoleLeakage, "a PoleLeakage or none")

    @cached_property
    def terms(self) -> tuple:
        """(a_0, a_1): a_0(psi) = [sum_iron l H(psi / (N A)) + psi R_fixed / N] / N, the iron
        and the fixed gaps merged into one function; a_1(psi) = psi / N^2, weighted by the
        reluctance of the working gap and the leakage in parallel."""
        nt = float(self.turns)
        fixed = sum(gap.reluctance for gap in self.fixed_gap) / (nt * nt)
        tubes = [tube.current_term(nt) for tube in self.iron]
        slope = fixed + sum(t.slope for t in tubes if isinstance(t, Linear))
        pwls = [t for t in tubes if isinstance(t, OddPwl)]
        iron = merged(pwls + [Linear(slope)]) if pwls else Linear(slope)
        return (iron, Linear(1.0 / (nt * nt)))

    @property
    def gap_range(self) -> tuple[float, float]:
        return (self.working_gap.minimum, float("inf"))

    def _gap(self, gap):
        return np.maximum(np.asarray(gap, dtype=float), self.working_gap.minimum)

    def gap_permeance(self, gap):
        """G_w(g) + G_l(g), H: the working gap and the leakage around the poles."""
        g = self._gap(gap)
        perm = working_gap_permeance(self.working_gap.area, g)
        if self.pole_leakage is not None:
            perm = perm + pole_leakage_permeance(self.pole_leakage.width, self.pole_leakage.radius, g)
        return perm

    def weights(self, gap) -> list:
        return [(0, 1.0), (1, 1.0 / self.gap_permeance(gap))]

    def weight_slopes(self, gap) -> list:
        g = np.asarray(gap, dtype=float)
        gc = self._gap(g)
        slope = working_gap_permeance_slope(self.working_gap.area, gc)
        if self.pole_leakage is not None:
            slope = slope + pole_leakage_permeance_slope(self.pole_leakage.width, self.pole_leakage.radius, gc)
        perm = self.gap_permeance(gc)
        return [(1, np.where(g > self.working_gap.minimum, -slope / (perm * perm), 0.0))]

    def weight_expressions(self, gap: str) -> list:
        g = f"max(({gap}), {number(self.working_gap.minimum)})"
        perm = f"{number(self.working_gap.area * MU0)}/{g}"
        if self.pole_leakage is not None:
            lk = self.pole_leakage
            perm += f" + {number(MU0 * lk.width / np.pi)}*ln(1 + {number(np.pi * lk.radius)}/{g})"
        return [None, f"1/({perm})"]

    def reluctance(self, gap):
        """The whole path's reluctance at B -> 0, A/Wb: N^2 / L(g)."""
        return _out(self.turns ** 2 / np.asarray(self.inductance(gap), dtype=float))
