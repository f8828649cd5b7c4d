"""The co-simulation core: scenes, the master that steps mechanics and circuit, results.

Imports nothing of ``coupling.app``; the contact laws come from ``coupling.laws``.
"""
