"""The tribological laws as small pure functions, and the candidate families the fits choose among.

Friction: the generalized law |F_t| = mu(I) F_n^(1 - gamma) (gamma = 0 is Coulomb).
Contact resistance: Holm constriction R = rho_e / (2 a) with the contact radius a from
the contact mechanics (elastic Hertz a ~ F_n^(1/3), plastic a ~ F_n^(1/2)), plus a
load-independent series (film) resistance, times a factor that falls with current.
Every function takes numpy arrays or scalars; currents enter as given (the laws in
`laws.py` apply |I| and the validity clamps).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from mech.frozen import frozen

# ---------------------------------------------------------------------------------
# Physics building blocks


def generalized_friction_force(normal_force_N, mu, gamma):
    """Sliding friction magnitude |F_t| = mu F_n^(1 - gamma).

    normal_force_N: N (>= 0); mu: N^gamma; gamma: dimensionless (< 1).
    Returns N. Zero where F_n <= 0 (no contact, no friction).
    """
    f = np.asarray(normal_force_N, dtype=float)
    return np.where(f > 0.0, mu * np.maximum(f, 0.0) ** (1.0 - gamma), 0.0)


def holm_constriction_resistance(resistivity_ohm_m, contact_radius_m):
    """Holm's constriction resistance of one circular spot, R = rho_e / (2 a).

    resistivity_ohm_m: effective resistivity rho_e = (rho_1 + rho_2) / 2, ohm m;
    contact_radius_m: a, m. Returns ohm.
    """
    return resistivity_ohm_m / (2.0 * np.asarray(contact_radius_m, dtype=float))


def hertz_contact_radius(normal_force_N, sphere_radius_m, effective_modulus_Pa):
    """Elastic Hertz contact radius of a sphere on a flat, a = (3 F R / (4 E*))^(1/3).

    normal_force_N: N; sphere_radius_m: m; effective_modulus_Pa: E*, Pa
    (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2). Returns m.
    """
    f = np.asarray(normal_force_N, dtype=float)
    return (3.0 * f * sphere_radius_m / (4.0 * effective_modulus_Pa)) ** (1.0 / 3.0)


def plastic_contact_radius(normal_force_N, hardness_Pa):
    """Fully plastic contact radius, F = H pi a^2, a = sqrt(F / (pi H)).

    normal_force_N: N; hardness_Pa: H, Pa. Returns m.
    """
    f = np.asarray(normal_force_N, dtype=float)
    return np.sqrt(f / (np.pi * hardness_Pa))


def constriction_film_resistance(normal_force_N, r_film_ohm, r_1N_ohm, load_exponent):
    """R(F_n) = R_f + R_1 (F_n / 1 N)^(-m): constriction (Holm) plus series film resistance.

    normal_force_N: N; r_film_ohm: R_f, ohm (>= 0); r_1N_ohm: constriction resistance
    at 1 N, ohm (> 0); load_exponent: m (1/3 elastic Hertz, 1/2 plastic). Returns ohm;
    +inf where F_n <= 0 (open contact).
    """
    f = np.asarray(normal_force_N, dtype=float)
    closed = f > 0.0
    safe = np.where(closed, f, 1.0)
    return np.where(closed, r_film_ohm + r_1N_ohm * safe ** (-load_exponent), np.inf)


def constriction_film_conductance(normal_force_N, r_film_ohm, r_1N_ohm, load_exponent):
    """1 / R(F_n) of `constriction_film_resistance`, written so it is finite everywhere.

    G = F^m / (R_f F^m + R_1) with F in N: it goes to 0 continuously as F_n -> 0+ (like
    F_n^m) and is exactly 0 for F_n <= 0. Returns siemens.
    """
    f = np.maximum(np.asarray(normal_force_N, dtype=float), 0.0)
    fm = f**load_exponent
    return fm / (r_film_ohm * fm + r_1N_ohm)


# ---------------------------------------------------------------------------------
# mu(I) candidates; current_A >= 0, results in N^gamma


def mu_constant(current_A, mu0):
    """mu(I) = mu0 (no current effect). mu0: N^gamma."""
    return mu0 + 0.0 * np.asarray(current_A, dtype=float)


def mu_linear(current_A, mu0, slope_per_A):
    """mu(I) = mu0 + s I. mu0: N^gamma; slope_per_A: s, N^gamma / A."""
    return mu0 + slope_per_A * np.asarray(current_A, dtype=float)


def mu_saturating_exponential(current_A, mu0, dmu, current_scale_A):
    """mu(I) = mu0 + dmu (1 - exp(-I / I_c)): rises and levels off at mu0 + dmu.

    mu0, dmu: N^gamma; current_scale_A: I_c, A (> 0).
    """
    i = np.asarray(current_A, dtype=float)
    return mu0 + dmu * -np.expm1(-i / current_scale_A)


def mu_power_law(current_A, mu0, coeff, exponent):
    """mu(I) = mu0 + c I^p. mu0: N^gamma; coeff: c, N^gamma A^-p; exponent: p (> 0)."""
    i = np.maximum(np.asarray(current_A, dtype=float), 0.0)
    return mu0 + coeff * i**exponent


# ---------------------------------------------------------------------------------
# Current factors of the contact resistance; g(0) = 1, current_A >= 0


def current_factor_none(current_A):
    """g(I) = 1: resistance independent of current."""
    return 1.0 + 0.0 * np.asarray(current_A, dtype=float)


def current_factor_hyperbolic(current_A, current_scale_A):
    """g(I) = 1 / (1 + I / I_0). current_scale_A: I_0, A (> 0)."""
    return 1.0 / (1.0 + np.asarray(current_A, dtype=float) / current_scale_A)


def current_factor_exponential_floor(current_A, current_scale_A, floor_fraction):
    """g(I) = r + (1 - r) exp(-I / I_c): falls from 1 to the floor r at high current.

    current_scale_A: I_c, A (> 0); floor_fraction: r, dimensionless (> 0).
    """
    e = np.exp(-np.asarray(current_A, dtype=float) / current_scale_A)
    return floor_fraction + (1.0 - floor_fraction) * e


# ---------------------------------------------------------------------------------
# Candidate registries: names, parameters with units, bounds for the fits


@frozen
class Family:
    """One candidate family: its law, parameter names, units and fit bounds."""

    name: str
    formula: str
    function: Callable
    parameters: tuple[str, ...]
    units: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]


INF = np.inf

MU_FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family("constant", "mu0", mu_constant, ("mu0",), ("N^gamma",), (1e-12,), (INF,)),
        Family(
            "linear", "mu0 + slope_per_A*I", mu_linear,
            ("mu0", "slope_per_A"), ("N^gamma", "N^gamma/A"), (1e-12, -INF), (INF, INF),
        ),
        Family(
            "saturating_exponential", "mu0 + dmu*(1 - exp(-I/current_scale_A))",
            mu_saturating_exponential,
            ("mu0", "dmu", "current_scale_A"), ("N^gamma", "N^gamma", "A"),
            (1e-12, -INF, 1e-6), (INF, INF, 1e4),
        ),
        Family(
            "power_law", "mu0 + coeff*I^exponent", mu_power_law,
            ("mu0", "coeff", "exponent"), ("N^gamma", "N^gamma/A^exponent", "1"),
            (1e-12, -INF, 1e-3), (INF, INF, 10.0),
        ),
    )
}


@frozen
class LoadFamily:
    """A load law R(F) = R_f + R_1 F^-m with some of (R_f, R_1, m) fixed."""

    name: str
    formula: str
    parameters: tuple[str, ...]  # free ones, among r_film_ohm, r_1N_ohm, load_exponent
    units: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    fixed: tuple[tuple[str, float], ...]


LOAD_FAMILIES: dict[str, LoadFamily] = {
    f.name: f
    for f in (
        LoadFamily(
            "holm_elastic", "r_1N_ohm*F^(-1/3)", ("r_1N_ohm",), ("ohm",),
            (1e-15,), (INF,), (("r_film_ohm", 0.0), ("load_exponent", 1.0 / 3.0)),
        ),
        LoadFamily(
            "holm_plastic", "r_1N_ohm*F^(-1/2)", ("r_1N_ohm",), ("ohm",),
            (1e-15,), (INF,), (("r_film_ohm", 0.0), ("load_exponent", 0.5)),
        ),
        LoadFamily(
            "holm_elastic_film", "r_film_ohm + r_1N_ohm*F^(-1/3)",
            ("r_film_ohm", "r_1N_ohm"), ("ohm", "ohm"),
            (0.0, 1e-15), (INF, INF), (("load_exponent", 1.0 / 3.0),),
        ),
        LoadFamily(
            "holm_plastic_film", "r_film_ohm + r_1N_ohm*F^(-1/2)",
            ("r_film_ohm", "r_1N_ohm"), ("ohm", "ohm"),
            (0.0, 1e-15), (INF, INF), (("load_exponent", 0.5),),
        ),
        LoadFamily(
            "power_law", "r_1N_ohm*F^(-load_exponent)",
            ("r_1N_ohm", "load_exponent"), ("ohm", "1"),
            (1e-15, 1e-3), (INF, 5.0), (("r_film_ohm", 0.0),),
        ),
    )
}

CURRENT_FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family("none", "1", current_factor_none, (), (), (), ()),
        Family(
            "hyperbolic", "1/(1 + I/current_scale_A)", current_factor_hyperbolic,
            ("current_scale_A",), ("A",), (1e-6,), (1e4,),
        ),
        Family(
            "exponential_floor",
            "floor_fraction + (1 - floor_fraction)*exp(-I/current_scale_A)",
            current_factor_exponential_floor,
            ("current_scale_A", "floor_fraction"), ("A", "1"), (1e-6, 1e-6), (1e4, 1e3),
        ),
    )
}


def load_law_parameters(load_model: str, params: dict[str, float]) -> tuple[float, float, float]:
    """(r_film_ohm, r_1N_ohm, load_exponent) of a load family from its free parameters."""
    full = dict(LOAD_FAMILIES[load_model].fixed)
    full.update({k: params[k] for k in LOAD_FAMILIES[load_model].parameters})
    return full["r_film_ohm"], full["r_1N_ohm"], full["load_exponent"]
