"""The plunger solenoid of issue 19, a built-in named magnet: an axisymmetric lifting magnet
with a planar armature end face (the "SimpleSolenoid" of the Modelica Standard Library,
Modelica.Magnetic.FluxTubes.Examples.SolenoidActuator, T. Bödrich; its dimensions and
flux-tube partition are carried over, docs/magnet.md derives each tube).

Along the axis: a pot-shaped yoke (outer radius 15 mm, bore 13.5 mm, 35 mm long) closed by
a bottom at each end (3.5 mm thick); the pole (radius 5 mm, 6.5 mm long) stands on the
pole-side bottom; the armature (radius 5 mm, 26 mm long) slides in the bore of the other
bottom (radial clearance 0.65 mm, the slide guiding) and faces the pole across the working
gap g, 5 mm at rest to 0.25 mm on the stop at the pole. The coil (957 turns, 10 ohm) fills
the space between pole, armature and yoke.
"""

from __future__ import annotations

import functools
import math

from mech.frozen import frozen
from coupling.laws.magnet.bh_curves import STEEL_9SMNPB28
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.tubes import (
    AxialIron, FixedGap, PoleLeakage, QuarterCylinder, QuarterHollowCylinder, RadialGap, RadialIron, WorkingGap,
)

# the drawing, m (issue 19; Modelica FluxTubes SimpleSolenoid)
YOKE_OUTER_RADIUS = 15e-3
YOKE_INNER_RADIUS = 13.5e-3
YOKE_LENGTH = 35e-3
YOKE_BOTTOM = 3.5e-3          # axial thickness of the bottom at the armature side
POLE_BOTTOM = 3.5e-3          # axial thickness of the bottom at the pole side
POLE_RADIUS = 5e-3
POLE_LENGTH = 6.5e-3
GUIDE_CLEARANCE = 0.65e-3     # radial parasitic gap of the slide guiding
ARMATURE_RADIUS = 5e-3
ARMATURE_LENGTH = 26e-3
STEEL_DENSITY = 7853.0        # kg/m^3
LOAD_MASS = 0.010             # kg, rigidly attached to the armature
REST_GAP = 5e-3               # m, armature on its rest stop
CLOSED_GAP = 0.25e-3          # m, armature on the stop at the pole
TURNS = 957
COIL_RESISTANCE = 10.0        # ohm
STOP_STIFFNESS = 1e11         # N/m, both stops
STOP_DAMPING = 400.0          # N s/m
# the leakage field around the working gap (FluxTubes SimpleSolenoid's choice): mean
# circumference at 1.5 mm outside the pole, reaching 3 mm
LEAKAGE_OFFSET = 1.5e-3
LEAKAGE_RADIUS = 3e-3
# the quarter annulus from the inside of the yoke bottom to the armature's side: thickness
# / inner radius (the inner radius being the guide clearance), FluxTubes' choice
BOTTOM_LEAKAGE_RATIO = 8.0


@frozen
class PlungerSolenoid:
    """The built-in solenoid: its ``magnet``, ``coil_resistance`` (ohm), the moving
    ``armature_mass`` (kg, armature and load), ``rest_gap`` and ``closed_gap`` (m, the
    working gap on the two stops) and the stops' ``stop_stiffness`` (N/m) and
    ``stop_damping`` (N s/m)."""

    magnet: FluxTubeMagnet
    coil_resistance: float
    armature_mass: float
    rest_gap: float
    closed_gap: float
    stop_stiffness: float
    stop_damping: float


def plunger_solenoid(material=STEEL_9SMNPB28) -> PlungerSolenoid:
    """The plunger solenoid of issue 19 (iron: ``material``, 9SMnPb28 by default). The default
    one is built once a process and shared (it is frozen)."""
    # (a run reads the scene's device three times, its links twice and its relay metrics once:
    # a new magnet each time computed its merged iron term and breakpoints again, ~0.25 ms
    # each, where the shared one keeps them; the same values, from the same arithmetic)
    if material is STEEL_9SMNPB28:
        return _default_solenoid()
    return _built(material)


@functools.lru_cache(maxsize=1)
def _default_solenoid() -> PlungerSolenoid:
    return _built(STEEL_9SMNPB28)


def _built(material) -> PlungerSolenoid:
    mid_stroke = 0.5 * (REST_GAP + CLOSED_GAP)
    # iron path lengths run between the mid-planes of the two bottoms
    between_bottoms = YOKE_LENGTH - 0.5 * (YOKE_BOTTOM + POLE_BOTTOM)
    iron = (
        AxialIron(POLE_RADIUS, POLE_LENGTH, material, name="pole"),
        RadialIron(POLE_RADIUS, YOKE_INNER_RADIUS, POLE_BOTTOM, material, name="pole_bottom"),
        AxialIron(YOKE_OUTER_RADIUS, between_bottoms, material, inner_radius=YOKE_INNER_RADIUS, name="yoke"),
        RadialIron(ARMATURE_RADIUS + GUIDE_CLEARANCE, YOKE_INNER_RADIUS, YOKE_BOTTOM, material,
                   name="yoke_bottom"),
        # from the yoke bottom's mid-plane to the armature's face, taken at mid-stroke
        AxialIron(ARMATURE_RADIUS, between_bottoms - POLE_LENGTH - mid_stroke, material, name="armature"),
    )
    guide = FixedGap((
        RadialGap(ARMATURE_RADIUS, GUIDE_CLEARANCE, YOKE_BOTTOM),
        QuarterCylinder(2.0 * math.pi * (ARMATURE_RADIUS + 0.5 * GUIDE_CLEARANCE)),
        QuarterHollowCylinder(2.0 * math.pi * ARMATURE_RADIUS, BOTTOM_LEAKAGE_RATIO),
    ), name="guide")
    magnet = FluxTubeMagnet(
        turns=TURNS,
        working_gap=WorkingGap(math.pi * POLE_RADIUS ** 2),
        iron=iron,
        fixed_gap=(guide,),
        pole_leakage=PoleLeakage(2.0 * math.pi * (POLE_RADIUS + LEAKAGE_OFFSET), LEAKAGE_RADIUS),
    )
    mass = STEEL_DENSITY * ARMATURE_LENGTH * math.pi * ARMATURE_RADIUS ** 2 + LOAD_MASS
    return PlungerSolenoid(magnet, COIL_RESISTANCE, mass, REST_GAP, CLOSED_GAP, STOP_STIFFNESS, STOP_DAMPING)


BUILTIN_MAGNETS = {"plunger_solenoid": plunger_solenoid}
