"""The contact laws as the coupling sees them: formulas, vectorization, F_n -> 0, |I|, clamps, dict/JSON forms."""

import json
import math
import warnings

import numpy as np
import pytest

from coupling.laws.tribology import ContactLaws, MuLaw, ResistanceLaw, TribometerFit, default_fit
from coupling.laws.tribology.illustrative import (
    EFFECTIVE_MODULUS_Pa, ILLUSTRATIVE_LAWS, PIN_RADIUS_m, R_1N_ohm, RESISTIVITY_ohm_m,
)
from coupling.laws.tribology.models import (
    constriction_film_conductance, constriction_film_resistance, generalized_friction_force,
    hertz_contact_radius, holm_constriction_resistance, plastic_contact_radius,
)


def test_holm_with_hertz_gives_minus_one_third_and_plastic_minus_one_half():
    rho, R, E = 1e-6, 3e-3, 115e9
    f = np.array([1.0, 8.0])
    r_el = holm_constriction_resistance(rho, hertz_contact_radius(f, R, E))
    r_pl = holm_constriction_resistance(rho, plastic_contact_radius(f, 2e9))
    assert r_el[0] / r_el[1] == pytest.approx(8.0 ** (1 / 3), rel=1e-12)
    assert r_pl[0] / r_pl[1] == pytest.approx(8.0 ** 0.5, rel=1e-12)
    # formula values: a = (3 F R / 4 E*)^(1/3), R = rho / 2a
    a1 = (3 * 1.0 * R / (4 * E)) ** (1 / 3)
    assert r_el[0] == pytest.approx(rho / (2 * a1), rel=1e-12)


def test_illustrative_r1_is_holm_over_hertz_radius_at_one_newton():
    a = (3 * 1.0 * PIN_RADIUS_m / (4 * EFFECTIVE_MODULUS_Pa)) ** (1 / 3)
    assert R_1N_ohm == pytest.approx(RESISTIVITY_ohm_m / (2 * a), rel=1e-12)
    assert 20e-6 < a < 40e-6  # a few tens of micrometres at 1 N: a plausible Hertz spot


def test_generalized_friction_reduces_to_coulomb_at_gamma_zero():
    f = np.array([0.0, 1.0, 3.0, 8.0])
    assert np.array_equal(generalized_friction_force(f, 0.2, 0.0), 0.2 * f)
    assert generalized_friction_force(8.0, 0.3, 0.7) == pytest.approx(0.3 * 8.0**0.3)


def test_conductance_is_reciprocal_of_resistance_for_positive_loads():
    f = np.geomspace(1e-6, 1e4, 50)
    g = constriction_film_conductance(f, 3e-3, 0.02, 1 / 3)
    r = constriction_film_resistance(f, 3e-3, 0.02, 1 / 3)
    assert np.allclose(g * r, 1.0, rtol=1e-14, atol=0)


LAWS = [ILLUSTRATIVE_LAWS, default_fit().laws]


@pytest.mark.parametrize("laws", LAWS, ids=["illustrative_truth", "shipped_fit"])
def test_vectorized_equals_scalar(laws):
    forces = np.array([-1.0, 0.0, 1e-9, 0.5, 3.0, 5.5, 8.0, 1e3])
    currents = np.array([-7.0, -5.0, -1.5, 0.0, 0.3, 2.0, 5.0, 12.0])
    F, I = np.meshgrid(forces, currents)
    for method in (laws.contact_resistance, laws.contact_conductance, laws.friction_force):
        grid = method(F, I)
        scalar = np.array([[method(float(f), float(i)) for f, i in zip(fr, ir)] for fr, ir in zip(F, I)])
        # equal up to the last bit of numpy's SIMD power/exp against its scalar path
        assert np.allclose(grid, scalar, rtol=4 * np.finfo(float).eps, atol=0)
        assert np.array_equal(np.isinf(grid), np.isinf(scalar)) and np.array_equal(grid == 0, scalar == 0)
    assert np.allclose(laws.mu(currents), [laws.mu(float(i)) for i in currents], rtol=4 * np.finfo(float).eps, atol=0)


@pytest.mark.parametrize("laws", LAWS, ids=["illustrative_truth", "shipped_fit"])
def test_open_contact_and_continuity_as_load_vanishes(laws):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no division-by-zero or invalid-value warnings
        assert laws.contact_conductance(0.0, 1.0) == 0.0
        assert laws.contact_conductance(-3.0, 1.0) == 0.0
        assert laws.contact_resistance(0.0, 1.0) == math.inf
        assert laws.contact_resistance(-3.0, 1.0) == math.inf
        eps = np.geomspace(1e-15, 1e-3, 25)
        g = laws.contact_conductance(eps, 1.0)
    assert np.all(np.isfinite(g)) and np.all(g > 0) and np.all(np.diff(g) > 0)
    # continuous at 0+: G ~ F^m / (g(I) R_1), so it vanishes like a power of F
    m = laws.resistance_law.load_exponent
    assert g[0] < 1e-3 * g[-1]
    assert np.allclose(np.log(g[1:4] / g[:3]) / np.log(eps[1:4] / eps[:3]), m, rtol=1e-3)


@pytest.mark.parametrize("laws", LAWS, ids=["illustrative_truth", "shipped_fit"])
def test_current_direction_does_not_matter(laws):
    f = np.linspace(0.0, 50.0, 11)
    for i in (0.5, 2.0, 4.9, 9.0):
        assert laws.mu(-i) == laws.mu(i)
        assert np.array_equal(laws.contact_conductance(f, -i), laws.contact_conductance(f, i))
        assert np.array_equal(laws.contact_resistance(f, -i), laws.contact_resistance(f, i))


def test_current_held_at_edge_outside_measured_range_and_load_extrapolates():
    mu = MuLaw(0.7, "linear", (("mu0", 0.2), ("slope_per_A", 0.03)), (1.0, 5.0))
    assert mu(0.0) == mu(1.0) == pytest.approx(0.23)
    assert mu(40.0) == mu(5.0) == pytest.approx(0.35)
    assert mu(3.0) == pytest.approx(0.29)
    r = ResistanceLaw("holm_elastic_film", "hyperbolic",
                      (("r_film_ohm", 3e-3), ("r_1N_ohm", 0.02), ("current_scale_A", 2.0)), (0.0, 5.0))
    assert r.resistance(5.0, 100.0) == r.resistance(5.0, 5.0)
    # load is not clamped: at 1 kN the law itself, far outside 3-8 N
    assert r.resistance(1000.0, 0.0) == pytest.approx(3e-3 + 0.02 * 1000.0 ** (-1 / 3), rel=1e-14)
    assert r.resistance(1000.0, 2.0) == pytest.approx(0.5 * (3e-3 + 0.02 * 1000.0 ** (-1 / 3)), rel=1e-14)


def test_resistance_falls_with_load_and_current_in_the_shipped_fit():
    fit = default_fit()
    f = np.linspace(3.0, 8.0, 6)
    for i in fit.data_range.currents_A:
        assert np.all(np.diff(fit.contact_resistance(f, i)) < 0)
    r = [fit.contact_resistance(5.0, i) for i in fit.data_range.currents_A]
    assert np.all(np.diff(r) < 0)
    assert np.all(np.diff([fit.mu(i) for i in fit.data_range.currents_A]) > 0)


def test_laws_round_trip_through_dicts_and_json():
    d = json.loads(json.dumps(ILLUSTRATIVE_LAWS.to_dict()))
    assert ContactLaws.from_dict(d) == ILLUSTRATIVE_LAWS


def test_fit_json_round_trip_is_exact(tmp_path):
    fit = default_fit()
    path = tmp_path / "fit.json"
    fit.to_json(path)
    again = TribometerFit.from_json(path)
    assert again == fit
    f, i = np.array([0.0, 1.0, 5.0, 900.0]), np.array([0.0, -1.0, 2.0, 7.0])
    assert np.array_equal(again.contact_conductance(f, i), fit.contact_conductance(f, i))
    again.to_json(tmp_path / "again.json")
    assert (tmp_path / "again.json").read_text() == path.read_text()


def test_from_json_refuses_other_files(tmp_path):
    p = tmp_path / "x.json"
    p.write_text('{"hello": 1}')
    with pytest.raises(ValueError, match="not a tribometer fit"):
        TribometerFit.from_json(p)


INLINE = {
    "mu": {"gamma": 0.7, "model": "linear", "params": {"mu0": 0.2, "slope_per_A": 0.03}, "current_range_A": [0, 5]},
    "resistance": {"load_model": "holm_elastic_film", "current_model": "none",
                   "params": {"r_film_ohm": 0.003, "r_1N_ohm": 0.02}, "current_range_A": [0, 5]},
}


@pytest.mark.parametrize("path, value, message", [
    (("mu", "model"), "cubic", "model must be one of"),
    (("mu", "gamma"), 1.0, "gamma must be finite and < 1"),
    (("mu", "params"), {"mu0": 0.2}, r"missing \['slope_per_A'\]"),
    (("mu", "params"), {"mu0": 0.2, "slope_per_A": 0.03, "k": 1}, r"unknown \['k'\]"),
    (("mu", "params"), {"mu0": -0.2, "slope_per_A": 0.03}, "mu must be > 0"),
    (("mu", "current_range_A"), [5, 0], "0 <= I_min <= I_max"),
    (("resistance", "load_model"), "holm", "load_model must be one of"),
    (("resistance", "params"), {"r_film_ohm": -1e-3, "r_1N_ohm": 0.02}, "r_film_ohm must be >= 0"),
    (("resistance", "params"), {"r_film_ohm": 1e-3, "r_1N_ohm": "x"}, "'r_1N_ohm' must be a number"),
])
def test_inline_laws_are_validated_with_named_fields(path, value, message):
    bad = json.loads(json.dumps(INLINE))
    bad[path[0]][path[1]] = value
    with pytest.raises(ValueError, match=message):
        ContactLaws.from_dict(bad)


def test_inline_laws_build_and_evaluate():
    laws = ContactLaws.from_dict(INLINE)
    assert laws.gamma == 0.7
    assert laws.contact_resistance(8.0, 3.0) == pytest.approx(0.003 + 0.02 / 2.0)
    assert laws.friction_force(8.0, 1.0) == pytest.approx(0.23 * 8.0**0.3)
