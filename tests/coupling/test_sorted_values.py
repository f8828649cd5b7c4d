"""The run's own sorted-value routines against numpy's: the magnet's union of breakpoints
(coupling.laws.magnet.pwl.union, np.unique's result) and the waveform page's quantile
(coupling.app.panels.quantile, np.quantile's linear method). Both exist only to keep
numpy.ma out of a run's start (tests/coupling/test_startup.py); numpy is the independent
route. The quantile repeats numpy's arithmetic (the same order statistics and the same
interpolation), so it agrees to the last bit; 1e-15 is allowed for a machine that rounds
differently.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.app.panels import quantile
from coupling.laws.magnet.pwl import union


@pytest.mark.parametrize("n", [1, 2, 3, 7, 200, 4097])
def test_quantile_is_numpys_linear_quantile(n):
    rng = np.random.default_rng(n)
    for _ in range(10):
        a = rng.standard_normal(n) * 10.0 ** rng.uniform(-5, 5, n)
        for q in (0.0, 0.25, 0.5, 0.99, 99.5 / 100, 1.0, float(rng.uniform())):
            assert math.isclose(quantile(a, q), float(np.quantile(a, q)), rel_tol=1e-15, abs_tol=0.0), (n, q)
        assert math.isclose(quantile(np.abs(a), 99.5 / 100), float(np.percentile(np.abs(a), 99.5)), rel_tol=1e-15)


def test_quantile_of_ties_and_a_single_value():
    assert quantile(np.array([3.0]), 0.7) == 3.0
    assert quantile(np.array([2.0, 2.0, 2.0, 5.0]), 0.5) == float(np.quantile([2.0, 2.0, 2.0, 5.0], 0.5))


def test_union_is_numpys_unique_of_the_concatenation():
    rng = np.random.default_rng(7)
    parts = [np.round(rng.uniform(0, 1, k), 2) for k in (5, 40, 1, 17)]
    np.testing.assert_array_equal(union(parts), np.unique(np.concatenate(parts)))
    np.testing.assert_array_equal(union([np.array([0.0, -0.0, 1.0]), np.array([1.0])]), [0.0, 1.0])
    assert union([np.zeros(0)]).size == 0
