"""modes = "auto": the counting rule against closed forms, and auto against twice its
count on short scenes (the convergence the rule promises; docs/accuracy-modes.md)."""

from __future__ import annotations

import math

import pytest

from mech import Bar, Contact, Friction, ImpactSolver, Initial, MechScene, SolverOptions
from mech.contact_laws import hertz_stiffness
from mech.mode_count import CAP, FLOOR, SAFETY, choose_mode_count
from mech.model import build_model, resolve_auto_modes
from mech.modes import axial_frequencies, bending_frequencies


def test_counts_are_the_modes_below_the_cutoff_with_floor_and_cap():
    L, E, rho = 0.3, 210e9, 7850.0
    c = math.sqrt(E / rho)
    t_c = 50e-6
    axial = axial_frequencies(CAP, L, E, rho)
    bend = bending_frequencies(CAP, L, E, math.pi * 0.006**4 / 64, math.pi * 0.006**2 / 4, rho)
    ch = choose_mode_count(axial, bend, t_c, safety=3.0)
    f_cut = 3.0 / t_c
    # axial k c / (2L) < f_cut  <=>  k < 2 L f_cut / c
    assert ch.axial == max(FLOOR, math.ceil(2 * L * f_cut / c) - 1)
    # bending (beta_k L)^2 ~ ((k + 1/2) pi)^2 for k >= 2: count from the asymptotic roots
    f1 = math.sqrt(E * 0.006**2 / 16 / rho) / (2 * math.pi * L**2)
    assert ch.bending == sum(1 for k in range(1, CAP + 1) if f1 * ((k + 0.5) * math.pi) ** 2 < f_cut)
    assert ch.cutoff == pytest.approx(f_cut, rel=1e-15)
    assert "3 / t_c" in ch.reason and f"{ch.bending} bending" in ch.reason
    # a very short contact: everything below the cutoff, capped; a long one: the floor
    short = choose_mode_count(axial, bend, 1e-9)
    assert (short.axial, short.bending) == (CAP, CAP) and short.capped == ("axial", "bending")
    long = choose_mode_count(axial, bend, 1.0)
    assert (long.axial, long.bending) == (FLOOR, FLOOR) and "floor" in long.reason
    with pytest.raises(ValueError, match="contact_time"):
        choose_mode_count(axial, bend, 0.0)


def test_the_floor_leaves_a_family_the_impact_does_not_load_below_the_cutoff():
    # A steel strip 20 mm long: its axial modes k c / (2 L) lie 129 kHz apart, its bending
    # modes far below. A cutoff of 1.5 c / (2 L) admits one axial mode and many bending ones.
    L, E, rho, h, w = 0.02, 210e9, 7850.0, 2e-4, 3e-3
    c = math.sqrt(E / rho)
    axial = axial_frequencies(CAP, L, E, rho)
    bend = bending_frequencies(CAP, L, E, w * h**3 / 12, w * h, rho)
    t_c = 3.0 / (1.5 * c / (2 * L))
    loaded = choose_mode_count(axial, bend, t_c)
    across = choose_mode_count(axial, bend, t_c, unloaded=("axial",))
    n_bend = sum(1 for f in bend if f < 1.5 * c / (2 * L))
    assert n_bend >= FLOOR and (loaded.bending, across.bending) == (n_bend, n_bend)
    # loaded (struck on its end): the floor adds axial modes 2 and 3, above the cutoff
    assert loaded.axial == FLOOR and loaded.floored == ("axial",)
    # struck across its axis: the cutoff's one axial mode, and no kept mode above the cutoff
    # (the highest one sets the explicit integrator's stability-limited step)
    assert across.axial == 1 and across.unloaded == ("axial",) and across.floored == ()
    assert max(axial[across.axial - 1], bend[across.bending - 1]) < across.cutoff < axial[FLOOR - 1]
    assert "not raised to the floor" in across.reason
    assert across.next_frequencies[0] == pytest.approx(c / L, rel=1e-12)  # the 2nd axial mode, k = 2
    # both families short of the floor (a contact long against every mode): both raised
    slow = choose_mode_count(axial, bend, 1.0, unloaded=("axial",))
    assert (slow.axial, slow.bending) == (FLOOR, FLOOR) and slow.unloaded == ()


def test_a_bar_lying_along_the_surface_keeps_the_axial_modes_below_its_cutoff():
    # The stocky 12 mm bar at 0.1 m/s: lying flat (angle 0) its axial modes take no normal
    # force; standing (90) they take all of it and the floor holds. Axial frequencies are
    # k c / (2 L) on a free-free bar, so the counts follow from the chosen cutoff alone.
    bar = Bar(diameter=0.012, tip_radius=0.006)
    axial = axial_frequencies(CAP, bar.length, bar.youngs_modulus, bar.density)
    for angle, raised in ((0.0, False), (90.0, True)):
        scene = MechScene(bar=bar, initial=Initial(height=1e-4, angle_deg=angle, velocity=(0.0, 0.0, -0.1)),
                          gravity=0.0)
        resolved, ch = resolve_auto_modes(scene)
        below = sum(1 for f in axial if f < ch.cutoff)
        assert 0 < below < FLOOR and ch.bending >= FLOOR  # the case the rule is about
        assert resolved.bar.axial_modes == (FLOOR if raised else below)
        assert ("axial" in ch.floored) == raised and ("axial" in ch.unloaded) == (not raised)


def test_contact_time_of_a_vertical_drop_is_the_hertz_closed_form():
    # Vertical bar: the impacting tip's effective mass is the bar's mass.
    bar = Bar(diameter=0.012, tip_radius=0.006)
    scene = MechScene(bar=bar, initial=Initial(height=0.0, angle_deg=90.0, velocity=(0.0, 0.0, -0.8)),
                      gravity=0.0)
    resolved, ch = resolve_auto_modes(scene)
    k = hertz_stiffness(0.006, 210e9, 0.3, 210e9, 0.3)
    dmax = (5 * bar.mass * 0.8**2 / (4 * k)) ** 0.4
    assert ch.contact_time == pytest.approx(2.943275 * dmax / 0.8, rel=1e-5)
    assert (resolved.bar.axial_modes, resolved.bar.bending_modes) == (ch.axial, ch.bending)
    # an explicit family count is kept, the other is chosen
    mixed, ch2 = resolve_auto_modes(MechScene(bar=Bar(diameter=0.012, tip_radius=0.006, axial_modes=5),
                                              initial=scene.initial, gravity=0.0))
    assert mixed.bar.axial_modes == 5 and mixed.bar.bending_modes == ch2.bending
    model = build_model(scene)
    assert model.n == ch.axial + ch.bending  # planar: axial + one bending family


def _scene(diameter, angle, elastic, modes, t_end=1.0e-3):
    con = dict(damping=0.0, restitution=None) if elastic else dict(restitution=0.8)
    fr = dict(mu=0.0) if elastic else dict(mu=0.3, gamma=0.7)
    return MechScene(
        bar=Bar(diameter=diameter, tip_radius=diameter / 2, axial_modes=modes[0], bending_modes=modes[1]),
        contact=Contact(**con), friction=Friction(**fr),
        initial=Initial(height=1e-4, angle_deg=angle, velocity=(0.0, 0.0, -1.0)),
        solver=SolverOptions(t_end=t_end))


def _intervals(res):
    c = res.contacts
    return [[(a, b) for a, b in zip(c.t_start[c.tip == i], c.t_end[c.tip == i])] for i in (0, 1)]


def _mismatch(a, b):
    """Total time where 'tip i touches' differs between two runs (s), summed over tips."""
    total = 0.0
    for ia, ib in zip(a, b):
        cuts = sorted({x for iv in ia + ib for x in iv})
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            mid = 0.5 * (lo + hi)
            if any(s <= mid <= e for s, e in ia) != any(s <= mid <= e for s, e in ib):
                total += hi - lo
    return total


def _compare(scene_args, safety):
    base = _scene(*scene_args, modes=("auto", "auto"))
    n = resolve_auto_modes(base, safety=safety)[0].bar
    auto = ImpactSolver(_scene(*scene_args, modes=(n.axial_modes, n.bending_modes))).run()
    ref = ImpactSolver(_scene(*scene_args, modes=(min(CAP, 2 * n.axial_modes), min(CAP, 2 * n.bending_modes)))).run()
    ca, cr = auto.contacts, ref.contacts
    total = float((cr.t_end - cr.t_start).sum())
    return dict(mismatch=_mismatch(_intervals(auto), _intervals(ref)), total=total,
                contacts=(len(ca), len(cr)),
                peak=abs(ca.peak_force.max() / cr.peak_force.max() - 1.0),
                last=abs(ca.t_end.max() - cr.t_end.max()),
                restitution=abs(ca.kinematic_restitution.iloc[0] - cr.kinematic_restitution.iloc[0]))


# (diameter m, angle deg, elastic): stocky tilted and grazing, slender tilted with friction
SCENES = [(0.012, 30.0, True), (0.012, 10.0, False), (0.006, 30.0, False)]


@pytest.mark.parametrize("scene_args", SCENES)
def test_auto_agrees_with_twice_its_count(scene_args):
    d = _compare(scene_args, SAFETY)
    # docs/accuracy-modes.md tolerances: the bounce pattern and its forces
    assert d["contacts"][0] == d["contacts"][1]
    assert d["mismatch"] <= 2e-6 + 0.05 * d["total"]
    assert d["last"] <= 1e-6 + 0.03 * d["total"]
    assert d["peak"] <= 0.05
    assert d["restitution"] <= 0.05


def test_a_third_of_the_cutoff_misses_the_bounce_pattern():
    # The same check fails for f_cut = 1 / t_c on the stocky tilted bar: it can tell.
    d = _compare(SCENES[0], 1.0)
    assert d["contacts"][0] != d["contacts"][1] or d["mismatch"] > 2e-6 + 0.05 * d["total"]


def test_the_floors_axial_modes_change_the_contact_only_where_the_impact_loads_them():
    """What the rule rests on (docs/accuracy-modes.md, the floor): against 10 axial modes, a
    bar struck on its end needs the floor's 3 (the cutoff's 1 misses its contact's end by
    more than the tolerance of 'agrees'), a bar lying flat does not (2 and 3 give the same
    contacts, though sliding with friction along its axis loads its axial modes a little).
    Tolerances as in test_auto_agrees_with_twice_its_count."""

    def run(angle, speed, modes, sliding=False):
        return ImpactSolver(MechScene(
            bar=Bar(diameter=0.012, tip_radius=0.006, axial_modes=modes[0], bending_modes=modes[1]),
            contact=Contact(restitution=0.8) if sliding else Contact(damping=0.0, restitution=None),
            friction=Friction(mu=0.3, gamma=0.7) if sliding else Friction(mu=0.0),
            initial=Initial(height=1e-4, angle_deg=angle, velocity=(0.2 * speed if sliding else 0.0, 0.0, -speed)),
            solver=SolverOptions(t_end=1.0e-3))).run()

    # standing, 1 m/s: auto is (3, 7), the cutoff alone admits 1 axial mode
    ref, floor, cut = (run(90.0, 1.0, m) for m in ((10, 7), (3, 7), (1, 7)))
    total = float((ref.contacts.t_end - ref.contacts.t_start).sum())
    allowed = 1e-6 + 0.03 * total
    assert abs(floor.contacts.t_end.max() - ref.contacts.t_end.max()) <= allowed
    assert abs(cut.contacts.t_end.max() - ref.contacts.t_end.max()) > allowed
    # lying flat, 0.1 m/s down and 0.02 m/s along: auto is (2, 7); the floor's third axial
    # mode changes nothing
    ref, floor, cut = (run(0.0, 0.1, m, sliding=True) for m in ((10, 7), (3, 7), (2, 7)))
    total = float((ref.contacts.t_end - ref.contacts.t_start).sum())
    for run_ in (floor, cut):
        assert len(run_.contacts) == len(ref.contacts)
        assert _mismatch(_intervals(run_), _intervals(ref)) <= 2e-6 + 0.05 * total
        assert abs(run_.contacts.peak_force.max() / ref.contacts.peak_force.max() - 1.0) <= 0.05


def test_scene_files_take_auto_counts_and_name_a_bad_value():
    from mech import scene_from_dict

    sc = scene_from_dict({"bar": {"modes": {"bending": 5}}})
    assert (sc.bar.axial_modes, sc.bar.bending_modes) == ("auto", 5)
    assert scene_from_dict({"bar": {"modes": "auto"}}).bar.axial_modes == "auto"
    with pytest.raises(ValueError, match=r"bar\.modes = 'many'.*\"auto\""):  # the key the user wrote
        scene_from_dict({"bar": {"modes": "many"}})


@pytest.mark.parametrize("length, thickness, clamp", [(0.015, 3e-4, True), (0.04, 2e-4, True), (0.01, 8e-4, False)])
def test_held_frequencies_below_a_cutoff_equal_those_of_the_finest_mesh(length, thickness, clamp):
    """"auto" on a held bar solves the finite-element modes on the mesh the count below the
    cutoff needs; the same frequencies (within the FE error of the coarser mesh's highest
    mode, 4e-5) and so the same count as on the cap's mesh, for cutoffs across the spectrum."""
    import numpy as np

    from mech.beam_fe import beam_modes
    from mech.mechanism import fe_beam
    from mech.mode_count import count_below
    from mech.model import frequencies_below
    from mech.parameters import Mount, Rivet

    bar = Bar(length=length, diameter=None, width=3e-3, thickness=thickness, tip_radius=1.6e-3, youngs_modulus=128e9,
              density=8250.0)
    mount = Mount(kind="clamp" if clamp else "pivot", position=length)
    scene = MechScene(bar=bar, mount=mount, rivets=(Rivet(position=0.1 * length, radius=1.5e-3, mass=2e-5),),
                      initial=Initial(height=1e-4, velocity=(0.0, 0.0, 0.0)))
    beam = fe_beam(scene)
    for family in ("axial", "bend3"):
        finest = beam_modes(beam, family, CAP).frequencies
        for cutoff in np.geomspace(0.5 * finest[0], 1.2 * finest[-1], 12):
            got = frequencies_below(beam, family, cutoff, CAP)
            below = count_below(got, cutoff)
            assert below == count_below(finest, cutoff)
            assert below < len(got) or len(got) == CAP  # the first mode above the cutoff was reached
            np.testing.assert_allclose(got[:below], finest[:below], rtol=4e-5)
