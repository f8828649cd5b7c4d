"""Mechanical impact solver: a flexible bar striking a massive block.

Floating-frame bar (rigid motion + free-free modes), Hertz contact with damping at both
tips, generalized friction |F_t| = mu F_n^(1-gamma) with exact stick/slip/separation
switching, repeated impacts and an energy audit. SI units throughout.
"""
