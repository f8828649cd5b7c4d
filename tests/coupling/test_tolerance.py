"""Tolerance studies (design = "tolerance", coupling.app.tolerance) against closed forms.

The study: a pushbutton read by a microcontroller pin (template mcu_input, contact made
at t_m on a prescribed schedule). After the make the pin falls from the open level V_o
towards the divider level V_c = Vcc R_c / (R_pull + R_c) with tau = (R_s + R_pull || R_c) C,
so the input's first edge, at the low threshold V_L, is

    t_edge = t_m + ln((V_o - V_c) / (V_L - V_c)) (R_s + R_pull || R_c) C = t_m + k R C,

linear in C (and in R = R_s + R_pull || R_c): a normal tolerance on C gives an exactly normal
t_edge (mean, std, percentiles and the fraction beyond a limit in closed form); a uniform
tolerance on R_s besides gives a product of independent variables, whose mean and variance
are exact too. ngspice's edge time meets the closed form per sample to 1.5 ns (TMAX 0.2 us),
0.6 % of the spread: the scatter is the tolerances', not numerical noise.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from coupling.app import tolerance as tol
from coupling.app.sweep import Sweep, load_sweep, run_sweep_inline
from coupling.core.scene import scene_from_dict

VCC, R_PULL, R_S, C_IN, R_C, V_LOW, T_MAKE = 3.3, 10e3, 2.2e3, 4.7e-9, 0.01, 0.99, 20e-6
SCENE = {
    "circuit": {"template": "mcu_input", "voltage": VCC, "pull_resistance": R_PULL, "series_resistance": R_S,
                "input_capacitance": C_IN, "contact_capacitance": 0.0, "logic_low": V_LOW, "max_step": 0.2e-6,
                "schedule": {"make": [T_MAKE], "break": [], "closed_resistance": R_C, "edge_time": 0.0}},
    "solver": {"t_end": 60e-6},
}
V_CLOSED = VCC * R_C / (R_PULL + R_C)
K = math.log((VCC - V_CLOSED) / (V_LOW - V_CLOSED))  # t_edge - t_m = K R C
R_PAR = R_PULL * R_C / (R_PULL + R_C)


def edge_exact(r_s, c):
    return T_MAKE + K * (np.asarray(r_s) + R_PAR) * np.asarray(c)


def _inside(entry: dict, truth: float, name: str) -> None:
    lo, hi = entry["interval"]
    assert (lo is None or lo <= truth) and (hi is None or truth <= hi), f"{name}: {truth!r} not in [{lo}, {hi}]"


@pytest.fixture(scope="module")
def normal_study():
    """400 runs, C normal with T = 6 % (3 sigma): t_edge exactly normal."""
    sweep = Sweep.tolerance(scene_from_dict(SCENE), {"circuit.input_capacitance": {
        "tolerance": 0.06 * C_IN, "distribution": "normal"}}, samples=400, seed=11,
        limits={"logic.first_edge": float(edge_exact(R_S, C_IN) + 1.5 * K * (R_S + R_PAR) * 0.02 * C_IN)})
    return sweep, pd.DataFrame(run_sweep_inline(sweep))


def test_a_normal_tolerance_recovers_mean_spread_percentiles_and_the_fraction_beyond(normal_study):
    sweep, df = normal_study
    assert (df.status == "ok").all()
    # each sample against the closed form: numerical error far below the spread (measured 1.5 ns, 0.6 %)
    exact = edge_exact(R_S, df["circuit.input_capacitance"])
    sigma = K * (R_S + R_PAR) * 0.02 * C_IN
    assert np.max(np.abs(df["logic.first_edge"] - exact)) < 0.01 * sigma
    out = tol.statistics(df, list(sweep.study["tolerances"]), sweep.study["limits"])["logic.first_edge"]
    mu = float(edge_exact(R_S, C_IN))
    assert out["unit"] == "s" and out["n"] == 400
    _inside(out["mean"], mu, "mean")
    _inside(out["std"], sigma, "std")
    for p in (50, 95, 99):
        _inside(out[f"p{p}"], mu + stats.norm.ppf(p / 100) * sigma, f"p{p}")
    beyond = 1.0 - stats.norm.cdf(1.5)  # the limit sits at mu + 1.5 sigma
    _inside(out["limit"]["fraction"], beyond, "fraction beyond the limit")
    # and the intervals are as narrow as n = 400 makes them (not trivially wide)
    width = out["mean"]["interval"][1] - out["mean"]["interval"][0]
    assert width == pytest.approx(2 * 1.966 * sigma / 20, rel=0.15)
    std_width = out["std"]["interval"][1] - out["std"]["interval"][0]
    assert std_width == pytest.approx(2 * 1.96 * sigma / math.sqrt(2 * 399), rel=0.15)
    assert out["sensitivity"]["circuit.input_capacitance"]["spearman"] > 0.999  # t_edge rises with C alone


def test_two_tolerances_product_moments_and_which_one_drives_the_spread():
    """R_s uniform +-10 % (sigma 5.8 %) and C normal 3 sigma = 6 % (sigma 2 %): t - t_m = k R C
    with independent R, C, so E = k R0 C0 and Var = k^2 ((R0^2 + sR^2)(C0^2 + sC^2) - R0^2 C0^2);
    R_s's tolerance drives the spread (linearised correlations 0.94 and 0.33; measured Spearman
    0.95 and 0.29)."""
    sweep = Sweep.tolerance(scene_from_dict(SCENE), {
        "circuit.series_resistance": {"tolerance": 0.1, "distribution": "uniform", "relative": True},
        "circuit.input_capacitance": {"tolerance": 0.06, "distribution": "normal", "relative": True}},
        samples=300, seed=5)
    df = pd.DataFrame(run_sweep_inline(sweep))
    r = df["circuit.series_resistance"].to_numpy()
    assert r.min() >= 0.9 * R_S and r.max() <= 1.1 * R_S  # uniform: inside +-T
    out = tol.statistics(df, list(sweep.study["tolerances"]))["logic.first_edge"]
    r0, s_r, c0, s_c = R_S + R_PAR, 0.1 * R_S / math.sqrt(3), C_IN, 0.02 * C_IN
    _inside(out["mean"], T_MAKE + K * r0 * c0, "mean")
    _inside(out["std"], K * math.sqrt((r0 ** 2 + s_r ** 2) * (c0 ** 2 + s_c ** 2) - r0 ** 2 * c0 ** 2), "std")
    rho = out["sensitivity"]
    assert rho["circuit.series_resistance"]["spearman"] > 0.85
    assert 0.1 < rho["circuit.input_capacitance"]["spearman"] < 0.5


def test_the_intervals_cover_at_their_confidence():
    """Coverage of each interval over 2000 synthetic normal (and binomial) data sets against
    the known truth: 0.95 +- 3 binomial standard errors (0.015); the order-statistic
    intervals are conservative (>= 0.95), Wilson's is approximate."""
    rng = np.random.default_rng(2)
    m = 2000
    hits = {"mean": 0, "std": 0, "p50": 0, "p95": 0, "wilson": 0}
    for _ in range(m):
        x = rng.normal(1.0, 2.0, 100)
        lo, hi = tol.mean_interval(x)
        hits["mean"] += lo <= 1.0 <= hi
        lo, hi = tol.std_interval(x)
        hits["std"] += lo <= 2.0 <= hi
        for p in (50, 95):
            lo, hi = tol.quantile_interval(x, p / 100)
            truth = 1.0 + 2.0 * stats.norm.ppf(p / 100)
            hits[f"p{p}"] += (lo is None or lo <= truth) and (hi is None or truth <= hi)
        lo, hi = tol.wilson_interval(int(rng.binomial(50, 0.1)), 50)
        hits["wilson"] += lo <= 0.1 <= hi
    cover = {k: v / m for k, v in hits.items()}
    assert abs(cover["mean"] - 0.95) < 0.015 and abs(cover["std"] - 0.95) < 0.015, cover
    assert cover["p50"] > 0.935 and cover["p95"] > 0.935, cover
    assert 0.92 < cover["wilson"] < 0.98, cover


def _write(tmp_path, body: str, scene: dict = SCENE):
    from test_scene_key_paths import toml_text

    (tmp_path / "mcu.toml").write_text(toml_text(scene))
    (tmp_path / "study.toml").write_text('[sweep]\nscene = "mcu.toml"\n' + body)
    return tmp_path / "study.toml"


TOLERANCE = '[sweep.tolerances]\n"circuit.input_capacitance" = { tolerance = 0.1, distribution = "normal", ' \
            'relative = true }\n'


def test_the_same_seed_gives_the_same_runs(tmp_path):
    path = _write(tmp_path, 'design = "tolerance"\nsamples = 5\nseed = 7\n' + TOLERANCE)
    a, b = load_sweep(path), load_sweep(path)
    assert a.runs == b.runs and a.fingerprint() == b.fingerprint()
    other = load_sweep(_write(tmp_path, 'design = "tolerance"\nsamples = 5\nseed = 8\n' + TOLERANCE))
    assert [r.params for r in other.runs] != [r.params for r in a.runs]


@pytest.mark.parametrize("body, fragments", [
    ('design = "tolerance"\nsamples = 4\n[sweep.tolerances]\n"circuit.template" = { tolerance = 1.0 }\n',
     ["'circuit.template'", "non-numeric key", "'mcu_input'"]),
    ('design = "tolerance"\nsamples = 4\n[sweep.tolerances]\n"circuit.logic_high" = { tolerance = 0.1 }\n',
     ["'circuit.logic_high'", "does not give"]),
    ('design = "tolerance"\nsamples = 4\n[sweep.tolerances]\n"circuit.input_capacitance" = '
     '{ tolerance = 1e-10, distribution = "gauss" }\n', ["'circuit.input_capacitance'", "distribution = 'gauss'",
                                                         "'normal', 'uniform'"]),
    ('design = "tolerance"\nsamples = 4\nlimits = { "logic.first_edg" = 1e-5 }\n' + TOLERANCE,
     ["no metric 'logic.first_edg'", "did you mean 'logic.first_edge'"]),
    ('design = "tolerance"\nsamples = 4\nlimits = { "bounce.total_bounce_tim" = 4e-3 }\n' + TOLERANCE,
     ["did you mean 'bounce.total_bounce_time'"]),
    ('design = "tolerance"\nsamples = 4\nlimits = { "logic.first_edge" = "soon" }\n' + TOLERANCE,
     ["'logic.first_edge' = 'soon'", "finite number"]),
    ('design = "tolerance"\nsamples = 4\n[sweep.tolerances]\n"circuit.input_capacitance" = { tolerance = -1.0 }\n',
     ["tolerance = -1.0", "> 0"]),
    ('design = "tolerance"\n' + TOLERANCE, ["needs sweep.samples"]),
    ('design = "tolerance"\nsamples = 4\ncheck = 5\n' + TOLERANCE, ["sweep check = 5", "0 to samples = 4"]),
    ('design = "lhs"\nsamples = 4\ncheck = 1\n[sweep.ranges]\n"circuit.input_capacitance" = [1e-9, 2e-9]\n',
     ["sweep.check", "tolerance\" only"]),
    ('design = "lhs"\nsamples = 4\nlimits = { "logic.first_edge" = 1e-5 }\n[sweep.ranges]\n'
     '"circuit.input_capacitance" = [1e-9, 2e-9]\n', ["sweep.limits", "tolerance\" only"]),
    ('design = "tolerance"\nsamples = 4\n[sweep.tolerances]\n"circuit.input_capacitance" = '
     '{ tolerance = 1e-9, shape = "normal" }\n', ["unknown key 'shape'"]),
])
def test_bad_input_is_one_line(tmp_path, body, fragments):
    with pytest.raises(ValueError) as err:
        load_sweep(_write(tmp_path, body))
    msg = str(err.value)
    assert "\n" not in msg, msg
    for fragment in fragments:
        assert fragment in msg, msg


def test_a_study_on_dask_writes_statistics_and_plots(tmp_path):
    pytest.importorskip("distributed")
    from coupling.app.sweep import read_results, run_sweep

    path = _write(tmp_path, 'design = "tolerance"\nsamples = 6\nseed = 1\nlimits = { "logic.first_edge" = 32.5e-6 }\n'
                  + TOLERANCE)
    report = run_sweep(load_sweep(path), tmp_path / "out", workers=1, progress=False)
    assert report.complete and report.statistics == str(tmp_path / "out" / "statistics.json")
    doc = json.loads((tmp_path / "out" / "statistics.json").read_text())
    df = read_results(tmp_path / "out")
    assert set(doc) - {"_study"} <= set(df.columns)  # keyed by the rows' column names
    edge = doc["logic.first_edge"]
    assert edge["n"] == 6 and set(edge) >= {"mean", "std", "p50", "p95", "p99", "limit", "sensitivity"}
    assert edge["mean"]["value"] == pytest.approx(df["logic.first_edge"].mean(), rel=1e-12)
    assert edge["limit"]["beyond"] == int((df["logic.first_edge"] > 32.5e-6).sum())
    assert doc["_study"]["seed"] == 1 and doc["_study"]["intervals"]["fraction_beyond"] == "Wilson score interval"
    assert (tmp_path / "out" / "plots" / "tolerance_logic.first_edge.png").stat().st_size > 10_000


def test_free_drop_first_make_under_a_height_tolerance_with_the_numerical_check():
    """The built-in free drop, coupled: the bar falls freely (no rotation) from height h at
    v = 1 m/s down, so its first make is at t(h) = (sqrt(v^2 + 2 g h) - v) / g. A normal
    tolerance on h (T = 3 sigma = 5 %) gives t's std = t'(h0) sigma_h and mean
    t(h0) + t''(h0) sigma_h^2 / 2 (to O(sigma^4): 1e-13 s here); the fraction beyond
    t(h0) + t'(h0) sigma_h is 1 - Phi(1) = 0.159. Two runs are rerun refined (check = 2):
    their numerical change is far below the spread."""
    from coupling import builtin_scene

    g, v, h0 = 9.80665, 1.0, 1e-3
    sigma_h = 0.05 * h0 / 3.0
    root = math.sqrt(v * v + 2 * g * h0)
    t0, slope, curvature = (root - v) / g, 1.0 / root, -g / root ** 3
    base = builtin_scene("free_drop").set("solver.t_end", 1.3e-3)
    assert base.raw["initial"]["velocity"][2] == -v and base.raw["initial"]["height"] == h0
    sweep = Sweep.tolerance(base, {"initial.height": {"tolerance": 0.05, "distribution": "normal",
                                                      "relative": True}},
                            samples=40, seed=4, check=2, limits={"bounce.first_make": t0 + slope * sigma_h})
    df = pd.DataFrame(run_sweep_inline(sweep))
    h = df["initial.height"].to_numpy()
    # each sample's event time against free fall: the mechanics locates the touchdown to 1e-12 s
    assert np.max(np.abs(df["bounce.first_make"] - (np.sqrt(v * v + 2 * g * h) - v) / g)) < 1e-12
    out = tol.statistics(df, ["initial.height"], sweep.study["limits"])["bounce.first_make"]
    _inside(out["mean"], t0 + curvature * sigma_h ** 2 / 2.0, "mean")
    _inside(out["std"], slope * sigma_h, "std")
    _inside(out["p50"], t0, "p50")
    _inside(out["limit"]["fraction"], 1.0 - stats.norm.cdf(1.0), "fraction beyond")
    numerical = out["numerical"]
    assert numerical["checked_runs"] == 2 and numerical["ratio_to_std"] < tol.NUMERICAL_FRACTION
    assert numerical["verdict"] == "scatter from the tolerances"
    assert df["numerical.status"].notna().sum() == 2  # the first two runs alone were checked
