"""Names and SI units of what the plots draw: waveform and history columns, summary.json
keys as a sweep flattens them ("bounce.peak_contact_voltage"), and scene keys
("circuit.snubber.capacitance"). One table, read by the run plots, the waveform page and
the sweep plots, so an axis says the same quantity and unit wherever it appears.

Units are written as in docs/scene_keys.md ("ohm", "N/m^1.5"); "-" marks a pure number (a
ratio, a count, a setting). The scene keys' units are those of docs/scene_keys.md's unit
column (tests/coupling/test_plot_units.py compares the two).
"""

from __future__ import annotations

import re
from mech.frozen import frozen


@frozen
class Quantity:
    """What an axis shows: ``name`` (words) and ``unit`` (SI, "-" for a pure number)."""

    name: str
    unit: str

    def label(self, unit: str | None = None) -> str:
        """"name (unit)"; ``unit`` replaces the SI unit where the plot scales the values (mm, ms)."""
        return f"{self.name} ({unit or self.unit})"


# waveforms.csv/.parquet columns, the mechanics' history columns drawn, and the derived
# series the plots compute (abs_voltage, arc_power)
WAVEFORM = {
    "time": Quantity("time", "s"),
    "contact_voltage": Quantity("contact voltage", "V"),
    "abs_voltage": Quantity("|contact voltage|", "V"),
    "contact_current": Quantity("contact current", "A"),
    "load_current": Quantity("load current", "A"),
    "arc_current": Quantity("arc current", "A"),
    "current": Quantity("current", "A"),
    "contact_resistance": Quantity("contact resistance", "ohm"),
    "contact_conductance": Quantity("contact conductance", "S"),
    "normal_force": Quantity("normal force", "N"),
    "penetration": Quantity("penetration", "m"),
    "gap": Quantity("gap", "m"),
    "tip_height": Quantity("contact point height", "m"),
    "mu": Quantity("friction coefficient", "-"),
    "arc_power": Quantity("arc power |V i_arc|", "W"),
    "probe_voltage": Quantity("probe voltage", "V"),
    "probe_current": Quantity("probe current", "A"),
    "energy": Quantity("energy", "J"),
    "coil_current": Quantity("coil current", "A"),
    "coil_voltage": Quantity("coil voltage", "V"),
    "coil_flux_linkage": Quantity("coil flux linkage", "Wb"),
    "armature_position": Quantity("armature travel", "m"),
    "working_gap": Quantity("working air gap", "m"),
    "magnetic_force": Quantity("magnetic force", "N"),
}

# summary.json scalars, flattened with dots as a sweep's results rows hold them
# (coupling.app.sweep.flatten_summary); docs/coupling.md and docs/mechanics.md say what each is
_SUMMARY = {
    "restitution": {"kinematic": ("kinematic restitution", "-"), "energetic": ("energetic restitution", "-")},
    "energy": {**{k: (k.replace("_", " ") + " energy", "J") for k in (
        "initial", "kinetic", "elastic", "potential_change", "contact_stored", "spring_stored")},
        **{k: (k.replace("_", " "), "J") for k in (
            "normal_dissipation", "friction_dissipation", "modal_dissipation", "load_dissipation", "work_in")},
        "residual": ("energy residual", "J"), "relative_residual": ("relative energy residual", "-")},
    "solver": {"steps": ("solver steps", "-"), "rejected_steps": ("rejected solver steps", "-"),
               "rhs_evals": ("right-hand-side evaluations", "-"), "events": ("solver events", "-"),
               "wall_time": ("mechanics wall time", "s"), "modes": ("elastic modes", "-"),
               "states": ("solver states", "-"), "damping": ("contact damping c", "N s/m^2(.5)"),
               "stiffness": ("contact stiffness k", "N/m^1.5"), "history.rows": ("history rows kept", "-"),
               "history.resolution": ("history resolution", "s"),
               "history.thinned_until": ("history thinned until", "s")},
    "bounce": {"first_make": ("first make", "s"), "last_make": ("last make", "s"), "bounces": ("bounces", "-"),
               "total_bounce_time": ("total bounce time", "s"), "settle_window": ("settle window", "s"),
               "settle_time": ("settle time", "s"), "peak_contact_voltage": ("peak contact voltage", "V"),
               "peak_bounce_voltage": ("peak bounce voltage", "V"),
               "peak_final_opening_voltage": ("peak final-opening voltage", "V"),
               "arc_energy": ("arc energy", "J"), "arc_toggles": ("arc toggles", "-"),
               "final_opening.break_time": ("final break time", "s"),
               "final_opening.current_at_break": ("current at the final break", "A"),
               "final_opening.arc_duration": ("final arc duration", "s"),
               "final_opening.arc_energy": ("final-opening arc energy", "J"),
               "final_opening.peak_voltage": ("final-opening peak voltage", "V")},
    "relay": {"operate_time": ("operate time", "s"), "release_time": ("release time", "s"),
              "pull_in_current": ("pull-in current", "A"), "drop_out_current": ("drop-out current", "A"),
              "armature_arrival": ("armature arrival at the pole", "s"),
              "energy.into_coil": ("energy into the coil", "J"), "energy.copper": ("coil copper loss", "J"),
              "energy.magnetic_change": ("change of magnetic energy", "J"),
              "energy.armature_work": ("magnetic work on the armature", "J"),
              "energy.residual": ("coil energy residual", "J"),
              "energy.relative_residual": ("relative coil energy residual", "-"),
              "energy.armature_received": ("work the armature received from its drive", "J"),
              "energy.interface_residual": ("coil-armature interface residual", "J"),
              "energy.interface_relative_residual": ("relative coil-armature interface residual", "-")},
    "logic": {"low": ("logic low threshold", "V"), "high": ("logic high threshold", "V"),
              "edges": ("logic edges", "-"), "rising_edges": ("rising logic edges", "-"),
              "falling_edges": ("falling logic edges", "-"), "first_edge": ("first logic edge", "s"),
              "last_edge": ("last logic edge", "s"), "edge_burst": ("logic edge burst", "s"),
              "stable_margin": ("logic stable margin", "V")},
    "run": {"macro_steps": ("macro steps", "-"), "aligned_steps": ("aligned macro steps", "-"),
            "approach_steps": ("macro steps redone to approach an armature's unseat", "-"),
            "contact_steps": ("macro steps in contact", "-"), "mech_seconds": ("mechanics time", "s"),
            "circuit_seconds": ("circuit time", "s"), "wall_time": ("run wall time", "s"),
            "circuit.steps": ("circuit steps", "-"), "circuit.points": ("circuit points", "-"),
            "circuit.conductance_calls": ("conductance calls", "-"), "circuit.gap_calls": ("gap calls", "-"),
            "circuit.ngspice_seconds": ("ngspice time", "s"), "circuit.arc_switches": ("arc switches", "-"),
            "circuit.coil_gap_calls": ("coil gap calls", "-")},
    # a changeover's (coupling.core.arrangement.changeover_metrics)
    "changeover": {"transfer_time": ("transfer time (NC break to NO make)", "s"),
                   "release_transfer_time": ("release transfer time (NO break to NC make)", "s"),
                   "overlap_time": ("both throws closed", "s")},
    "soundness": {"energy_scale": ("energy scale", "J"), "relative_residual": ("relative energy residual", "-"),
                  "max_kinetic": ("largest kinetic energy", "J"), "max_speed": ("largest speed", "m/s"),
                  "speed_bound": ("speed bound", "m/s"), "max_penetration": ("largest penetration", "m"),
                  "penetration_bound": ("penetration bound", "m"),
                  "max_load_current": ("largest load current", "A"),
                  "load_current_bound": ("load current bound", "A"),
                  "coil_relative_residual": ("relative coil energy residual", "-")},
    "duty": {"conductor_radius": ("conductor radius", "m"), "blow_off_current": ("blow-off current", "A"),
             "held_force": ("held normal force", "N"), "contact_resistance": ("held contact resistance", "ohm"),
             "arc_energy": ("arc energy by stage", "J"),
             **{f"{side}_{k}": (f"{side} contact's {w}", u) for side in ("moving", "fixed") for k, w, u in (
                 ("anodic_energy", "anodic-stage arc energy", "J"),
                 ("cathodic_energy", "cathodic-stage arc energy", "J"),
                 ("eroded_volume", "eroded volume", "m^3"), ("eroded_mass", "eroded mass", "kg"))}},
    # a life study's outcome, as `switchsim life SWEEP.toml` rows hold it (coupling.app.life)
    "life": {"operations": ("operations asked", "-"), "every": ("sampled every", "-"), "samples": ("samples", "-"),
             "operations_done": ("operations done", "-"),
             "moving_worn_volume": ("moving contact's worn volume", "m^3"),
             "fixed_worn_volume": ("fixed contact's worn volume", "m^3"),
             "moving_cap_height": ("moving cap height", "m"), "moving_cap_radius": ("moving cap radius", "m"),
             "fixed_cap_height": ("fixed cap height", "m"), "fixed_cap_radius": ("fixed cap radius", "m"),
             "gap": ("contact gap", "m"), "held_force": ("held normal force", "N"),
             "contact_resistance": ("held contact resistance", "ohm"), "bounce_time": ("bounce time", "s"),
             "gap_low": ("least gap", "m"), "gap_high": ("largest gap", "m"), "min_force": ("least held force", "N"),
             "max_resistance": ("largest held resistance", "ohm")},
    # the armature's motion (coupling.core.relay; docs/mechanics.md): its own coordinate q
    "armature": {"first_arrival": ("armature's first arrival at the pole", "s"),
                 "last_arrival": ("armature's last arrival at the pole", "s"),
                 "left_pole": ("armature left the pole", "s"), "pole_bounces": ("armature pole bounces", "-"),
                 "arrival_speed": ("armature arrival speed", "m/s or rad/s")},
    # the first operation as a sweep row holds it (coupling.app.sweep.flatten_summary;
    # docs/coupling.md "Operations", docs/contact_duty.md "In a run")
    "operations.0": {
        "make.time": ("make", "s"), "make.bounces": ("make bounces", "-"),
        "make.bounce_time": ("make bounce time", "s"),
        "make.settle_time": ("make settle time", "s"), "make.peak_current": ("make peak current (inrush)", "A"),
        "make.i2t": ("make i^2 t", "A^2 s"), "make.arc_energy": ("make arc energy", "J"),
        "make.make_energy": ("make energy in the contact", "J"),
        "break.time": ("break", "s"), "break.current_at_break": ("current at the break", "A"),
        "break.arc_duration": ("break arc duration", "s"), "break.arc_energy": ("break arc energy", "J"),
        "break.peak_voltage": ("break peak voltage", "V"),
        "break.more_time_needed": ("time the break's arc still needed", "s"),
        "held.start": ("held closure's start", "s"), "held.end": ("held closure's end", "s"),
        "held.current": ("held contact current", "A"), "held.force": ("held contact force", "N"),
        "held.contact_resistance": ("held contact resistance", "ohm"),
        "held.contact_voltage": ("held contact voltage", "V"), "held.spot_radius": ("held a-spot radius", "m"),
        "held.conductor_radius": ("conductor radius", "m"), "held.blow_off_current": ("blow-off current", "A"),
        "held.shrinking_blow_off_current": ("blow-off current, spot shrinking with the force", "A"),
        "make.weld.held_force": ("weld verdict's held force", "N"),
        "make.weld.held_voltage": ("weld verdict's held contact voltage", "V"),
        "make.weld.held_hot_voltage": ("held hot contact voltage", "V"), "make.weld.margin": ("weld margin", "-"),
        "make.weld.melting_voltage": ("melting voltage", "V"), "make.weld.opening_force": ("opening force", "N"),
        "make.weld.peak_current": ("weld verdict's peak current", "A"),
        "make.weld.welding_current": ("welding current", "A"),
        **{f"make.weld.ratios.{k}": (f"weld ratio, {w}", "-") for k, w in (
            ("static", "static"), ("held_spot", "held spot"), ("separation", "bounce separations"))},
        "erosion.arc_energy": ("arc energy by stage", "J"),
        **{f"erosion.{side}.{k}": (f"{side} contact's {w}", u) for side in ("moving", "fixed") for k, w, u in (
            ("anodic", "anodic-stage arc energy", "J"), ("cathodic", "cathodic-stage arc energy", "J"),
            ("loss_volume", "volume lost", "m^3"), ("net_volume", "net eroded volume", "m^3"),
            ("net_mass", "net eroded mass", "kg"))}},
    # (the fitted laws' parameters: tribology_quantity, from the law families' own units)
    "tribology": {"laws.mu.gamma": ("friction exponent gamma", "-"),
                  "laws.resistance.spots": ("contact spots", "-"),
                  "laws.resistance.radius": ("rivet radius of the material law", "m"),
                  "laws.resistance.film_resistivity": ("film resistivity", "ohm m^2")},
}
# columns a sweep adds to every row (coupling.app.sweep)
_SWEEP = {"wall_time": ("wall time", "s"), "stopped_at": ("where the run stopped", "s"), "finished_at": ("finish time since 1970 (Unix time)", "s")}
SUMMARY = {f"{section}.{key}": Quantity(*v) for section, keys in _SUMMARY.items() for key, v in keys.items()}
SUMMARY.update({key: Quantity(*v) for key, v in _SWEEP.items()})

# docs/scene_keys.md's unit column: section -> key -> unit
SCENE = {
    "bar": {"length": "m", "diameter": "m", "width": "m", "thickness": "m", "tip_radius": "m",
            "youngs_modulus": "Pa", "poisson_ratio": "-", "density": "kg/m^3", "modes": "-", "bending": "-",
            "modal_damping": "-"},
    "block": {"youngs_modulus": "Pa", "poisson_ratio": "-", "shape": "-", "radius": "m", "offset": "m"},
    "mount": {"kind": "-", "position": "m", "base_motion": "s, m", "stiffness": "N m/rad",
              "preload_torque": "N m", "damping": "N m s/rad"},
    "force": {"position": "m", "direction": "-", "frame": "-", "magnitude": "N", "time": "s", "value": "N",
              "interpolation": "-", "travel": "m", "share": "-"},
    "spring": {"anchor": "m", "position": "m", "stiffness": "N/m", "preload": "N", "rest_length": "m",
               "damping": "N s/m", "travel": "m", "force": "N", "release_force": "N",
               "between": "-", "lever": "m per m or rad"},
    "rivet": {"position": "m", "offset": "m", "radius": "m", "mass": "kg", "youngs_modulus": "Pa",
              "poisson_ratio": "-", "name": "-"},
    "fixed": {"point": "-", "name": "-", "shape": "-", "radius": "m", "offset": "m", "facing": "-", "height": "m",
              "gap": "m", "youngs_modulus": "Pa", "poisson_ratio": "-", "electrical": "-"},
    "initial": {"height": "m", "angle_deg": "deg", "azimuth_deg": "deg", "velocity": "m/s",
                "angular_velocity": "rad/s", "resting": "-"},
    "contact": {"law": "-", "restitution": "-", "damping": "N s/m^2(.5)", "reference_speed": "m/s",
                "calibration": "-", "stiffness": "N/m^1.5"},
    "friction": {"mu": "N^gamma", "gamma": "-", "model": "-", "max_ratio": "-", "regularization_speed": "m/s"},
    "solver": {"t_end": "s", "rtol": "-", "model": "-", "max_step": "s", "stick_velocity_tol": "m/s",
               "energy_tolerance": "-", "max_steps": "-", "history_rows": "-"},
    "environment": {"gravity": "m/s^2"},
    "armature": {"kind": "-", "mass": "kg", "inertia": "kg m^2", "travel": "m or rad", "spring_rate": "N/m or N m/rad",
                 "spring_preload": "N or N m", "stop_stiffness": "N/m or N m/rad",
                 "stop_damping": "N s/m or N m s/rad", "damping": "N s/m or N m s/rad",
                 "initial_position": "m or rad", "initial_speed": "m/s or rad/s", "card_position": "m",
                 "card_lever": "m/m or m/rad", "card_free_travel": "m", "card_stiffness": "N/m",
                 "card_damping": "N s/m", "force_gain": "m or rad, -"},
    "coil": {"voltage": "V", "on_time": "s", "off_time": "s", "suppression": "-", "zener_voltage": "V",
             "rc_resistance": "ohm", "rc_capacitance": "F", "switch_resistance": "ohm", "switch_capacitance": "F",
             "switch_breakdown": "V", "edge_time": "s", "resistance": "ohm", "turns": "-"},
    "magnet": {"model": "-", "rest_gap": "m", "lever": "m/m or m/rad", "working_gap": "-", "pole_leakage": "-",
               "iron": "-", "fixed_gap": "-", "currents": "A", "gaps": "m", "flux_linkages": "Wb", "forces": "N",
               "force_tolerance": "-"},
    "tribology": {"source": "-", "fit": "path", "data": "path", "mu": "N^gamma", "resistance": "-",
                  "feedback": "-"},
    "circuit": {"template": "-", "voltage": "V", "source_resistance": "ohm", "frequency": "Hz", "phase_deg": "deg",
                "current": "A", "compliance_voltage": "V", "output_capacitance": "F", "output_resistance": "ohm",
                "wiring_resistance": "ohm", "wiring_inductance": "H", "load_resistance": "ohm",
                "nc_load_resistance": "ohm", "nc_load_inductance": "H",
                "load_inductance": "H", "load_capacitance": "F", "bleed_resistance": "ohm",
                "contact_capacitance": "F", "leakage_conductance": "S", "snubber": "-", "flyback": "-", "arc": "-",
                "netlist": "path", "load_probe": "-", "probes": "-", "max_step": "s", "reltol": "-", "abstol": "A",
                "vntol": "V", "chgtol": "C", "temperature": "degC", "method": "-", "wall_timeout": "s",
                "schedule": "-", "pull": "-", "pull_resistance": "ohm", "series_resistance": "ohm",
                "input_capacitance": "F", "logic_low": "V", "logic_high": "V", "fault_time": "s",
                "fault_resistance": "ohm", "fault_rise": "s", "params": "-"},
    "circuit.snubber": {"resistance": "ohm", "capacitance": "F"},
    "circuit.flyback": {"saturation_current": "A", "emission_coefficient": "-", "series_resistance": "ohm"},
    "circuit.arc": {"min_voltage": "V", "min_current": "A", "resistance": "ohm", "formation_time": "s",
                    "breakdown_voltage": "V", "column_gradient": "V/m", "breakdown_gradient": "V/m",
                    "characteristic": "-", "ayrton_c": "W", "ayrton_d": "W/m", "time_constant": "s"},
    "circuit.schedule": {"make": "s", "break": "s", "closed_resistance": "ohm", "edge_time": "s",
                         "opening_speed": "m/s"},
    "coupling": {"scheme": "-", "macro_step": "s", "max_macro_step": "s", "align_events": "-",
                 "onset_penetration": "m", "time_scale_fraction": "-", "coil_time_scale_fraction": "-",
                 "gap_change_fraction": "-", "coil_step_points": "-",
                 "coil_point_fraction": "-"},
    "output": {"csv": "-", "parquet": "-", "plots": "-", "history": "-", "html": "-", "history_resolution": "s",
               "history_max_rows": "-"},
    "metrics": {"settle_window": "s", "make_guard": "s", "arc_toggle_limit": "-", "logic": "-"},
    "duty": {"materials": "-", "moving_node": "-", "repulsion": "-", "conductor_radius": "m", "transition_gap": "m",
             "transfer_fraction": "-", "erosion_coefficient": "m^3/J", "weld_margin": "-", "melt_fraction": "-",
             "cap_height": "m", "life": "-"},
    "duty.life": {"gap_range": "m", "min_force": "N", "max_resistance": "ohm", "stop_on_weld": "-"},
}


def scene_quantity(key: str) -> Quantity | None:
    """A scene key as a sweep names it ("circuit.snubber.capacitance", "initial.angle_deg"):
    its words (the key's parts, a unit suffix dropped) and unit; None when the key is not in
    docs/scene_keys.md's table."""
    section, _, last = re.sub(r"\[\d+\]", "", key).rpartition(".")  # rivet[0].mass: a [[rivet]] key
    unit = SCENE.get(section, {}).get(last)
    if unit is None:
        return None
    words = re.sub(r"_deg$", "", key).replace(".", " ").replace("_", " ")
    return Quantity(words, unit)


def waveform_quantity(column: str) -> Quantity | None:
    """A waveform or history column ("contact_voltage", "normal_force_1", "load_current_NO",
    "v(snubber)")."""
    if column in WAVEFORM:
        return WAVEFORM[column]
    base = re.sub(r"_[01]$", "", column)  # per contact point: normal_force_0 -> normal_force
    if base != column and base in WAVEFORM:
        q = WAVEFORM[base]
        return Quantity(f"{q.name}, contact point {column[-1]}", q.unit)
    named = re.fullmatch(r"(\w+)_([A-Za-z][A-Za-z0-9]*)", column)  # a named contact's: load_current_NO
    if named and named.group(1) in WAVEFORM:
        q = WAVEFORM[named.group(1)]
        return Quantity(f"{q.name}, {named.group(2)}", q.unit)
    if column[:2].lower() == "v(":
        return Quantity(column, "V")
    if column[:2].lower() == "i(":
        return Quantity(column, "A")
    return None


def tribology_quantity(key: str) -> Quantity | None:
    """A fitted law's parameter in the summary ("tribology.laws.mu.params.dmu"), its unit
    from the law families (coupling.laws.tribology.models: "1" there is "-" here)."""
    m = re.fullmatch(r"tribology\.laws\.(mu|resistance)\.params\.(\w+)", key)
    if m is None:
        return None
    from coupling.laws.tribology.models import CURRENT_FAMILIES, LOAD_FAMILIES, MU_FAMILIES

    families = (MU_FAMILIES,) if m.group(1) == "mu" else (LOAD_FAMILIES, CURRENT_FAMILIES)
    for family in families:
        for law in family.values():
            if m.group(2) in law.parameters:
                unit = law.units[law.parameters.index(m.group(2))]
                return Quantity(f"{m.group(1)} law {m.group(2)}", "-" if unit == "1" else unit)
    return None


def quantity(key: str) -> Quantity | None:
    """Any column a plot may draw: a summary key, a scene key or a waveform column; None if unknown."""
    return SUMMARY.get(key) or scene_quantity(key) or waveform_quantity(key) or tribology_quantity(key)


def label(key: str) -> str:
    """An axis label with its unit; a column no table knows keeps its name and says the unit
    is not known (rather than passing for a pure number)."""
    q = quantity(key)
    return q.label() if q is not None else f"{key} (unit unknown)"


def value_text(key: str, value) -> str:
    """"snubber capacitance = 1e-07 F": a legend entry for one value of a key."""
    q = quantity(key)
    number = f"{value:.3g}" if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)
    if q is None:
        return f"{key} = {number}"
    return f"{q.name} = {number}" + ("" if q.unit == "-" else f" {q.unit}")
