"""Scenes shared by the circuit tests: the 2 ms five-bounce schedule (SI units)."""

from __future__ import annotations

# A make at 0.1 ms followed by five bounces (five breaks, six makes) within 2 ms.
BOUNCE_MAKES = (0.10e-3, 0.30e-3, 0.55e-3, 0.73e-3, 0.87e-3, 0.96e-3)
BOUNCE_BREAKS = (0.25e-3, 0.50e-3, 0.70e-3, 0.85e-3, 0.95e-3)
BOUNCE_T_END = 2e-3
