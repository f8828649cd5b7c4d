"""The magnet against closed forms: a linear magnet's inductance and force, the coil
current's L/R rise integrated from i(psi), the held force bounded by saturation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.laws.magnet.bh_curves import MU0, STEEL_9SMNPB28, LinearMaterial
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.tubes import IronPath, PoleLeakage, WorkingGap

N = 400
AREA = 1.5e-4  # m^2
GAPS = np.array([0.05e-3, 0.3e-3, 1e-3, 4e-3])


def test_single_air_gap_inductance_and_force():
    # no iron reluctance: L = mu0 N^2 A / g, F = (1/2) i^2 |dL/dg| = mu0 N^2 A i^2 / (2 g^2)
    magnet = FluxTubeMagnet(N, WorkingGap(AREA))
    currents = np.array([0.01, 0.5, 3.0])
    i, g = np.meshgrid(currents, GAPS)
    L = MU0 * N ** 2 * AREA / GAPS
    assert np.allclose(magnet.inductance(GAPS), L, rtol=1e-14, atol=0)
    assert np.allclose(magnet.flux_linkage(i, g), (MU0 * N ** 2 * AREA / g) * i, rtol=1e-14, atol=0)
    assert np.allclose(magnet.force_at_current(i, g), 0.5 * i ** 2 * MU0 * N ** 2 * AREA / g ** 2, rtol=1e-13, atol=0)


def test_linear_iron_and_leakage_against_closed_forms():
    # R = l / (mu0 mu_r A) + g / (mu0 A) in series; the leakage G_l = (mu0 w / pi) ln(1 + pi r / g)
    # in parallel with the gap; L = N^2 / R, F = (1/2) i^2 |dL/dg|
    l_iron, mu_r, w, r = 0.08, 1200.0, 0.05, 2.5e-3
    magnet = FluxTubeMagnet(N, WorkingGap(AREA), iron=(IronPath(l_iron, AREA, LinearMaterial(mu_r)),),
                            pole_leakage=PoleLeakage(w, r))
    g = GAPS
    g_gap = MU0 * AREA / g + MU0 * w / math.pi * np.log(1.0 + math.pi * r / g)
    dg_gap = -MU0 * AREA / g ** 2 + MU0 * w / math.pi * (-math.pi * r / g ** 2) / (1.0 + math.pi * r / g)
    r_total = l_iron / (MU0 * mu_r * AREA) + 1.0 / g_gap
    L = N ** 2 / r_total
    dL = -N ** 2 / r_total ** 2 * (dg_gap / g_gap ** 2)  # dR/dg = -G'/G^2
    assert np.allclose(magnet.inductance(g), L, rtol=1e-13, atol=0)
    for i in (0.02, 1.7):
        assert np.allclose(magnet.flux_linkage(i, g), L * i, rtol=1e-13, atol=0)
        assert np.allclose(magnet.force_at_current(i, g), 0.5 * i ** 2 * np.abs(dL), rtol=1e-12, atol=0)
        assert np.allclose(magnet.coenergy(i, g), 0.5 * L * i ** 2, rtol=1e-13, atol=0)


@pytest.mark.parametrize("gap", [0.2e-3, 2e-3])
def test_coil_current_rises_with_time_constant_L_over_R(gap):
    # armature held: dpsi/dt = V - R i(psi), integrated with RK4 on i(psi) alone, against
    # i(t) = V/R (1 - exp(-t R / L)); RK4's error at dt = tau/400 is ~ (dt/tau)^4 / 120 ~ 3e-13
    magnet = FluxTubeMagnet(N, WorkingGap(AREA), iron=(IronPath(0.08, AREA, LinearMaterial(1500.0)),),
                            pole_leakage=PoleLeakage(0.05, 2e-3))
    V, R = 12.0, 8.0
    tau = magnet.inductance(gap) / R
    dt = tau / 400
    rate = lambda psi: V - R * magnet.current(psi, gap)  # noqa: E731
    psi, worst = 0.0, 0.0
    for k in range(1, 2001):
        k1 = rate(psi)
        k2 = rate(psi + 0.5 * dt * k1)
        k3 = rate(psi + 0.5 * dt * k2)
        k4 = rate(psi + dt * k3)
        psi += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        exact = V / R * (1.0 - math.exp(-k * dt / tau))
        worst = max(worst, abs(magnet.current(psi, gap) - exact))
    assert worst <= 1e-10 * V / R
    assert magnet.current(psi, gap) > 0.99 * V / R  # five time constants: settled


def test_saturation_bounds_the_held_force():
    # one iron path of the gap's area and one gap, no leakage: the force at constant flux is
    # B^2 A / (2 mu0) with B the gap's flux density (exactly, at any saturation); the iron's
    # polarization J = B - mu0 H stays below J_s (2.07 T, the table's end), so with H <= N i / l
    # the force is bounded by (J_s + mu0 N i / l)^2 A / (2 mu0) and, once the iron is saturated,
    # stays near J_s^2 A / (2 mu0), while the same magnet with linear iron goes on as i^2
    l_iron, gap = 0.06, 0.02e-3
    steel = STEEL_9SMNPB28
    js = steel.saturation_polarization
    magnet = FluxTubeMagnet(N, WorkingGap(AREA), iron=(IronPath(l_iron, AREA, steel),))
    linear = FluxTubeMagnet(N, WorkingGap(AREA), iron=(IronPath(l_iron, AREA, LinearMaterial(400.0)),))
    currents = np.geomspace(0.05, 60.0, 40)
    psi = magnet.flux_linkage(currents, gap)
    b = psi / (N * AREA)
    force = magnet.force(psi, gap)
    assert np.allclose(force, b ** 2 * AREA / (2 * MU0), rtol=1e-13, atol=0)
    bound = (js + MU0 * N * currents / l_iron) ** 2 * AREA / (2 * MU0)
    assert np.all(force <= bound)
    # saturated: N i / l from 3e4 to 1.2e5 A/m (past the knee, mu0 H <= 0.15 T): the force
    # stays within [0.85, 1.2] of J_s^2 A / (2 mu0) and grows by < 1.4x over a 4x current
    # range, where the linear iron's grows 16x
    held = js ** 2 * AREA / (2 * MU0)
    deep = (N * currents / l_iron >= 3e4) & (N * currents / l_iron <= 1.2e5)
    assert deep.sum() >= 5
    assert np.all(force[deep] >= 0.85 * held) and np.all(force[deep] <= 1.2 * held)
    lo, hi = currents[deep][0], currents[deep][-1]
    assert force[deep][-1] / force[deep][0] < 1.4
    assert linear.force_at_current(hi, gap) / linear.force_at_current(lo, gap) == pytest.approx((hi / lo) ** 2)
