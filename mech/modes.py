"""Free-free mode shapes of a uniform bar: axial cos modes and Euler-Bernoulli bending modes.

Shapes are functions of xi = x/L in [0, 1] (x from the tip-0 end), normalized so that
int_0^1 phi^2 dxi = 1 (mean square 1): with that, every mode's modal mass is the bar's mass.
Both families have zero mean, and the bending modes zero first moment, so they are
orthogonal to the rigid-body motions: a frame at the centroid is a mean-axis frame.
"""

from __future__ import annotations

import math

import numpy as np

# Free-free Euler-Bernoulli: cos(b) cosh(b) = 1. Written as cos(b) - 1/cosh(b) = 0, which
# stays well scaled for large b; the n-th root lies within 0.02 of (n + 1/2) pi.


def free_free_roots(count: int) -> np.ndarray:
    """beta_n L of the first ``count`` elastic free-free bending modes (4.730041, 7.853205, ...).

    Newton's method on f(b) = cos b - 1/cosh b from (n + 1/2) pi, kept inside the bracket
    [guess - 0.5, guess + 0.5] that holds the n-th root alone (a step leaving it bisects),
    then the nearby float with the smallest residual.
    """
    roots = []
    for n in range(1, count + 1):
        lo = (n + 0.5) * math.pi - 0.5
        hi = lo + 1.0
        f_lo = math.cos(lo) - 1.0 / math.cosh(lo)
        b = lo + 0.5
        for _ in range(100):
            f = math.cos(b) - 1.0 / math.cosh(b)
            if f == 0.0:
                break
            if (f < 0.0) == (f_lo < 0.0):
                lo, f_lo = b, f
            else:
                hi = b
            slope = -math.sin(b) + math.tanh(b) / math.cosh(b)
            nxt = b - f / slope if slope != 0.0 else 0.5 * (lo + hi)
            if not lo < nxt < hi:
                nxt = 0.5 * (lo + hi)
            if abs(nxt - b) <= 4e-16 * b:
                b = nxt
                break
            b = nxt
        # of the floats within 4 spacings of b (1.4e-14 at b ~ 90), the smallest residual
        near = [b]
        for _ in range(4):
            near = [math.nextafter(near[0], 0.0)] + near + [math.nextafter(near[-1], math.inf)]
        b = min(near, key=lambda c: abs(math.cos(c) - 1.0 / math.cosh(c)))
        roots.append(b)
    return np.array(roots)


def _one_minus_sigma(b: float) -> tuple[float, float]:
    """(1 - sigma, 1 + sigma), sigma = (cosh b - cos b)/(sinh b - sin b), without cancellation."""
    den = math.sinh(b) - math.sin(b)
    one_minus = (-math.exp(-b) - math.sin(b) + math.cos(b)) / den
    return one_minus, 2.0 - one_minus


def bending_shape(beta_l: float, xi: np.ndarray, derivative: int = 0) -> np.ndarray:
    """Free-free bending mode with root ``beta_l`` at ``xi`` = x/L; derivative 0, 1 or 2 w.r.t. xi.

    phi = cosh(b xi) + cos(b xi) - sigma (sinh(b xi) + sin(b xi)); the hyperbolic pair is
    evaluated as exponentials weighted by (1 -/+ sigma) so high modes keep full precision.
    With this form int_0^1 phi^2 = 1 and phi(0) = phi(1) = +-2.
    """
    b = beta_l
    xi = np.asarray(xi, dtype=float)
    om, op = _one_minus_sigma(b)
    sigma = 1.0 - om
    bx = b * xi
    ep = np.exp(bx)
    em = np.exp(-bx)
    if derivative == 0:
        hyp = 0.5 * (om * ep + op * em)  # cosh - sigma sinh
        return hyp + np.cos(bx) - sigma * np.sin(bx)
    if derivative == 1:
        hyp = 0.5 * (om * ep - op * em)  # sinh - sigma cosh
        return b * (hyp - np.sin(bx) - sigma * np.cos(bx))
    if derivative == 2:
        hyp = 0.5 * (om * ep + op * em)
        return b * b * (hyp - np.cos(bx) + sigma * np.sin(bx))
    raise ValueError(f"derivative = {derivative!r}: allowed values are 0, 1, 2")


def axial_shape(k: int, xi: np.ndarray, derivative: int = 0) -> np.ndarray:
    """k-th free-free axial mode sqrt(2) cos(k pi xi); derivative 0 or 1 w.r.t. xi."""
    xi = np.asarray(xi, dtype=float)
    a = k * math.pi
    if derivative == 0:
        return math.sqrt(2.0) * np.cos(a * xi)
    if derivative == 1:
        return -math.sqrt(2.0) * a * np.sin(a * xi)
    raise ValueError(f"derivative = {derivative!r}: allowed values are 0, 1")


def bending_frequencies(count: int, length: float, youngs_modulus: float, second_moment: float,
                        area: float, density: float) -> np.ndarray:
    """Hz: free-free Euler-Bernoulli frequencies (beta_n L)^2/(2 pi L^2) sqrt(E I/(rho A))."""
    b = free_free_roots(count)
    return b**2 / (2.0 * math.pi * length**2) * math.sqrt(youngs_modulus * second_moment / (density * area))


def axial_frequencies(count: int, length: float, youngs_modulus: float, density: float) -> np.ndarray:
    """Hz: free-free axial frequencies k c/(2L), c = sqrt(E/rho)."""
    c = math.sqrt(youngs_modulus / density)
    return np.arange(1, count + 1) * c / (2.0 * length)
