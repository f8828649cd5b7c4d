"""Shared pieces of the accuracy study (`make accuracy`, docs/accuracy.md): scenes, metrics
of a run against a reference, the machine-load note, and where fragments and figures go.

Each benchmarks/accuracy_<part>.py writes docs/accuracy/<part>.md (a markdown fragment)
and its PNGs into docs/accuracy/; benchmarks/accuracy_report.py joins the fragments into
docs/accuracy.md. Every figure and number comes from these scripts.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
OUT = ROOT / "docs" / "accuracy"

from coupling.app.accuracy import contact_metrics, mismatch_time, tip_intervals  # noqa: E402


def load_note() -> str:
    """The machine's load right now (1-minute load average, cores)."""
    return f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores"


class Section:
    """Collects one part's markdown; notes the load at start and end."""

    def __init__(self, part: str, title: str, command: str):
        OUT.mkdir(parents=True, exist_ok=True)
        self.part = part
        self.start_load = load_note()
        self.tick = time.perf_counter()
        self.lines = [f"## {title}", "", f"`{command}` ({self.start_load} at its start)", ""]

    def add(self, *lines: str) -> None:
        self.lines.extend(lines)

    def table(self, header: list[str], rows: list[list]) -> None:
        self.lines.append("| " + " | ".join(header) + " |")
        self.lines.append("|" + "---|" * len(header))
        for r in rows:
            self.lines.append("| " + " | ".join(str(c) for c in r) + " |")
        self.lines.append("")

    def figure(self, fig, name: str, caption: str) -> None:
        path = OUT / f"{name}.png"
        fig.savefig(path, dpi=90, bbox_inches="tight")
        import matplotlib.pyplot as plt

        plt.close(fig)
        self.lines += [f"![{caption}](accuracy/{name}.png)", "", f"*{caption}* ({load_note()} when drawn)", ""]

    def write(self) -> None:
        wall = time.perf_counter() - self.tick
        self.lines += [f"(this part: {wall:.0f} s of wall time; {load_note()} at its end)", ""]
        (OUT / f"{self.part}.md").write_text("\n".join(self.lines))
        print(f"wrote {OUT / (self.part + '.md')} in {wall:.0f} s", file=sys.stderr)


def plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as p

    return p


def fmt(x, digits=3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, (int,)) and not isinstance(x, bool):
        return str(x)
    return f"{x:.{digits}g}"


def us(x) -> str:
    return "-" if x is None else f"{x * 1e6:.3g}"


# --- mechanics runs ---------------------------------------------------------------------

def mech_scene(doc: dict):
    """A validated mechanics scene (coupling.Scene) from a TOML-like dict."""
    from coupling import scene_from_dict

    return scene_from_dict(doc)


class RunTimeLimit(Exception):
    """A run took longer than its time limit (checked whenever the solver is back in Python)."""


def run_mech(scene, *, backend: str = "dopri5", rtol: float | None = None, limit: float = 60.0):
    """(mech.ImpactResult, wall seconds of the integration) for a coupling.Scene's mechanics;
    RunTimeLimit after ``limit`` s (the alarm fires when the compiled loop returns to Python,
    at the next event or segment end)."""
    import signal

    from mech import ImpactSolver

    from mech.parameters import RTOL_MAX

    ms = scene.mech
    if rtol is not None and rtol > RTOL_MAX:
        # a work-precision study measures past the allowed range on purpose (that range is
        # set from it): the options are validated at RTOL_MAX, then their rtol is replaced
        opts = replace(ms.solver, rtol=RTOL_MAX)
        object.__setattr__(opts, "rtol", rtol)
        ms = replace(ms, solver=opts)
    elif rtol is not None:
        ms = replace(ms, solver=replace(ms.solver, rtol=rtol))
    solver = ImpactSolver(ms, backend=backend)

    def expired(*_):
        raise RunTimeLimit(f"no result within {limit:g} s")

    old = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, limit)
    tick = time.perf_counter()
    try:
        result = solver.run()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    return result, time.perf_counter() - tick


def mech_tips(result) -> dict:
    c = result.contacts
    return {i: [(float(a), float(b)) for a, b in zip(c.t_start[c.tip == i], c.t_end[c.tip == i])] for i in (0, 1)}


def mech_metrics(result) -> dict:
    """Contact metrics, peak force, first contact's duration and energetic restitution,
    energy residual of an ImpactResult."""
    tips = mech_tips(result)
    out = contact_metrics(tips)
    c = result.contacts
    out["peak_force"] = float(c.peak_force.max()) if len(c) else 0.0
    first = c.iloc[0] if len(c) else None
    out["first_duration"] = float(first.t_end - first.t_start) if first is not None else None
    out["first_restitution"] = float(first.energetic_restitution) if first is not None else None
    out["first_peak_force"] = float(first.peak_force) if first is not None else None
    out["energy_residual"] = float(result.energy["relative_residual"])
    out["tips"] = tips
    return out


def errors_against(m: dict, ref: dict) -> dict:
    """Errors of metrics m against the reference's: mismatch time (s, both tips), count
    differences, make-instant errors (s), relative peak-force error."""
    mism = sum(mismatch_time(m["tips"][i], ref["tips"][i]) for i in (0, 1))

    def dt(key):
        a, b = m.get(key), ref.get(key)
        return None if a is None or b is None else abs(a - b)

    pf = abs(m["peak_force"] - ref["peak_force"]) / ref["peak_force"] if ref["peak_force"] else None
    return dict(mismatch=mism, contacts=m["contacts"] - ref["contacts"], bounces=m["bounces"] - ref["bounces"],
                first_make=dt("first_make"), last_make=dt("last_make"), bounce_time=dt("total_bounce_time"),
                peak_force=pf, energy_residual=m["energy_residual"])


def dump(name: str, data) -> None:
    (OUT / f"{name}.json").write_text(json.dumps(data, indent=1, default=float))


def git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True, timeout=10).stdout.strip() or "unknown"
    except Exception:  # noqa: BLE001
        return "unknown"


# --- coupled runs -----------------------------------------------------------------------

def short_default_scene():
    """The built-in free-drop scene (builtin_scene("free_drop"): 24 V, 12 ohm, arc, 3 modes), released 20 um above
    the block (first make at 20 us), 2 ms, no files."""
    from coupling import builtin_scene

    return builtin_scene("free_drop").update({"initial.height": 2e-5, "solver.t_end": 2e-3, "bar.modes": 3,
                                   "output.plots": False, "output.csv": False, "output.parquet": False})


def coupled_metrics(result) -> dict:
    """Contact metrics (both tips), bounce metrics and the closed-contact voltage (time
    average of |contact voltage| while the contact is closed, 2 us clear of makes and
    breaks, V) of a CoupledResult."""
    import numpy as np

    from coupling.app.accuracy import metrics_of

    m = metrics_of(result)
    m["tips"] = tip_intervals(result)
    w = result.waveforms
    t, v = w.time.to_numpy(), np.abs(w.contact_voltage.to_numpy())
    # sampled on a 0.1 us grid inside each closed interval, 2 us clear of its make and break
    # (the transition itself belongs to the bounce waveform, not to the closed level)
    grid = np.concatenate([np.arange(a + 2e-6, b - 2e-6, 1e-7) for a, b in result.closed_intervals
                           if b - a > 5e-6] or [np.zeros(0)])
    m["closed_voltage"] = float(np.mean(np.interp(grid, t, v))) if len(grid) else None
    m["waves"] = (t, w.contact_voltage.to_numpy(), w.load_current.to_numpy())
    return m


def coupled_errors(m: dict, ref: dict) -> dict:
    """Errors of a coupled run's metrics against a reference's: mismatch (s), count
    differences, make errors (s), relative errors of peak contact voltage, arc energy and
    closed-contact voltage, and the RMS contact-voltage and load-current differences over
    the reference's bounce window (V, A)."""
    import numpy as np

    mism = sum(mismatch_time(m["tips"].get(i, []), ref["tips"].get(i, [])) for i in (0, 1))

    def rel(key):
        a, b = m.get(key), ref.get(key)
        return None if a is None or b is None or b == 0 else abs(a - b) / abs(b)

    def dt(key):
        a, b = m.get(key), ref.get(key)
        return None if a is None or b is None else abs(a - b)

    t0 = ref["first_make"] or 0.0
    t1 = (ref["first_make"] or 0.0) + max(ref["span"], 1e-4)
    grid = np.linspace(t0, t1, 4001)
    (ta, va, ia), (tb, vb, ib) = m["waves"], ref["waves"]
    rms_v = float(np.sqrt(np.mean((np.interp(grid, ta, va) - np.interp(grid, tb, vb)) ** 2)))
    rms_i = float(np.sqrt(np.mean((np.interp(grid, ta, ia) - np.interp(grid, tb, ib)) ** 2)))
    return dict(mismatch=mism, contacts=m["contacts"] - ref["contacts"], bounces=m["bounces"] - ref["bounces"],
                first_make=dt("first_make"), last_make=dt("last_make"), peak_voltage=rel("peak_contact_voltage"),
                arc_energy=rel("arc_energy"), closed_voltage=rel("closed_voltage"), rms_voltage=rms_v,
                rms_current=rms_i)
