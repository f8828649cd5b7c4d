"""The seeded generator of synthetic tribometer data, and of the shipped ILLUSTRATIVE (not measured) dataset.

`python -m coupling.laws.tribology.illustrative` rewrites
coupling/laws/data/tribometer_illustrative.csv byte for byte. The true laws are written into
the file's header and docs/tribology.md. The tests use `synthetic_tribometer_data` with
other laws to check that the fits recover what was put in.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mech.frozen import frozen
from coupling.laws.tribology.laws import ContactLaws, MuLaw, ResistanceLaw
from coupling.laws.tribology.models import hertz_contact_radius, holm_constriction_resistance

if TYPE_CHECKING:  # pandas only to make data; the path above is read without it
    import pandas as pd

ILLUSTRATIVE_CSV = Path(__file__).resolve().parent.parent / "data" / "tribometer_illustrative.csv"
ILLUSTRATIVE_SEED = 2024


@frozen
class SyntheticDesign:
    """A tribometer test plan and its scatter.

    loads_N: normal loads, N; currents_A: DC currents, A; repeats: passes per
    (load, current); friction_scatter, resistance_scatter: standard deviation of the
    multiplicative (ln) scatter, dimensionless (0.03 = about 3 %).
    """

    loads_N: tuple[float, ...] = (3.0, 4.0, 5.0, 6.0, 7.0, 8.0)
    currents_A: tuple[float, ...] = (0.0, 1.0, 2.0, 5.0)
    repeats: int = 3
    friction_scatter: float = 0.03
    resistance_scatter: float = 0.04


def synthetic_tribometer_data(laws: ContactLaws, design: SyntheticDesign, rng: np.random.Generator) -> pd.DataFrame:
    """Draw one dataset: true friction mu(I) F^(1-gamma) and resistance R_c(F, I), times lognormal scatter.

    Returns the CSV columns (load_N, current_A, friction_N, resistance_ohm, run).
    The laws must cover the design's currents in their current_range_A.
    """
    import pandas as pd

    rows = [(f, i, run) for run in range(1, design.repeats + 1) for i in design.currents_A for f in design.loads_N]
    load = np.array([r[0] for r in rows])
    current = np.array([r[1] for r in rows])
    friction = laws.friction_force(load, current) * np.exp(design.friction_scatter * rng.standard_normal(len(rows)))
    resistance = laws.contact_resistance(load, current) * np.exp(
        design.resistance_scatter * rng.standard_normal(len(rows))
    )
    return pd.DataFrame(
        {"load_N": load, "current_A": current, "friction_N": friction, "resistance_ohm": resistance,
         "run": [r[2] for r in rows]}
    )


# The illustrative truth. Contact: a 3 mm radius steel pin tip on a steel disk, Hertz
# elastic (E = 210 GPa, nu = 0.3 for both), Holm constriction with an effective
# resistivity of 1.0e-6 ohm m for the film-covered spot, plus 3 mOhm of film and bulk
# series resistance; current lowers R_c towards 60 % of its zero-current value.
PIN_RADIUS_m = 3.0e-3
STEEL_E_Pa, STEEL_NU = 210e9, 0.3
EFFECTIVE_MODULUS_Pa = 1.0 / (2.0 * (1.0 - STEEL_NU**2) / STEEL_E_Pa)
RESISTIVITY_ohm_m = 1.0e-6
R_1N_ohm = float(holm_constriction_resistance(
    RESISTIVITY_ohm_m, hertz_contact_radius(1.0, PIN_RADIUS_m, EFFECTIVE_MODULUS_Pa)))
ILLUSTRATIVE_DESIGN = SyntheticDesign()
ILLUSTRATIVE_LAWS = ContactLaws(
    MuLaw(0.7, "saturating_exponential", (("mu0", 0.20), ("dmu", 0.15), ("current_scale_A", 1.5)), (0.0, 5.0)),
    ResistanceLaw(
        "holm_elastic_film", "exponential_floor",
        (("r_film_ohm", 3.0e-3), ("r_1N_ohm", R_1N_ohm), ("current_scale_A", 2.0), ("floor_fraction", 0.6)),
        (0.0, 5.0),
    ),
)


def _header() -> list[str]:
    mu, res = ILLUSTRATIVE_LAWS.mu_law, ILLUSTRATIVE_LAWS.resistance_law
    d = ILLUSTRATIVE_DESIGN
    fmt = lambda params: ", ".join(f"{k} = {v:.6g}" for k, v in params)  # noqa: E731
    return [
        "ILLUSTRATIVE, NOT MEASURED: synthetic tribometer data made by a seeded generator",
        "(python -m coupling.laws.tribology.illustrative) to follow the trends reported for a burnished",
        "NbSe2 film (pin-on-disk, 0.5 mm/s): friction rises with load and current, gamma = 0.7,",
        "mu rises with current, contact resistance falls with load and current. Do not cite as data.",
        f"True friction law: F_t = mu(I) F_n^(1 - gamma), gamma = {mu.gamma:g},",
        f"  mu(I) = {mu.model}: {fmt(mu.params)} (mu in N^gamma)",
        f"True resistance law: R_c = g(I) (r_film_ohm + r_1N_ohm F_n^-1/3), {res.load_model} x {res.current_model}:",
        f"  {fmt(res.params)}",
        f"  (r_1N_ohm = Holm rho_e/(2a) with rho_e = {RESISTIVITY_ohm_m:g} ohm m and the Hertz radius a at 1 N of a",
        f"  {PIN_RADIUS_m * 1e3:g} mm steel sphere on steel, E* = {EFFECTIVE_MODULUS_Pa / 1e9:.4g} GPa)",
        f"Scatter: lognormal, sigma = {d.friction_scatter:g} (friction), {d.resistance_scatter:g} (resistance); "
        f"{d.repeats} runs; seed {ILLUSTRATIVE_SEED}",
        "Columns: load_N = normal load (N), current_A = DC current (A), friction_N = friction force (N),",
        "resistance_ohm = contact resistance (ohm), run = repeat id",
    ]


def illustrative_csv_text() -> str:
    """The shipped CSV's exact text (header comments + data) from the fixed seed."""
    df = synthetic_tribometer_data(ILLUSTRATIVE_LAWS, ILLUSTRATIVE_DESIGN, np.random.default_rng(ILLUSTRATIVE_SEED))
    out = io.StringIO()
    for line in _header():
        out.write(f"# {line}\n")
    out.write("load_N,current_A,friction_N,resistance_ohm,run\n")
    for r in df.itertuples(index=False):
        out.write(f"{r.load_N:g},{r.current_A:g},{r.friction_N:.4f},{r.resistance_ohm:.7f},{r.run}\n")
    return out.getvalue()


def write_illustrative_csv(path: Path = ILLUSTRATIVE_CSV) -> Path:
    """Write the illustrative dataset to path (default: the shipped file); returns path."""
    path = Path(path)
    path.write_text(illustrative_csv_text())
    return path


if __name__ == "__main__":
    print(f"wrote {write_illustrative_csv()}")
