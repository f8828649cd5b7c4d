"""The built-in plunger solenoid: its flux tubes derived from the drawing (issue 19), its
unsaturated inductance against the reluctances summed by hand, and how it behaves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.laws.magnet.bh_curves import MU0
from coupling.laws.magnet.solenoid import BUILTIN_MAGNETS, plunger_solenoid

MM = 1e-3


def _mu_r_initial():
    # 9SMnPb28 (Roschke's fit: mu_i 400, B_mumax 1.488 T, c_a 1200, c_b 3, n 12.5) between
    # B = 0 and the table's first point, 0.25 T: the secant permeability there
    b = 0.25 / 1.488
    return 1.0 + (400.0 - 1.0 + 1200.0 * b) / (1.0 + 3.0 * b + b ** 12.5)


def test_tubes_follow_the_drawing():
    s = plunger_solenoid()
    m = s.magnet
    tubes = {t.name: t for t in m.iron}
    assert tubes["pole"].path_area == pytest.approx(math.pi * (5 * MM) ** 2, rel=1e-15)
    assert tubes["pole"].path_length == pytest.approx(6.5 * MM, rel=1e-15)
    assert tubes["yoke"].path_area == pytest.approx(math.pi * ((15 * MM) ** 2 - (13.5 * MM) ** 2), rel=1e-14)
    assert tubes["yoke"].path_length == pytest.approx((35 - 3.5) * MM, rel=1e-15)
    # armature: from the yoke bottom's mid-plane to its face at mid-stroke (2.625 mm)
    assert tubes["armature"].path_length == pytest.approx((35 - 3.5 - 6.5 - 2.625) * MM, rel=1e-14)
    assert m.working_gap.area == pytest.approx(math.pi * (5 * MM) ** 2, rel=1e-15)
    assert s.armature_mass == pytest.approx(7853 * 26 * MM * math.pi * (5 * MM) ** 2 + 0.010, rel=1e-15)
    assert (s.coil_resistance, m.turns, s.rest_gap, s.closed_gap) == (10.0, 957, 5 * MM, 0.25 * MM)
    assert BUILTIN_MAGNETS["plunger_solenoid"]().magnet == m


def test_unsaturated_inductance_against_reluctances_by_hand():
    # B -> 0: every iron tube has mu_r of the table's first segment; radial discs
    # ln(r_o / r_i) / (2 pi mu t); the guide's radial gap in parallel with its two edge leakages;
    # the working gap in parallel with the leakage around the poles
    m = plunger_solenoid().magnet
    mu = MU0 * _mu_r_initial()
    r_iron = (6.5 * MM / (mu * math.pi * (5 * MM) ** 2)
              + math.log(13.5 / 5) / (2 * math.pi * mu * 3.5 * MM)
              + 31.5 * MM / (mu * math.pi * ((15 * MM) ** 2 - (13.5 * MM) ** 2))
              + math.log(13.5 / 5.65) / (2 * math.pi * mu * 3.5 * MM)
              + 22.375 * MM / (mu * math.pi * (5 * MM) ** 2))
    g_guide = (2 * math.pi * MU0 * 3.5 * MM / math.log(5.65 / 5)
               + 0.52 * MU0 * 2 * math.pi * 5.325 * MM
               + 2 * MU0 * 2 * math.pi * 5 * MM * math.log(9.0) / math.pi)
    for g in (0.25 * MM, 1 * MM, 5 * MM):
        g_work = MU0 * math.pi * (5 * MM) ** 2 / g + MU0 * 2 * math.pi * 6.5 * MM / math.pi * math.log(1 + math.pi * 3 * MM / g)
        L = 957 ** 2 / (r_iron + 1 / g_guide + 1 / g_work)
        assert m.inductance(g) == pytest.approx(L, rel=1e-12)


def test_behaves_like_a_lifting_magnet():
    m = plunger_solenoid().magnet
    gaps = np.geomspace(0.25 * MM, 5 * MM, 12)
    i_hold = 12.0 / 10.0
    force = m.force_at_current(i_hold, gaps)
    assert np.all(np.diff(force) < 0)  # the pull falls as the gap opens
    assert np.all(np.diff(m.flux_linkage(i_hold, gaps)) < 0)
    # closed at the 12 V current the pole saturates: the secant inductance falls below the
    # unsaturated one, while at rest (5 mm, mostly air) they agree within 0.1 %
    closed, rest = gaps[0], gaps[-1]
    assert m.flux_linkage(i_hold, closed) / i_hold < 0.9 * m.inductance(closed)
    assert m.flux_linkage(i_hold, rest) / i_hold == pytest.approx(m.inductance(rest), rel=1e-3)
    b_pole = m.flux_linkage(i_hold, closed) / (957 * math.pi * (5 * MM) ** 2)
    assert 1.6 < b_pole < 2.2
