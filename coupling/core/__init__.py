"""The co-simulation core: scenes, the master that steps mechanics and circuit, results.

Imports nothing of ``coupling.app`` but in one doorway: ``CoupledResult.save`` calls the
application's one writer of result folders when it is called. The contact laws come from
``coupling.laws``.
"""
