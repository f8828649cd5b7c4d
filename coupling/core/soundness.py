"""Is a finished run physically sound? Bounds every run must respect, as small pure laws.

A run whose integration is too coarse can still finish: the explicit integrator may pump
energy into the bar (speeds of km/s, a tip "penetrating" millimetres into the block) and
the circuit then carries currents its source cannot drive. Such a result gets the status
"unsound" (``switchsim`` exits 3), with each violated bound named, its cause and the fix.

The bounds, all from the scene's own energy scale E (J, ``mech.ImpactResult.energy_scale``:
what the scene brings in, initial kinetic, elastic, contact- and spring-stored energy,
and the most work its loads and drives can do: gravity, actuator forces, springs, a
pivot's preload torque, a moving clamp; bounded from the scene before the run where it can
be (docs/mechanics.md section 9, "Energy audit"). Contact damping, friction and modal
damping only take energy out. Past their history's row budget, a run's extremes include
the rows it thinned away (``mech.ImpactResult.thinning``)):

- energy audit: max |residual| <= energy_tolerance * E ([solver] energy_tolerance);
- speeds: the kinetic energy (translation, rotation, vibration) never exceeds E, and so
  the centre of mass moves at most sqrt(2 E / m) (m/s);
- penetration: the Hertz spring stores (2/5) k y^(5/2), at most E plus the work of the
  weight W = m g over the penetration itself, so no tip goes deeper than the root of
  (2/5) k y^(5/2) = E + W y (m; (5 E / (2 k))^(2/5) without gravity);
- contact law: Hertz's law treats the cap as a paraboloid on a half-space, valid while
  the contact radius a = sqrt(R y) stays small against the cap radius R; the paraboloid
  is off the sphere by y / (4 R) of the gap at the contact's edge. Beyond 5 % (y > 0.2 R,
  a > 0.45 R) the result is unsound; between 1 % and 5 % (y > 0.04 R) it carries a
  warning (coupling.core.diagnostics), its forces and contact times being approximate to
  about that fraction;
- coil (a relay's or solenoid's coil, coupling.core.relay): its energy audit's |residual|
  <= COIL_UNSOUND_FACTOR x energy_tolerance x the energy into the coil; above
  energy_tolerance x that energy it carries a warning (coupling.core.diagnostics), its coil
  side approximate to about that fraction (the default relay with an RC suppression:
  3.4e-3 at ngspice's own steps; a coil drawing 5 % too much current: 1.5e-2);
- circuit (template circuits): the loop current through the load is at most
  2 V / (R_source + R_wiring + R_load) (A): the supply across the series loop, plus one
  full overshoot of the loop's ringing (a short_circuit template: R_load || R_fault; a
  changeover: R_load || R_nc_load, its two throws closed together before one breaks). A
  netlist circuit's topology is not known: no current bound.

Bounds are compared with a relative margin (BOUND_MARGIN) for round-off and the
integration error the energy check already limits.
"""

from __future__ import annotations

import math

import numpy as np


BOUND_MARGIN = 0.01  # relative slack on the energy-derived bounds
RINGING_FACTOR = 2.0  # a passive loop's step response reaches at most twice its final value

FIX = "the integration is not accurate enough: set a tighter [solver] rtol (e.g. 10 times smaller)"


def speed_bound(energy_scale: float, mass: float) -> float:
    """m/s: the fastest the centre of mass can move with energy E (J) and mass m (kg)."""
    return math.sqrt(2.0 * max(energy_scale, 0.0) / mass)


def penetration_bound(energy_scale: float, stiffness: float, weight: float = 0.0) -> float:
    """m: the deepest Hertz penetration energy E (J) can make against k y^1.5 (N/m^1.5),
    with the weight W (N) doing work W y on the way down: the root of (2/5) k y^2.5 = E + W y
    (fixed-point iteration; the right side grows more slowly than the left)."""
    e = max(energy_scale, 0.0)
    y = (2.5 * e / stiffness) ** 0.4
    for _ in range(200):
        y_new = (2.5 * (e + weight * y) / stiffness) ** 0.4
        if abs(y_new - y) <= 1e-14 * y_new:
            return y_new
        y = y_new
    return y


def loop_current_bound(voltage: float, series_resistance: float) -> float:
    """A: the largest loop current a DC source V (V) can drive through series R (ohm)."""
    return RINGING_FACTOR * abs(voltage) / series_resistance


def energy_problem(max_residual: float, energy_scale: float, tolerance: float) -> str | None:
    """The energy audit's verdict: None if |residual| (J) <= tolerance x scale (J)."""
    rel = max_residual / energy_scale if energy_scale > 0 else math.inf
    if rel <= tolerance:
        return None
    return (f"energy audit: residual {max_residual:.3g} J is {rel:.3g} of the scene's energy {energy_scale:.3g} J "
            f"(allowed: solver.energy_tolerance = {tolerance:g}); {FIX}")


COIL_FIX = ("the coil's flux is not integrated accurately enough: raise [coupling] coil_step_points "
            "(e.g. 8), cap [coupling] max_macro_step (e.g. 2e-5 s) or [circuit] max_step")
# the coil's audit: above energy_tolerance a warning, above this many times it unsound (as
# Hertz's validity: warned from 1 %, unsound from 5 %)
COIL_UNSOUND_FACTOR = 5.0


def coil_energy_line(relative_residual: float, tolerance: float, bound: float) -> str:
    """The one line of a coil audit above ``bound`` (a fraction of the energy into the coil)."""
    return (f"coil energy audit: residual {relative_residual:.3g} of the energy into the coil, above "
            f"{bound:g} (solver.energy_tolerance = {tolerance:g}); {COIL_FIX}")


def coil_energy_problem(relative_residual: float | None, tolerance: float) -> str | None:
    """The coil's energy audit's verdict (coupling.core.relay): None if its |residual| is
    at most COIL_UNSOUND_FACTOR x tolerance x the energy into the coil (both J); a coil into
    which no energy went (None) has nothing to judge. Between tolerance and that, a warning
    (coupling.core.diagnostics.coil_audit_warning)."""
    bound = COIL_UNSOUND_FACTOR * tolerance
    if relative_residual is None or relative_residual <= bound:
        return None
    return coil_energy_line(relative_residual, tolerance, bound)


def speed_problem(max_speed: float, bound: float) -> str | None:
    """None if the largest centre-of-mass speed (m/s) respects the energy bound (m/s)."""
    if max_speed <= bound * (1.0 + BOUND_MARGIN):
        return None
    return (f"speed: the bar's centre moved at {max_speed:.3g} m/s, more than the {bound:.3g} m/s "
            f"its energy allows; {FIX}")


def kinetic_problem(max_kinetic: float, energy_scale: float) -> str | None:
    """None if the largest kinetic energy (J; translation, rotation and vibration: every
    speed of the bar) stays within the scene's energy (J)."""
    if max_kinetic <= energy_scale * (1.0 + BOUND_MARGIN):
        return None
    return (f"speed: the bar's kinetic energy (translation, rotation and vibration) reached {max_kinetic:.3g} J, "
            f"more than the scene's energy {energy_scale:.3g} J; {FIX}")


def penetration_problem(max_penetration: float, bound: float, tip_radius: float) -> str | None:
    """None if the deepest tip penetration (m) respects the energy bound and the tip radius (m)."""
    if max_penetration <= min(bound * (1.0 + BOUND_MARGIN), tip_radius):
        return None
    return (f"penetration: a tip went {max_penetration:.3g} m into the block (tip radius {tip_radius:.3g} m), "
            f"deeper than the {bound:.3g} m the scene's energy allows; {FIX}")


HERTZ_WARN_ERROR = 0.01  # the paraboloid's gap error y / (4 R) above which a run is warned
HERTZ_UNSOUND_ERROR = 0.05  # ... and above which it is unsound


def hertz_gap_error(penetration: float, radius: float) -> float:
    """-: how far Hertz's paraboloid r^2 / (2 R) is from the sphere at the edge of a contact
    of penetration y (m) on a cap of radius R (m), relative to the gap there: a^2 / (4 R^2)
    = y / (4 R) to leading order (a = sqrt(R y) the contact radius)."""
    return max(penetration, 0.0) / (4.0 * radius)


def hertz_validity_line(penetration: float, radius: float, name: str) -> str:
    err = hertz_gap_error(penetration, radius)
    return (f"contact law: {name} went {penetration:.3g} m into the block, {penetration / radius:.2g} of its "
            f"{radius:.3g} m radius (contact radius {math.sqrt(radius * penetration) / radius:.2g} R): Hertz's "
            f"small-deformation law is off by ~{100 * err:.2g} % there; a stiffer material, a larger cap or "
            "a slower impact keeps it valid")


def hertz_problem(penetration: float, radius: float, name: str) -> str | None:
    """None unless the deepest penetration (m) of a cap of radius R (m) puts Hertz's law
    beyond HERTZ_UNSOUND_ERROR."""
    if hertz_gap_error(penetration, radius) <= HERTZ_UNSOUND_ERROR:
        return None
    return hertz_validity_line(penetration, radius, name)


def current_problem(max_current: float, bound: float) -> str | None:
    """None if the largest |loop current| (A) respects the circuit's bound (A)."""
    if max_current <= bound * (1.0 + BOUND_MARGIN):
        return None
    return (f"circuit: {max_current:.3g} A through the load, more than the {bound:.3g} A the source and the "
            f"loop's resistances allow; {FIX}")


def assess(result) -> dict:
    """The soundness block of summary.json for a finished ``CoupledResult``: the measured
    extremes, their bounds and ``problems`` (one line each; empty when sound)."""
    out: dict = {}
    problems: list[str] = []
    mres = result.mechanics
    if mres is not None and len(mres.t):
        scene = mres.model.scene
        scale = float(mres.energy_scale)
        # from the records themselves and the extremes of those a long run thinned away
        # (mech.ImpactResult.thinning), not from the history table
        residual = mres.max_abs_residual
        kinetic = mres.max_kinetic
        out.update(energy_scale=scale, relative_residual=residual / scale if scale > 0 else None,
                   max_kinetic=kinetic)
        problems += [p for p in (energy_problem(residual, scale, scene.solver.energy_tolerance),
                                 kinetic_problem(kinetic, scale)) if p]
        if scene.bar is not None:  # (an armature alone has no bar to speed or to sink into a contact)
            speed = mres.max_speed
            pen = mres.deepest_penetration
            v_max = speed_bound(scale, scene.bar.mass)
            y_max = penetration_bound(scale, float(mres.solver["stiffness"]), scene.bar.mass * scene.gravity)
            out.update(max_speed=speed, speed_bound=v_max, max_penetration=pen, penetration_bound=y_max)
            problems += [p for p in (speed_problem(speed, v_max),
                                     penetration_problem(pen, y_max, scene.bar.tip_radius)) if p]
            problems += [p for p in (hertz_problem(y, r, name) for name, y, r in mres.contact_depths) if p]
        relay = result.relay
        coil = relay.get("energy") if relay else None
        if coil is not None:
            out["coil_relative_residual"] = coil["relative_residual"]
            problem = coil_energy_problem(coil["relative_residual"], scene.solver.energy_tolerance)
            if problem:
                problems.append(problem)
    bound = _circuit_current_bound(result.scene)
    waves = result.waveform_columns
    if bound is not None and waves is not None and len(waves["time"]) and "load_current" in waves:
        current = float(np.nanmax(np.abs(waves["load_current"])))
        out.update(max_load_current=current, load_current_bound=bound)
        problem = current_problem(current, bound)
        if problem:
            problems.append(problem)
    if mres is None and waves is not None and len(waves["time"]) and "contact_resistance" in waves:
        problems += schedule_contact_problems(result.scene, waves)
    out["problems"] = problems
    return out


BOILING_VOLTAGE_BOUND = 1.5  # V across a closed metallic contact: above every contact metal's boiling voltage
OPEN_VOLTAGE_BOUND = 3e5  # V across an open contact: air's ~3 MV/m across 0.1 m, a gap no switch has


def schedule_contact_problems(scene, waves: dict) -> list[str]:
    """A prescribed contact (no mechanics, no gap unless opening_speed is given) that its
    circuit drives beyond what a contact can be: closed, a voltage above BOILING_VOLTAGE_BOUND
    (Holm's boiling voltage of the a-spot: Ag 0.67 V, Cu 0.79 V, W 1.1 V; above it the spot
    boils and no metallic contact, whatever its resistance, carries the current); open, a
    voltage above OPEN_VOLTAGE_BOUND (air breaks down across any gap shorter than V / 3 MV/m;
    with opening_speed the breakdown warning judges the gap itself)."""
    r = np.asarray(waves["contact_resistance"], dtype=float)
    v = np.abs(np.asarray(waves["contact_voltage"], dtype=float))
    t = np.asarray(waves["time"], dtype=float)
    schedule = getattr(getattr(scene, "circuit", None), "schedule", None)
    closed_r = getattr(schedule, "closed_resistance", None)
    out = []
    if closed_r:
        closed = np.isfinite(r) & (r <= 2.0 * closed_r)
        if np.any(closed & (v > BOILING_VOLTAGE_BOUND)):
            k = int(np.argmax(np.where(closed, v, -np.inf)))
            current = v[k] / r[k]
            out.append(f"contact: {v[k]:.3g} V across the closed contact at {t[k]:.6g} s ({current:.3g} A through "
                       f"{r[k]:.3g} ohm), above the ~{BOILING_VOLTAGE_BOUND:g} V at which a contact spot boils "
                       "(Holm: Ag 0.67 V, Cu 0.79 V, W 1.1 V): no metallic contact carries that; lower the "
                       "source or raise the loop's resistance")
    open_ = ~np.isfinite(r)
    if np.any(open_ & (v > OPEN_VOLTAGE_BOUND)):
        k = int(np.argmax(np.where(open_, v, -np.inf)))
        out.append(f"contact: {v[k]:.3g} V across the open contact at {t[k]:.6g} s: air breaks down across any gap "
                   f"shorter than {v[k] / 3e6:.3g} m (~3 MV/m), far beyond a switch's; lower the source")
    return out


def _circuit_current_bound(scene) -> float | None:
    spec = getattr(scene, "circuit", None)
    circ = getattr(spec, "circuit", None)
    try:
        voltage = circ.source.amplitude  # an AC source's peak
        load = circ.load.load_resistance
        series = circ.source.source_resistance + circ.wiring.wiring_resistance + load
    except AttributeError:  # a netlist circuit: its topology is the user's
        return None
    fault = getattr(circ, "fault_resistance", None)  # circuit.ShortCircuit: the load shorted by it
    if fault is not None:
        series += load * fault / (load + fault) - load
    if getattr(circ, "arrangement", None) == "changeover":
        # load_current is the common's lead: NC's throw alone, or (make before break) both
        # throws in parallel; NO's load alone bounded a run on a smaller NC load as unsound
        nc = circ.nc_load_resistance if circ.nc_load_resistance is not None else load
        series += load * nc / (load + nc) - load
    return loop_current_bound(voltage, series) if series > 0 else None
