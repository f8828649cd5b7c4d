"""The exchange itself: mu follows the current as the law says; R_c in the circuit is the fitted law."""

from __future__ import annotations

import numpy as np
import pytest

from coupling import builtin_scene, run
from coupling.core.master import CoSimulation


def short(scene, t_end=2.3e-3):
    """The default scene over its four impacts."""
    return scene.set("solver.t_end", t_end)


@pytest.fixture(scope="module")
def default_run():
    sim = CoSimulation(short(builtin_scene("free_drop")))
    return sim, sim.run()


def test_without_current_mu_stays_at_mu0():
    # a 1 Mohm load: the contact closes but carries ~24 uA
    scene = short(builtin_scene("free_drop").set("circuit.load_resistance", 1e6))
    res = run(scene)
    laws = scene.tribology.laws
    mu0 = float(laws.mu(0.0))
    i_max = float(np.abs(res.waveforms.load_current).max())
    assert len(res.mechanics.contacts) >= 3 and i_max < 3e-5
    # mu stays within what the law allows over that current (~1e-5 of mu0), not mu(2 A)
    spread = float(laws.mu(i_max)) - mu0
    assert 0.0 <= spread < 1e-4 * mu0
    assert np.all(np.abs(res.waveforms.mu - mu0) <= 2.0 * spread + 1e-15)


def test_with_current_mu_is_the_law_at_the_extrapolated_current(default_run):
    """Each macro step starts from mu(I) of the current at its start (zero-order hold right
    after a jump, linear extrapolation otherwise); over the contacts mu moves with I."""
    sim, res = default_run
    laws = sim.scene.tribology.laws
    w = res.waveforms
    mu_at_2A = float(laws.mu(2.0))
    during = w[w.normal_force > 0]
    # closed on 12 ohm at 24 V: about 2 A, so mu is mu(2 A), not mu(0)
    assert during.load_current.median() == pytest.approx(2.0, rel=0.02)
    assert during.mu.median() == pytest.approx(mu_at_2A, rel=0.01)
    assert mu_at_2A > 1.3 * float(laws.mu(0.0))
    for t0, t1, m0, m1 in sim.mu_log:
        assert np.isfinite(m0) and np.isfinite(m1)
        assert min(m0, m1) >= float(laws.mu(0.0)) - 1e-12  # mu(I) >= mu(0) for this law


def test_feedback_off_keeps_mu0_even_with_current():
    scene = short(builtin_scene("free_drop").set("tribology.feedback", False))
    res = run(scene)
    assert res.waveforms.load_current.max() > 1.5
    np.testing.assert_allclose(res.waveforms.mu, float(scene.tribology.laws.mu(0.0)), rtol=1e-12)


def test_contact_resistance_in_the_circuit_is_the_fitted_law(default_run):
    """ngspice applies g(|I|) to the conductance the mechanics gives: the effective
    resistance at every closed point equals R_c(F_n, I) of the fit (two tips in parallel)."""
    sim, res = default_run
    laws = sim.scene.tribology.laws
    w = res.waveforms
    closed = w[(w.normal_force_0 > 1.0) & (w.normal_force_1 == 0.0)]
    assert len(closed) > 20
    expected = laws.contact_resistance(closed.normal_force_0.to_numpy(), closed.contact_current.to_numpy())
    # ngspice evaluates g(I) at its last Newton iterate, converged to its RELTOL: that is the
    # agreement to expect (the force part G_F(F(t)) it receives is exact, see below)
    reltol = sim.scene.circuit.options.reltol
    np.testing.assert_allclose(closed.contact_resistance, expected, rtol=2 * reltol)
    assert np.median(np.abs(closed.contact_resistance / expected - 1)) < 1e-2 * reltol



def test_conductance_is_zero_outside_the_contact_intervals(default_run):
    _, res = default_run
    w = res.waveforms
    iv = res.closed_intervals
    # at a make/break instant (within the stepper's 1e-12 relative window) ngspice has the left limit
    eps = 1e-12
    inside = np.zeros(len(w), bool)
    for a, b in iv:
        inside |= (w.time > a * (1 + eps)) & (w.time < b * (1 - eps))
    outside = np.ones(len(w), bool)
    for a, b in iv:
        outside &= (w.time < a * (1 - eps)) | (w.time > b * (1 + eps))
    assert np.all(w.contact_conductance[outside] == 0.0)
    # pressed (F_n > 0: not in the paper law's force clip) beyond the onset ramp (the
    # first 10 nm of penetration), the contact conducts
    onset = res.scene.coupling.onset_penetration
    beyond = ((w.penetration_0 > onset) | (w.penetration_1 > onset)) & (w.normal_force > 0)
    assert np.all(w.contact_conductance[inside & beyond] > 0.0)
    assert (inside & beyond).sum() > 100


def test_mu_does_not_overshoot_the_current_after_a_make(default_run):
    """After a make the loop current rises on its L/R time scale (~83 ns), far below a macro
    step: extrapolating a slope taken inside that rise over a full step gave mu(3.3 A) in a
    2 A circuit. The steps now follow the current's time scale: mu stays within the law's
    value at the largest current the circuit carried (this law rises with current)."""
    sim, res = default_run
    laws = sim.scene.tribology.laws
    w = res.waveforms
    assert w.mu.max() <= float(laws.mu(w.load_current.max())) * (1.0 + 1e-3)
