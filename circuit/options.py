"""Transient-analysis options shared by the stepping API and the one-shot runs."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .validation import check_choice, check_range, scene_key

_METHODS = ("trap", "gear")


@dataclass(frozen=True)
class SimulationOptions:
    """ngspice transient settings (SI units). Defaults are ngspice's own, except ``method`` and ``reltol``.

    max_step: largest internal time step, s (``None``: ngspice's default, t_end / 50).
        ngspice still shortens steps by its truncation-error control.
    reltol: relative tolerance (ngspice RELTOL; default here 1e-4, ngspice's is 1e-3:
        with gear at 1e-3 the ringing after an arc extinction came out 2.6 % low and
        dependent on max_step, at 1e-4 within 0.3 % for max_step 0.1-10 us).
    abstol: absolute current tolerance, A (ABSTOL, default 1e-12).
    vntol: absolute voltage tolerance, V (VNTOL, default 1e-6).
    chgtol: absolute charge tolerance, C (CHGTOL, default 1e-14).
    method: 'gear' (default here: second-order BDF) or 'trap' (ngspice's default).
        After the hard switching of a contact or an arc, trap leaves a point-to-point
        oscillation in capacitor currents that does not decay (measured: +-1.8 % on the
        arc current of a burning DC arc; at reltol 1e-3, second differences of 4 A in
        the closed-contact current of an inductive load); gear damps it, at the price of
        some damping of resolved LC ringing (hence the tighter reltol).
    temperature: circuit temperature, degC (TEMP, default 27).
    wall_timeout: wall-clock limit of one run or one macro step, s (``None``: no limit).
        On expiry the run is aborted and SimulationTimeout raised.
    """

    SECTION: ClassVar[str] = "circuit"
    max_step: float | None = scene_key(
        None, unit="s", doc="ngspice TMAX; omitted: from the run length (docs/circuit.md)")
    reltol: float = scene_key(1e-4, unit="-", doc="ngspice RELTOL")
    abstol: float = scene_key(1e-12, unit="A", doc="ngspice ABSTOL")
    vntol: float = scene_key(1e-6, unit="V", doc="ngspice VNTOL")
    chgtol: float = scene_key(1e-14, unit="C", doc="ngspice CHGTOL")
    method: str = scene_key("gear", unit="-", doc='or "trap"')
    temperature: float = scene_key(27.0, unit="degC", doc="ngspice TEMP")
    wall_timeout: float | None = scene_key(600.0, unit="s", doc="wall-clock limit of one run or macro step")

    def __post_init__(self) -> None:
        name = self.SECTION
        if self.max_step is not None:
            check_range(name, "max_step", self.max_step, "s", 0.0, 1.0, low_open=True)
        check_range(name, "reltol", self.reltol, "", 1e-9, 0.1)
        check_range(name, "abstol", self.abstol, "A", 1e-18, 1e-3, low_open=False)
        check_range(name, "vntol", self.vntol, "V", 1e-12, 1e-1)
        check_range(name, "chgtol", self.chgtol, "C", 1e-20, 1e-6)
        check_range(name, "temperature", self.temperature, "degC", -273.15, 1000.0)
        check_choice(name, "method", self.method, _METHODS)
        if self.wall_timeout is not None:
            check_range(name, "wall_timeout", self.wall_timeout, "s", 0.0, math.inf, low_open=True, allow_inf=True)

    def tmax(self, t_end: float) -> float:
        """ngspice's maximum internal step (TMAX) for a run to ``t_end`` (s)."""
        return self.max_step if self.max_step is not None else t_end / 50.0

    def min_break(self, t_end: float) -> float:
        """ngspice's CKTminBreak = 5e-5 TMAX (s): breakpoints closer than this merge."""
        return 5e-5 * self.tmax(t_end)

    def sliver(self, t_end: float) -> float:
        """s: a step no circuit should be left to take, 1000 times ngspice's smallest
        (CKTdelmin = 1e-11 TMAX, below which it aborts with "timestep too small"): a step
        after a restart that fails its Newton iterations is cut by 8, and from a sliver four
        such cuts abort the run (measured: makes 3e-15 s before a pause, 37 CKTdelmin, and
        5e-15 s after one, aborted runs with inductive loads behind flyback diodes)."""
        return 1e-8 * self.tmax(t_end)

    def end_tolerance(self, t_end: float) -> float:
        """How early (s) ngspice may end a run to ``t_end``: within CKTminBreak = 5e-5 TMAX
        of the end it stops (after rejected steps near the end its last point can be there)."""
        return self.min_break(t_end)

    def deck_lines(self, t_end: float) -> list[str]:
        """``.options`` and ``.tran`` lines for a transient from 0 to ``t_end`` (s)."""
        tmax = self.tmax(t_end)
        # TSTEP only sets ngspice's first step (min(TSTEP, TSTOP/100) / 10) and the
        # default TMAX; both are pinned here so that a run is fully specified.
        tstep = min(tmax, t_end / 100.0)
        return [
            # noinit/noacct: no operating-point table and no statistics in the output
            # stream, which would otherwise cross into Python line by line.
            f".options reltol={self.reltol!r} abstol={self.abstol!r} vntol={self.vntol!r} "
            f"chgtol={self.chgtol!r} method={self.method} temp={self.temperature!r} noinit noacct",
            f".tran {tstep!r} {t_end!r} 0 {tmax!r}",
        ]
