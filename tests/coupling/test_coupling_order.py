"""Co-simulation error against the monolithic reference falls with the macro step at the expected order.

The reference integrates mechanics and circuit in one stiff solve (no coupling error).
The scene (scenes/impact_inrush.toml) makes mu(I) matter: a capacitive inrush starts at
the make while the tip slides with Coulomb friction whose mu doubles with the current.
Mechanics-first with the current extrapolated linearly is second order (the step after a
make is H^2/H_free long, so the current jump costs O(H^2)); Jacobi with both sides held
is first order and sees the make a macro step late.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from coupling import load_scene, run
from coupling.core.monolithic import run_monolithic, series_loop

SCENE = Path(__file__).parent / "scenes" / "impact_inrush.toml"
STEPS = (4e-5, 2e-5, 1e-5, 5e-6)


@pytest.fixture(scope="module")
def reference():
    return run_monolithic(load_scene(SCENE))


def speed_error(result, reference) -> float:
    """m/s: largest difference of the centre-of-mass tangential speed over the run."""
    t = np.linspace(0.01, 1.0, 400) * reference.scene.t_end
    h, hr = result.mechanics.history, reference.mechanics.history
    return float(np.max(np.abs(np.interp(t, h.time, h.vx) - np.interp(t, hr.time, hr.vx))))


@pytest.fixture(scope="module")
def errors(reference):
    base = load_scene(SCENE)
    out = {}
    for scheme in ("mechanics_first", "jacobi"):
        out[scheme] = np.array([speed_error(run(base.set("coupling.scheme", scheme).set("coupling.macro_step", h)),
                                            reference) for h in STEPS])
    return out


def observed_order(errs) -> float:
    return float(np.polyfit(np.log(STEPS), np.log(errs), 1)[0])


def test_the_reference_is_a_series_loop_of_the_scene():
    loop = series_loop(load_scene(SCENE).circuit.circuit)
    assert loop.resistance == pytest.approx(5.0) and loop.load_capacitance == pytest.approx(10e-6)
    assert not loop.has_inductance


@pytest.mark.parametrize("template", ["bridge", "changeover"])
def test_the_reference_refuses_a_loop_of_several_contacts(template):
    """A bridge's two contacts in series (or a changeover's two throws) read as the one
    contact of a series loop would be a wrong reference, their load_inductance missed: refused
    with a one-line error before anything runs."""
    import circuit as ck

    cls = ck.BridgeCircuit if template == "bridge" else ck.ChangeoverCircuit
    with pytest.raises(ValueError, match="holds 2 contacts") as err:
        series_loop(cls(ck.DCSource(24.0), ck.ResistiveLoad(10.0)))
    assert "\n" not in str(err.value)


def test_current_and_friction_really_couple(reference):
    """Precondition: the inrush reaches amperes during the contact and mu moves with it."""
    w = reference.waveforms
    contact = w.normal_force > 0
    assert w.load_current[contact].max() > 3.0
    assert w.mu[contact].max() - w.mu[contact].min() > 0.3


def test_mechanics_first_error_falls_at_second_order(errors):
    order = observed_order(errors["mechanics_first"])
    assert order > 1.7, errors["mechanics_first"]
    assert np.all(np.diff(errors["mechanics_first"]) < 0)


def test_jacobi_is_first_order_and_less_accurate(errors):
    assert observed_order(errors["jacobi"]) < observed_order(errors["mechanics_first"]) - 0.3
    assert np.all(errors["jacobi"] > errors["mechanics_first"])


def test_jacobi_sees_the_make_a_macro_step_late(reference):
    """Held on the conductance at the step start, Jacobi closes the circuit one step late."""
    h = 2e-5
    res = run(load_scene(SCENE).set("coupling.scheme", "jacobi").set("coupling.macro_step", h))
    make = res.mechanics.contacts.t_start.iloc[0]
    w = res.waveforms
    first_current = w.time[w.load_current > 1.0].iloc[0]
    assert make < first_current <= make + h * (1 + 1e-9) + 1e-7
    ref_first = reference.waveforms.time[reference.waveforms.load_current > 1.0].iloc[0]
    assert ref_first == pytest.approx(make, abs=1e-7)


# --- the coil's channels: armature.force (psi^2 extrapolated) and coil.gap ------------------

COIL_STEPS = (2e-5, 1e-5, 5e-6, 2.5e-6)


def test_the_coil_channels_keep_second_order():
    """The plunger solenoid of examples/ pulled in (psi^2 into the mechanics, extrapolated by
    the step rules; the working gap into ngspice from the armature's dense output), at fixed
    macro steps halved three times: the armature's arrival at the pole (a located event) and
    its travel at 10 ms (mid-flight) converge at second order, neither less nor more
    (successive differences fall 4x per halving; measured orders 1.96 and 1.99, 2.00 and
    1.91). ngspice takes coupling.coil_step_points points per macro step, so its own error
    falls with the macro step too; at one point per step and its truncation control the
    orders over 80-10 us were erratic (2.3-3.9), and from 80 us down the convergence is not
    yet asymptotic (1.5-1.9 at the first halving)."""
    scene = load_scene(Path(__file__).parents[2] / "examples" / "plunger_solenoid.toml").set("solver.t_end", 0.014)
    values = []
    for h in COIL_STEPS:
        res = run(scene.update({"coupling.macro_step": h, "coupling.max_macro_step": h}))
        w = res.waveforms
        values.append((res.relay["armature_arrival"], float(np.interp(0.010, w.time, w.armature_position))))
    diffs = np.abs(np.diff(np.array(values), axis=0))
    orders = np.log2(diffs[:-1] / diffs[1:])
    assert np.all((orders > 1.8) & (orders < 2.2)), (values, orders)
