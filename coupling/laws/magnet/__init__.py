"""The magnet as a law between the coil circuit and the armature (docs/magnet.md).

In flux form: the coil's flux linkage psi (Wb) is a circuit state, the working air gap g
(m) a mechanical one. Every magnet gives

- ``current(psi, g)`` (A), explicit, and the same as one ngspice B-source expression,
  ``current_expression("V(coil_psi)", "V(coil_gap)")``;
- ``force(psi, g)`` (N, >= 0 closing the gap) = dW/dg at constant psi, and ``energy(psi, g)``
  (J), W = integral_0^psi i dpsi', so that v i = R i^2 + dW/dt + F (-dg/dt) holds exactly;
- ``flux_linkage(i, g)`` (Wb, the inverse), ``coenergy(i, g)`` (J), ``force_at_current(i, g)``
  and ``inductance(g)`` (H, at i -> 0).

Magnets: ``FluxTubeMagnet`` (a network of flux tubes: iron with B-H curves, fixed air
gaps, the working gap and the leakage around the poles), ``TableMagnet`` (psi(i, g) and
F(i, g) tables from FEA or measurement, checked on load) and the built-in
``plunger_solenoid()``. Pure Python and numpy; nothing of mech or circuit.
"""

from coupling.laws.magnet.bh_curves import (
    MAGNETIC_MATERIALS, MU0, STEEL_9SMNPB28, LinearMaterial, TabulatedMaterial, magnetic_material,
    roschke_relative_permeability,
)
from coupling.laws.magnet.law import FluxTubeMagnet, Magnet
from coupling.laws.magnet.solenoid import BUILTIN_MAGNETS, PlungerSolenoid, plunger_solenoid
from coupling.laws.magnet.table import TableMagnet, table_consistency, tabulate
from coupling.laws.magnet.tubes import (
    AIR_SHAPES, IRON_SHAPES, AxialGap, AxialIron, FixedGap, IronPath, PoleLeakage, QuarterCylinder,
    QuarterHollowCylinder, RadialGap, RadialIron, WorkingGap,
)

__all__ = [
    "AIR_SHAPES", "BUILTIN_MAGNETS", "IRON_SHAPES", "MAGNETIC_MATERIALS", "MU0", "STEEL_9SMNPB28",
    "AxialGap", "AxialIron", "FixedGap", "FluxTubeMagnet", "IronPath", "LinearMaterial", "Magnet",
    "PlungerSolenoid", "PoleLeakage", "QuarterCylinder", "QuarterHollowCylinder", "RadialGap", "RadialIron",
    "TableMagnet", "TabulatedMaterial", "WorkingGap", "magnetic_material", "plunger_solenoid",
    "roschke_relative_permeability", "table_consistency", "tabulate",
]
