"""Tolerance studies: a base scene with manufacturing tolerances on some of its keys, sampled
(a seeded Monte Carlo), run as a sweep, and judged by the statistics of every scalar metric.

    [sweep]
    design = "tolerance"
    samples = 200
    seed = 1
    limits = { "bounce.total_bounce_time" = 4e-3 }     # optional: datasheet limits (SI)

    [sweep.tolerances]
    "rivet[0].mass" = { tolerance = 2e-6, distribution = "normal" }   # T = 3 sigma
    "spring[0].stiffness" = { tolerance = 0.05, distribution = "uniform", relative = true }

normal: value = base + (T / 3) z, z standard normal (T is three standard deviations);
uniform: value = base + T (2u - 1), u uniform in [0, 1) (base +- T). T is in the key's unit
(SI), or a fraction of the base value with ``relative = true``. The base value is the one the
base scene gives (after ``[sweep] set``); the key must be a number there. Draws are
independent per key, from numpy's default_rng(seed), in the order the keys are written:
the same seed gives the same runs.

``statistics(df, study)`` judges the rows (``DIR/statistics.json``, keyed by the row's
column name): per scalar metric mean, std, p50, p95, p99, each with a confidence interval
(CONFIDENCE):

- mean: Student's t interval (normal theory; for other distributions asymptotically right);
- std: chi-square interval (normal theory: exact for a normal metric, too narrow for a
  heavy-tailed one);
- p50, p95, p99: distribution-free order-statistic intervals (the count of samples below a
  percentile is binomial): [x_(l), x_(u)] with coverage at least the confidence; a bound
  that would need more samples than there are is null (p99's upper bound needs n >= ~300
  at 95 %);
- a limit: the fraction of runs beyond it (metric > limit) with Wilson's score interval;
- sensitivity: Spearman's rank correlation of each toleranced key with the metric (and its
  p-value): which tolerance drives the spread;
- numerical: with ``[sweep] check = N`` the first N runs (a random subset: the draws are
  random) are also rerun refined as ``switchsim run --check`` does (coupling.app.accuracy,
  without its input perturbations), and each metric the check knows gets the largest change
  a refinement made, against the study's std: a ratio well below 1 says the scatter is the
  tolerances', not numerical noise.
"""

from __future__ import annotations

import math

import numpy as np

DISTRIBUTIONS = ("normal", "uniform")
CONFIDENCE = 0.95
_SPEC_KEYS = ("tolerance", "distribution", "relative")
#: The metrics ``run --check`` judges (coupling.app.accuracy.metrics_of) by their row columns.
CHECKED_METRICS = {f"bounce.{k}": k for k in ("first_make", "last_make", "bounces", "total_bounce_time",
                                               "peak_contact_voltage", "arc_energy")}
#: A metric's numerical change below this fraction of its std: the scatter is the tolerances'.
NUMERICAL_FRACTION = 0.1
#: Row columns that are never metrics (the run's bookkeeping).
_NOT_METRICS = ("run_id", "name", "status", "error", "session", "finished_at", "wall_time")

INTERVALS = {
    "mean": "Student's t interval (normal theory)",
    "std": "chi-square interval (normal theory)",
    "p50": "order-statistic interval (binomial, distribution-free, coverage >= confidence)",
    "p95": "order-statistic interval (binomial, distribution-free, coverage >= confidence)",
    "p99": "order-statistic interval (binomial, distribution-free, coverage >= confidence)",
    "fraction_beyond": "Wilson score interval",
    "sensitivity": "Spearman rank correlation of the toleranced key with the metric, with its p-value",
}


# --- the draws ----------------------------------------------------------------------------


def check_tolerances(tolerances: dict, base_doc: dict) -> dict:
    """{key: (base value, T in the key's unit, distribution)} of a ``[sweep.tolerances]``
    table, checked against the base scene's document; one line naming the key otherwise."""
    from coupling.core.scene import key_value

    if not isinstance(tolerances, dict) or not tolerances:
        raise ValueError(f"sweep.tolerances = {tolerances!r:.200}: expected a table of "
                         "'key' = {{ tolerance = T, distribution = \"normal\" | \"uniform\" }}")
    out = {}
    for key, spec in tolerances.items():
        where = f"sweep.tolerances {key!r}"
        if not isinstance(spec, dict):
            raise ValueError(f"{where} = {spec!r:.100}: expected {{ tolerance = T, distribution = \"normal\" | "
                             "\"uniform\" }")
        unknown = sorted(set(spec) - set(_SPEC_KEYS))
        if unknown:
            from mech.validation import suggest

            raise ValueError(f"{where}: unknown key {unknown[0]!r}{suggest(unknown[0], _SPEC_KEYS)}; allowed: "
                             f"{', '.join(_SPEC_KEYS)}")
        distribution = spec.get("distribution", "normal")
        if distribution not in DISTRIBUTIONS:
            from mech.validation import suggest

            raise ValueError(f"{where}: distribution = {distribution!r}{suggest(distribution, DISTRIBUTIONS)}; "
                             f"allowed: {', '.join(map(repr, DISTRIBUTIONS))}")
        tolerance = spec.get("tolerance")
        if (isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not math.isfinite(tolerance)
                or tolerance <= 0):
            raise ValueError(f"{where}: tolerance = {tolerance!r}: expected a finite number > 0 (the key's unit; "
                             "normal: 3 sigma, uniform: +- T)")
        relative = spec.get("relative", False)
        if not isinstance(relative, bool):
            raise ValueError(f"{where}: relative = {relative!r}: expected true or false")
        value = key_value(base_doc, key, where)
        if value is None:
            raise ValueError(f"{where}: the base scene does not give {key}; a tolerance varies a value around the "
                             "one the scene states: set it in the scene (or in sweep.set)")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            hint = f" (a list: give one entry, e.g. {key}[0])" if isinstance(value, list) else ""
            raise ValueError(f"{where}: tolerance on a non-numeric key: the base scene gives {key} = {value!r:.80}"
                             f"{hint}; a tolerance applies to numbers")
        if relative:
            if value == 0:
                raise ValueError(f"{where}: relative = true, but the base value is 0; give tolerance in the key's unit")
            tolerance = tolerance * abs(value)
        out[key] = (float(value), float(tolerance), distribution)
    return out


def draw(tolerances: dict, samples: int, seed: int) -> list[dict]:
    """``samples`` runs' values ({key: value}) of checked tolerances (check_tolerances)."""
    rng = np.random.default_rng(seed)
    columns = {}
    for key, (base, tolerance, distribution) in tolerances.items():
        if distribution == "normal":
            columns[key] = base + (tolerance / 3.0) * rng.standard_normal(samples)
        else:
            columns[key] = base + tolerance * (2.0 * rng.random(samples) - 1.0)
    return [{key: float(columns[key][k]) for key in tolerances} for k in range(samples)]


def check_limits(limits, where: str = "sweep.limits") -> dict:
    """{metric column: limit} with each metric a summary column (coupling.app.quantities.SUMMARY,
    the rows' columns) and each limit a finite number; one line with a did-you-mean otherwise."""
    from coupling.app.quantities import SUMMARY
    from mech.validation import suggest

    if limits is None:
        return {}
    if not isinstance(limits, dict):
        raise ValueError(f"{where} = {limits!r:.200}: expected a table of \"metric\" = limit, e.g. "
                         "{ \"bounce.total_bounce_time\" = 4e-3 }")
    out = {}
    for metric, limit in limits.items():
        if metric not in SUMMARY or metric in _NOT_METRICS:
            raise ValueError(f"{where}: no metric {metric!r}{suggest(metric, SUMMARY)}; the metrics are the "
                             "summary's columns (docs/sweeps.md, Results), e.g. bounce.total_bounce_time")
        if isinstance(limit, bool) or not isinstance(limit, (int, float)) or not math.isfinite(limit):
            raise ValueError(f"{where}: {metric!r} = {limit!r}: expected a finite number (the metric's SI unit)")
        out[metric] = float(limit)
    return out


def numerical_changes(accuracy: dict) -> dict:
    """{"numerical.<metric column>": the largest |change| any refinement that ran made} of a
    run's ``run --check`` verdict (coupling.app.accuracy.check), and "numerical.status"."""
    out: dict = {"numerical.status": accuracy.get("status")}
    for column, name in CHECKED_METRICS.items():
        changes = [abs(entry["metrics"][name]["change"]) for entry in accuracy.get("refinements", [])
                   if entry.get("status") == "ok" and entry.get("metrics", {}).get(name, {}).get("change") is not None]
        if changes:
            out[f"numerical.{column}"] = float(max(changes))
    return out


# --- the statistics -----------------------------------------------------------------------


def mean_interval(x: np.ndarray, confidence: float = CONFIDENCE) -> tuple[float, float]:
    from scipy import stats

    n = len(x)
    half = stats.t.ppf(0.5 + confidence / 2.0, n - 1) * np.std(x, ddof=1) / math.sqrt(n)
    m = float(np.mean(x))
    return m - half, m + half


def std_interval(x: np.ndarray, confidence: float = CONFIDENCE) -> tuple[float, float]:
    from scipy import stats

    n = len(x)
    ss = (n - 1) * float(np.var(x, ddof=1))
    a = 1.0 - confidence
    return math.sqrt(ss / stats.chi2.ppf(1.0 - a / 2.0, n - 1)), math.sqrt(ss / stats.chi2.ppf(a / 2.0, n - 1))


def quantile_interval(x: np.ndarray, p: float, confidence: float = CONFIDENCE) -> tuple[float | None, float | None]:
    """[x_(l), x_(u)] (1-based order statistics) holding the p-quantile with probability at
    least ``confidence``: the count below it is binomial(n, p), l and u its (1 -+ c)/2
    quantiles; None for a bound beyond the samples."""
    from scipy import stats

    xs = np.sort(x)
    n = len(xs)
    a = (1.0 - confidence) / 2.0
    lo = int(stats.binom.ppf(a, n, p))  # P(count <= lo - 1) < a
    hi = int(stats.binom.ppf(1.0 - a, n, p)) + 1  # P(count >= hi) <= a
    return (float(xs[lo - 1]) if lo >= 1 else None), (float(xs[hi - 1]) if hi <= n else None)


def wilson_interval(k: int, n: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    from scipy import stats

    z = stats.norm.ppf(0.5 + confidence / 2.0)
    centre = (k + z * z / 2.0) / (n + z * z)
    half = z / (n + z * z) * math.sqrt(k * (n - k) / n + z * z / 4.0)
    return max(0.0, centre - half), min(1.0, centre + half)


def _entry(value, interval) -> dict:
    return {"value": _num(value), "interval": [_num(interval[0]), _num(interval[1])]}


def _num(v):
    return None if v is None or not math.isfinite(v) else float(v)


def metric_columns(df, parameters) -> list[str]:
    """The rows' scalar metric columns: numeric, not a parameter, not the run's bookkeeping."""
    import pandas as pd

    out = []
    for column in df.columns:
        if (column in parameters or column in _NOT_METRICS or column.startswith("numerical.")
                or column.startswith("summary.") and column[8:] in parameters):
            continue
        series = df[column]
        if pd.api.types.is_bool_dtype(series) or not pd.api.types.is_numeric_dtype(series):
            continue
        out.append(column)
    return out


def statistics(df, parameters, limits: dict | None = None, confidence: float = CONFIDENCE) -> dict:
    """The statistics of a tolerance study's rows (pandas, as read_results gives them): per
    metric column {n, missing, unit, mean, std, p50, p95, p99 (each value and interval),
    limit (value, beyond, fraction with its interval), sensitivity {key: {spearman,
    p_value}}}. ``parameters``: the toleranced keys; ``limits``: {metric: limit}."""
    from scipy import stats

    from coupling.app.quantities import quantity

    limits = limits or {}
    ok = df[df["status"] == "ok"] if "status" in df.columns else df
    out = {}
    for column in metric_columns(ok, parameters):
        values = ok[column].to_numpy(float)
        finite = np.isfinite(values)
        x = values[finite]
        n = len(x)
        if n < 2:
            continue
        q = quantity(column)
        entry = {"unit": q.unit if q is not None else None, "n": n, "missing": int(len(values) - n)}
        entry["mean"] = _entry(np.mean(x), mean_interval(x, confidence))
        entry["std"] = _entry(np.std(x, ddof=1), std_interval(x, confidence))
        for p in (50, 95, 99):
            entry[f"p{p}"] = _entry(np.percentile(x, p), quantile_interval(x, p / 100.0, confidence))
        if column in limits:
            k = int(np.sum(x > limits[column]))
            entry["limit"] = {"value": limits[column], "beyond": k,
                              "fraction": _entry(k / n, wilson_interval(k, n, confidence))}
        sens = {}
        for key in parameters:
            p = ok[key].to_numpy(float)[finite]
            if np.ptp(p) == 0 or np.ptp(x) == 0:
                sens[key] = {"spearman": None, "p_value": None}
                continue
            rho, pv = stats.spearmanr(p, x)
            sens[key] = {"spearman": _num(float(rho)), "p_value": _num(float(pv))}
        entry["sensitivity"] = sens
        if f"numerical.{column}" in ok.columns:
            changes = ok[f"numerical.{column}"].to_numpy(float)
            changes = changes[np.isfinite(changes)]
            if len(changes):
                std = float(np.std(x, ddof=1))
                worst = float(np.max(changes))
                ratio = worst / std if std > 0 else None
                entry["numerical"] = {
                    "checked_runs": int(len(changes)), "max_change": worst, "ratio_to_std": _num(ratio),
                    "verdict": ("scatter from the tolerances" if ratio is not None and ratio < NUMERICAL_FRACTION
                                else "numerical error is a sizeable part of the spread: refine the scene "
                                     "(switchsim run --check names the setting)")}
        out[column] = entry
    return out


def write_statistics(out_dir, study: dict, *, plots: bool = True) -> dict:
    """DIR/statistics.json (and, with ``plots``, DIR/plots/tolerance_<metric>.png: a histogram
    and the empirical CDF of each metric with a limit, else of each varying bounce.* and
    logic.* metric) of the rows in DIR/results. ``study``: the sweep's {tolerances, limits,
    samples, seed}."""
    import json
    import os
    from pathlib import Path

    from coupling.app.sweep import read_results

    out = Path(out_dir)
    df = read_results(out)
    parameters = list(study["tolerances"])
    metrics = statistics(df, parameters, study.get("limits"), study.get("confidence", CONFIDENCE))
    failed = int((df["status"] != "ok").sum()) if "status" in df.columns else 0
    doc = {"_study": {"samples": study.get("samples"), "seed": study.get("seed"), "rows": int(len(df)),
                      "checked_runs": study.get("check", 0),
                      "failed": failed, "confidence": study.get("confidence", CONFIDENCE),
                      "tolerances": study["tolerances"], "limits": study.get("limits") or {},
                      "intervals": INTERVALS,
                      # a limit's metric that no run reported (the scene's kind does not compute it, or
                      # fewer than two runs had it): said here rather than silently left out
                      "limits_not_reported": sorted(set(study.get("limits") or {}) - set(metrics))},
           **metrics}
    path = out / "statistics.json"
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(doc, indent=1))
    os.replace(tmp, path)
    if plots:
        from coupling.app.sweep_plots import save

        limits = study.get("limits") or {}
        chosen = list(limits) or [m for m in metrics if m.startswith(("bounce.", "logic."))
                                  and metrics[m]["std"]["value"]]
        folder = out / "plots"
        folder.mkdir(exist_ok=True)
        ok = df[df["status"] == "ok"] if "status" in df.columns else df
        for metric in chosen:
            if metric in metrics:
                save(plot_distribution(ok, metric, limits.get(metric), metrics[metric]),
                     folder / f"tolerance_{metric}.png")
    return doc


def plot_distribution(df, metric: str, limit: float | None = None, stats: dict | None = None):
    """A histogram (left) and the empirical CDF (right) of ``metric`` over the rows, the
    normal of the same mean and std over both, p50/p95/p99 and the limit marked; axes in
    the metric's unit (coupling.app.quantities)."""
    from matplotlib.figure import Figure
    from scipy import stats as st

    from coupling.app.quantities import label

    x = df[metric].to_numpy(float)
    x = np.sort(x[np.isfinite(x)])
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    hist, cdf = fig.subplots(1, 2)
    m, s = float(np.mean(x)), float(np.std(x, ddof=1))
    grid = np.linspace(x[0] - 0.1 * (x[-1] - x[0] + s), x[-1] + 0.1 * (x[-1] - x[0] + s), 200)
    hist.hist(x, bins=max(5, min(40, int(math.sqrt(len(x))) + 1)), density=True, color="C0", alpha=0.6,
              label=f"{len(x)} runs")
    empirical = np.arange(1, len(x) + 1) / len(x)
    cdf.step(x, empirical, where="post", color="C0", label="runs")
    if s > 0:
        hist.plot(grid, st.norm.pdf(grid, m, s), "k-", lw=1, label="normal, same mean and std")
        cdf.plot(grid, st.norm.cdf(grid, m, s), "k-", lw=1, label="normal, same mean and std")
    for p, style in ((50, ":"), (95, "-."), (99, "--")):
        v = float(np.percentile(x, p))
        cdf.axvline(v, color="C2", ls=style, lw=0.9, label=f"p{p}")
    if limit is not None:
        for ax in (hist, cdf):
            ax.axvline(limit, color="C3", lw=1.2, label="limit")
        if stats is not None and "limit" in stats:
            frac = stats["limit"]["fraction"]
            cdf.set_title(f"runs beyond the limit: {100 * frac['value']:.3g} % ({100 * CONFIDENCE:g} % Wilson interval "
                          f"{100 * frac['interval'][0]:.3g} to {100 * frac['interval'][1]:.3g} %)", fontsize=9)
    name = label(metric)
    hist.set_xlabel(name)
    hist.set_ylabel(f"probability density (1/{_unit_of(metric)})")
    cdf.set_xlabel(name)
    cdf.set_ylabel("fraction of runs <= value (-)")
    from coupling.app.sweep_plots import _si_ticks

    for ax in (hist, cdf):
        _si_ticks(ax.xaxis, x)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    return fig


def _unit_of(metric: str) -> str:
    from coupling.app.quantities import quantity

    q = quantity(metric)
    return q.unit if q is not None and q.unit != "-" else "unit of the metric"
