"""Benchmark: switch mechanisms (issue 8) -- held bars, the hold at rest, the coupled relay.

Four measurements, each against a baseline measured in the same run (no timed tests):

(a) Cost per simulated ms of a clamped blade against a free bar of the same mode count:
    the relay default scene's mechanics (CuBe blade 15 x 3 x 0.3 mm clamped at one end,
    silver rivet, armature force, spherical fixed rivet; finite-element modes) against the
    same bar free (analytic free-free modes, no mount, rivet, force), with the same Hertz
    contact (the clamped run's contact stiffness and damping on the free bar's end caps,
    plane block) and the same friction, striking at the blade's measured first-impact
    speed, 10 deg tilt. 1 axial mode and 2, 4, 8, 12 bending modes, mechanics only, over
    A_T_END of simulated time (both bounce and settle in it; no hold starts before its end).
    Fitted exponent p of cost ~ (bending modes)^p.
(b) The relay default scene's mechanics with t_end = 1 s: solver wall time, steps, events,
    the holds (ImpactSolver.holds), the final contact force against the blade's statics
    (closed-form Euler-Bernoulli cantilever with the armature force, gravity, the rivet's
    weight and the Hertz penetration). The hold cannot be switched off from outside the
    solver (no scene key; it is built in), so the cost without it is extrapolated from the
    cost per simulated ms of the settled contact over the last rest window before the hold
    starts (the same solver advanced to the window's start, then timed over the window).
(c) The coupled relay closure: coupling.builtin_scene("relay_force") with t_end = the start of
    the final closure + 2 ms (first make to 2 ms after settling); solver time =
    result.stats mech_seconds + circuit_seconds, median of --repeat runs. Target < 0.3 s.
    Next to it the mechanics alone over the same span, in one advance and in macro steps.
(d) The free bar lying flat at rest on its two tips with friction (mech.default_scene(),
    initial.resting) for 1 s, planar and 3D: steps, events, holds.

Baseline: `python -c "import numpy"` whole-process wall (median of 5), as in
bench_startup.py; load average from os.getloadavg(). Not a test: run by hand or by
`make bench`,

    .venv/bin/python benchmarks/bench_mechanisms.py [--repeat 3] [--no-write]

It rewrites the block between the bench_mechanisms markers in docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from doc_block import write_block

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy: no BLAS threads on a shared box

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench_mechanisms:begin -->", "<!-- bench_mechanisms:end -->"

A_MODES = (2, 4, 8, 12)
A_T_END = 0.003  # s
B_T_END = 1.0  # s
TARGET_C = 0.3  # s


def baseline_import_numpy(repeat: int = 5) -> float:
    """s: median whole-process wall of `python -c "import numpy"`."""
    walls = []
    for _ in range(repeat):
        tick = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import numpy"], check=True)
        walls.append(time.perf_counter() - tick)
    return statistics.median(walls)


def relay_mech(**changes):
    """The relay default scene's mechanics (a MechScene), with "section.key" changes."""
    from coupling import builtin_scene

    return builtin_scene("relay_force").update(changes).mech if changes else builtin_scene("relay_force").mech


def timed_run(scene, repeat: int, best: bool = False):
    """(median wall s of the solver, or the best with ``best``; last solver, last result):
    ImpactSolver.run, warm; wall = the result's stats wall_time (integration, not the
    model build)."""
    from mech import ImpactSolver

    walls, solver, result = [], None, None
    for _ in range(repeat):
        solver = ImpactSolver(scene)
        result = solver.run()
        walls.append(result.stats["wall_time"])
    return (min(walls) if best else statistics.median(walls)), solver, result


def free_bar_like(clamped_scene, clamped_solver, speed: float):
    """The clamped scene's bar, free: no mount, rivets or forces, plane block; the end caps
    take the clamped run's contact stiffness and damping (the same Hertz contact)."""
    m = clamped_solver.model
    sc = clamped_scene
    contact = dataclasses.replace(sc.contact, stiffness=float(m.cpar[0, 0]), damping=float(m.cpar[0, 1]),
                                  restitution=None)
    block = dataclasses.replace(sc.block, shape="plane", radius=None)
    initial = dataclasses.replace(sc.initial, angle_deg=10.0, velocity=(0.0, 0.0, -speed))
    mount = dataclasses.replace(sc.mount, kind="free", position=None, base_motion=None)
    return dataclasses.replace(sc, mount=mount, rivets=(), forces=(), springs=(), block=block,
                               contact=contact, initial=initial)


def part_a(repeat: int) -> dict:
    rows = []
    for nb in A_MODES:
        clamped = relay_mech(**{"bar.modes": {"axial": 1, "bending": nb}, "solver.t_end": A_T_END})
        wc, sc_, rc = timed_run(clamped, repeat, best=True)
        c = rc.contacts
        speed = float(c.normal_speed_in.iloc[0]) if len(c) else 1.0
        free = free_bar_like(clamped, sc_, speed)
        wf, sf, rf = timed_run(free, repeat, best=True)
        rows.append(dict(
            bending=nb, n_clamped=sc_.model.n, n_free=sf.model.n,
            f_max_clamped=float(np.max(sc_.model.basis.frequencies)),
            f_max_free=float(np.max(sf.model.basis.frequencies)),
            max_step_clamped=sc_.model.max_step, max_step_free=sf.model.max_step,
            ms_clamped=wc / (A_T_END * 1e3), ms_free=wf / (A_T_END * 1e3),
            steps_clamped=rc.stats["steps"], steps_free=rf.stats["steps"],
            events_clamped=rc.stats["events"], events_free=rf.stats["events"],
            contacts_clamped=len(rc.contacts), contacts_free=len(rf.contacts),
            holds_clamped=len(sc_.holds), holds_free=len(sf.holds), speed=speed,
            rhs_us_clamped=wc / rc.stats["rhs_evals"] * 1e6, rhs_us_free=wf / rf.stats["rhs_evals"] * 1e6,
        ))
        r = rows[-1]
        print(f"(a) bending {nb:2d}: clamped {r['ms_clamped'] * 1e3:8.2f} ms per simulated ms "
              f"({r['steps_clamped']} steps), free {r['ms_free'] * 1e3:8.2f} ms ({r['steps_free']} steps)")
    nb = np.log([r["bending"] for r in rows])
    fit = {k: float(np.polyfit(nb, np.log([r[k] for r in rows]), 1)[0])
           for k in ("ms_clamped", "ms_free", "steps_clamped", "steps_free")}
    return dict(rows=rows, fit=fit)


def cantilever_statics(scene, friction: float = 0.0) -> tuple[float, float]:
    """(contact force N, Hertz penetration m) of the relay blade at rest under its final
    armature force: Euler-Bernoulli cantilever clamped at mount.position, the force P at a,
    the blade's weight (uniform) and the rivet's weight at b, the contact reaction R at b
    (distances from the clamp); the rivet's cap moves down by the gap plus (R/k)^(2/3).
    friction: N, a tangential force at the contact along the bar, towards the clamp when
    positive (a stuck contact's); at the cap's lowest point, |offset| + radius below the
    axis, it is a couple on the section that bends the rivet further down by M b^2/(2 EI)."""
    from scipy.optimize import brentq

    from mech.contact_laws import hertz_stiffness

    bar, blk, rv, f = scene.bar, scene.block, scene.rivets[0], scene.forces[0]
    ei = bar.youngs_modulus * bar.second_moments[0]  # bending of the blade's thickness (b3)
    L = max(scene.mount.position, bar.length - scene.mount.position)  # clamp to the free end
    a = abs(scene.mount.position - f.position)
    b = abs(scene.mount.position - rv.position)
    P = float(f.table()[1][-1]) * -f.direction[2]
    q = bar.mass / bar.length * scene.gravity
    w_loads = (P * a * a * (3 * b - a) / (6 * ei) + q * b * b * (6 * L * L - 4 * L * b + b * b) / (24 * ei)
               + rv.mass * scene.gravity * b**3 / (3 * ei)
               + friction * (abs(rv.offset) + rv.radius) * b * b / (2 * ei))
    r_eff = rv.radius * blk.radius / (rv.radius + blk.radius)
    k = hertz_stiffness(r_eff, rv.youngs_modulus, rv.poisson_ratio, blk.youngs_modulus, blk.poisson_ratio)
    gap = scene.initial.height

    def residual(R):
        return w_loads - R * b**3 / (3 * ei) - gap - (R / k) ** (2.0 / 3.0)

    R = brentq(residual, 0.0, 3 * ei * w_loads / b**3)
    return R, (R / k) ** (2.0 / 3.0)


def part_b(repeat: int) -> dict:
    from mech import ImpactSolver

    scene = relay_mech(**{"solver.t_end": B_T_END})
    wall, solver, res = timed_run(scene, repeat)
    holds = [list(h) for h in solver.holds]
    f_end = float(solver.contact_now()[:, 2].sum())
    f_static, pen_static = cantilever_statics(scene)
    # the contact sticks (mu = 0.3): its tangential force at the end is part of the statics
    last = res.history.iloc[-1]
    towards_clamp = math.copysign(1.0, scene.mount.position - scene.rivets[0].position)
    f_t = float(last.friction_x_0) * towards_clamp
    f_static_t, _ = cantilever_statics(scene, friction=f_t)
    # the spherical fixed contact is taken as its tangent plane at the top: the gap error
    # of a cap centre d off the sphere's axis is ~ d^2 / (2 (R1 + R2)) (two spheres)
    m = solver.model
    q = res.states[:, m.slices()["q"]]
    d = q @ m.points[0][0, :, 0]  # lateral travel of the first cap's centre (the frame is fixed)
    r_sum = scene.rivets[0].radius + scene.block.radius
    out_sphere = dict(d_max=float(np.max(np.abs(d))), d_end=float(abs(d[-1])),
                      gap_err_end=float(d[-1] ** 2 / (2 * r_sum)),
                      pen_end=float(res.history.penetration_0.iloc[-1]))
    out = dict(**out_sphere, wall=wall, steps=res.stats["steps"], rejected=res.stats["rejected_steps"],
               events=res.stats["events"], contacts=len(res.contacts), holds=holds, f_end=f_end,
               f_static=f_static, pen_static=pen_static, f_t=f_t, f_static_t=f_static_t,
               regime_end=str(last.regime_0), rtol=scene.solver.rtol,
               window=solver.model.rest_window)
    # cost without the hold: the settled contact over the last rest window before the hold
    if holds:
        t1 = holds[0][0]
        t0 = t1 - solver.model.rest_window
        walls, steps = [], []
        for _ in range(repeat):
            s = ImpactSolver(scene)
            s.advance(t0)
            n0, tick = int(s.result().stats["steps"]), time.perf_counter()
            s.advance(t1)
            walls.append(time.perf_counter() - tick)
            steps.append(int(s.result().stats["steps"]) - n0)
        span = t1 - t0
        out.update(pre_t0=t0, pre_t1=t1, pre_wall_per_ms=statistics.median(walls) / (span * 1e3),
                   pre_steps_per_ms=statistics.median(steps) / (span * 1e3))
    print(f"(b) 1 s held relay: {wall:.3f} s, {out['steps']} steps, {out['events']} events, holds {holds}, "
          f"F_end {f_end:.4f} N against statics {f_static:.4f} N")
    return out


def part_d(repeat: int) -> list:
    """Free bars at rest for 1 s (mech.default_scene(): steel, 10 mm, 0.3 m, automatic mode
    count, friction mu = 0.3, gamma = 0.7): lying flat (initial.resting, angle 0) planar
    and 3D, standing on a tip (angle 90), and coming to rest from a 1 mm drop at 2 deg
    (e = 0.5, Coulomb mu = 0.3; the stiff-and-extreme study's case), flexible and rigid.
    Each with its final total normal force over the weight (static equilibrium: 1)."""
    from mech import default_scene

    base = default_scene()
    fric = dataclasses.replace(base.friction, gamma=0.0, mu=0.3)
    cases = []
    for model in ("auto", "3d"):
        cases.append(("lying flat", dataclasses.replace(
            base, initial=dataclasses.replace(base.initial, angle_deg=0.0, height=0.0,
                                                        velocity=(0.0, 0.0, 0.0), resting=True),
            solver=dataclasses.replace(base.solver, t_end=1.0, model=model))))
    cases.append(("standing on a tip", dataclasses.replace(
        base, initial=dataclasses.replace(base.initial, angle_deg=90.0, height=0.0,
                                                    velocity=(0.0, 0.0, 0.0), resting=True),
        solver=dataclasses.replace(base.solver, t_end=1.0))))
    for label, bar in (("coming to rest", base.bar),
                       ("coming to rest, rigid", dataclasses.replace(base.bar, axial_modes=0, bending_modes=0))):
        contact = dataclasses.replace(base.contact, restitution=0.5)
        cases.append((label, dataclasses.replace(
            base, bar=bar, contact=contact, friction=fric,
            initial=dataclasses.replace(base.initial, angle_deg=2.0, height=1e-3, velocity=(0.0, 0.0, -1.0)),
            solver=dataclasses.replace(base.solver, t_end=1.0))))
    rows = []
    for label, sc in cases:
        wall, solver, res = timed_run(sc, repeat)
        h = res.history
        weight = sc.bar.mass * sc.gravity
        rows.append(dict(case=label, model="planar" if solver.planar else "3d", wall=wall,
                         steps=res.stats["steps"], events=res.stats["events"],
                         holds=[list(h_) for h_ in solver.holds],
                         force_ratio=float(h.normal_force_0.iloc[-1] + h.normal_force_1.iloc[-1]) / weight,
                         residual=float(res.energy["relative_residual"]),
                         gamma=sc.friction.gamma, mu=sc.friction.mu_at(0.0)))
        print(f"(d) {label}, {rows[-1]['model']}: {wall:.3f} s, {res.stats['steps']} steps, "
              f"{res.stats['events']} events, holds {solver.holds}, F/W {rows[-1]['force_ratio']:.9f}")
    return rows


def part_c(repeat: int) -> dict:
    from coupling import builtin_scene, run

    probe = run(builtin_scene("relay_force"))
    bnc = probe.bounce
    first_make, final_start = bnc["first_make"], bnc["last_make"]
    t_end = final_start + 0.002
    scene = builtin_scene("relay_force").set("solver.t_end", t_end)
    solver_s, walls, res = [], [], None
    for _ in range(repeat):
        res = run(scene)
        solver_s.append(res.stats["mech_seconds"] + res.stats["circuit_seconds"])
        walls.append(res.stats["wall_time"])
    out = dict(t_end=t_end, first_make=first_make, final_start=final_start,
               settle_time=res.bounce.get("settle_time"), settled=res.bounce.get("settled"),
               bounces=res.bounce.get("bounces"), solver=statistics.median(solver_s), best=min(solver_s),
               mech=res.stats["mech_seconds"], circuit=res.stats["circuit_seconds"],
               wall=statistics.median(walls), macro_steps=res.stats["macro_steps"],
               mech_steps=int(res.mechanics.stats["steps"]), status=res.status)
    # the mechanics alone over the same span: in one advance, and in advances of the
    # coupling's macro step (what the master's per-step calls cost without the circuit)
    from mech import ImpactSolver

    H = float(scene.raw.get("coupling", {}).get("macro_step", 5e-6))
    alone = {}
    mu = scene.mech.friction.mu_at(0.0)
    for label, step in (("one", None), ("macro", H)):
        walls = []
        for _ in range(repeat):
            s = ImpactSolver(scene.mech, keep_dense=True)
            tick = time.perf_counter()
            if step is None:
                s.advance(t_end)
            else:
                for k in range(1, int(math.ceil(t_end / step - 1e-9)) + 1):
                    s.advance(min(k * step, t_end), mu=(mu, mu))
            walls.append(time.perf_counter() - tick)
        alone[label] = statistics.median(walls)
    out.update(alone_one=alone["one"], alone_macro=alone["macro"], macro_step=H)
    print(f"(c) coupled relay to {t_end * 1e3:.3f} ms: solver {out['solver']:.3f} s (best {out['best']:.3f})")
    return out


def render(a: dict, b: dict, c: dict, d: list, base: float, load: tuple, repeat: int) -> str:
    L = [f"`.venv/bin/python benchmarks/bench_mechanisms.py --repeat {repeat}` "
         f"(load average {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f} at the end of the run, 2 cores; "
         f"baseline `python -c \"import numpy\"` {base:.3f} s in the same run; solver times warm, "
         f"median of {repeat})", ""]
    L += ["**(a) Clamped blade against the free bar, same bar, contact and mode count** (mechanics "
          f"only, {A_T_END * 1e3:g} ms simulated, 1 axial mode; the free bar strikes at the blade's "
          f"first-impact speed, 10 deg tilt; best of {repeat}):", "",
          "| bending modes | clamped: ms per simulated ms | steps | f_max (kHz) | max_step (us) | free: ms per "
          "simulated ms | steps | f_max (kHz) | max_step (us) | clamped / free | wall per rhs eval, "
          "clamped / free (us) | events, clamped / free |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in a["rows"]:
        L.append(f"| {r['bending']} | {r['ms_clamped'] * 1e3:.2f} | {r['steps_clamped']} | "
                 f"{r['f_max_clamped'] / 1e3:.1f} | {r['max_step_clamped'] * 1e6:.2f} | {r['ms_free'] * 1e3:.2f} | "
                 f"{r['steps_free']} | {r['f_max_free'] / 1e3:.1f} | {r['max_step_free'] * 1e6:.2f} | "
                 f"{r['ms_clamped'] / r['ms_free']:.2f}x | {r['rhs_us_clamped']:.2f} / {r['rhs_us_free']:.2f} | "
                 f"{r['events_clamped']} / {r['events_free']} |")
    f = a["fit"]
    holds = sum(r["holds_clamped"] + r["holds_free"] for r in a["rows"])
    L += ["", f"Fitted exponent, cost ~ (bending modes)^p over {A_MODES[0]}-{A_MODES[-1]}: clamped p = "
          f"{f['ms_clamped']:.2f} (steps {f['steps_clamped']:.2f}), free p = {f['ms_free']:.2f} (steps "
          f"{f['steps_free']:.2f}). Holds at rest in these runs: {holds}. Contacts (clamped / free): "
          + ", ".join(f"{r['contacts_clamped']}/{r['contacts_free']}" for r in a["rows"]) + ".", ""]
    L += [f"**(b) The relay held for {B_T_END:g} s** (the default scene's mechanics, t_end = {B_T_END:g} s, "
          f"rtol {b['rtol']:g}, rest window {b['window'] * 1e3:.3f} ms):", "",
          "| solver wall | steps | rejected | events | contacts | holds [start, end] (s) | final contact "
          "force | statics, no friction | statics with the stuck friction force | difference |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    holds_txt = "; ".join(f"[{h[0]:.5f}, {h[1]:g}]" for h in b["holds"]) or "none"
    L.append(f"| {b['wall']:.3f} s ({b['wall'] / base:.1f}x baseline) | {b['steps']} | {b['rejected']} | "
             f"{b['events']} | {b['contacts']} | {holds_txt} | {b['f_end']:.4f} N | {b['f_static']:.4f} N | "
             f"{b['f_static_t']:.4f} N | {(b['f_end'] / b['f_static_t'] - 1) * 100:+.3f} % |")
    L.append("")
    L.append("Statics: Euler-Bernoulli cantilever (closed form, `cantilever_statics`) with the final "
             "armature force, the blade's and the rivet's weight and the Hertz penetration; the contact "
             f"ends in {b['regime_end']} with a tangential force of {b['f_t']:.4f} N (towards the clamp), "
             "which at the cap's lowest point, |offset| + radius below the axis, bends the blade "
             "further down: with it the statics is the last column. The hold's own bound on the "
             f"force's distance from equilibrium is ~sqrt(rtol) = {math.sqrt(b['rtol']) * 100:.1f} %. All "
             "events are before the hold (nothing is integrated during it).")
    L += ["", f"Spherical fixed contact (tangent-plane approximation): the rivet's cap centre travels at "
          f"most {b['d_max'] * 1e6:.2f} um sideways ({b['d_end'] * 1e6:.2f} um at the end); the gap error "
          f"d^2/(2(R1 + R2)) at the end is {b['gap_err_end'] * 1e9:.2f} nm against a Hertz penetration of "
          f"{b['pen_end'] * 1e6:.3f} um ({b['gap_err_end'] / b['pen_end'] * 100:.2f} %)."]
    if "pre_wall_per_ms" in b:
        per_s = b["pre_wall_per_ms"] * 1e3
        L += ["", f"Without the hold (it cannot be switched off from outside the solver, so this is "
              f"extrapolated): the settled contact over the last rest window before the hold, "
              f"[{b['pre_t0'] * 1e3:.3f}, {b['pre_t1'] * 1e3:.3f}] ms, costs {b['pre_wall_per_ms'] * 1e3:.2f} ms "
              f"and {b['pre_steps_per_ms']:.0f} steps per simulated ms: {per_s:.2f} s and "
              f"{b['pre_steps_per_ms'] * 1e3:.3g} steps per simulated second at rest, against "
              f"{b['wall']:.3f} s for the whole held second ({per_s / b['wall']:.0f}x)."]
    ok = c["solver"] < TARGET_C
    L += ["", f"**(c) Coupled relay closure** (`builtin_scene(\"relay_force\")`, t_end = final closure "
          f"{c['final_start'] * 1e3:.3f} ms + 2 ms = {c['t_end'] * 1e3:.3f} ms; first make "
          f"{c['first_make'] * 1e3:.3f} ms, {c['bounces']} bounces, settle time "
          + (f"{c['settle_time'] * 1e3:.3f} ms" if c["settle_time"] is not None else "none") + "):", "",
          "| solver time (mech + circuit) | best | mech | circuit | run wall | macro steps | mech steps | "
          "/ baseline |", "|---|---|---|---|---|---|---|---|",
          f"| {c['solver']:.3f} s | {c['best']:.3f} s | {c['mech']:.3f} s | {c['circuit']:.3f} s | "
          f"{c['wall']:.3f} s | {c['macro_steps']} | {c['mech_steps']} | {c['solver'] / base:.2f}x |", "",
          f"The mechanics alone over the same span (ImpactSolver, dense output on): {c['alone_one']:.3f} s in "
          f"one advance, {c['alone_macro']:.3f} s advanced in steps of the macro step "
          f"({c['macro_step'] * 1e6:g} us) with the friction coefficient set at each, against "
          f"{c['mech']:.3f} s of mech_seconds in the coupled run; the difference is not attributed "
          "here (the coupled run also redoes the steps that end at a make or break).", "",
          f"Target solver time < {TARGET_C:g} s: **{'met' if ok else 'not met'}** ({c['solver']:.3f} s, "
          f"{c['solver'] / base:.2f}x this run's `import numpy`)."]
    L += ["", "**(d) Free bars at rest for 1 s** (`mech.default_scene()`, automatic mode count: lying flat "
          f"and standing on a tip from `initial.resting` (friction mu = {d[0]['mu']:g}, gamma = "
          f"{d[0]['gamma']:g}); coming to rest from a 1 mm drop at 2 deg, 1 m/s, e = 0.5, Coulomb mu = "
          f"{d[-1]['mu']:g}). Final force: both contacts' normal force over the weight (the static "
          "equilibrium is 1):", "",
          "| case | model | solver wall | steps | events | holds [start, end] (s) | final force / weight | "
          "energy residual |", "|---|---|---|---|---|---|---|---|"]
    for r in d:
        holds_txt = "; ".join(f"[{h[0]:.5f}, {h[1]:g}]" for h in r["holds"]) or "none"
        L.append(f"| {r['case']} | {r['model']} | {r['wall']:.3f} s | {r['steps']} | {r['events']} | {holds_txt} | "
                 f"{r['force_ratio']:.9f} | {r['residual']:.2g} |")
    return "\n".join(L)


def write_doc(block: str) -> None:
    write_block(DOC, BEGIN, END, block,
                heading="## Switch mechanisms: held bars, the hold at rest, the coupled relay (issue 8)\n"
                        "Written by benchmarks/bench_mechanisms.py (what each part measures: its docstring).\n\n")
    print(f"wrote {DOC}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    args = ap.parse_args()
    # warm-up: compile / load the kernels and start ngspice outside the timings
    from coupling import builtin_scene, run

    from mech import simulate

    simulate(relay_mech(**{"solver.t_end": 2e-4}))
    run(builtin_scene("relay_force").set("solver.t_end", 2e-4))
    base0 = baseline_import_numpy()
    a = part_a(args.repeat)
    b = part_b(args.repeat)
    d = part_d(args.repeat)
    c = part_c(args.repeat)
    base = 0.5 * (base0 + baseline_import_numpy())
    block = render(a, b, c, d, base, os.getloadavg(), args.repeat)
    print()
    print(block)
    if not args.no_write:
        write_doc(block)


if __name__ == "__main__":
    main()
