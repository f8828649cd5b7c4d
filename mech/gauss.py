"""Gauss-Legendre rules on [-1, 1], written out: n -> (nodes, weights).

numpy.polynomial.legendre.leggauss(n)'s own floats for n = 3 and 4 (the finite-element
beam's element quadratures, mech.beam_fe, and the co-simulation's quadrature of the
armature's drive work, coupling.core.exchange), so that a run does not import
numpy.polynomial for them (~2 ms of its start). tests/mech/test_beam_fe.py holds them to the
closed-form nodes and weights and to the degree the rule integrates exactly.
"""

LEGGAUSS = {
    3: ((-0.7745966692414834, 0.0, 0.7745966692414834), (0.5555555555555557, 0.8888888888888888, 0.5555555555555557)),
    4: ((-0.8611363115940526, -0.33998104358485626, 0.33998104358485626, 0.8611363115940526),
        (0.34785484513745357, 0.6521451548625464, 0.6521451548625464, 0.34785484513745357)),
}
