"""The fitted contact laws as plain callables for the coupling: mu(I) and R_c(F_n, I).

They apply the documented out-of-range behaviour (docs/tribology.md):
- current enters as |I| (direction does not matter) and is held at the edge of the
  measured current range [I_min, I_max] outside it: mu and the resistance's current
  factor keep their edge values;
- load is not clamped: the resistance extrapolates with its fitted physical exponent
  (impacts reach kN, far above the 3-8 N of a tribometer);
- F_n <= 0 is an open contact: resistance +inf, conductance exactly 0, and the
  conductance falls to 0 continuously as F_n -> 0+.
Each law builds from a plain dict (a scene's inline `[tribology]` table or a fit file)
and validates it once, naming the field and the allowed values.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Mapping

import numpy as np

from mech.frozen import frozen
from coupling.laws.tribology.models import (
    CURRENT_FAMILIES,
    LOAD_FAMILIES,
    MU_FAMILIES,
    constriction_film_conductance,
    generalized_friction_force,
    load_law_parameters,
)


def _params_from(where: str, family_params: tuple[str, ...], given: Mapping[str, Any]) -> tuple[tuple[str, float], ...]:
    missing = [p for p in family_params if p not in given]
    extra = [p for p in given if p not in family_params]
    if missing or extra:
        raise ValueError(
            f"{where}: parameters must be exactly {list(family_params)}"
            + (f"; missing {missing}" if missing else "")
            + (f"; unknown {extra}" if extra else "")
        )
    out = []
    for p in family_params:
        try:
            v = float(given[p])
        except (TypeError, ValueError):
            raise ValueError(f"{where}: parameter {p!r} must be a number, got {given[p]!r}") from None
        if not np.isfinite(v):
            raise ValueError(f"{where}: parameter {p!r} must be finite, got {v}")
        out.append((p, v))
    return tuple(out)


def _current_range(where: str, value: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: current_range_A must be two numbers [I_min, I_max] in A, got {value!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 <= lo <= hi):
        raise ValueError(f"{where}: current_range_A must satisfy 0 <= I_min <= I_max (A), got {[lo, hi]}")
    return lo, hi


@contextmanager
def _errors_named(default: str, where: str):
    """Re-raise a law's TypeError/ValueError as one ValueError line that starts with `where`
    (the key the user wrote) instead of the law's generic name."""
    try:
        yield
    except (TypeError, ValueError, AttributeError) as err:
        message = str(err)
        if message.startswith(default):
            message = where + message[len(default):]
        elif not message.startswith(where):
            message = f"{where}: {message}"
        raise ValueError(message) from None


def _check_keys(where: str, data: Mapping[str, Any], required: tuple[str, ...], optional: tuple[str, ...] = ()) -> None:
    missing = [k for k in required if k not in data]
    extra = [k for k in data if k not in required + optional]
    if missing or extra:
        raise ValueError(
            f"{where}: expected keys {list(required + optional)}"
            + (f"; missing {missing}" if missing else "")
            + (f"; unknown {extra}" if extra else "")
        )


@frozen
class MuLaw:
    """Generalized friction law |F_t| = mu(|I|) F_n^(1 - gamma) with a fitted mu(I).

    gamma: dimensionless, < 1 (0 is Coulomb); model: a name in `models.MU_FAMILIES`;
    params: (name, value) pairs, mu in N^gamma, currents in A; current_range_A: the
    measured |I| range (A) outside which mu is held at its edge value.

    >>> law = MuLaw.from_dict({"gamma": 0.7, "model": "linear",
    ...     "params": {"mu0": 0.2, "slope_per_A": 0.03}, "current_range_A": [0, 5]})
    >>> float(law(-2.0)), float(law(9.0))   # |I|; held at I = 5 A above the range
    (0.26, 0.35)
    """

    gamma: float
    model: str
    params: tuple[tuple[str, float], ...]
    current_range_A: tuple[float, float]

    def __post_init__(self):
        where = "mu law"
        if self.model not in MU_FAMILIES:
            raise ValueError(f"{where}: model must be one of {list(MU_FAMILIES)}, got {self.model!r}")
        g = float(self.gamma)
        if not (np.isfinite(g) and g < 1.0):
            raise ValueError(f"{where}: gamma must be finite and < 1 (F_t must vanish as F_n -> 0), got {self.gamma}")
        object.__setattr__(self, "gamma", g)
        object.__setattr__(
            self, "params", _params_from(f"{where} ({self.model})", MU_FAMILIES[self.model].parameters, dict(self.params))
        )
        object.__setattr__(self, "current_range_A", _current_range(where, self.current_range_A))
        object.__setattr__(self, "_values", tuple(v for _, v in self.params))
        object.__setattr__(self, "_function", MU_FAMILIES[self.model].function)
        lo, hi = self.current_range_A
        # the candidate families are monotone in I, so the ends bound mu over the range
        ends = self._function(np.array([lo, hi]), *self._values)
        if not np.all(ends > 0.0):
            raise ValueError(f"{where}: mu must be > 0 over current_range_A {[lo, hi]} A; got mu = {ends.tolist()}")

    def __call__(self, current_A):
        """mu at current I (A, any sign), N^gamma; vectorized over numpy arrays."""
        lo, hi = self.current_range_A
        i = np.minimum(np.maximum(np.abs(current_A), lo), hi)
        return self._function(i, *self._values)

    def friction_force(self, normal_force_N, current_A):
        """Sliding friction magnitude mu(I) F_n^(1-gamma), N; 0 where F_n <= 0."""
        return generalized_friction_force(normal_force_N, self(current_A), self.gamma)

    def to_dict(self) -> dict[str, Any]:
        return {
            "gamma": self.gamma,
            "model": self.model,
            "params": dict(self.params),
            "current_range_A": list(self.current_range_A),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "mu law") -> "MuLaw":
        """The law from its table; errors start with `where` (a scene key such as tribology.mu)."""
        with _errors_named("mu law", where):
            _check_keys("mu law", data, ("gamma", "model", "params", "current_range_A"))
            if not isinstance(data["params"], Mapping):
                raise ValueError(f"mu law: params must be a table of name = value, got {data['params']!r}")
            return cls(data["gamma"], data["model"], tuple(data["params"].items()), tuple(data["current_range_A"]))


@frozen
class ResistanceLaw:
    """Contact resistance R_c(F_n, I) = g(|I|) (R_f + R_1 (F_n / 1 N)^(-m)).

    load_model: a name in `models.LOAD_FAMILIES` (Holm elastic m = 1/3, plastic
    m = 1/2, with or without the film R_f, or a free power law); current_model: a name
    in `models.CURRENT_FAMILIES` (g(0) = 1); params: (name, value) pairs of both,
    resistances in ohm, currents in A; current_range_A: |I| range (A) outside which g is
    held at its edge value. Load is not clamped (see the module docstring).
    """

    load_model: str
    current_model: str
    params: tuple[tuple[str, float], ...]
    current_range_A: tuple[float, float]

    def __post_init__(self):
        where = "resistance law"
        if self.load_model not in LOAD_FAMILIES:
            raise ValueError(f"{where}: load_model must be one of {list(LOAD_FAMILIES)}, got {self.load_model!r}")
        if self.current_model not in CURRENT_FAMILIES:
            raise ValueError(
                f"{where}: current_model must be one of {list(CURRENT_FAMILIES)}, got {self.current_model!r}"
            )
        names = LOAD_FAMILIES[self.load_model].parameters + CURRENT_FAMILIES[self.current_model].parameters
        params = _params_from(f"{where} ({self.load_model}+{self.current_model})", names, dict(self.params))
        object.__setattr__(self, "params", params)
        object.__setattr__(self, "current_range_A", _current_range(where, self.current_range_A))
        p = dict(params)
        for name, ok, rule in (
            ("r_film_ohm", lambda v: v >= 0.0, ">= 0 ohm"),
            ("r_1N_ohm", lambda v: v > 0.0, "> 0 ohm"),
            ("load_exponent", lambda v: v > 0.0, "> 0"),
            ("current_scale_A", lambda v: v > 0.0, "> 0 A"),
            ("floor_fraction", lambda v: v > 0.0, "> 0"),
        ):
            if name in p and not ok(p[name]):
                raise ValueError(f"{where}: {name} must be {rule}, got {p[name]}")
        object.__setattr__(self, "_load", load_law_parameters(self.load_model, p))
        object.__setattr__(
            self, "_current", (CURRENT_FAMILIES[self.current_model].function,
                               tuple(p[k] for k in CURRENT_FAMILIES[self.current_model].parameters)),
        )

    @property
    def load_exponent(self) -> float:
        """m of R_1 F^-m (1/3 Holm elastic, 1/2 Holm plastic, or fitted): the extrapolation in load."""
        return self._load[2]

    @property
    def film_resistance_ohm(self) -> float:
        """R_f, ohm: the floor R_c approaches at high load (0 for the laws without film), at I = 0."""
        return self._load[0]

    def current_factor(self, current_A):
        """g(|I|) with |I| held inside current_range_A; dimensionless."""
        lo, hi = self.current_range_A
        function, values = self._current
        return function(np.minimum(np.maximum(np.abs(current_A), lo), hi), *values)

    def conductance(self, normal_force_N, current_A):
        """1 / R_c, siemens: exactly 0 for F_n <= 0, -> 0 continuously as F_n -> 0+."""
        return constriction_film_conductance(normal_force_N, *self._load) / self.current_factor(current_A)

    def force_conductance(self, normal_force_N):
        """The load part G_F(F_n) = 1/(R_f + R_1 F^-m), siemens: conductance at I = 0.

        The conductance is G_F(F_n) / g(|I|); a circuit can take G_F from the mechanics
        and apply g itself (``current_factor_expression``).
        """
        return constriction_film_conductance(normal_force_N, *self._load)

    def scalar_force_conductance(self, normal_force_N: float) -> float:
        """``force_conductance`` for one float, without numpy: the circuit callbacks call it
        thousands of times per run. Siemens; 0 for F_n <= 0."""
        if normal_force_N <= 0.0:
            return 0.0
        r_film, r_1, m = self._load
        fm = normal_force_N**m
        return fm / (r_film * fm + r_1)

    def current_factor_expression(self, current: str = "I") -> str:
        """g(|I|) as an ngspice expression of the variable ``current`` (A), with |I| held
        inside current_range_A as ``current_factor`` does; dimensionless and > 0."""
        lo, hi = self.current_range_A
        i = f"min(max(abs({current}),{lo!r}),{hi!r})"
        p = dict(self.params)
        if self.current_model == "none":
            return "1"
        if self.current_model == "hyperbolic":
            return f"(1/(1+{i}/{p['current_scale_A']!r}))"
        if self.current_model == "exponential_floor":
            r = p["floor_fraction"]
            return f"({r!r}+{1.0 - r!r}*exp(-{i}/{p['current_scale_A']!r}))"
        raise ValueError(f"resistance law: no ngspice form for current_model {self.current_model!r}")

    def resistance(self, normal_force_N, current_A):
        """R_c, ohm: +inf for F_n <= 0 (open contact)."""
        g = self.conductance(normal_force_N, current_A)
        with np.errstate(divide="ignore"):
            return 1.0 / g

    def to_dict(self) -> dict[str, Any]:
        return {
            "load_model": self.load_model,
            "current_model": self.current_model,
            "params": dict(self.params),
            "current_range_A": list(self.current_range_A),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "resistance law") -> "ResistanceLaw":
        """The law from its table; errors start with `where` (a scene key such as tribology.resistance)."""
        with _errors_named("resistance law", where):
            _check_keys("resistance law", data, ("load_model", "current_model", "params", "current_range_A"))
            if not isinstance(data["params"], Mapping):
                raise ValueError(f"resistance law: params must be a table of name = value, got {data['params']!r}")
            return cls(data["load_model"], data["current_model"], tuple(data["params"].items()),
                       tuple(data["current_range_A"]))


@frozen
class ContactLaws:
    """The two laws the coupling needs: friction mu(I) (with gamma) and R_c(F_n, I).

    Built from a fit (`TribometerFit.laws`) or inline from a dict:
    {"mu": {...MuLaw...}, "resistance": {...ResistanceLaw...}}.
    """

    mu_law: MuLaw
    resistance_law: ResistanceLaw

    @property
    def gamma(self) -> float:
        """Friction exponent gamma of |F_t| = mu F_n^(1 - gamma); dimensionless."""
        return self.mu_law.gamma

    def mu(self, current_A):
        """Friction coefficient mu(|I|), N^gamma; held at the edge outside the measured currents."""
        return self.mu_law(current_A)

    def friction_force(self, normal_force_N, current_A):
        """Sliding friction magnitude mu(I) F_n^(1 - gamma), N."""
        return self.mu_law.friction_force(normal_force_N, current_A)

    def contact_resistance(self, normal_force_N, current_A):
        """R_c(F_n, |I|), ohm; +inf for F_n <= 0."""
        return self.resistance_law.resistance(normal_force_N, current_A)

    def contact_conductance(self, normal_force_N, current_A):
        """1 / R_c, siemens; exactly 0 for F_n <= 0 and continuous as F_n -> 0+."""
        return self.resistance_law.conductance(normal_force_N, current_A)

    def to_dict(self) -> dict[str, Any]:
        return {"mu": self.mu_law.to_dict(), "resistance": self.resistance_law.to_dict()}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], where: str = "") -> "ContactLaws":
        """Both laws from {"mu": ..., "resistance": ...}; with `where` (a scene table such as
        tribology) errors name where.mu and where.resistance."""
        with _errors_named("contact laws", where or "contact laws"):
            _check_keys("contact laws", data, ("mu", "resistance"))
        prefix = f"{where}." if where else ""
        return cls(MuLaw.from_dict(data["mu"], f"{prefix}mu" if where else "mu law"),
                   ResistanceLaw.from_dict(data["resistance"], f"{prefix}resistance" if where else "resistance law"))
