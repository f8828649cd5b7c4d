"""The magnet's ngspice expression for i(psi, g), read by an evaluator of this test's own
(the functions ngspice B-sources know, pwl as ngspice's PTpwl computes it), equals the
magnet's i(psi, g) to round-off, is odd in psi and smooth through psi = 0."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from coupling.laws.magnet.bh_curves import STEEL_9SMNPB28, LinearMaterial
from coupling.laws.magnet.law import FluxTubeMagnet
from coupling.laws.magnet.solenoid import plunger_solenoid
from coupling.laws.magnet.table import TableMagnet
from coupling.laws.magnet.tubes import AxialIron, IronPath, PoleLeakage, WorkingGap

TOKEN = re.compile(r"\s*(?:(\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)|([A-Za-z_]\w*)|(.))")


def _pwl(x, points):
    """ngspice's PTpwl: binary search for the segment, the end segments extended."""
    xs, ys = np.asarray(points[0::2], dtype=float), np.asarray(points[1::2], dtype=float)
    assert np.all(np.diff(xs) > 0), "pwl abscissae must increase"
    k0 = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
    return ys[k0] + (ys[k0 + 1] - ys[k0]) * (x - xs[k0]) / (xs[k0 + 1] - xs[k0])


FUNCTIONS = {"ln": np.log, "exp": np.exp, "sqrt": np.sqrt, "abs": np.abs}


def evaluate(text: str, nodes: dict):
    """The value of an ngspice B-source expression; V(name) reads ``nodes[name]``."""
    tokens = [t for t in TOKEN.findall(text)]
    tokens = [num or name or op for num, name, op in tokens if (num or name or op.strip())]
    pos = 0

    def peek():
        return tokens[pos] if pos < len(tokens) else None

    def take(expected=None):
        nonlocal pos
        tok = tokens[pos]
        if expected is not None and tok != expected:
            raise SyntaxError(f"expected {expected!r}, got {tok!r}")
        pos += 1
        return tok

    def expr():
        value = term()
        while peek() in ("+", "-"):
            value = value + term() if take() == "+" else value - term()
        return value

    def term():
        value = unary()
        while peek() in ("*", "/"):
            value = value * unary() if take() == "*" else value / unary()
        return value

    def unary():
        if peek() == "-":
            take()
            return -unary()
        if peek() == "+":
            take()
            return unary()
        return power()

    def power():
        value = atom()
        if peek() == "^":
            take()
            return value ** unary()
        return value

    def atom():
        tok = take()
        if tok == "(":
            value = expr()
            take(")")
            return value
        if re.fullmatch(r"[\d.].*", tok):
            return float(tok)
        name = tok.lower()
        take("(")
        if name == "v":
            node = take()
            take(")")
            return nodes[node]
        args = [expr()]
        while peek() == ",":
            take()
            args.append(expr())
        take(")")
        if name == "pwl":
            return _pwl(args[0], [float(a) for a in args[1:]])
        if name in ("max", "min"):
            return (np.maximum if name == "max" else np.minimum)(args[0], args[1])
        if name not in FUNCTIONS:
            raise NameError(f"{name!r} is not a function ngspice B-sources know")
        return FUNCTIONS[name](*args)

    value = expr()
    assert pos == len(tokens), f"trailing tokens {tokens[pos:pos + 3]}"
    return value


def test_evaluator_reads_ngspice_arithmetic():
    # the evaluator itself: precedence, unary minus, pwl extension beyond its ends
    assert evaluate("1 + 2*3 - 4/2", {}) == 5.0
    assert evaluate("pwl(3, 0,0, 1,2)", {}) == 6.0
    assert evaluate("pwl(-1, 0,1, 1,3)", {}) == -1.0
    assert evaluate("max((V(a)), 2) + ln(1 + 0)", {"a": 1.0}) == 2.0
    with pytest.raises(NameError):
        evaluate("tanh(1)", {})


def _magnets():
    steel = STEEL_9SMNPB28
    linear = FluxTubeMagnet(300, WorkingGap(1e-4), iron=(IronPath(0.06, 1e-4, LinearMaterial(800)),))
    saturating = FluxTubeMagnet(500, WorkingGap(1.2e-4, minimum=2e-5),
                                iron=(AxialIron(6e-3, 0.04, steel), IronPath(0.03, 2e-4, steel)),
                                pole_leakage=PoleLeakage(0.04, 2e-3))
    solenoid = plunger_solenoid().magnet
    table = TableMagnet.from_magnet(solenoid, np.linspace(0.0, 3.0, 16), np.geomspace(0.25e-3, 5e-3, 9),
                                    force_tolerance=0.3)
    return {"linear": linear, "saturating": saturating, "solenoid": solenoid, "table": table}


@pytest.mark.parametrize("kind", ["linear", "saturating", "solenoid", "table"])
def test_expression_equals_current_to_round_off(kind):
    magnet = _magnets()[kind]
    text = magnet.current_expression("V(coil_psi)", "V(coil_gap)")
    low, high = magnet.gap_range
    high = min(high, 6e-3)
    # gaps through and beyond the magnet's range (the law is extended there), fluxes into
    # deep saturation and both signs
    gaps = np.concatenate((np.linspace(0.2 * low, high * 1.2, 57), [low, high]))
    psi_max = abs(magnet.flux_linkage(4.0, low))
    psis = np.linspace(-1.5 * psi_max, 1.5 * psi_max, 301)
    p, g = np.meshgrid(psis, gaps)
    got = evaluate(text, {"coil_psi": p, "coil_gap": g})
    want = magnet.current(p, g)
    # round-off: the two sides differ in the order of operations only (the mirrored pwl
    # segment for psi < 0, the table's weights extrapolated up to 4x beyond its gaps, whose
    # terms then cancel), a few ulp of the largest term; measured 2e-16 to 4e-16 of max |i|
    scale = np.max(np.abs(want))
    assert np.max(np.abs(got - want)) <= 1e-14 * scale
    # the coupling calls with one psi and one g at a time (a faster path for tables)
    for row, col in ((0, 0), (3, 150), (30, 200), (-1, 300), (-3, 77)):
        one = magnet.current(float(p[row, col]), float(g[row, col]))
        assert abs(one - got[row, col]) <= 1e-14 * scale
    # odd and smooth through 0: the value at -psi, and the slopes on both sides of 0
    assert np.allclose(evaluate(text, {"coil_psi": -p, "coil_gap": g}), -got, rtol=0, atol=1e-14 * scale)
    h = psi_max * 1e-6
    right = evaluate(text, {"coil_psi": h, "coil_gap": high}) / h
    left = -evaluate(text, {"coil_psi": -h, "coil_gap": high}) / h
    assert evaluate(text, {"coil_psi": 0.0, "coil_gap": high}) == 0.0
    assert math.isclose(left, right, rel_tol=1e-9)


def test_expression_uses_only_ngspice_functions():
    text = _magnets()["table"].current_expression("V(psi)", "V(gap)")
    names = set(re.findall(r"([A-Za-z_]\w*)\s*\(", text))
    assert names <= {"pwl", "max", "ln", "V"}
    assert text.startswith("pwl(")
