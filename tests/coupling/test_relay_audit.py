"""The coil's energy audit (coupling.core.relay, relay.energy) judged by the run's soundness:
a coil whose circuit flux disagrees with its magnet is unsound, the default relay is sound,
and the residual falls at second order with the circuit's step through the coil's rise."""

from __future__ import annotations

import numpy as np

from coupling import default_scene, run
from coupling.core.device import DeviceSpec


def tolerance(result) -> float:
    """solver.energy_tolerance of the run's scene (its mechanics' parameters)."""
    return result.mechanics.model.scene.solver.energy_tolerance


def coil_problems(result) -> list[str]:
    return [p for p in result.problems if p.startswith("coil energy audit")]


def test_the_default_relay_is_sound_and_its_coil_audit_is_within_tolerance():
    res = run(default_scene())
    e = res.relay["energy"]
    assert e["into_coil"] > 0 and e["copper"] > 0
    assert e["relative_residual"] <= tolerance(res)
    assert res.soundness["coil_relative_residual"] == e["relative_residual"]
    assert res.status == "ok" and not coil_problems(res), res.problems


def test_a_coil_circuit_carrying_5_percent_too_much_current_is_unsound(monkeypatch):
    """The circuit's coil drawn with i = 1.05 i(psi, g), the magnet (force, stored energy)
    unchanged: i d(psi) is no longer the magnet's exact differential, and 5 % of the energy
    the magnet passes on (its armature work, here ~1/3 of what enters the coil) stays
    unaccounted, some 1e-2 of the energy into the coil, far above the tolerance (1e-3)."""
    law = DeviceSpec.current_law
    monkeypatch.setattr(DeviceSpec, "current_law", lambda self: f"{law(self)} + 0.05*({law(self)})")
    res = run(default_scene())
    assert res.relay["energy"]["relative_residual"] > 5 * tolerance(res)
    assert res.status == "unsound"
    (line,) = coil_problems(res)
    assert "solver.energy_tolerance" in line and "max_macro_step" in line and "\n" not in line


def test_the_coil_residual_falls_at_second_order_with_the_circuits_step():
    """The audit's quadrature is the circuit's (the current's trapezoid against the flux's
    increments and the trapezoid of F in the gap, path integrals of the magnet's exact
    co-energy differential), so what is left is the flux's integration error: second order in
    the spacing of the points where the coil moves fastest, its rise. With one point per
    macro step at least (coupling.coil_step_points = 1), coupling.coil_point_fraction of the
    coil's time constant (3.0 ms) sets that spacing, 60 .. 15 us here (at 0.08, 240 us,
    ngspice's own t_end / 50 bounds it instead: the residual 8.9e-4 then, as before the rule).

    The coil stays on to the end (coil.off_time after t_end): the switch-off's share of the
    residual (2e-5 .. 9e-5 of the energy into the coil) is set by the release's macro steps,
    which coil_point_fraction does not bound, and it has the other sign. Over the whole run
    the two shares summed to -3.0e-4, -8.2e-5 and +2.0e-5 at fractions 0.04, 0.02, 0.01: an
    order of 1.9 and 2.1 that was their cancellation, while the rise's own share fell at 1.3
    and 1.6 over that coarser range."""
    fractions = (0.02, 0.01, 0.005)
    residuals = [abs(run(default_scene().update({"coil.off_time": 0.02, "coupling.coil_step_points": 1,
                                                 "coupling.coil_point_fraction": f}))
                     .relay["energy"]["relative_residual"]) for f in fractions]
    orders = np.log(np.array(residuals[:-1]) / residuals[1:]) / np.log(2.0)
    # measured orders 1.54 and 2.60 (2.1 over the four-fold refinement); a first-order audit
    # (F at the step's start in the gap) gave 0.4 and 0.6 under the macro step cap that set
    # the spacing before
    assert np.all(orders > 1.5) and orders.mean() > 1.8, (residuals, orders)
    # and the defaults (two points per macro step, 1/80 of the time constant) leave the
    # residual at a twentieth of solver.energy_tolerance and below (measured 3.3e-5 of 1e-3)
    res = run(default_scene())
    assert abs(res.relay["energy"]["relative_residual"]) < 0.1 * tolerance(res)


def test_a_coil_audit_above_the_tolerance_but_within_five_times_it_is_a_warning():
    """The default relay run to 20 ms with ngspice at its own steps in the coil (one point per
    macro step at least, no bound from the coil's L/R: coupling.coil_step_points = 1,
    coil_point_fraction = 1) and the coil's macro steps at twice their time-scale fraction
    (0.2: with psi^2's curvature bounding the steps after the switch-on, the default fraction
    left this audit at the tolerance itself, 1.0005e-3): ngspice steps as long as the macro
    steps through the coil's rise, and the audit leaves 2.1e-3 of the energy into the coil
    (3.3e-5 at the default rules):
    above solver.energy_tolerance, below five times it. The run stays "ok" and carries one
    warning naming the key and what to cap (as Hertz's validity: warned from 1 %, unsound from
    5 %); a coil drawing 5 % too much current (the test above, 1.5e-2) is unsound."""
    own_steps = {"solver.t_end": 0.02, "coupling.coil_step_points": 1, "coupling.coil_point_fraction": 1.0,
                 "coupling.coil_time_scale_fraction": 0.2}
    res = run(default_scene().update(own_steps))
    rel = res.relay["energy"]["relative_residual"]
    assert tolerance(res) < rel <= 5 * tolerance(res), rel
    assert res.status == "ok" and not coil_problems(res), res.problems
    (line,) = [w for w in res.warnings if w.startswith("coil energy audit")]
    assert "solver.energy_tolerance" in line and "max_macro_step" in line and "\n" not in line
