"""The history's quaternions of a planar run (mech.results.planar_quaternions) are, bit for
bit, what the rotation matrix's own conversion gives record by record."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech.results import planar_quaternions
from mech.rotations import matrix_to_quaternion, rotation_y, rotation_z


@pytest.mark.parametrize("azimuth", [0.0, 0.3, -1.2, math.pi / 2, math.pi, -math.pi, 2.5, 1e-17])
def test_planar_quaternions_equal_the_matrix_conversion_bit_for_bit(azimuth):
    rng = np.random.default_rng(abs(hash(azimuth)) % 2**32)
    angles = np.concatenate([rng.uniform(-7.0, 7.0, 3000), rng.uniform(-1e-3, 1e-3, 300),
                             math.pi / 2 + rng.uniform(-1e-6, 1e-6, 300), math.pi + rng.uniform(-1e-6, 1e-6, 300),
                             [0.0, -0.0, math.pi, -math.pi, math.pi / 2, -math.pi / 2, 1e-300, 5e-324, np.nan]])
    ref = np.array([matrix_to_quaternion(rotation_z(azimuth) @ rotation_y(a)) for a in angles])
    got = planar_quaternions(azimuth, angles)
    assert got.shape == ref.shape
    same = (got.view(np.uint64) == ref.view(np.uint64)) | (np.isnan(got) & np.isnan(ref))
    assert same.all(), f"{(~same.all(axis=1)).sum()} records differ, first at angle {angles[~same.all(axis=1)][0]!r}"
