"""Bad magnet input: one line naming the key as the scene spells it, the value and what is
allowed, raised where the dataclass is built."""

from __future__ import annotations

import numpy as np

from coupling.laws.magnet.bh_curves import STEEL_9SMNPB28, LinearMaterial, TabulatedMaterial, magnetic_material
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.solenoid import plunger_solenoid
from coupling.laws.magnet.table import TableMagnet, tabulate
from coupling.laws.magnet.tubes import (
    AxialGap, AxialIron, FixedGap, IronPath, PoleLeakage, QuarterHollowCylinder, RadialGap, RadialIron, WorkingGap,
)
from value_errors import one_line_value_error as _raises

STEEL = STEEL_9SMNPB28


def test_flux_tube_magnet_fields():
    gap = WorkingGap(1e-4)
    _raises(lambda: FluxTubeMagnet(-957, gap), "magnet.turns = -957", "must be > 0")
    _raises(lambda: FluxTubeMagnet("957", gap), "magnet.turns = '957'", "expected a number")
    _raises(lambda: FluxTubeMagnet(100, 1e-4), "magnet.working_gap", "expected a WorkingGap")
    _raises(lambda: FluxTubeMagnet(100, gap, iron=(FixedGap((AxialGap(1e-3, 1e-4),)),)),
            "magnet.iron[0]", "expected iron tubes")
    _raises(lambda: FluxTubeMagnet(100, gap, fixed_gap=(AxialGap(1e-3, 1e-4),)), "magnet.fixed_gap[0]",
            "expected FixedGap entries")
    _raises(lambda: FluxTubeMagnet(100, gap, pole_leakage=3e-3), "magnet.pole_leakage", "expected a PoleLeakage")
    _raises(lambda: WorkingGap(0.0), "magnet.working_gap.area = 0.0", "must be > 0 m^2")
    _raises(lambda: WorkingGap(1e-4, minimum=-1e-6), "magnet.working_gap.minimum = -1e-06", "must be > 0 m")
    _raises(lambda: PoleLeakage(0.04, float("nan")), "magnet.pole_leakage.radius = nan", "finite")


def test_tubes_name_their_place():
    _raises(lambda: IronPath(0.0, 1e-4, STEEL, name="magnet.iron[2]"), "magnet.iron[2].length = 0.0", "> 0 m")
    _raises(lambda: IronPath(0.01, 1e-4, "steel", name="magnet.iron[0]"), "magnet.iron[0].material",
            "expected a LinearMaterial or a TabulatedMaterial")
    _raises(lambda: AxialIron(5e-3, 0.01, STEEL, inner_radius=6e-3, name="magnet.iron[1]"),
            "magnet.iron[1].inner_radius = 0.006", "must be < outer_radius = 0.005")
    _raises(lambda: RadialIron(13.5e-3, 5e-3, 3.5e-3, STEEL, name="magnet.iron[3]"),
            "magnet.iron[3].outer_radius = 0.005", "must be > inner_radius = 0.0135")
    _raises(lambda: RadialGap(5e-3, -0.65e-3, 3.5e-3, name="magnet.fixed_gap[0].tube[0]"),
            "magnet.fixed_gap[0].tube[0].thickness = -0.00065", "must be > 0 m")
    _raises(lambda: QuarterHollowCylinder(0.03, 0.0), "magnet.fixed_gap.tube.ratio = 0.0", "must be > 0")
    _raises(lambda: FixedGap(()), "magnet.fixed_gap.tube", "at least one air tube")
    _raises(lambda: FixedGap((IronPath(0.01, 1e-4, STEEL),), name="magnet.fixed_gap[1]"),
            "magnet.fixed_gap[1].tube[0]", "expected an air tube")


def test_bh_curves():
    def table(b, h):
        return lambda: TabulatedMaterial(b, h, name="magnet.iron[0].material")

    _raises(table((0.0, 1.0, 0.9), (0.0, 100.0, 200.0)), "magnet.iron[0].material.flux_density[2] = 0.9",
            "must increase strictly", "previous 1.0 T")
    _raises(table((0.0, 1.0, 1.5), (0.0, 500.0, 400.0)), "magnet.iron[0].material.field_strength[2] = 400.0",
            "must increase strictly")
    _raises(table((0.0, 1.0, 1.5), (0.0, 500.0, 1e6)), "field_strength[2] = 1000000.0",
            "differential permeability", "must be >= mu0")
    _raises(table((0.1, 1.0), (0.0, 500.0)), "starts at B = 0.1 T", "must start at B = 0, H = 0")
    _raises(table((0.0, 1.0), (0.0, 500.0, 900.0)), "2 flux densities for 3 field strengths")
    _raises(table((0.0, "1.0"), (0.0, 500.0)), "flux_density[1] = '1.0'", "expected a number")
    _raises(table("0 1", (0.0, 500.0)), "flux_density = '0 1'", "expected a list of numbers (T)")
    _raises(lambda: LinearMaterial(0.5), "magnet.material.relative_permeability = 0.5", "must be >= 1")
    _raises(lambda: magnetic_material("9SMnPb29", "magnet.iron[0].material"), "magnet.iron[0].material",
            "'9SMnPb29'", "did you mean '9SMnPb28'")


def _tables(n_i=6, n_g=5):
    magnet = plunger_solenoid().magnet
    currents, gaps = np.linspace(0, 3, n_i), np.geomspace(0.25e-3, 5e-3, n_g)
    psi, force = tabulate(magnet, currents, gaps)
    return [list(currents), list(gaps), [list(r) for r in psi], [list(r) for r in force]]


def _table(currents, gaps, psi, force, **kw):
    return lambda: TableMagnet(currents, gaps, psi, force, **kw)


def test_table_magnet_fields():
    currents, gaps, psi, force = _tables()
    TableMagnet(currents, gaps, psi, force)  # the good one builds
    _raises(_table([0.1] + currents[1:], gaps, psi, force), "magnet.currents[0] = 0.1", "must start at 0 A")
    c = currents.copy()
    c[3] = c[2]
    _raises(_table(c, gaps, psi, force), "magnet.currents[3] = 1.2", "must increase strictly")
    g = gaps.copy()
    g[2], g[3] = g[3], g[2]
    _raises(_table(currents, g, psi, force), "magnet.gaps[3] =", "must increase strictly")
    _raises(_table(currents, [-g for g in gaps[::-1]], psi, force), "magnet.gaps[0] = -0.005", "must be > 0 m")
    _raises(_table(currents, gaps[:1], [r[:1] for r in psi], [r[:1] for r in force]), "magnet.gaps: 1 gap(s)")
    _raises(_table(currents, gaps, psi[:-1], force), "magnet.flux_linkages: 5 rows for 6 currents")
    _raises(_table(currents, gaps, psi, [r[:-1] for r in force]), "magnet.forces[0]: 4 values for 5 gaps")
    p = [r.copy() for r in psi]
    p[0][2] = 1e-4
    _raises(_table(currents, gaps, p, force), "magnet.flux_linkages[0][2] = 0.0001", "at 0 A must be 0")
    p = [r.copy() for r in psi]
    p[3][1] = p[2][1]
    _raises(_table(currents, gaps, p, force), "magnet.flux_linkages[3][1] =", "must increase strictly with the current")
    # the gap axis given as armature travel (psi rising with "g"): not monotonic in g
    _raises(_table(currents, gaps, [r[::-1] for r in psi], [r[::-1] for r in force]),
            "magnet.flux_linkages[1][1] =", "must not grow as the gap opens", "armature's travel")
    _raises(_table(currents, gaps, psi, [[-v for v in r] for r in force]), "magnet.forces[1][0] = -",
            "must be >= 0", "opposite sign convention")
    _raises(_table(currents, gaps, psi, force, force_tolerance=1.5), "magnet.force_tolerance = 1.5",
            "allowed range is (0, 1)")
    _raises(_table(currents, gaps, psi, [[v, *r[1:]] for v, r in zip([float("inf")] * 6, force)]),
            "magnet.forces[0][0] = inf", "finite")
