"""mech.eigen_cache: a finite-element eigenproblem's solution read back from the cache is the
solver's, bit for bit; any change of the problem is another entry; a damaged entry is
solved again; turned off, nothing is written; the folder keeps at most FILES_MAX entries.
(The rest of the suite runs with the cache off: tests/conftest.py.)"""

from __future__ import annotations

import numpy as np
import pytest

from mech import eigen_cache
from mech.beam_fe import FEBeam, _solve_generalized_eigh, beam_basis, beam_frequencies


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv(eigen_cache.ENV, "1")
    return tmp_path / eigen_cache.FOLDER


def problem(n: int = 12, seed: int = 0):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((n, n))
    a = x @ x.T
    y = rng.standard_normal((n, n))
    return a, y @ y.T + n * np.eye(n)


def solver():
    """beam_fe's own solver, its calls counted (a call the cache answers is not one)."""
    calls = []

    def solve(a, b, vectors):
        calls.append(vectors)
        return _solve_generalized_eigh(a, b, vectors)

    return solve, calls


def test_a_solution_read_back_is_the_solvers_bit_for_bit(cache):
    a, b = problem()
    solve, calls = solver()
    fresh = solve(a, b, True)
    first = eigen_cache.cached(a, b, True, solve)
    again = eigen_cache.cached(a, b, True, solve)
    values = eigen_cache.cached(a, b, False, solve)
    assert calls == [True, True, False]  # the second call read the first's solution
    for got in (first, again):
        assert got[0].tobytes() == fresh[0].tobytes() and got[1].tobytes() == fresh[1].tobytes()
    assert values[1] is None and values[0].tobytes() == solve(a, b, False)[0].tobytes()
    assert len(list(cache.glob("*.npy"))) == 2


def test_any_change_of_the_problem_is_solved_afresh(cache):
    a, b = problem()
    solve, calls = solver()
    eigen_cache.cached(a, b, True, solve)
    moved = a.copy()
    moved[3, 4] = moved[4, 3] = np.nextafter(a[3, 4], np.inf)  # one ulp
    got = eigen_cache.cached(moved, b, True, solve)
    assert calls == [True, True]
    assert got[0].tobytes() == solve(moved, b, True)[0].tobytes()
    signed = a.copy()
    signed[0, 5] = signed[5, 0] = 0.0
    negative = signed.copy()
    negative[0, 5] = negative[5, 0] = -0.0  # (the same numbers, another zero's sign)
    assert eigen_cache.key(signed, b, True, solve) != eigen_cache.key(negative, b, True, solve)
    assert eigen_cache.key(a, b, True, solve) != eigen_cache.key(a, b, False, solve)
    # another solver's code is another entry too
    assert eigen_cache.key(a, b, True, solve) != eigen_cache.key(a, b, True, lambda a, b, v: None)


def test_a_damaged_entry_is_solved_again_and_replaced(cache):
    a, b = problem()
    solve, calls = solver()
    fresh = solver()[0](a, b, True)
    eigen_cache.cached(a, b, True, solve)
    (entry,) = cache.glob("*.npy")
    entry.write_bytes(entry.read_bytes()[:100])
    got = eigen_cache.cached(a, b, True, solve)
    assert calls == [True, True] and got[1].tobytes() == fresh[1].tobytes()
    again = eigen_cache.cached(a, b, True, solve)  # the replaced entry is read
    assert calls == [True, True] and again[1].tobytes() == fresh[1].tobytes()


def test_turned_off_it_writes_nothing(cache, monkeypatch):
    monkeypatch.setenv(eigen_cache.ENV, "0")
    a, b = problem()
    solve, calls = solver()
    eigen_cache.cached(a, b, True, solve)
    eigen_cache.cached(a, b, True, solve)
    assert calls == [True, True] and not cache.exists()


def test_an_unwritable_folder_only_computes(tmp_path, monkeypatch):
    (tmp_path / "file").write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "file"))  # (a file where the folder would go)
    monkeypatch.setenv(eigen_cache.ENV, "1")
    a, b = problem()
    solve, calls = solver()
    assert eigen_cache.cached(a, b, True, solve)[0].tobytes() == solve(a, b, True)[0].tobytes()


def test_at_most_files_max_entries_are_kept(cache, monkeypatch):
    monkeypatch.setattr(eigen_cache, "FILES_MAX", 3)
    solve, _ = solver()
    for seed in range(5):
        eigen_cache.cached(*problem(seed=seed), True, solve)
    assert len(list(cache.glob("*.npy"))) == 3


def test_a_held_bars_modes_are_the_same_from_the_cache(cache):
    """A clamped strip's modes and frequencies, solved, then read back: the same bits."""
    beam = FEBeam(length=0.02, youngs_modulus=1.1e11, density=8900.0, area=4e-7, i22=1.3e-15, i33=3.3e-14,
                  support="clamp", support_position=0.02)
    solved = beam_basis(beam, 2, 6), beam_frequencies(beam, "bend3", 6)
    assert len(list(cache.glob("*.npy"))) == 3  # axial, bending, the frequencies alone
    read = beam_basis(beam, 2, 6), beam_frequencies(beam, "bend3", 6)
    for fresh, again in zip(solved[0], read[0]):
        assert fresh.coefficients.tobytes() == again.coefficients.tobytes()
        assert fresh.frequencies.tobytes() == again.frequencies.tobytes()
    assert solved[1].tobytes() == read[1].tobytes()
