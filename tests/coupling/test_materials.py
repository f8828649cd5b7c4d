"""Contact resistance from materials: Holm and Greenwood closed forms, validity, library, scene keys."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.laws.materials import (
    MATERIALS,
    ConstantResistance,
    HolmResistance,
    greenwood_resistance,
    hertz_radius,
    resistance_law_from_table,
)

F = np.array([0.1, 0.4, 1.0, 4.0, 16.0])


def test_plastic_single_spot_is_holm_with_the_softer_hardness():
    law = HolmResistance(("Ag", "Cu"))
    ag, cu = MATERIALS["Ag"], MATERIALS["Cu"]
    h = min(ag.hardness, cu.hardness)
    a = np.sqrt(F / (math.pi * h))
    np.testing.assert_allclose(law.resistance(F), (ag.resistivity + cu.resistivity) / (4 * a), rtol=1e-12)
    # R ~ F^-1/2: four times the force, half the resistance
    np.testing.assert_allclose(law.resistance(4 * F) / law.resistance(F), 0.5, rtol=1e-12)
    # Ag on Ag at 1 N: a ~ 25 um, R ~ 0.3 mOhm (the familiar constriction scale of a relay contact)
    assert 1e-4 < float(HolmResistance(("Ag", "Ag")).resistance(1.0)) < 1e-3


@pytest.mark.parametrize("law", [
    HolmResistance(("Ag", "Ag")),
    HolmResistance(("Ag", "Cu"), film_resistivity=1e-12),  # the softer side's hardness, a film
    HolmResistance(("Cu", "Cu"), regime="elastic", radius=1e-3, film_resistivity=1e-12),
    HolmResistance(("Cu", "Cu"), spots=4, radius=1e-3),
])
def test_scalar_conductance_is_the_array_route(law):
    """The one-float route the circuit's conductance channel calls (plain floats for the
    plastic single spot) against the array route at forces over eight decades: the same
    operations in the same order and a correctly rounded sqrt in both, so equal to a few
    ulp (rtol 1e-15: one or two roundings apart at most on any IEEE machine); 0 when open."""
    forces = np.geomspace(1e-4, 1e4, 97)
    scalar = np.array([law.scalar_force_conductance(float(f)) for f in forces])
    np.testing.assert_allclose(scalar, law.force_conductance(forces), rtol=1e-15, atol=0.0)
    assert law.scalar_force_conductance(0.0) == 0.0 and law.scalar_force_conductance(-1.0) == 0.0


def test_resistivities_add():
    """Same hardness on both sides: R(1, 2) = (R(1, 1) + R(2, 2)) / 2 at the same force."""
    one, two = HolmResistance(("Au", "Au")), HolmResistance(("AuCo", "AuCo"))
    mixed = HolmResistance(("Au", "AuCo"))  # softer: Au, so the spot is Au's
    a = np.sqrt(F / (math.pi * MATERIALS["Au"].hardness))
    rho = MATERIALS["Au"].resistivity, MATERIALS["AuCo"].resistivity
    np.testing.assert_allclose(mixed.resistance(F), rho[0] / (4 * a) + rho[1] / (4 * a), rtol=1e-12)
    np.testing.assert_allclose(2 * mixed.resistance(F) - one.resistance(F),
                               rho[1] / (2 * a), rtol=1e-12)
    assert two.resistance(1.0) > one.resistance(1.0)  # harder and more resistive


def test_elastic_spot_follows_hertz():
    law = HolmResistance(("Ag", "Ag"), regime="elastic", radius=2e-3)
    np.testing.assert_allclose(law.resistance(8 * F) / law.resistance(F), 0.5, rtol=1e-12)  # R ~ F^-1/3
    e_star = MATERIALS["Ag"].youngs_modulus / (2 * (1 - MATERIALS["Ag"].poisson_ratio ** 2))
    a = (3 * F * 2e-3 / (4 * e_star)) ** (1 / 3)
    np.testing.assert_allclose(law.resistance(F), 2 * MATERIALS["Ag"].resistivity / (4 * a), rtol=1e-12)


def test_film_term_scales_with_the_real_area():
    sigma = 1e-12  # ohm m^2
    clean, filmed = HolmResistance(("Cu", "Cu")), HolmResistance(("Cu", "Cu"), film_resistivity=sigma)
    film = filmed.resistance(F) - clean.resistance(F)
    np.testing.assert_allclose(film, sigma * MATERIALS["Cu"].hardness / F, rtol=1e-9)  # sigma / (F/H)
    el0 = HolmResistance(("Cu", "Cu"), regime="elastic", radius=1e-3)
    el1 = HolmResistance(("Cu", "Cu"), regime="elastic", radius=1e-3, film_resistivity=sigma)
    ratio = (el1.resistance(8 * F) - el0.resistance(8 * F)) / (el1.resistance(F) - el0.resistance(F))
    np.testing.assert_allclose(ratio, 0.25, rtol=1e-9)  # sigma / (pi a^2), a ~ F^1/3


def test_greenwood_cluster_against_the_pair_sum():
    """The closed form against Greenwood's sum over an actual random cluster of n spots."""
    rng = np.random.default_rng(7)
    n, alpha, a, rho1, rho2 = 300, 1e-4, 1e-6, 1.6e-8, 1.7e-8
    r, th = alpha * np.sqrt(rng.random(n)), 2 * math.pi * rng.random(n)
    x, y = r * np.cos(th), r * np.sin(th)
    s = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    inv = np.where(s > 0, 1.0 / np.where(s > 0, s, 1.0), 0.0)
    rho = (rho1 + rho2) / 2
    pair_sum = rho / (2 * n * a) + rho / (math.pi * n ** 2) * inv.sum()
    assert greenwood_resistance(rho1, rho2, n, a, alpha) == pytest.approx(pair_sum, rel=0.03)
    assert greenwood_resistance(rho1, rho2, 1, a, alpha) == pytest.approx((rho1 + rho2) / (4 * a), rel=1e-12)
    # many small spots in a cluster conduct nearly like one spot of the cluster's size
    many = greenwood_resistance(rho1, rho2, 1_000_000, 1e-8, alpha)  # n a = 100 alpha
    assert many == pytest.approx(16 / (3 * math.pi ** 2) * (rho1 + rho2) / (2 * alpha), rel=0.03)


def test_validity_ranges_are_where_the_assumptions_hold():
    plastic = HolmResistance(("Ag", "Ag"), radius=1e-3)
    lo, hi = plastic.validity["force_N"]
    h = MATERIALS["Ag"].hardness
    assert math.sqrt(lo / (math.pi * h)) == pytest.approx(0.1e-6)  # spot radius 0.1 um
    assert hi / h == pytest.approx(math.pi * 1e-6)  # real area = the rivet's pi r^2
    elastic = HolmResistance(("Ag", "Ag"), regime="elastic", radius=1e-3)
    lo, hi = elastic.validity["force_N"]
    a = hertz_radius(hi, 1e-3, elastic.modulus)
    assert 3 * hi / (2 * math.pi * a ** 2) == pytest.approx(0.57 * h)  # Hertz peak pressure at first yield
    assert hertz_radius(lo, 1e-3, elastic.modulus) == pytest.approx(0.1e-6)
    assert ConstantResistance(1e-3).validity["force_N"] == (0.0, math.inf)


def test_library_has_the_common_contact_materials_with_sources():
    for name in ("Ag", "AgNi10", "AgSnO2", "AgCdO", "Au", "Cu", "CuBe", "AuCo"):
        m = MATERIALS[name]
        for prop in ("resistivity", "hardness", "youngs_modulus", "poisson_ratio"):
            lo, hi = m.ranges[prop]
            assert lo <= getattr(m, prop) <= hi and m.sources[prop]
        assert 1.5e-8 < m.resistivity < 1e-7 and 0.2 < m.poisson_ratio < 0.45


@pytest.mark.parametrize("table,match", [
    ({"law": "holm2"}, r"tribology\.resistance\.law = 'holm2': allowed values are 'holm', 'constant'"),
    ({"law": "holm", "materials": ["Ag", "Pt"]},
     r"tribology\.resistance\.materials: unknown contact material 'Pt'; allowed contact materials: Ag, "),
    ({"law": "holm", "materials": ["AgNi", "Ag"]}, r"unknown contact material 'AgNi' \(did you mean 'AgNi10'\?\)"),
    ({"law": "holm", "materials": "Ag", "spots": 0}, r"tribology\.resistance\.spots = 0: expected a whole number >= 1"),
    ({"law": "holm", "materials": "Ag", "regime": "elastic"}, r"needs radius"),
    ({"law": "holm", "materials": "Ag", "film_resistivity": -1.0},
     r"tribology\.resistance\.film_resistivity = -1.0: must be >= 0"),
    ({"law": "constant", "value": 0.0}, r"tribology\.resistance\.value = 0.0: must be > 0"),
    ({"law": "constant", "value": 1e-3, "materials": "Ag"},
     r"tribology\.resistance \(law = 'constant'\): unknown key 'materials'; allowed keys: law, value"),
])
def test_bad_resistance_tables_give_one_line_errors(table, match):
    with pytest.raises(ValueError, match=match) as err:
        resistance_law_from_table(table)
    assert "\n" not in str(err.value)


def _scene(tribology):
    from coupling.core.scene import builtin_scene

    base = builtin_scene("free_drop")
    raw = dict(base.raw, tribology=tribology)
    from coupling.core.scene import scene_from_dict

    return scene_from_dict(raw)


def test_scene_selects_material_laws():
    sc = _scene({"resistance": {"law": "holm", "materials": ["AgNi10", "Ag"]}, "mu": 0.3})
    law = sc.tribology.laws.resistance_law
    assert law.materials == ("AgNi10", "Ag") and sc.tribology.laws.mu(5.0) == pytest.approx(0.3)
    assert sc.mech.friction.gamma == 0.0  # Coulomb
    fitted = _scene({"resistance": {"law": "constant", "value": 2e-3}, "source": "illustrative"})
    assert float(fitted.tribology.laws.resistance_law.resistance(10.0)) == 2e-3
    assert fitted.tribology.fit is not None  # mu(I) still from the fit
    import json

    # summary.json stays strict JSON (no Infinity) for a law without an upper force bound
    text = json.dumps(sc.tribology.laws.to_dict(), allow_nan=False)
    assert '"validity_force_N": [' in text
    with pytest.raises(ValueError, match="gives R_c only; give mu too"):
        _scene({"resistance": {"law": "holm", "materials": "Ag"}})


def test_coupled_run_warns_when_hertz_is_used_beyond_yield():
    """The default drop presses ~100s of N through an Ag rivet of 5 mm radius: far beyond the
    ~1 N where elastic Hertz contact of silver yields."""
    from coupling import run

    sc = _scene({"resistance": {"law": "holm", "materials": "Ag", "regime": "elastic", "radius": 5e-3},
                 "mu": 0.3}).set("solver.t_end", 1.1e-3)
    res = run(sc)
    assert res.status == "ok"
    lines = [w for w in res.warnings if "contact-resistance law holm: normal force used up to" in w]
    assert len(lines) == 1 and "first yield" in lines[0]
    w = res.waveforms
    closed = w.normal_force > 0
    # the circuit saw the material law: R_c = 1/G at the force the mechanics gave
    np.testing.assert_allclose(w.contact_conductance[closed].iloc[-1],
                               sc.tribology.laws.resistance_law.force_conductance(w.normal_force[closed].iloc[-1]),
                               rtol=1e-6)


def test_the_library_document_is_parsed_once_per_version_of_its_file(tmp_path, monkeypatch):
    """library_document keeps the parsed TOML by the file's bytes: read back without tomllib,
    the same document (bit for bit: marshal keeps the floats); a damaged entry is parsed
    again; an edited file is parsed again and the old entry removed; an unwritable cache
    folder only parses."""
    import tomllib

    from coupling.laws import materials

    source = tmp_path / "library.toml"
    source.write_bytes(materials.LIBRARY.read_bytes())
    cache = tmp_path / "cache"
    parsed = tomllib.loads(source.read_text(encoding="utf-8"))
    assert materials.library_document(source, cache) == parsed
    (entry,) = cache.glob("*.marshal")

    def refuse(text):
        raise AssertionError("parsed again")

    with monkeypatch.context() as patch:
        patch.setattr(materials.tomllib, "loads", refuse)
        again = materials.library_document(source, cache)
    assert again == parsed and repr(again) == repr(parsed)

    entry.write_bytes(b"\x00 damaged")
    assert materials.library_document(source, cache) == parsed
    assert list(cache.glob("*.marshal")) == [entry] and entry.read_bytes() != b"\x00 damaged"

    source.write_bytes(source.read_bytes().replace(b"8960", b"8961", 1))  # an edit (a density)
    edited = materials.library_document(source, cache)
    assert edited != parsed and edited == tomllib.loads(source.read_text(encoding="utf-8"))
    assert [p.name for p in cache.glob("*.marshal")] != [entry.name] and len(list(cache.glob("*.marshal"))) == 1

    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    assert materials.library_document(source, blocked / "cache") == edited
