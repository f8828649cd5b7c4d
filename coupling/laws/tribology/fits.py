"""Fitting the tribometer laws: gamma and mu(I) from friction, R_c(F_n, I) from resistance, with model selection.

All fits are least squares on log values: the scatter of a tribometer is
multiplicative (a few % of the reading at every load), so ln F_t and ln R_c have
constant variance. Uncertainties are the usual Gauss-Newton covariance
s^2 (J^T J)^-1 with Student-t 95 % intervals. Candidates are ranked by BIC (AICc is
reported alongside); docs/tribology.md gives the reasons.

Rows are reduced to their (load, |I|) cells before fitting: a least-squares fit on ln
values depends on the rows only through each cell's count, its mean ln value and the
within-cell sum of squares, so the estimates, the residual sum of squares and the
covariance are exactly those of the row-by-row fit, at the cost of the number of cells
(a 1,000,000-row file of repeated settings fits as fast as its few dozen cells).

Outliers (`fit_tribometer`): rows far from the rest are flagged and left out of the fit,
by a stated rule (docs/tribology.md): (1) gross values, whose ln lies more than
GROSS_MADS robust standard deviations (1.4826 MAD) and more than a factor GROSS_FACTOR
from the column's median (a 1e308 N load, a 1e-320 N friction); (2) then, in up to MAX_ROUNDS
rounds, rows whose externally studentized ln residual from the chosen model exceeds the
Bonferroni limit of the Student t distribution for a 1 % chance of flagging any row of
Gaussian data (the Bonferroni outlier test), refitting after each round. The flagged rows and the
reason are reported in the fit (and fit.json, and `switchsim fit`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

import numpy as np

from mech.frozen import frozen
from coupling.laws.tribology.data import validate_tribometer_frame
from coupling.laws.tribology.laws import ContactLaws, MuLaw, ResistanceLaw
from coupling.laws.tribology.models import CURRENT_FAMILIES, LOAD_FAMILIES, MU_FAMILIES, load_law_parameters

if TYPE_CHECKING:  # pandas is imported by the fitting, not by a stored fit's reading
    import pandas as pd

CRITERION = "BIC"
# Delta BIC below this is "not worth more than a bare mention" (Kass & Raftery 1995):
# such candidates are listed as indistinguishable from the chosen one.
AMBIGUOUS_DELTA = 2.0
FORMAT = "switchsim-tribometer-fit"
FORMAT_VERSION = 1


# ---------------------------------------------------------------------------------
# Result objects


@frozen
class ParameterEstimate:
    """A fitted parameter: value, standard error and 95 % interval (None when not estimable), unit."""

    name: str
    value: float
    stderr: float | None
    ci95: tuple[float, float] | None
    unit: str

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "value": self.value, "stderr": self.stderr,
                "ci95": None if self.ci95 is None else list(self.ci95), "unit": self.unit}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ParameterEstimate":
        return cls(d["name"], d["value"], d["stderr"], None if d["ci95"] is None else tuple(d["ci95"]), d["unit"])


@frozen
class Outlier:
    """A data row left out of a fit: its position in the table (0-based), where it is
    ("line 57" of the CSV, or "row 12"), the column and value, and why (the rule)."""

    row: int
    where: str
    column: str
    value: float
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {"row": self.row, "where": self.where, "column": self.column, "value": self.value,
                "reason": self.reason}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Outlier":
        return cls(int(d["row"]), str(d["where"]), str(d["column"]), float(d["value"]), str(d["reason"]))


@frozen
class ModelFit:
    """One fitted candidate and its goodness of fit (all in log space).

    resid_std_log: standard deviation of the ln residuals, about the relative scatter;
    r_squared_log: R^2 of ln values; lack_of_fit_p: p-value of the lack-of-fit F-test
    against the scatter of repeats at equal (load, current) (None without repeats):
    small means the curve misses the repeat means by more than the repeats scatter.
    covariance: of the parameters in their listed order (None when a parameter sits on
    a bound or the parameters are not identifiable; `note` says which).
    """

    name: str
    formula: str
    parameters: tuple[ParameterEstimate, ...]
    covariance: tuple[tuple[float, ...], ...] | None
    n_points: int
    rss_log: float
    resid_std_log: float
    r_squared_log: float | None
    aicc: float
    bic: float
    lack_of_fit_p: float | None
    note: str

    @property
    def n_parameters(self) -> int:
        return len(self.parameters)

    def value(self, name: str) -> float:
        for p in self.parameters:
            if p.name == name:
                return p.value
        raise KeyError(f"{self.name} has no parameter {name!r}; it has {[p.name for p in self.parameters]}")

    def estimate(self, name: str) -> ParameterEstimate:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(f"{self.name} has no parameter {name!r}; it has {[p.name for p in self.parameters]}")

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name, "formula": self.formula,
            "parameters": [p.to_dict() for p in self.parameters],
            "covariance": None if self.covariance is None else [list(r) for r in self.covariance],
            "n_points": self.n_points, "rss_log": self.rss_log, "resid_std_log": self.resid_std_log,
            "r_squared_log": self.r_squared_log, "aicc": self.aicc, "bic": self.bic,
            "lack_of_fit_p": self.lack_of_fit_p, "note": self.note,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ModelFit":
        return cls(
            d["name"], d["formula"], tuple(ParameterEstimate.from_dict(p) for p in d["parameters"]),
            None if d["covariance"] is None else tuple(tuple(r) for r in d["covariance"]),
            d["n_points"], d["rss_log"], d["resid_std_log"], d["r_squared_log"], d["aicc"], d["bic"],
            d["lack_of_fit_p"], d["note"],
        )


@frozen
class ModelSelection:
    """Candidates ranked by the criterion (lowest first); `chosen` is the first.

    skipped: (name, reason) of candidates the data cannot fit (too few current levels
    or loads, or a failed fit). ambiguous: candidates within AMBIGUOUS_DELTA of the
    chosen one's criterion, i.e. not distinguishable by these data.
    """

    criterion: str
    candidates: tuple[ModelFit, ...]
    skipped: tuple[tuple[str, str], ...]

    @property
    def chosen(self) -> ModelFit:
        return self.candidates[0]

    def score(self, m: ModelFit) -> float:
        return m.bic if self.criterion == "BIC" else m.aicc

    def delta(self, name: str) -> float:
        """Criterion of candidate `name` minus the chosen one's (>= 0)."""
        return self.score(self.candidate(name)) - self.score(self.chosen)

    def candidate(self, name: str) -> ModelFit:
        for m in self.candidates:
            if m.name == name:
                return m
        raise KeyError(f"no fitted candidate {name!r}; fitted: {[m.name for m in self.candidates]}")

    @property
    def ambiguous(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.candidates[1:] if self.delta(m.name) < AMBIGUOUS_DELTA)

    def to_dict(self) -> dict[str, Any]:
        return {
            "criterion": self.criterion, "chosen": self.chosen.name,
            "candidates": [m.to_dict() for m in self.candidates],
            "skipped": [list(s) for s in self.skipped],
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ModelSelection":
        return cls(d["criterion"], tuple(ModelFit.from_dict(m) for m in d["candidates"]),
                   tuple(tuple(s) for s in d["skipped"]))


@frozen
class CoulombComparison:
    """Free gamma against Coulomb (gamma = 0), both with one free mu per current level.

    The models are nested (Coulomb fixes one parameter), so the F-test is exact for
    Gaussian ln scatter. delta_bic, delta_aicc: Coulomb minus power law (> 0 favours
    the power law). preferred: by BIC, like every selection here.
    """

    power_law: ModelFit
    coulomb: ModelFit
    f_statistic: float
    p_value: float
    delta_aicc: float
    delta_bic: float

    @property
    def preferred(self) -> str:
        return "power_law" if self.delta_bic > 0.0 else "coulomb"

    def rejects_coulomb(self, level: float = 0.05) -> bool:
        """True when the F-test rejects gamma = 0 at the given significance level."""
        return self.p_value < level

    def to_dict(self) -> dict[str, Any]:
        return {"power_law": self.power_law.to_dict(), "coulomb": self.coulomb.to_dict(),
                "f_statistic": self.f_statistic, "p_value": self.p_value,
                "delta_aicc": self.delta_aicc, "delta_bic": self.delta_bic, "preferred": self.preferred}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "CoulombComparison":
        return cls(ModelFit.from_dict(d["power_law"]), ModelFit.from_dict(d["coulomb"]),
                   d["f_statistic"], d["p_value"], d["delta_aicc"], d["delta_bic"])


@frozen
class CurrentLevelMu:
    """mu at one measured current level (free-mu power-law fit): N^gamma, 95 % interval."""

    current_A: float
    n_points: int
    mu: float
    stderr_log: float
    ci95: tuple[float, float]

    def to_dict(self) -> dict[str, Any]:
        return {"current_A": self.current_A, "n_points": self.n_points, "mu": self.mu,
                "stderr_log": self.stderr_log, "ci95": list(self.ci95)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "CurrentLevelMu":
        return cls(d["current_A"], d["n_points"], d["mu"], d["stderr_log"], tuple(d["ci95"]))


@frozen
class DataRange:
    """What the data span: the validity range of the fitted laws (N, A)."""

    n_points: int
    loads_N: tuple[float, ...]
    currents_A: tuple[float, ...]

    @property
    def load_range_N(self) -> tuple[float, float]:
        return self.loads_N[0], self.loads_N[-1]

    @property
    def current_range_A(self) -> tuple[float, float]:
        return self.currents_A[0], self.currents_A[-1]

    def to_dict(self) -> dict[str, Any]:
        return {"n_points": self.n_points, "loads_N": list(self.loads_N), "currents_A": list(self.currents_A),
                "load_range_N": list(self.load_range_N), "current_range_A": list(self.current_range_A)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "DataRange":
        return cls(d["n_points"], tuple(d["loads_N"]), tuple(d["currents_A"]))


@frozen
class FrictionFit:
    """gamma and mu(I): per-current estimates, the Coulomb test and the chosen mu(I) model."""

    per_current: tuple[CurrentLevelMu, ...]
    coulomb_test: CoulombComparison
    mu_selection: ModelSelection
    law: MuLaw
    outliers: tuple[Outlier, ...] = ()  # at most MAX_LISTED_OUTLIERS; n_outliers counts all
    n_outliers: int = 0

    @property
    def gamma(self) -> ParameterEstimate:
        """gamma of the chosen mu(I) model (the one the law uses)."""
        return self.mu_selection.chosen.estimate("gamma")

    def to_dict(self) -> dict[str, Any]:
        return {"gamma": self.gamma.to_dict(), "per_current": [c.to_dict() for c in self.per_current],
                "coulomb_test": self.coulomb_test.to_dict(), "mu_selection": self.mu_selection.to_dict(),
                "law": self.law.to_dict(), "n_outliers": self.n_outliers,
                "outliers": [o.to_dict() for o in self.outliers]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "FrictionFit":
        return cls(tuple(CurrentLevelMu.from_dict(c) for c in d["per_current"]),
                   CoulombComparison.from_dict(d["coulomb_test"]), ModelSelection.from_dict(d["mu_selection"]),
                   MuLaw.from_dict(d["law"]), tuple(Outlier.from_dict(o) for o in d.get("outliers", ())),
                   int(d.get("n_outliers", 0)))


@frozen
class ResistanceFit:
    """R_c(F_n, I): the ranked candidates (load law x current factor) and the chosen law."""

    selection: ModelSelection
    law: ResistanceLaw
    outliers: tuple[Outlier, ...] = ()  # at most MAX_LISTED_OUTLIERS; n_outliers counts all
    n_outliers: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"selection": self.selection.to_dict(), "law": self.law.to_dict(), "n_outliers": self.n_outliers,
                "outliers": [o.to_dict() for o in self.outliers]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ResistanceFit":
        return cls(ModelSelection.from_dict(d["selection"]), ResistanceLaw.from_dict(d["law"]),
                   tuple(Outlier.from_dict(o) for o in d.get("outliers", ())), int(d.get("n_outliers", 0)))


@frozen
class TribometerFit:
    """Everything fitted from one tribometer dataset, and the laws the coupling calls.

    source: where the data came from; header: the data file's comment lines (an
    illustrative dataset says so there, and the fit carries it along).
    Callables (numpy-vectorized, SI): `mu(current_A)`, `contact_resistance(F_n, I)`,
    `contact_conductance(F_n, I)`; behaviour outside the data range as in `laws.py`.
    """

    source: str
    header: tuple[str, ...]
    data_range: DataRange
    friction: FrictionFit
    resistance: ResistanceFit

    @property
    def laws(self) -> ContactLaws:
        return ContactLaws(self.friction.law, self.resistance.law)

    @property
    def gamma(self) -> float:
        """Friction exponent gamma, dimensionless."""
        return self.friction.law.gamma

    @property
    def gamma_stderr(self) -> float | None:
        return self.friction.gamma.stderr

    @property
    def gamma_ci95(self) -> tuple[float, float] | None:
        return self.friction.gamma.ci95

    def mu(self, current_A):
        """Friction coefficient mu(|I|), N^gamma; held at the edge value outside the measured currents."""
        return self.friction.law(current_A)

    def friction_force(self, normal_force_N, current_A):
        """Sliding friction magnitude mu(I) F_n^(1 - gamma), N."""
        return self.friction.law.friction_force(normal_force_N, current_A)

    def contact_resistance(self, normal_force_N, current_A):
        """R_c(F_n, |I|), ohm; +inf for F_n <= 0; extrapolates in load with the fitted exponent."""
        return self.resistance.law.resistance(normal_force_N, current_A)

    def contact_conductance(self, normal_force_N, current_A):
        """1 / R_c, siemens; exactly 0 for F_n <= 0, continuous as F_n -> 0+."""
        return self.resistance.law.conductance(normal_force_N, current_A)

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": FORMAT, "version": FORMAT_VERSION,
            "source": self.source, "header": list(self.header),
            "data_range": self.data_range.to_dict(),
            "laws": self.laws.to_dict(),
            "friction": self.friction.to_dict(),
            "resistance": self.resistance.to_dict(),
        }

    def to_json(self, path) -> None:
        Path(path).write_text(json.dumps(self.to_dict(), indent=2) + "\n")

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "TribometerFit":
        """Rebuild a saved fit. The ``laws`` block must be the one the fit wrote: an edited
        law would no longer match the fit's estimates, intervals and model selection, so
        it is refused (give your own laws inline in the scene instead)."""
        if not isinstance(d, Mapping):
            raise ValueError(f"not a tribometer fit: expected a JSON object, got a JSON {type(d).__name__}")
        if d.get("format") != FORMAT or d.get("version") != FORMAT_VERSION:
            raise ValueError(
                f"not a tribometer fit: expected \"format\": {FORMAT!r} and \"version\": {FORMAT_VERSION}"
            )
        fit = cls(d["source"], tuple(d["header"]), DataRange.from_dict(d["data_range"]),
                  FrictionFit.from_dict(d["friction"]), ResistanceFit.from_dict(d["resistance"]))
        if "laws" in d and ContactLaws.from_dict(d["laws"]).to_dict() != fit.laws.to_dict():
            raise ValueError(
                "the 'laws' block differs from the laws the fit found (edited by hand?): a fit file "
                "is a record of a fit and is used as written; put your own laws inline in the scene "
                "([tribology.mu] and [tribology.resistance], docs/tribology.md)"
            )
        return fit

    @classmethod
    def from_json(cls, path) -> "TribometerFit":
        path = Path(path)
        try:
            if path.is_dir():
                raise ValueError("is a folder, not a fit.json file")
            data = path.read_bytes()
            return cls.from_dict(json.loads(data.decode("utf-8-sig")))
        except UnicodeDecodeError as err:
            raise ValueError(f"{path}: not a readable tribometer fit (byte {err.start} is not UTF-8)") from None
        except json.JSONDecodeError as err:
            raise ValueError(f"{path}: not a readable tribometer fit (invalid JSON at line {err.lineno}, "
                             f"column {err.colno})") from None
        except (KeyError, TypeError, ValueError, AttributeError, IndexError) as err:
            text = str(err) if isinstance(err, ValueError) else f"{type(err).__name__}: {str(err)[:60]}"
            raise ValueError(f"{path}: not a readable tribometer fit ({text})") from None


# ---------------------------------------------------------------------------------
# Least-squares machinery


@frozen
class _Problem:
    """The used rows reduced to their (load, |I|) cells (see the module docstring).

    Per cell: load (N), |I| (A), ln load, row count and its square root (the weight of
    the cell's mean residual); levels: the distinct |I|, level_index: each cell's level;
    cell_of_row: each used row's cell; n: rows used.
    """

    load: np.ndarray
    current: np.ndarray
    ln_load: np.ndarray
    count: np.ndarray
    sqrt_w: np.ndarray
    levels: np.ndarray
    level_index: np.ndarray
    cell_of_row: np.ndarray
    n: int

    @property
    def n_cells(self) -> int:
        return len(self.load)


@frozen
class _Response:
    """A ln response over the cells: cell means, within-cell and total sums of squares."""

    mean: np.ndarray
    ss_within: float
    tss: float
    n: int


def _problem_from(load: np.ndarray, current: np.ndarray) -> _Problem:
    import pandas as pd

    # cells by hashing (no sort of the rows: memory and time linear in the rows)
    load_code, load_values = pd.factorize(load)
    current_code, current_values = pd.factorize(np.abs(current))
    key = load_code.astype(np.int64)
    key *= len(current_values)
    key += current_code
    del load_code, current_code
    n_keys = len(load_values) * len(current_values)
    if n_keys <= 4 * len(key) + 1024:
        # a direct table of the (load, current) pairs: no second hash table
        present = np.bincount(key, minlength=n_keys) > 0
        cell_keys = np.flatnonzero(present)
        table = np.cumsum(present) - 1
        cell_of_row = table[key]
        del table, present
    else:
        cell_of_row, cell_keys = pd.factorize(key)
    del key
    count = np.bincount(cell_of_row, minlength=len(cell_keys)).astype(float)
    c_load = np.asarray(load_values, float)[cell_keys // len(current_values)]
    c_current = np.asarray(current_values, float)[cell_keys % len(current_values)]
    levels, level_index = np.unique(c_current, return_inverse=True)
    return _Problem(c_load, c_current, np.log(c_load), count, np.sqrt(count), levels, level_index.ravel(),
                    cell_of_row, len(load))


def _subproblem(P: _Problem, use: np.ndarray) -> _Problem:
    """The problem of the rows in boolean mask ``use`` (over P's rows), without sorting again."""
    count = np.bincount(P.cell_of_row[use], minlength=P.n_cells).astype(float)
    keep = count > 0
    new_index = np.cumsum(keep) - 1
    levels_used = np.unique(P.level_index[keep])
    level_map = np.full(len(P.levels), -1)
    level_map[levels_used] = np.arange(len(levels_used))
    return _Problem(P.load[keep], P.current[keep], P.ln_load[keep], count[keep], np.sqrt(count[keep]),
                    P.levels[levels_used], level_map[P.level_index[keep]], new_index[P.cell_of_row[use]],
                    int(use.sum()))


def _problem(df: pd.DataFrame) -> _Problem:
    return _problem_from(df["load_N"].to_numpy(float), df["current_A"].to_numpy(float))


def _response(P: _Problem, y: np.ndarray) -> _Response:
    mean = np.bincount(P.cell_of_row, weights=y, minlength=P.n_cells) / P.count
    d = mean[P.cell_of_row]
    np.subtract(y, d, out=d)
    ss_within = float(d @ d)
    np.subtract(y, y.mean(), out=d)
    tss = float(d @ d)
    return _Response(mean, ss_within, tss, len(y))


def _jacobian(residual: Callable[[np.ndarray], np.ndarray], x: np.ndarray) -> np.ndarray:
    # Central differences: the covariance needs an accurate J at the optimum, which the
    # optimizer's last (possibly forward-difference) J is not.
    h = 1e-6 * np.maximum(np.abs(x), 1e-3)
    cols = []
    for j in range(len(x)):
        e = np.zeros_like(x)
        e[j] = h[j]
        cols.append((residual(x + e) - residual(x - e)) / (2.0 * h[j]))
    return np.column_stack(cols) if cols else np.zeros((len(residual(x)), 0))


def _lack_of_fit_p(rss: float, resp: _Response, n_cells: int, n_params: int) -> float | None:
    from scipy import stats  # lazily: a scene with a fitted law loads it without scipy.stats
    n = resp.n
    df_pe = n - n_cells
    df_lof = n - n_params - df_pe
    ss_pe = resp.ss_within
    if df_pe <= 0 or df_lof <= 0 or ss_pe <= 0.0:
        return None
    f = ((rss - ss_pe) / df_lof) / (ss_pe / df_pe)
    return float(stats.f.sf(max(f, 0.0), df_lof, df_pe))


def _model_fit(
    name: str, formula: str, names: tuple[str, ...], units: tuple[str, ...], x: np.ndarray,
    residual: Callable[[np.ndarray], np.ndarray], resp: _Response, n_cells: int,
    active: np.ndarray | None = None,
) -> ModelFit:
    """Statistics of a fit whose ``residual`` is the weighted cell residual sqrt(n_c) (mean - f)."""
    from scipy import stats  # lazily: a scene with a fitted law loads it without scipy.stats
    r = residual(x)
    n, p = resp.n, len(x)
    rss = float(r @ r) + resp.ss_within
    dof = n - p
    s2 = rss / dof
    k = p + 1  # the scatter is a parameter too
    loglik_term = n * np.log(max(rss, 1e-300) / n)
    aicc = float(loglik_term + 2 * k + 2 * k * (k + 1) / (n - k - 1)) if n - k - 1 > 0 else float("inf")
    bic = float(loglik_term + k * np.log(n))
    r2 = None if resp.tss == 0.0 else 1.0 - rss / resp.tss
    note = ""
    cov = None
    at_bound = [] if active is None else [names[j] for j in np.flatnonzero(active)]
    if at_bound:
        note = f"parameter(s) on a bound: {', '.join(at_bound)}; no covariance (the model reduces to a simpler one)"
    elif p:
        J = _jacobian(residual, x)
        jtj = J.T @ J
        if not np.all(np.isfinite(jtj)) or np.linalg.cond(jtj) > 1e14:
            note = "parameters not identifiable from these data (singular J^T J); no covariance"
        else:
            cov = s2 * np.linalg.inv(jtj)
    t = float(stats.t.ppf(0.975, dof))
    params = []
    for j in range(p):
        if cov is None:
            params.append(ParameterEstimate(names[j], float(x[j]), None, None, units[j]))
        else:
            se = float(np.sqrt(cov[j, j]))
            params.append(ParameterEstimate(names[j], float(x[j]), se, (float(x[j] - t * se), float(x[j] + t * se)), units[j]))
    return ModelFit(
        name, formula, tuple(params),
        None if cov is None else tuple(tuple(float(v) for v in row) for row in cov),
        n, rss, float(np.sqrt(s2)), r2, aicc, bic, _lack_of_fit_p(rss, resp, n_cells, p), note,
    )


def _solve(residual, starts, lower, upper):
    from scipy import optimize  # lazily: a scene with a fitted law loads it without scipy.optimize

    best = None
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, float), lower, upper)
        try:
            res = optimize.least_squares(residual, x0, bounds=(lower, upper), x_scale="jac", method="trf",
                                         xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=2000)
        except ValueError:
            continue
        if np.all(np.isfinite(res.fun)) and (best is None or res.cost < best.cost):
            best = res
    return best


def _rank(selection_items: list[ModelFit]) -> tuple[ModelFit, ...]:
    return tuple(sorted(selection_items, key=lambda m: (m.bic if CRITERION == "BIC" else m.aicc, m.n_parameters)))


# ---------------------------------------------------------------------------------
# Friction


def _ln_mu(model: str, theta: np.ndarray, current: np.ndarray) -> np.ndarray:
    mu = MU_FAMILIES[model].function(current, *theta)
    # a trial step that makes mu <= 0 is steered back by a steep, finite penalty
    return np.where(mu > 0.0, np.log(np.maximum(mu, 1e-300)), -700.0 + 1e3 * mu)


def _mu_starts(model: str, levels: np.ndarray, mu_k: np.ndarray) -> list[np.ndarray]:
    """Starting points from the per-current estimates: grid the nonlinear parameter, solve the rest."""
    scale = levels.max() if levels.max() > 0 else 1.0
    if model == "constant":
        return [np.array([np.exp(np.mean(np.log(mu_k)))])]
    if model == "linear":
        s, m0 = np.polyfit(levels, mu_k, 1)
        return [np.array([max(m0, 1e-6), s])]
    if model == "saturating_exponential":
        grid, basis = np.geomspace(0.02, 20.0, 25) * scale, lambda c: -np.expm1(-levels / c)
    else:
        grid, basis = np.geomspace(0.1, 5.0, 25), lambda c: levels**c
    trials = []
    for c in grid:
        A = np.c_[np.ones_like(levels), basis(c)] / mu_k[:, None]
        coef, *_ = np.linalg.lstsq(A, np.ones_like(levels), rcond=None)
        sse = float(np.sum((A @ coef - 1.0) ** 2))
        trials.append((sse, np.array([max(coef[0], 1e-6), coef[1], c])))
    trials.sort(key=lambda t: t[0])
    return [t[1] for t in trials[:2]]


def fit_friction(df: pd.DataFrame, mu_models: list[str] | None = None) -> FrictionFit:
    """Fit gamma and mu(I) to the friction column of a validated tribometer table (all rows).

    Steps: (1) free mu per current level with a shared gamma (linear in ln), and the
    same with gamma = 0 (Coulomb), compared by F-test and BIC; (2) each mu(I) candidate
    (all of `models.MU_FAMILIES`, or the names in mu_models) fitted jointly with gamma,
    ranked by BIC. `fit_tribometer` adds the outlier rule.
    """
    P = _problem(df)
    return _fit_friction(P, np.log(df["friction_N"].to_numpy(float)), mu_models)[0]


def _fit_friction(P: _Problem, y: np.ndarray, mu_models: list[str] | None) -> tuple[FrictionFit, np.ndarray, int]:
    """The friction fit on cells; also the chosen model's ln prediction per cell and its parameter count."""
    from scipy import stats  # lazily: a scene with a fitted law loads it without scipy.stats
    if mu_models is None:
        mu_models = list(MU_FAMILIES)
    unknown = [m for m in mu_models if m not in MU_FAMILIES]
    if unknown or not mu_models:
        raise ValueError(f"mu models must be among {list(MU_FAMILIES)}, got {unknown or mu_models}")
    resp = _response(P, y)
    ybar, w, m = resp.mean, P.sqrt_w, P.n_cells
    n = resp.n
    L = len(P.levels)
    X = np.zeros((m, L + 1))
    X[np.arange(m), P.level_index] = 1.0
    X[:, L] = -P.ln_load  # column for gamma: ln F_t = ln mu_k + ln F_n - gamma ln F_n
    level_names = tuple(f"ln_mu_at_{i:g}A" for i in P.levels)
    level_units = ("ln(N^gamma)",) * L
    target = ybar - P.ln_load

    def r_power(x):
        return w * (target - X @ x)

    x_pow, *_ = np.linalg.lstsq(w[:, None] * X, w * target, rcond=None)
    power = _model_fit("per_current_power_law", "F_t = mu_k F_n^(1-gamma), one mu_k per current",
                       level_names + ("gamma",), level_units + ("1",), x_pow, r_power, resp, m)

    Xc = X[:, :L]

    def r_coulomb(x):
        return w * (target - Xc @ x)

    x_c, *_ = np.linalg.lstsq(w[:, None] * Xc, w * target, rcond=None)
    coulomb = _model_fit("per_current_coulomb", "F_t = mu_k F_n, one mu_k per current (gamma = 0)",
                         level_names, level_units, x_c, r_coulomb, resp, m)
    dof = n - (L + 1)
    f_stat = (coulomb.rss_log - power.rss_log) / (power.rss_log / dof) if power.rss_log > 0 else float("inf")
    comparison = CoulombComparison(
        power, coulomb, float(f_stat), float(stats.f.sf(max(f_stat, 0.0), 1, dof)),
        coulomb.aicc - power.aicc, coulomb.bic - power.bic,
    )

    t = float(stats.t.ppf(0.975, dof))
    counts = np.bincount(P.level_index, weights=P.count, minlength=L)
    if power.covariance is None:
        se = np.full(L, np.nan)
    else:
        se = np.sqrt(np.diag(np.array(power.covariance))[:L])
    per_current = tuple(
        CurrentLevelMu(float(P.levels[k]), int(counts[k]), float(np.exp(x_pow[k])), float(se[k]),
                       (float(np.exp(x_pow[k] - t * se[k])), float(np.exp(x_pow[k] + t * se[k]))))
        for k in range(L)
    )

    gamma0 = x_pow[L]
    mu_k = np.exp(x_pow[:L])
    fitted, skipped, predictions = [], [], {}
    for model in mu_models:
        family = MU_FAMILIES[model]
        if L < len(family.parameters):
            skipped.append((model, f"needs >= {len(family.parameters)} current levels, data have {L}"))
            continue
        if n - len(family.parameters) - 3 < 0:
            skipped.append((model, f"needs >= {len(family.parameters) + 3} points, data have {n}"))
            continue

        def residual(x, model=model):
            return w * (ybar - _ln_mu(model, x[1:], P.current) - (1.0 - x[0]) * P.ln_load)

        lower = np.r_[-np.inf, family.lower]
        upper = np.r_[1.0 - 1e-9, family.upper]
        res = _solve(residual, [np.r_[gamma0, s] for s in _mu_starts(model, P.levels, mu_k)], lower, upper)
        if res is None:
            skipped.append((model, "the least-squares fit failed"))
            continue
        mu_range = MU_FAMILIES[model].function(np.array([P.levels[0], P.levels[-1]]), *res.x[1:])
        if not np.all(mu_range > 0.0):
            skipped.append((model, "fitted mu is not > 0 over the measured currents"))
            continue
        fitted.append(_model_fit(model, f"F_t = ({family.formula}) F_n^(1-gamma)", ("gamma",) + family.parameters,
                                 ("1",) + family.units, res.x, residual, resp, m, res.active_mask))
        predictions[model] = ybar - residual(res.x) / w
    if not fitted:
        raise ValueError(f"no mu(I) model could be fitted: {'; '.join(f'{n}: {r}' for n, r in skipped)}")
    selection = ModelSelection(CRITERION, _rank(fitted), tuple(skipped))
    chosen = selection.chosen
    law = MuLaw(chosen.value("gamma"), chosen.name, tuple((p.name, p.value) for p in chosen.parameters[1:]),
                (float(P.levels[0]), float(P.levels[-1])))
    return FrictionFit(per_current, comparison, selection, law), predictions[chosen.name], chosen.n_parameters


# ---------------------------------------------------------------------------------
# Contact resistance


def resistance_candidates() -> list[tuple[str, str]]:
    """All (load model, current model) pairs the resistance fit ranks."""
    return [(lm, cm) for lm in LOAD_FAMILIES for cm in CURRENT_FAMILIES]


def ln_resistance(load_model: str, current_model: str, x: np.ndarray, load: np.ndarray, current: np.ndarray) -> np.ndarray:
    """ln R_c (R_c in ohm) of the law (load_model, current_model) with parameters x (load
    law's then current law's, in their families' order) at normal loads ``load`` (N) and
    currents ``current`` (A)."""
    nl = len(LOAD_FAMILIES[load_model].parameters)
    rf, r1, m = load_law_parameters(load_model, dict(zip(LOAD_FAMILIES[load_model].parameters, x[:nl])))
    g = CURRENT_FAMILIES[current_model].function(current, *x[nl:])
    r = g * (rf + r1 * load ** (-m))
    return np.where(r > 0.0, np.log(np.maximum(r, 1e-300)), -700.0 + 1e3 * r)


def _current_grid(current_model: str, scale: float) -> list[tuple[float, ...]]:
    if current_model == "none":
        return [()]
    scales = np.geomspace(0.05, 20.0, 9) * scale
    if current_model == "hyperbolic":
        return [(c,) for c in scales]
    return [(c, r) for c in scales for r in (0.1, 0.3, 0.5, 0.7, 0.9, 1.2)]


def _load_start(load_model: str, F: np.ndarray, R: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, float]:
    """Best load parameters for a given current-corrected resistance R per cell (relative
    least squares, each cell weighted by its row count)."""
    fam = LOAD_FAMILIES[load_model]
    fixed = dict(fam.fixed)
    w = np.sqrt(count)
    if load_model == "power_law":
        slope, icpt = np.polyfit(np.log(F), np.log(R), 1, w=w)
        x = np.array([np.exp(icpt), min(max(-slope, 1e-3), 5.0)])
    elif "r_film_ohm" in fam.parameters:
        m = fixed["load_exponent"]
        A = np.c_[np.ones_like(F), F ** (-m)] / R[:, None]
        coef, *_ = np.linalg.lstsq(w[:, None] * A, w, rcond=None)
        if coef[0] < 0.0 or coef[1] <= 0.0:
            coef = np.array([0.0, np.exp(np.average(np.log(R * F**m), weights=count))])
        x = coef
    else:
        m = fixed["load_exponent"]
        x = np.array([np.exp(np.average(np.log(R * F**m), weights=count))])
    pred = load_law_parameters(load_model, dict(zip(fam.parameters, x)))
    model = pred[0] + pred[1] * F ** (-pred[2])
    return x, float(np.sum(count * np.log(R / model) ** 2))


def fit_resistance(df: pd.DataFrame, candidates: list[tuple[str, str]] | None = None) -> ResistanceFit:
    """Fit R_c(F_n, I) = g(I) (R_f + R_1 F^-m): every load law x current factor, ranked by BIC (all rows).

    candidates: (load model, current model) pairs to rank instead of all of
    `resistance_candidates()`, e.g. to keep only the Holm laws. `fit_tribometer` adds
    the outlier rule.
    """
    P = _problem(df)
    return _fit_resistance(P, np.log(df["resistance_ohm"].to_numpy(float)), candidates)[0]


def _fit_resistance(P: _Problem, y: np.ndarray, candidates: list[tuple[str, str]] | None
                    ) -> tuple[ResistanceFit, np.ndarray, int]:
    """The resistance fit on cells; also the chosen model's ln prediction per cell and its parameter count."""
    if candidates is None:
        candidates = resistance_candidates()
    unknown = [c for c in candidates if tuple(c) not in resistance_candidates()]
    if unknown or not candidates:
        raise ValueError(f"resistance candidates must be among {resistance_candidates()}, got {unknown or candidates}")
    resp = _response(P, y)
    ybar, w, m = resp.mean, P.sqrt_w, P.n_cells
    n = resp.n
    R = np.exp(ybar)  # geometric mean per cell
    n_loads = len(np.unique(P.load))
    L = len(P.levels)
    scale = P.levels.max() if P.levels.max() > 0 else 1.0
    fitted, skipped, predictions = [], [], {}
    for load_model, current_model in candidates:
        name = f"{load_model}+{current_model}"
        lf, cf = LOAD_FAMILIES[load_model], CURRENT_FAMILIES[current_model]
        if n_loads < len(lf.parameters):
            skipped.append((name, f"needs >= {len(lf.parameters)} different loads, data have {n_loads}"))
            continue
        if L < len(cf.parameters) + 1:
            skipped.append((name, f"needs >= {len(cf.parameters) + 1} current levels, data have {L}"))
            continue
        if n - len(lf.parameters) - len(cf.parameters) - 3 < 0:
            skipped.append((name, f"needs >= {len(lf.parameters) + len(cf.parameters) + 3} points, data have {n}"))
            continue
        trials = []
        for c in _current_grid(current_model, scale):
            g = cf.function(P.current, *c)
            if np.any(g <= 0.0):
                continue
            xl, sse = _load_start(load_model, P.load, R / g, P.count)
            trials.append((sse, np.r_[xl, c]))
        trials.sort(key=lambda t: t[0])

        def residual(x, lm=load_model, cm=current_model):
            return w * (ybar - ln_resistance(lm, cm, x, P.load, P.current))

        lower = np.r_[lf.lower, cf.lower]
        upper = np.r_[lf.upper, cf.upper]
        res = _solve(residual, [t[1] for t in trials[:2]], lower, upper)
        if res is None:
            skipped.append((name, "the least-squares fit failed"))
            continue
        formula = f"R_c = ({cf.formula}) * ({lf.formula}), F in N"
        fitted.append(_model_fit(name, formula, lf.parameters + cf.parameters, lf.units + cf.units,
                                 res.x, residual, resp, m, res.active_mask))
        predictions[name] = ybar - residual(res.x) / w
    if not fitted:
        raise ValueError(f"no R_c model could be fitted: {'; '.join(f'{n}: {r}' for n, r in skipped)}")
    selection = ModelSelection(CRITERION, _rank(fitted), tuple(skipped))
    chosen = selection.chosen
    load_model, current_model = chosen.name.split("+")
    law = ResistanceLaw(load_model, current_model, tuple((p.name, p.value) for p in chosen.parameters),
                        (float(P.levels[0]), float(P.levels[-1])))
    return ResistanceFit(selection, law), predictions[chosen.name], chosen.n_parameters


# ---------------------------------------------------------------------------------
# Outliers

#: Gross-value rule: ln value beyond this many robust standard deviations from the
#: column's median, and beyond GROSS_FACTOR (a factor) from it.
GROSS_MADS = 10.0
GROSS_FACTOR = 1e3
#: Residual rule: overall chance of flagging any row of Gaussian data (Bonferroni).
FALSE_ALARM = 0.01
MAX_ROUNDS = 3
#: More flagged rows than this fraction: the data do not follow one law (an error).
MAX_OUTLIER_FRACTION = 0.2
MAX_LISTED_OUTLIERS = 100
_MAD_TO_SD = 1.4826


def t_crit(n: int, p: int) -> float:
    """Limit of the externally studentized ln residual for n rows and p parameters: the
    two-sided Student-t quantile (n - p - 1 degrees of freedom) for a FALSE_ALARM chance
    over all n rows (Bonferroni outlier test)."""
    from scipy import stats  # lazily: a scene with a fitted law loads it without scipy.stats
    return float(stats.t.isf(FALSE_ALARM / (2.0 * max(n, 1)), max(n - p - 1, 1)))


def _robust_sd(r: np.ndarray) -> float:
    med = np.median(r)
    return _MAD_TO_SD * float(np.median(np.abs(r - med)))


def _gross(ln_values: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Rows whose ln value is gross (see GROSS_MADS, GROSS_FACTOR); the median and the limit."""
    med = float(np.median(ln_values))
    sd = _robust_sd(ln_values)
    limit = max(GROSS_MADS * sd, float(np.log(GROSS_FACTOR)))
    return np.abs(ln_values - med) > limit, med, limit


def _with_rejection(P_all: _Problem, fit: Callable, y: np.ndarray, use: np.ndarray,
                    flagged: dict[int, tuple[str, str]], column: str) -> Any:
    """Fit on the rows in ``use``; flag rows whose externally studentized ln residual
    |r_k| / s_(k), s_(k)^2 = (RSS - r_k^2) / (n - p - 1), exceeds t_crit; refit; at most
    MAX_ROUNDS rounds of flagging."""
    for round_ in range(MAX_ROUNDS + 1):
        P = P_all if use.all() else _subproblem(P_all, use)
        y_used = y if use.all() else y[use]
        result, prediction, p = fit(P, y_used)
        if round_ == MAX_ROUNDS:
            break
        r = y_used - prediction[P.cell_of_row]
        del y_used
        n = len(r)
        if n - p - 1 <= 0:
            break
        # externally studentized residuals, in place: |r_k| / sqrt((RSS - r_k^2) / (n - p - 1))
        s_k = r * r
        rss = float(s_k.sum())
        np.subtract(rss, s_k, out=s_k)
        np.maximum(s_k, 1e-24 * (n - p - 1), out=s_k)
        s_k /= n - p - 1
        np.sqrt(s_k, out=s_k)
        z = np.abs(r, out=r)
        z /= s_k
        del s_k
        limit = t_crit(n, p)
        bad = z > limit
        if not bad.any():
            break
        rows = np.flatnonzero(use)[bad]
        for k, row in zip(np.flatnonzero(bad), rows):
            flagged[int(row)] = (column, f"studentized ln residual {z[k]:.3g} of the fit (Bonferroni "
                                         f"limit {limit:.3g})")
        use[rows] = False
    return result


def fit_tribometer(
    df: pd.DataFrame, mu_models: list[str] | None = None, resistance_candidates: list[tuple[str, str]] | None = None,
) -> TribometerFit:
    """Fit gamma, mu(I) and R_c(F_n, I) to a tribometer table (see `read_tribometer_csv`), leaving out outliers.

    df: columns load_N (N), current_A (A), friction_N (N), resistance_ohm (ohm), optional
    run. Validated again here, so a hand-built DataFrame gets the same clear errors.
    mu_models, resistance_candidates: restrict the candidates ranked (default: all;
    see `fit_friction`, `fit_resistance`). Outliers are flagged by the rule of the
    module docstring and reported in `friction.outliers` / `resistance.outliers`.
    """
    source = str(df.attrs.get("source", "DataFrame"))
    header = tuple(df.attrs.get("header", ()))
    clean = validate_tribometer_frame(df, source=source)
    P_all = _problem(clean)
    ln_load = P_all.ln_load[P_all.cell_of_row]
    y_f = np.log(clean["friction_N"].to_numpy(float))
    y_r = np.log(clean["resistance_ohm"].to_numpy(float))
    n = len(clean)

    results = []
    for column, y, fit in (("friction_N", y_f, lambda P, yy: _fit_friction(P, yy, mu_models)),
                           ("resistance_ohm", y_r, lambda P, yy: _fit_resistance(P, yy, resistance_candidates))):
        flagged: dict[int, tuple[str, str]] = {}
        for col, values in (("load_N", ln_load), (column, y)):
            bad, med, limit = _gross(values)
            for k in np.flatnonzero(bad):
                flagged[int(k)] = (col, f"gross value: ln is {abs(values[k] - med):.3g} from the column's median "
                                        f"(limit {limit:.3g})")
        use = np.ones(n, dtype=bool)
        use[list(flagged)] = False
        _check_usable(clean.iloc[np.flatnonzero(use)], source, column, len(flagged), n)
        result = _with_rejection(P_all, fit, y, use, flagged, column)
        if len(flagged) > MAX_OUTLIER_FRACTION * n:
            raise ValueError(f"{source}: {len(flagged)} of {n} rows are outliers of the {column} fit by the "
                             f"stated rule (more than {MAX_OUTLIER_FRACTION:.0%}): the data do not follow one "
                             "law; check units and columns (docs/tribology.md, outliers)")
        outliers = _outliers(flagged, clean, df, source)
        results.append((result, outliers, len(flagged), use))
    (friction, f_out, f_n, f_use), (resistance, r_out, r_n, r_use) = results
    friction = FrictionFit(friction.per_current, friction.coulomb_test, friction.mu_selection, friction.law,
                           f_out, f_n)
    resistance = ResistanceFit(resistance.selection, resistance.law, r_out, r_n)
    used = f_use & r_use  # the validity range: rows neither fit left out
    P = _subproblem(P_all, used)
    data_range = DataRange(int(used.sum()), tuple(float(v) for v in np.unique(P.load)),
                           tuple(float(v) for v in P.levels))
    return TribometerFit(source, header, data_range, friction, resistance)


def _check_usable(rows: pd.DataFrame, source: str, column: str, n_flagged: int, n: int) -> None:
    if n_flagged > MAX_OUTLIER_FRACTION * n:
        raise ValueError(f"{source}: {n_flagged} of {n} rows hold gross values (load or {column} more than "
                         f"a factor {GROSS_FACTOR:g} and {GROSS_MADS:g} robust SD from the median): check units "
                         "and columns (docs/tribology.md, outliers)")
    try:
        validate_tribometer_frame(rows.reset_index(drop=True), source=f"{source} (outliers left out)")
    except ValueError as err:
        raise ValueError(f"{err}") from None


def _outliers(flagged: dict[int, tuple[str, str]], clean: pd.DataFrame, df: pd.DataFrame,
              source: str) -> tuple[Outlier, ...]:
    rows = sorted(flagged)[:MAX_LISTED_OUTLIERS]
    if not rows:
        return ()
    where = None
    if df.attrs.get("csv") and Path(source).is_file():
        from coupling.laws.tribology.data import lines_of_rows

        where = [f"line {k}" for k in lines_of_rows(source, rows)]
    if where is None:
        where = [f"row {clean.index[k]}" for k in rows]
    return tuple(Outlier(k, w, flagged[k][0], float(clean[flagged[k][0]].iloc[k]), flagged[k][1])
                 for k, w in zip(rows, where))


def _log_band(model: ModelFit, predict_log: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Curve and pointwise 95 % confidence band (delta method on the ln prediction)."""
    from scipy import stats  # lazily: a scene with a fitted law loads it without scipy.stats

    x = np.array([p.value for p in model.parameters])
    center = predict_log(x)
    if model.covariance is None:
        return np.exp(center), np.full_like(center, np.nan), np.full_like(center, np.nan)
    J = _jacobian(predict_log, x)
    se = np.sqrt(np.einsum("ij,jk,ik->i", J, np.array(model.covariance), J))
    t = float(stats.t.ppf(0.975, model.n_points - model.n_parameters))
    return np.exp(center), np.exp(center - t * se), np.exp(center + t * se)


def mu_band(fit: TribometerFit, current_A) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """mu(I) of the chosen model with its 95 % band at currents (A, within the data range)."""
    chosen = fit.friction.mu_selection.chosen
    i = np.abs(np.asarray(current_A, float))
    return _log_band(chosen, lambda x: _ln_mu(chosen.name, x[1:], i))


def friction_band(fit: TribometerFit, normal_force_N, current_A: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Friction force mu(I) F^(1-gamma) (N) with its 95 % band, loads in N, one current in A."""
    chosen = fit.friction.mu_selection.chosen
    ln_f = np.log(np.asarray(normal_force_N, float))
    i = np.full_like(ln_f, abs(current_A))
    return _log_band(chosen, lambda x: _ln_mu(chosen.name, x[1:], i) + (1.0 - x[0]) * ln_f)


def resistance_band(fit: TribometerFit, normal_force_N, current_A: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contact resistance (ohm) of the chosen model with its 95 % band, loads in N, one current in A."""
    chosen = fit.resistance.selection.chosen
    lm, cm = chosen.name.split("+")
    f = np.asarray(normal_force_N, float)
    i = np.full_like(f, abs(current_A))
    return _log_band(chosen, lambda x: ln_resistance(lm, cm, x, f, i))


def outlier_lines(fit: TribometerFit, shown: int = 5) -> list[str]:
    """One line per fit (friction, resistance) that left rows out, naming the first ``shown``."""
    lines = []
    for label, part in (("friction", fit.friction), ("resistance", fit.resistance)):
        if part.n_outliers:
            rows = "; ".join(f"{o.where} ({o.column} = {o.value:.4g}: {o.reason})" for o in part.outliers[:shown])
            more = f"; ... ({part.n_outliers - shown} more in fit.json)" if part.n_outliers > shown else ""
            lines.append(f"OUTLIERS left out of the {label} fit: {part.n_outliers} row(s): {rows}{more}")
    return lines
