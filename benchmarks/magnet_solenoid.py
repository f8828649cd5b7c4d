"""The plunger solenoid's static characteristics and the magnet's accuracy figures for docs/magnet.md.

    python benchmarks/magnet_solenoid.py [--no-write]

Measures, on the built-in plunger solenoid (coupling.laws.magnet.plunger_solenoid): its
static force F(i, g) at a few currents and gaps and its inductance at rest and closed;
how far the 9SMnPb28 table lies from Roschke's fit it samples; the table route: the
solenoid's own tables at a few grids, their consistency mismatch (power-law rule and the
trapezoid for comparison), the table magnet's error against the flux-tube magnet off the
grid, and the table magnet's own energy balance over a closed cycle; and the cost of one
call of ``current`` and ``force`` (Python, this machine). Writes its block between the
magnet-solenoid markers of docs/magnet.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from doc_block import command_line, load_line, publish

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from coupling.laws.magnet import (  # noqa: E402
    MU0, STEEL_9SMNPB28, TableMagnet, plunger_solenoid, roschke_relative_permeability, table_consistency, tabulate,
)
from coupling.laws.magnet.bh_curves import STEEL_9SMNPB28_PARAMETERS  # noqa: E402

DOC = REPO / "docs" / "magnet.md"
BEGIN, END = "<!-- magnet-solenoid:begin -->", "<!-- magnet-solenoid:end -->"
TUBES_BEGIN, TUBES_END = "<!-- magnet-tubes:begin -->", "<!-- magnet-tubes:end -->"
MM = 1e-3
CURRENTS = (0.3, 0.6, 1.2, 2.4)
GAPS = (0.25, 0.5, 1.0, 2.0, 3.0, 5.0)
GRIDS = ((6, 5), (11, 9), (16, 12), (31, 24))  # currents x gaps, the gaps geometric from 0.25 to 5 mm


def trapezoid_consistency(currents, gaps, psi, force):
    """The consistency measure of table_consistency with the trapezoid rule for the work."""
    from coupling.laws.magnet import table as table_module

    saved = table_module.power_law_work
    table_module.power_law_work = lambda g0, g1, f0, f1: 0.5 * (f0 + f1) * (g1 - g0)
    try:
        return table_consistency(currents, gaps, psi, force)[0]
    finally:
        table_module.power_law_work = saved


def cycle_residual(magnet, g1, g2, p1, p2, n=4001):
    """Loop integral of i dpsi + F dg over the rectangle (p1, p2) x (g1, g2), by the
    trapezoid on n points a side, over the loop integral of i dpsi."""
    from scipy.integrate import quad

    kinks = [x for x in magnet.breakpoints if p1 < x < p2]
    gap_kinks = [x for x in getattr(magnet, "gaps", ()) if g1 < x < g2] or None
    opts = dict(epsabs=0.0, epsrel=1e-13, limit=800)
    electrical = (quad(lambda x: magnet.current(x, g2), p1, p2, points=kinks, **opts)[0]
                  - quad(lambda x: magnet.current(x, g1), p1, p2, points=kinks, **opts)[0])
    mechanical = (quad(lambda x: magnet.force(p2, x), g1, g2, points=gap_kinks, **opts)[0]
                  - quad(lambda x: magnet.force(p1, x), g1, g2, points=gap_kinks, **opts)[0])
    return abs(electrical - mechanical) / abs(electrical)


def tube_lines(solenoid) -> list[str]:
    """The solenoid's flux tubes as built: each iron tube's path length and area, each air
    tube's permeance."""
    m = solenoid.magnet
    fields = {"AxialIron": ("outer_radius", "inner_radius", "length"),
              "RadialIron": ("inner_radius", "outer_radius", "thickness")}
    lines = [f"`{command_line()}` (the tubes as `plunger_solenoid()` builds them):", "",
             "| iron tube | shape | dimensions (mm) | l (mm) | A (mm^2) |", "|---|---|---|---:|---:|"]
    for t in m.iron:
        dims = ", ".join(f"{f} {getattr(t, f) * 1e3:g}" for f in fields[type(t).__name__])
        lines.append(f"| {t.name} | `{type(t).__name__}` | {dims} | {t.path_length * 1e3:.3f} | "
                     f"{t.path_area * 1e6:.1f} |")
    lines += ["", "| air tube of the guide (one fixed gap, in parallel) | permeance (nH) |", "|---|---:|"]
    for gap in m.fixed_gap:
        for t in gap.tube:
            dims = ", ".join(f"{k} {v * 1e3:g} mm" if k != "ratio" else f"ratio {v:g}"
                             for k, v in vars(t).items() if k != "name")
            lines.append(f"| `{type(t).__name__}` ({dims}) | {t.permeance * 1e9:.1f} |")
        lines.append(f"| together: reluctance {gap.reluctance:.3g} A/Wb | {1e9 / gap.reluctance:.1f} |")
    lk = m.pole_leakage
    lines += ["", f"- Working gap: pole face {m.working_gap.area * 1e6:.2f} mm^2; pole leakage: width "
              f"{lk.width * 1e3:.2f} mm, radius {lk.radius * 1e3:g} mm; armature and load "
              f"{solenoid.armature_mass * 1e3:.2f} g; {m.breakpoints.size} psi breakpoints in i(psi, g) "
              "(the union of the iron tubes' B-H points)."]
    return lines


def per_call(fn, repeats=3000):
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) / repeats


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the block only")
    args = parser.parse_args()
    solenoid = plunger_solenoid()
    m = solenoid.magnet
    lines = [f"`{command_line()}`: the built-in plunger solenoid (N = {m.turns}, R = {solenoid.coil_resistance:g} ohm, "
             "iron 9SMnPb28).", "",
             "Static force F(i, g), N (the armature held; >= 0 closes the gap):", "",
             "| i (A) \\ g (mm) | " + " | ".join(f"{g:g}" for g in GAPS) + " |",
             "|---:|" + "---:|" * len(GAPS)]
    for i in CURRENTS:
        forces = m.force_at_current(i, np.array(GAPS) * MM)
        lines.append(f"| {i:g} | " + " | ".join(f"{f:.3g}" for f in forces) + " |")
    i_hold = 12.0 / solenoid.coil_resistance
    lines += ["", f"Inductance: at i -> 0 and psi/i at the 12 V current {i_hold:g} A; B in the pole at {i_hold:g} A "
              "(flux / pole area, leakage included):", "",
              "| gap | L(i -> 0) H | psi/i at 1.2 A, H | B pole, T |", "|---|---:|---:|---:|"]
    for label, g in (("rest, 5 mm", solenoid.rest_gap), ("closed, 0.25 mm", solenoid.closed_gap)):
        psi = m.flux_linkage(i_hold, g)
        lines.append(f"| {label} | {m.inductance(g):.4f} | {psi / i_hold:.4f} | "
                     f"{psi / (m.turns * m.working_gap.area):.2f} |")
    tau_rest = m.inductance(solenoid.rest_gap) / solenoid.coil_resistance
    tau_closed = m.inductance(solenoid.closed_gap) / solenoid.coil_resistance
    lines += ["", f"- L/R: {tau_rest * 1e3:.2f} ms at rest, {tau_closed * 1e3:.1f} ms closed (unsaturated)."]

    # the B-H table against the fit it samples
    b = np.linspace(0.0, STEEL_9SMNPB28.flux_density[-1], 22001)
    fit = b / (MU0 * roschke_relative_permeability(b, **STEEL_9SMNPB28_PARAMETERS))
    h = STEEL_9SMNPB28.field_strength_at(b)
    rel = np.abs(h - fit) / np.maximum(fit, 1e-300)
    k = int(np.argmax(rel[1:])) + 1
    hh = np.linspace(0.0, STEEL_9SMNPB28.field_strength[-1], 20001)
    b_table = np.interp(hh, STEEL_9SMNPB28.field_strength, STEEL_9SMNPB28.flux_density)
    b_fit = np.interp(hh, fit, b)
    mu = roschke_relative_permeability(np.array([1.6, 1.8]), **STEEL_9SMNPB28_PARAMETERS)
    bb = np.linspace(0.0, 3.5, 35001)
    hb = bb / (MU0 * roschke_relative_permeability(bb, **STEEL_9SMNPB28_PARAMETERS))
    unphysical = bb[1:][np.diff(bb) / np.diff(hb) < MU0][0]
    lines += [f"- 9SMnPb28: Roschke's mu_r {mu[0]:.0f} at 1.6 T, {mu[1]:.0f} at 1.8 T (400 at 0); the fit's "
              f"differential permeability falls below mu0 from {unphysical:.2f} T on."]
    lines += [f"- 9SMnPb28 table ({len(STEEL_9SMNPB28.flux_density)} points to "
              f"{STEEL_9SMNPB28.flux_density[-1]:g} T) against Roschke's fit: H within {rel[k] * 100:.2f} % "
              f"(worst at {b[k]:.3f} T), B at given H within {np.max(np.abs(b_table - b_fit)) * 1e3:.1f} mT; "
              f"polarization beyond the table J_s = {STEEL_9SMNPB28.saturation_polarization:.3f} T."]

    # the table route
    rng = np.random.default_rng(7)
    gi = rng.uniform(0.27 * MM, 4.9 * MM, 3000)
    ii = rng.uniform(0.05, 2.9, 3000)
    psi_q = m.flux_linkage(ii, gi)
    f_q = m.force(psi_q, gi)
    lines += ["", "The table route, on the solenoid's own tables (currents 0 to 3 A evenly, gaps 0.25 to 5 mm "
              "geometric): consistency mismatch of F against -dW'/dg (power-law rule; the trapezoid for "
              "comparison), the table magnet's largest error against the flux-tube magnet at 3000 random "
              "(i, g) inside the grid, and the table magnet's own energy balance over a closed cycle "
              "(rectangle psi 0.1-2 A x g 0.3-4 mm, |loop i dpsi - loop F (-dg)| / loop i dpsi):", "",
              "| grid i x g | mismatch (power law) | (trapezoid) | with F x 1.2 | i error | F error | "
              "F error, median | cycle residual |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for n_i, n_g in GRIDS:
        currents, gaps = np.linspace(0.0, 3.0, n_i), np.geomspace(0.25 * MM, 5 * MM, n_g)
        psi, force = tabulate(m, currents, gaps)
        table = TableMagnet(tuple(currents), tuple(gaps), tuple(map(tuple, psi)), tuple(map(tuple, force)),
                            force_tolerance=0.5)
        err_i = np.abs(table.current(psi_q, gi) - ii) / ii
        err_f = np.abs(table.force(psi_q, gi) - f_q) / f_q
        p1, p2 = table.flux_linkage(0.1, 4 * MM), table.flux_linkage(2.0, 4 * MM)
        lines.append(f"| {n_i} x {n_g} | {table_consistency(currents, gaps, psi, force)[0] * 100:.2f} % | "
                     f"{trapezoid_consistency(currents, gaps, psi, force) * 100:.1f} % | "
                     f"{table_consistency(currents, gaps, psi, 1.2 * force)[0] * 100:.1f} % | "
                     f"{err_i.max() * 100:.2f} % | {err_f.max() * 100:.1f} % | {np.median(err_f) * 100:.2f} % | "
                     f"{cycle_residual(table, 0.3 * MM, 4 * MM, p1, p2):.1e} |")
    lines.append("")
    own = cycle_residual(m, 0.3 * MM, 4 * MM, m.flux_linkage(0.1, 4 * MM), m.flux_linkage(2.0, 4 * MM))
    lines.append(f"- The flux-tube magnet's own cycle residual (same rectangle): {own:.1e}"
                 + (" (the two quadratures agree to the last bit)." if own == 0.0 else "."))
    # what following the armature's iron length would add to the force: -A w_iron(B)
    shares = []
    for i in (1.2, 2.4):
        for g in (solenoid.rest_gap, solenoid.closed_gap):
            psi = m.flux_linkage(i, g)
            b = psi / (m.turns * m.working_gap.area)
            shares.append(m.working_gap.area * STEEL_9SMNPB28.energy_density(b) / m.force(psi, g))
    lines.append(f"- The armature's iron length held at mid-stroke: letting it follow g would add -A w_iron(B) "
                 f"to F, {min(shares) * 100:.1f}-{max(shares) * 100:.1f} % of F at 1.2 and 2.4 A, rest and "
                 "closed (B: all the flux over the armature's section, an upper bound).")

    table = TableMagnet.from_magnet(m, np.linspace(0, 3, 16), np.geomspace(0.25 * MM, 5 * MM, 12))
    psi0, g0 = float(m.flux_linkage(1.2, 2 * MM)), 2 * MM
    lines.append(f"- One call with scalars (Python, this machine): current {per_call(lambda: m.current(psi0, g0)) * 1e6:.0f} us, "
                 f"force {per_call(lambda: m.force(psi0, g0)) * 1e6:.0f} us (flux tubes); "
                 f"current {per_call(lambda: table.current(psi0, g0)) * 1e6:.0f} us, "
                 f"force {per_call(lambda: table.force(psi0, g0)) * 1e6:.0f} us (16 x 12 table); "
                 f"expression lengths {len(m.current_expression('V(coil_psi)', 'V(coil_gap)'))} and "
                 f"{len(table.current_expression('V(coil_psi)', 'V(coil_gap)'))} characters.")
    lines.append(load_line())
    publish(DOC, TUBES_BEGIN, TUBES_END, tube_lines(solenoid), write=not args.no_write)
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
