"""The fit comparison the fit tests use holds a fit to what round-off can move, no more."""

import numpy as np
import pytest
from fit_compare import assert_same_fit

from coupling.laws.tribology import default_fit, fit_tribometer, illustrative_data_path, read_tribometer_csv


def test_round_off_in_the_data_passes_and_a_real_change_fails():
    data = read_tribometer_csv(illustrative_data_path())
    base = default_fit()
    noisy = data.copy()
    rng = np.random.default_rng(7)
    for column in ("friction_N", "resistance_ohm"):  # ~2 ulp: what another BLAS does to the sums
        noisy[column] = noisy[column] * (1.0 + 4e-16 * rng.standard_normal(len(noisy)))
    assert_same_fit(fit_tribometer(noisy).laws, base.laws)
    changed = data.copy()
    changed["friction_N"] = changed["friction_N"] * (1.0 + 1e-5)  # far below any measurement's scatter
    with pytest.raises(AssertionError, match="relative tolerance"):
        assert_same_fit(fit_tribometer(changed).laws, base.laws)
