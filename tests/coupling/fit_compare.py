"""Two tribometer fits compared as the optimiser can reproduce them, not bit for bit.

Why the tolerance: the fit's last digits depend on the processor and the BLAS build
(measured: the stored fit and a fresh one on another machine differed by up to 4.2e-9
relative in ``load_exponent``). Perturbing the shipped CSV's friction and resistance by
about 2 ulp (relative 4e-16, six draws) moved the fitted parameters by up to 2.6e-8
relative (``current_scale_A`` of the resistance law): that is how far round-off alone
carries this fit. ``REL`` is 40 times that, and still some 1e4 times below the parameters'
own standard errors (percent level), so two fits that pass are the same fit for every
use, and a fit of other data, another model or another selection fails.
"""

from __future__ import annotations

import dataclasses
import math

REL = 1e-6
ABS = 1e-12  # for parameters that are zero in one fit (a floor, a zero current level)


def _walk(a, b, path: str):
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), f"{path}: {type(a).__name__} != {type(b).__name__}"
        yield from _items({f.name: getattr(a, f.name) for f in dataclasses.fields(a)},
                          {f.name: getattr(b, f.name) for f in dataclasses.fields(b)}, path)
    elif isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{path}: keys {sorted(a)} != {sorted(b or {})}"
        yield from _items(a, b, path)
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), f"{path}: {a!r} != {b!r}"
        for i, (x, y) in enumerate(zip(a, b)):
            yield from _walk(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and not isinstance(a, bool):
        yield path, a, b, max(abs(a), abs(b))
    elif hasattr(a, "__array__"):
        import numpy as np

        x, y = np.asarray(a), np.asarray(b)
        assert x.shape == y.shape, f"{path}: shape {x.shape} != {y.shape}"
        if x.dtype.kind == "f":
            for i, (p, q) in enumerate(zip(x.ravel(), y.ravel())):
                yield f"{path}[{i}]", float(p), float(q), max(abs(float(p)), abs(float(q)))
        else:
            assert (x == y).all(), f"{path}: {x!r} != {y!r}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def _items(a: dict, b: dict, path: str):
    for k in a:
        if k == "covariance":
            yield from _covariance(a[k], b[k], f"{path}.{k}")
        else:
            yield from _walk(a[k], b[k], f"{path}.{k}")


def _covariance(a, b, path: str):
    """A covariance matrix's entries, each on the scale sqrt(C_ii C_jj) of its row and column:
    an exactly uncorrelated pair is 1e-13 in one fit and -3e-13 in the other (round-off),
    which relative to itself is any size but relative to the variances is nothing."""
    import numpy as np

    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, f"{path}: shape {a.shape} != {b.shape}"
    for i, (row_a, row_b) in enumerate(zip(a, b)):
        for j, (x, y) in enumerate(zip(row_a, row_b)):
            scale = math.sqrt(abs(a[i][i] * a[j][j])) if i != j else max(abs(x), abs(y))
            yield f"{path}[{i}][{j}]", float(x), float(y), scale


def assert_same_fit(a, b, rel: float = REL) -> None:
    """a and b (TribometerFit, FittedLaws or their to_dict() forms) agree: every float to
    ``rel`` of its scale (its size; a covariance entry's, its row's and column's standard
    deviations) or ABS, everything else (model choices, texts, counts) exactly."""
    for path, x, y, scale in _walk(a, b, "fit"):
        if math.isnan(x) and math.isnan(y):
            continue
        assert abs(x - y) <= max(rel * scale, ABS), f"{path}: {x!r} != {y!r} (relative tolerance {rel:g})"
