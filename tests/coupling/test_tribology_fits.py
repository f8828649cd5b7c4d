"""The fits against data made with known laws: recovery within the intervals, model selection, Coulomb vs gamma.

Every statistical claim is checked over several seeds with a stated pass count, so
no test rests on one lucky draw. Rates measured over 100 other seeds while writing
these tests: BIC chose the true mu(I) model in 94-100 % of draws and the true
identifiable R_c model in 89-100 % (the misses are nested models with one superfluous
parameter, BIC's known small-sample rate). The pass counts are set so that a selection
working at those rates fails a 10-seed check < 2 % of the time (binomial), while one
right only half the time passes it < 17 % of the time.
"""

import numpy as np
import pytest

from coupling.laws.tribology import ContactLaws, MuLaw, ResistanceLaw, default_fit, fit_tribometer
from coupling.laws.tribology.fits import fit_friction, fit_resistance
from coupling.laws.tribology.illustrative import ILLUSTRATIVE_DESIGN, ILLUSTRATIVE_LAWS, synthetic_tribometer_data

DESIGN = ILLUSTRATIVE_DESIGN
MU_TRUE = ILLUSTRATIVE_LAWS.mu_law
R_TRUE = ILLUSTRATIVE_LAWS.resistance_law


def data(mu_law=MU_TRUE, r_law=R_TRUE, seed=0, design=DESIGN):
    return synthetic_tribometer_data(ContactLaws(mu_law, r_law), design, np.random.default_rng(seed))


def covered(estimate, truth):
    return estimate.ci95 is not None and estimate.ci95[0] <= truth <= estimate.ci95[1]


def check_coverage_and_honest_errors(fits, truths, n_seeds):
    """95 % intervals contain the truth in >= 80 % of seeds, and the reported standard
    errors match the seed-to-seed spread of the estimates within a factor 1.4."""
    for name, truth in truths.items():
        est = [m.estimate(name) for m in fits]
        hits = sum(covered(e, truth) for e in est)
        assert hits >= 0.8 * n_seeds, f"{name}: truth {truth} inside the 95 % CI in only {hits}/{n_seeds} seeds"
        spread = np.std([e.value for e in est], ddof=1)
        reported = np.sqrt(np.mean([e.stderr**2 for e in est if e.stderr is not None]))
        assert 1 / 1.4 < reported / spread < 1.4, f"{name}: stderr {reported:.3g} vs spread {spread:.3g}"
        assert abs(np.mean([e.value for e in est]) - truth) < 3 * spread / np.sqrt(n_seeds) + 0.02 * abs(truth)


def test_friction_fit_recovers_gamma_and_mu_law_within_intervals():
    n = 30
    fits = [fit_friction(data(seed=100 + s), mu_models=["saturating_exponential"]).mu_selection.chosen
            for s in range(n)]
    check_coverage_and_honest_errors(fits, {"gamma": 0.7, **dict(MU_TRUE.params)}, n)


def test_per_current_mu_intervals_cover_the_true_mu():
    n = 30
    hits = 0
    for s in range(n):
        fr = fit_friction(data(seed=200 + s), mu_models=["constant"])
        hits += sum(c.ci95[0] <= MU_TRUE(c.current_A) <= c.ci95[1] for c in fr.per_current)
    assert hits >= 0.85 * 4 * n


@pytest.mark.parametrize("r_law", [
    R_TRUE,
    ResistanceLaw("power_law", "hyperbolic", (("r_1N_ohm", 0.03), ("load_exponent", 0.45), ("current_scale_A", 3.0)), (0.0, 5.0)),
], ids=["holm_elastic_film+exponential_floor", "power_law+hyperbolic"])
def test_resistance_fit_recovers_parameters_within_intervals(r_law):
    n = 30
    fits = [fit_resistance(data(r_law=r_law, seed=300 + s), candidates=[(r_law.load_model, r_law.current_model)]).selection.chosen
            for s in range(n)]
    check_coverage_and_honest_errors(fits, dict(r_law.params), n)


MU_TRUTHS = {
    "constant": MuLaw(0.7, "constant", (("mu0", 0.25),), (0.0, 5.0)),
    "linear": MuLaw(0.7, "linear", (("mu0", 0.2), ("slope_per_A", 0.03)), (0.0, 5.0)),
    "saturating_exponential": MU_TRUE,
    "power_law": MuLaw(0.7, "power_law", (("mu0", 0.15), ("coeff", 0.08), ("exponent", 0.5)), (0.0, 5.0)),
}


@pytest.mark.parametrize("truth", list(MU_TRUTHS))
def test_selection_picks_the_true_mu_model(truth):
    n = 10
    chosen = [fit_friction(data(mu_law=MU_TRUTHS[truth], seed=400 + s)).mu_selection.chosen.name for s in range(n)]
    assert chosen.count(truth) >= 8, chosen  # P(fail) = 1.9 % at a 94 % rate


R_TRUTHS = {
    "holm_plastic+hyperbolic": ResistanceLaw(
        "holm_plastic", "hyperbolic", (("r_1N_ohm", 0.03), ("current_scale_A", 4.0)), (0.0, 5.0)),
    "power_law+exponential_floor": ResistanceLaw(
        "power_law", "exponential_floor",
        (("r_1N_ohm", 0.05), ("load_exponent", 0.8), ("current_scale_A", 1.0), ("floor_fraction", 0.5)), (0.0, 5.0)),
    "holm_elastic+none": ResistanceLaw("holm_elastic", "none", (("r_1N_ohm", 0.02),), (0.0, 5.0)),
}


@pytest.mark.parametrize("truth", list(R_TRUTHS))
def test_selection_picks_the_true_resistance_model_when_the_loads_can_tell(truth):
    n = 10
    chosen = [fit_resistance(data(r_law=R_TRUTHS[truth], seed=500 + s)).selection.chosen.name for s in range(n)]
    assert chosen.count(truth) >= 7, chosen  # P(fail) = 1.8 % at an 89 % rate


def test_film_laws_that_3_to_8_N_cannot_separate_are_reported_as_ambiguous():
    # Holm elastic + film differs from plastic + film and from a free power law by ~0.2 %
    # over 3-8 N (docs/tribology.md), far below 4 % scatter: the selection must say so.
    n = 8
    candidates = [(lm, "exponential_floor") for lm in ("holm_elastic", "holm_plastic", "holm_elastic_film",
                                                         "holm_plastic_film", "power_law")]
    truth = "holm_elastic_film+exponential_floor"
    for s in range(n):
        sel = fit_resistance(data(seed=600 + s), candidates=candidates).selection
        assert truth == sel.chosen.name or truth in sel.ambiguous
        assert sel.chosen.name not in ("holm_elastic+exponential_floor", "holm_plastic+exponential_floor")


def test_power_law_friction_is_preferred_over_coulomb_for_gamma_07():
    for s in range(10):
        test = fit_friction(data(seed=700 + s), mu_models=["constant"]).coulomb_test
        assert test.preferred == "power_law" and test.rejects_coulomb() and test.delta_bic > 10


def test_coulomb_data_do_not_reject_coulomb():
    coulomb = MuLaw(0.0, "saturating_exponential", (("mu0", 0.08), ("dmu", 0.05), ("current_scale_A", 1.5)), (0.0, 5.0))
    n = 20
    tests = [fit_friction(data(mu_law=coulomb, seed=800 + s), mu_models=["constant"]).coulomb_test for s in range(n)]
    # an exact F-test rejects a true null in 5 % of cases: expect ~1 of 20
    assert sum(t.rejects_coulomb() for t in tests) <= 3
    assert sum(t.preferred == "coulomb" for t in tests) >= 17
    gammas = [t.power_law.estimate("gamma") for t in tests]
    assert sum(covered(g, 0.0) for g in gammas) >= 17


def test_lack_of_fit_flags_a_wrong_mu_model_and_not_the_true_one():
    fits = [fit_friction(data(seed=900 + s)).mu_selection for s in range(6)]
    assert all(f.candidate("constant").lack_of_fit_p < 1e-6 for f in fits)
    assert sum(f.candidate("saturating_exponential").lack_of_fit_p < 0.05 for f in fits) <= 1


def test_models_the_data_cannot_support_are_skipped_with_a_reason():
    design = type(DESIGN)(currents_A=(0.0, 2.0))
    fr = fit_friction(data(design=design, seed=1))
    skipped = dict(fr.mu_selection.skipped)
    assert "needs >= 3 current levels, data have 2" in skipped["saturating_exponential"]
    assert {m.name for m in fr.mu_selection.candidates} == {"constant", "linear"}
    rs = dict(fit_resistance(data(design=design, seed=1)).selection.skipped)
    assert "needs >= 3 current levels" in rs["holm_elastic_film+exponential_floor"]


def test_shipped_fit_recovers_its_generator_and_is_computed_once():
    # its speed (target < 1 s) is measured in benchmarks/bench_tribology.py, not timed here
    default_fit.cache_clear()
    fit = default_fit()
    assert default_fit() is fit
    assert fit.gamma_ci95[0] <= 0.7 <= fit.gamma_ci95[1]
    assert fit.friction.mu_selection.chosen.name == MU_TRUE.model
    for name, value in MU_TRUE.params:
        assert covered(fit.friction.mu_selection.chosen.estimate(name), value)
    sel = fit.resistance.selection
    truth = f"{R_TRUE.load_model}+{R_TRUE.current_model}"
    assert truth == sel.chosen.name or truth in sel.ambiguous
    assert fit.data_range.load_range_N == (3.0, 8.0) and fit.data_range.current_range_A == (0.0, 5.0)
    assert fit.friction.law.current_range_A == (0.0, 5.0)


def test_fit_accepts_a_hand_built_dataframe_and_validates_it():
    df = data(seed=3)
    fit = fit_tribometer(df)
    assert fit.source == "DataFrame"
    df.loc[4, "resistance_ohm"] = -1.0
    with pytest.raises(ValueError, match=r"column resistance_ohm, row 4: value -1.0 must be > 0 ohm"):
        fit_tribometer(df)
