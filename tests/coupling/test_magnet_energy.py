"""One stored energy W(psi, g) gives the current and the force: i = dW/dpsi and F = dW/dg
(closing, at constant psi) by finite differences, to the error they allow; the co-energy
by an independent quadrature; no net work over a closed cycle in (psi, g); psi(i, g) the
inverse of i(psi, g)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from coupling.laws.magnet.bh_curves import STEEL_9SMNPB28, LinearMaterial
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.solenoid import plunger_solenoid
from coupling.laws.magnet.table import TableMagnet
from coupling.laws.magnet.tubes import AxialIron, FixedGap, IronPath, PoleLeakage, RadialGap, RadialIron, WorkingGap

EPS = np.finfo(float).eps


def _magnets():
    steel = STEEL_9SMNPB28
    solenoid = plunger_solenoid().magnet
    return {
        "linear": FluxTubeMagnet(250, WorkingGap(1e-4), iron=(IronPath(0.05, 1e-4, LinearMaterial(900)),),
                                 pole_leakage=PoleLeakage(0.04, 2e-3)),
        "saturating": FluxTubeMagnet(600, WorkingGap(8e-5), iron=(AxialIron(5e-3, 0.03, steel),
                                                                  RadialIron(5e-3, 12e-3, 3e-3, steel)),
                                     fixed_gap=(FixedGap((RadialGap(5e-3, 0.5e-3, 3e-3),)),),
                                     pole_leakage=PoleLeakage(0.04, 3e-3)),
        "solenoid": solenoid,
        "table": TableMagnet.from_magnet(solenoid, np.linspace(0, 3, 16), np.geomspace(0.25e-3, 5e-3, 9),
                                         force_tolerance=0.3),
    }


MAGNETS = _magnets()
KINDS = list(MAGNETS)


def _probe_points(magnet, n=7):
    """(psi, g) pairs in the magnet's range, psi into saturation, mid-way between psi
    breakpoints so that a step of a quarter segment crosses none."""
    low, high = magnet.gap_range
    high = min(high, 5e-3)
    low = max(low, 0.25e-3)
    gaps = np.geomspace(low * 1.01, high * 0.99, n)
    xs = np.append(magnet.breakpoints, np.inf)
    psi_top = abs(magnet.flux_linkage(2.5, low))
    picks, halves = [], []
    for x in np.linspace(0.1 * psi_top, psi_top, 9):
        j = np.searchsorted(xs, x, side="right") - 1
        if np.isfinite(xs[j + 1]):
            x, half = 0.5 * (xs[j] + xs[j + 1]), 0.5 * (xs[j + 1] - xs[j])
        else:
            half = 0.5 * (x - xs[j])
        if x not in picks:
            picks.append(x)
            halves.append(half)
    picks, halfwidth = np.array(picks), min(halves)
    return picks, gaps, halfwidth


@pytest.mark.parametrize("kind", KINDS)
def test_current_is_dW_dpsi(kind):
    # W is exactly quadratic in psi between breakpoints, so a central difference inside one
    # segment has no truncation error: what is left is round-off, ~ eps |W| / h
    magnet = MAGNETS[kind]
    psis, gaps, half = _probe_points(magnet)
    h = 0.25 * min(half, np.min(psis))
    for g in gaps:
        fd = (magnet.energy(psis + h, g) - magnet.energy(psis - h, g)) / (2 * h)
        i = magnet.current(psis, g)
        w = magnet.energy(psis + h, g)
        assert np.all(np.abs(fd - i) <= 50 * EPS * w / h + 1e-14 * np.abs(i))


@pytest.mark.parametrize("kind", ["linear", "saturating", "solenoid"])
def test_force_is_dW_dg(kind):
    # W is smooth in g: Richardson's 4th-order central difference, truncation (h/g)^4 ~ 1e-12,
    # round-off eps W / h ~ eps g / h ~ 2e-13 of F; 1e-9 relative leaves room for both
    magnet = MAGNETS[kind]
    psis, gaps, _ = _probe_points(magnet)
    p, g = np.meshgrid(psis, gaps)
    h = 1e-3 * g

    def d(step):
        return (magnet.energy(p, g + step) - magnet.energy(p, g - step)) / (2 * step)

    richardson = (4 * d(h / 2) - d(h)) / 3
    force = magnet.force(p, g)
    assert np.all(force > 0)
    assert np.allclose(richardson, force, rtol=1e-9, atol=0)


def test_table_force_is_dW_dg_within_each_gap_interval():
    # between two tabulated gaps W is linear in g at constant psi: a central difference that
    # stays inside the interval is exact up to round-off
    magnet = MAGNETS["table"]
    psis, _, _ = _probe_points(magnet)
    gaps = np.asarray(magnet.gaps)
    mid = 0.5 * (gaps[:-1] + gaps[1:])
    h = 0.1 * np.diff(gaps)
    p, g = np.meshgrid(psis, mid)
    fd = (magnet.energy(p, g + h[:, None]) - magnet.energy(p, g - h[:, None])) / (2 * h[:, None])
    w = magnet.energy(p, g)
    assert np.all(np.abs(fd - magnet.force(p, g)) <= 50 * EPS * w / h[:, None])


@pytest.mark.parametrize("kind", KINDS)
def test_closed_cycle_does_no_net_work(kind):
    # a rectangle in (psi, g): closing at low flux, opening at high flux. The electrical
    # energy taken in over the cycle, the loop integral of i dpsi, equals the mechanical work
    # the magnet does on the armature, the loop integral of F (-dg): both by adaptive
    # quadrature of i(psi, g) and F(psi, g), independent of W; the net work is not small
    # (the cycle converts energy), the balance closes to the quadrature's tolerance
    magnet = MAGNETS[kind]
    low, high = magnet.gap_range
    g1, g2 = max(low, 0.25e-3) * 1.3, min(high, 5e-3) * 0.8
    p1, p2 = 0.2 * magnet.flux_linkage(1.0, g2), magnet.flux_linkage(2.0, g2)
    kinks = [x for x in magnet.breakpoints if p1 < x < p2]
    opts = dict(epsabs=0.0, epsrel=1e-12, limit=500)
    gap_kinks = [x for x in getattr(magnet, "gaps", ()) if g1 < x < g2]
    i_dpsi = (quad(lambda x: magnet.current(x, g2), p1, p2, points=kinks, **opts)[0]     # at the open gap, psi up
              - quad(lambda x: magnet.current(x, g1), p1, p2, points=kinks, **opts)[0])  # at the closed gap, psi down
    f_dg = (quad(lambda x: magnet.force(p2, x), g1, g2, points=gap_kinks or None, **opts)[0]   # psi high: g1 -> g2 (opening)
            - quad(lambda x: magnet.force(p1, x), g1, g2, points=gap_kinks or None, **opts)[0])
    # loop: (p1, g2) -psi up-> (p2, g2) -close-> (p2, g1) -psi down-> (p1, g1) -open-> (p1, g2)
    electrical = i_dpsi
    mechanical = f_dg  # closing at p2 does F(p2) (g2 - g1) of work, opening at p1 takes F(p1) back
    assert electrical > 0.05 * magnet.energy(p2, g2)
    assert electrical == pytest.approx(mechanical, rel=1e-9)


@pytest.mark.parametrize("kind", KINDS)
def test_flux_linkage_inverts_current_and_coenergy_is_integral_of_psi_di(kind):
    magnet = MAGNETS[kind]
    low, high = magnet.gap_range
    gaps = np.geomspace(max(low, 0.25e-3), min(high, 5e-3), 6)
    currents = np.concatenate((-np.geomspace(1e-3, 4.0, 12), np.geomspace(1e-3, 4.0, 12)))
    i, g = np.meshgrid(currents, gaps)
    psi = magnet.flux_linkage(i, g)
    assert np.allclose(magnet.current(psi, g), i, rtol=1e-12, atol=0)
    assert np.all(np.sign(psi) == np.sign(i))
    for gap in gaps[[0, -1]]:
        top = 3.0
        kinks = [float(magnet.current(x, gap)) for x in magnet.breakpoints if 0 < magnet.current(x, gap) < top]
        coenergy = quad(lambda x: magnet.flux_linkage(x, gap), 0.0, top, points=kinks or None,
                        epsabs=0.0, epsrel=1e-12, limit=500)[0]
        assert magnet.coenergy(top, gap) == pytest.approx(coenergy, rel=1e-10)
        # and F = -dW'/dg at constant current (Richardson, as for dW/dg)
        h = 1e-3 * gap
        d = lambda s: (magnet.coenergy(top, gap + s) - magnet.coenergy(top, gap - s)) / (2 * s)  # noqa: E731
        if kind != "table":
            assert -(4 * d(h / 2) - d(h)) / 3 == pytest.approx(magnet.force_at_current(top, gap), rel=1e-7)
