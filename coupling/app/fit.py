"""`switchsim fit DATA.csv --out DIR`: fit a tribometer CSV, write fit.json and the figures, print a summary."""

from __future__ import annotations

import os
from pathlib import Path

from coupling.laws.tribology.data import read_tribometer_csv
from coupling.laws.tribology.fits import AMBIGUOUS_DELTA, ModelFit, TribometerFit, fit_tribometer, outlier_lines

FIT_JSON = "fit.json"


def _params(m: ModelFit, skip: tuple[str, ...] = ()) -> str:
    parts = []
    for p in m.parameters:
        if p.name in skip:
            continue
        ci = "" if p.ci95 is None else f" [{p.ci95[0]:.4g}, {p.ci95[1]:.4g}]"
        parts.append(f"{p.name} = {p.value:.4g}{ci}")
    return ", ".join(parts)


def summary(fit: TribometerFit) -> str:
    """A short human summary of a fit: chosen models, values with 95 % intervals, caveats."""
    dr = fit.data_range
    lines = []
    if any("ILLUSTRATIVE" in h for h in fit.header):
        lines.append("NOTE: the data file says it is ILLUSTRATIVE, NOT MEASURED.")
    lines.append(
        f"data: {fit.source}: {dr.n_points} points, loads {dr.load_range_N[0]:g}-{dr.load_range_N[1]:g} N, "
        f"currents {', '.join(f'{i:g}' for i in dr.currents_A)} A"
    )
    g = fit.friction.gamma
    ct = fit.friction.coulomb_test
    ci = "(no interval: " + (fit.friction.mu_selection.chosen.note or "not estimable") + ")" if g.ci95 is None \
        else f"[{g.ci95[0]:.4f}, {g.ci95[1]:.4f}] (95 % CI)"
    lines.append(
        f"gamma = {g.value:.4f} {ci}; vs Coulomb (gamma = 0): "
        f"dBIC = {ct.delta_bic:.1f}, F-test p = {ct.p_value:.2g} -> {ct.preferred} preferred"
    )
    lines += outlier_lines(fit)
    sel = fit.friction.mu_selection
    lines.append(f"mu(I) by {sel.criterion}: {sel.chosen.name}: {_params(sel.chosen, skip=('gamma',))} (N^gamma, A)")
    for label, s in (("mu(I)", sel), ("R_c", fit.resistance.selection)):
        runner = s.candidates[1] if len(s.candidates) > 1 else None
        if runner is not None:
            lines.append(f"  {label}: next best {runner.name} at d{s.criterion} = {s.delta(runner.name):.2f}")
    rs = fit.resistance.selection
    lines.append(f"R_c by {rs.criterion}: {rs.chosen.name}: {_params(rs.chosen)} (ohm, A)")
    if rs.ambiguous:
        lines.append(
            f"  not distinguishable from it (d{rs.criterion} < {AMBIGUOUS_DELTA:g}): {', '.join(rs.ambiguous)}; "
            "they agree on the tested loads but extrapolate differently (docs/tribology.md)"
        )
    lines.append(
        f"validity: loads {dr.load_range_N[0]:g}-{dr.load_range_N[1]:g} N (R_c extrapolates in load with the fitted law), "
        f"currents {dr.current_range_A[0]:g}-{dr.current_range_A[1]:g} A (|I|, held at the edge outside)"
    )
    return "\n".join(lines)


def _check_out(out_dir: str) -> Path:
    """The output folder, checked before any work: not empty, not a file, writable."""
    if not str(out_dir).strip():
        raise ValueError("--out: give a folder name (an empty name would write into the current folder)")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {str(out)!r}: exists and is not a folder")
    parent = out if out.exists() else next((p for p in out.absolute().parents if p.exists()), None)
    if parent is None or not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"--out {str(out)!r}: cannot write there (no permission)")
    return out


def fit_command(data_path: str, out_dir: str, *, overwrite: bool = False) -> int:
    """Fit DATA.csv, write DIR/fit.json and the PNG figures, print a summary; returns 0.

    DIR is written as a run's result folder is (coupling/app/output.py): whole or not at all
    (an interruption while drawing leaves DIR as it was), a folder holding anything but a
    fit of the same data file only with ``overwrite``. Bad input raises ValueError (or
    FileNotFoundError) with a one-line message.
    """
    import sys

    from coupling.app.output import ResultFolder, fit_identity, project_matplotlib, recover

    _check_out(out_dir)  # before the fit: a bad destination fails at once
    restored = recover(out_dir, marker=FIT_JSON)
    if restored:
        print(f"switchsim: {restored}", file=sys.stderr)
    folder = ResultFolder.check(out_dir, fit_identity(data_path), overwrite=overwrite)
    df = read_tribometer_csv(data_path)
    fit = fit_tribometer(df)
    project_matplotlib()
    from coupling.app.fit_plots import save_plots  # matplotlib only once the fit is done

    names: list[str] = []

    def fill(staging: Path) -> None:
        names.extend(p.name for p in save_plots(fit, df, staging))
        fit.to_json(staging / FIT_JSON)  # last: a folder with fit.json is a finished fit

    out = folder.publish(fill)
    print(summary(fit))
    print("wrote " + ", ".join(str(Path(out_dir) / n) for n in [FIT_JSON, *names]))
    for note in folder.notes:
        print(f"switchsim: {note}", file=sys.stderr)
    return 0
