"""The table route: a magnet given as psi(i, g) and F(i, g) reproduces an analytic magnet
within the interpolation error it claims (exactly for an ideal gap, whose reluctance is
linear in g; second order in the gap step for the current, first order for the force),
and a force table that does not come from the flux table's co-energy is refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.laws.magnet.bh_curves import MU0, LinearMaterial
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.solenoid import plunger_solenoid
from coupling.laws.magnet.table import TableMagnet, power_law_work, tabulate
from coupling.laws.magnet.tubes import IronPath, PoleLeakage, WorkingGap

N, AREA, L_IRON, MU_R = 300, 1e-4, 0.05, 1000.0
W_LEAK, R_LEAK = 0.04, 3e-3
IRON = (IronPath(L_IRON, AREA, LinearMaterial(MU_R)),)


def _leaky():
    return FluxTubeMagnet(N, WorkingGap(AREA), iron=IRON, pole_leakage=PoleLeakage(W_LEAK, R_LEAK))


def _rw_second_derivative(g):
    """d^2/dg^2 of 1/G(g), G = mu0 A / g + (mu0 w / pi) ln(1 + pi r / g), in closed form."""
    a, c = MU0 * AREA, MU0 * W_LEAK / math.pi
    s = math.pi * R_LEAK
    G = a / g + c * np.log1p(s / g)
    dG = -a / g ** 2 - c * s / (g * (g + s))
    d2G = 2 * a / g ** 3 + c * s * (2 * g + s) / (g * (g + s)) ** 2
    return (2 * dG ** 2 - G * d2G) / G ** 3


def _off_grid(magnet, table, currents=(0.3, 1.0, 2.5), t=0.37):
    gaps = np.asarray(table.gaps)
    g = gaps[:-1] + t * np.diff(gaps)
    i, g = np.meshgrid(np.asarray(currents), g)
    return magnet.flux_linkage(i, g), g


def test_ideal_gap_magnet_is_reproduced_exactly():
    # no leakage: the reluctance l/(mu0 mu_r A) + g/(mu0 A) is linear in g and i linear in psi,
    # so the table's linear interpolation in g and in psi is exact: round-off only
    magnet = FluxTubeMagnet(N, WorkingGap(AREA), iron=IRON)
    table = TableMagnet.from_magnet(magnet, np.linspace(0, 3, 4), np.geomspace(0.2e-3, 5e-3, 5))
    psi, g = _off_grid(magnet, table)
    psi = np.concatenate((psi, 2.0 * psi))  # beyond the tabulated currents too
    g = np.concatenate((g, g))
    assert np.allclose(table.current(psi, g), magnet.current(psi, g), rtol=1e-12, atol=0)
    assert np.allclose(table.force(psi, g), magnet.force(psi, g), rtol=1e-12, atol=0)
    assert np.allclose(table.energy(psi, g), magnet.energy(psi, g), rtol=1e-12, atol=0)


def test_leaky_magnet_within_the_interpolation_bounds():
    # at constant psi the model's current is linear in g between tabulated gaps and its force
    # the secant slope of W: |i - i_exact| <= (psi / N^2) h^2/8 max|R''|,
    # |F - F_exact| <= psi^2 / (2 N^2) h max|R''| over the interval, R(g) = 1 / G(g) the
    # reluctance of the gap and its leakage (closed form above)
    magnet = _leaky()
    gaps = np.geomspace(0.25e-3, 5e-3, 9)
    table = TableMagnet.from_magnet(magnet, np.linspace(0, 3, 7), gaps)
    for t in (0.1, 0.37, 0.5, 0.9):
        psi, g = _off_grid(magnet, table, t=t)
        k = np.arange(gaps.size - 1)[:, None] * np.ones_like(g, dtype=int)
        h = np.diff(gaps)[k]
        r2 = np.array([np.max(np.abs(_rw_second_derivative(np.linspace(gaps[j], gaps[j + 1], 200))))
                       for j in range(gaps.size - 1)])[k]
        bound_i = psi / N ** 2 * h ** 2 / 8 * r2
        bound_f = psi ** 2 / (2 * N ** 2) * h * r2
        err_i = np.abs(table.current(psi, g) - magnet.current(psi, g))
        err_f = np.abs(table.force(psi, g) - magnet.force(psi, g))
        assert np.all(err_i <= 1.001 * bound_i)
        assert np.all(err_f <= 1.001 * bound_f)
        assert np.max(err_i / bound_i) > 0.05  # the bound is not vacuous


def _errors(magnet, n):
    gaps = np.geomspace(0.25e-3, 5e-3, n + 1)
    table = TableMagnet.from_magnet(magnet, np.linspace(0, 3, 2 * n + 1), gaps, force_tolerance=0.5)
    psi, g = _off_grid(magnet, table, currents=(0.5, 1.0, 2.0), t=0.25)
    i, f = magnet.current(psi, g), magnet.force(psi, g)
    return (np.max(np.abs(table.current(psi, g) - i) / i), np.max(np.abs(table.force(psi, g) - f) / f))


def test_orders_of_the_gap_interpolation():
    # geometric gap grids refined by 2: the current's error falls 4x (linear interpolation),
    # the force's 2x (the secant slope of W at a quarter of the interval)
    magnet = _leaky()
    e8, e16, e32 = _errors(magnet, 8), _errors(magnet, 16), _errors(magnet, 32)
    for coarse, fine in ((e8, e16), (e16, e32)):
        assert math.log2(coarse[0] / fine[0]) == pytest.approx(2.0, abs=0.15)
        assert math.log2(coarse[1] / fine[1]) == pytest.approx(1.0, abs=0.15)


def test_saturating_solenoid_table_converges():
    # the plunger solenoid saturates (piecewise-linear B-H curve, its kinks smoothed by the
    # table's coarser psi points): refining both grids 4x still gains at least half of the
    # asymptotic 16x (current) and 4x (force)
    magnet = plunger_solenoid().magnet
    e8, e32 = _errors(magnet, 8), _errors(magnet, 32)
    assert e8[0] / e32[0] > 8.0
    assert e8[1] / e32[1] > 2.0


@pytest.mark.parametrize("p", [0.0, 0.5, 1.0, 2.0, 3.2, -1.0])
def test_power_law_work_is_exact_for_power_laws(p):
    c, g0, g1 = 2.5e-6, 0.3e-3, 0.9e-3
    exact = c * (math.log(g1 / g0) if p == 1.0 else (g1 ** (1 - p) - g0 ** (1 - p)) / (1 - p))
    assert power_law_work(g0, g1, c * g0 ** -p, c * g1 ** -p) == pytest.approx(exact, rel=1e-12)
    # near p = 1 the series branch joins the general formula
    q = 1.0 + 1e-7
    assert power_law_work(g0, g1, c * g0 ** -q, c * g1 ** -q) == pytest.approx(
        c * (g1 ** (1 - q) - g0 ** (1 - q)) / (1 - q), rel=1e-9)


def _tables(magnet=None, n_i=11, n_g=9):
    magnet = magnet or plunger_solenoid().magnet
    currents, gaps = np.linspace(0, 3, n_i), np.geomspace(0.25e-3, 5e-3, n_g)
    psi, force = tabulate(magnet, currents, gaps)
    return currents, gaps, psi, force


def _build(currents, gaps, psi, force, **kw):
    return TableMagnet(tuple(currents), tuple(gaps), tuple(map(tuple, psi)), tuple(map(tuple, force)), **kw)


def test_consistent_tables_pass_and_inconsistent_forces_are_refused():
    currents, gaps, psi, force = _tables()
    _build(currents, gaps, psi, force)  # the solenoid's own tables: consistent
    for factor in (1.2, 0.5):
        with pytest.raises(ValueError) as err:
            _build(currents, gaps, psi, factor * force)
        msg = str(err.value)
        assert "\n" not in msg and msg.startswith("magnet.forces: inconsistent with magnet.flux_linkages at ")
        assert "force_tolerance" in msg
    # a 20 % error in the force at one current only, named with that current
    bad = force.copy()
    bad[7] *= 1.2
    with pytest.raises(ValueError, match=rf"at {float(currents[7])!r} A from gap "):
        _build(currents, gaps, psi, bad)
    # the tolerance is the user's
    _build(currents, gaps, psi, 1.2 * force, force_tolerance=0.5)


def test_force_of_the_ideal_gap_is_its_flux_table_derivative():
    # consistency is physics, not a fit: an ideal gap's F = psi^2 / (2 N^2 mu0 A) at its
    # own flux table passes at 1e-6 (the power-law rule is exact for F ~ 1/g^2 at constant i)
    magnet = FluxTubeMagnet(N, WorkingGap(AREA))
    currents, gaps, psi, _ = _tables(magnet)
    force = psi ** 2 / (2 * N ** 2 * MU0 * AREA)
    _build(currents, gaps, psi, force, force_tolerance=1e-6)
