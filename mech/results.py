"""Results of an impact run: history, contact intervals, phases, restitution, energy audit.

Every table exists as columns of numpy arrays (``*_columns``: what the summary, the
soundness checks and the command line's CSV files use) and as a pandas DataFrame built
from them on first access (``history``, ``contacts``, ``phases``, ``energy_table``,
``event_table``): a run that only writes its summary and CSV files never imports pandas.

All quantities SI; the history is in the world frame (z up) for planar and 3D runs alike.
Energy audit (paper eqs. 21-23 with elastic strain energy added):
    E0 = K + U_elastic + (V - V0) + U_contact + D_normal + D_friction + D_modal + residual
where D_normal = int (F_n - k y^1.5) dy/dt dt is the normal-contact work not stored in
the Hertz spring, and D_friction = -int F_t . v_slip dt.
"""

from __future__ import annotations

import json
import math
from dataclasses import field
from pathlib import Path

import numpy as np

from .compiled import armature_table, energy_table
from .frozen import record
from .kernel_layout import (
    A_FN, A_FTX, A_FTY, A_VTX, A_VTY, A_Y, A_YDOT, Q_DFRICTION, Q_DMODAL, Q_DNORMAL,
    Q_DLOAD, Q_WIN, C_ON, quadrature_rows,
)
from .model import BarModel
from .rotations import rotation_z

REGIME_NAMES = ("free", "slip", "stick")
CONTACT_COLUMNS = ("tip", "t_start", "t_end", "peak_force", "impulse", "normal_speed_in", "normal_speed_out",
                   "kinematic_restitution", "energetic_restitution", "complete")
PHASE_COLUMNS = ("tip", "regime", "t_start", "t_end")


def _frame(columns: dict, categorical: tuple = ()):
    """A pandas DataFrame of ``columns`` (name -> array); columns named in ``categorical``
    (arrays of REGIME_NAMES codes) become categoricals."""
    import pandas as pd

    data = {k: (pd.Categorical.from_codes(v, REGIME_NAMES) if k in categorical else v) for k, v in columns.items()}
    return pd.DataFrame(data)


def seat_credit(t: np.ndarray, events: list[dict]) -> np.ndarray:
    """J at each time of ``t`` (s): the energy of the armature's ringing removed where it was
    seated on a stop (its "armature_seat" events), credited from then on (the record at that
    time holds the state before: its step ended at the turn where the armature was seated)."""
    out = np.zeros(len(t))
    for ev in events:
        if ev["kind"] == "armature_seat" and ev["energy"] != 0.0:
            out[t > ev["time"]] += ev["energy"]
    return out


@record
class ImpactResult:
    """Outcome of ``ImpactSolver.run``. Build tables with the properties; ``save`` writes them."""

    model: BarModel
    t: np.ndarray
    states: np.ndarray
    aux: np.ndarray
    peak_force: np.ndarray
    regimes: np.ndarray
    events: list
    stats: dict
    projection_energy: float = 0.0
    extra_states: np.ndarray | None = None  # (records, size) of CoupledStates, if any
    # None: every step is a row; else the history was thinned as it was made (mech.solver,
    # ImpactSolver._thin_history): resolution (s), until (s: every step after), rows_dropped,
    # and the extremes of the rows dropped: max_abs_residual, max_kinetic, max_drive_work (J),
    # max_speed (m/s), max_penetration (m, per contact point)
    thinning: dict | None = None
    # (5,) J: the energies (energy_table's row) of the run's first record, where this result
    # holds a later stretch of the run's records only (a piece of its history written while
    # the run goes on): the energy audit's columns are then measured from the run's start,
    # as the whole run's are. None: this result starts with the run's first record.
    energy_origin: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    # --- frames -------------------------------------------------------------------------

    def _world(self):
        """(position, quaternion, velocity, world angular velocity) per record."""
        m = self.model
        sl = m.slices()
        Y = self.states
        if not m.planar:
            pos = Y[:, sl["pos"]]
            quat = Y[:, sl["quat"]] / np.linalg.norm(Y[:, sl["quat"]], axis=1)[:, None]
            vel = Y[:, sl["vel"]]
            w_body = Y[:, sl["omega"]]
            w, x, yq, z = quat.T
            # rotate body angular velocity to world: R(q) w_body
            R = np.empty((len(Y), 3, 3))
            R[:, 0, 0] = 1 - 2 * (yq * yq + z * z)
            R[:, 0, 1] = 2 * (x * yq - z * w)
            R[:, 0, 2] = 2 * (x * z + yq * w)
            R[:, 1, 0] = 2 * (x * yq + z * w)
            R[:, 1, 1] = 1 - 2 * (x * x + z * z)
            R[:, 1, 2] = 2 * (yq * z - x * w)
            R[:, 2, 0] = 2 * (x * z - yq * w)
            R[:, 2, 1] = 2 * (yq * z + x * w)
            R[:, 2, 2] = 1 - 2 * (x * x + yq * yq)
            omega = np.einsum("kij,kj->ki", R, w_body)
            return pos, quat, vel, omega
        Rz = rotation_z(m.azimuth)
        zero = np.zeros(len(Y))
        xz = Y[:, sl["pos"]]
        pos = _rotated(Rz, xz[:, 0], zero, xz[:, 1])
        v = Y[:, sl["vel"]]
        vel = _rotated(Rz, v[:, 0], zero, v[:, 1])
        omega = _rotated(Rz, zero, Y[:, sl["omega"]][:, 0], zero)
        quat = planar_quaternions(m.azimuth, Y[:, sl["angle"]][:, 0])
        return pos, quat, vel, omega

    def _horizontal(self, xy: np.ndarray) -> np.ndarray:
        """Tangential (x, y) vectors of the solver frame to the world frame."""
        if not self.model.planar:
            return xy
        c, s = math.cos(self.model.azimuth), math.sin(self.model.azimuth)
        return np.column_stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]])

    def select(self, kept: np.ndarray) -> "ImpactResult":
        """This result restricted to the records ``kept`` (indices, ascending): its tables
        hold those records' rows, each as this result's own table holds it (the energy audit
        still measured from this result's first record); events, statistics and the stick
        projections' credit (at the last record, which a thinned history keeps) as they were."""
        kept = np.asarray(kept)
        if len(kept) == len(self.t):
            return self
        extra = None if self.extra_states is None else self.extra_states[kept]
        return ImpactResult(model=self.model, t=self.t[kept], states=self.states[kept], aux=self.aux[kept],
                            peak_force=self.peak_force[kept], regimes=self.regimes[kept], events=self.events,
                            stats=self.stats, projection_energy=self.projection_energy, extra_states=extra,
                            energy_origin=self.energy_origin_row())

    def energy_origin_row(self) -> np.ndarray:
        """(5,) J: the energies (kinetic, elastic, potential, contact stored, spring stored) the
        energy audit is measured from: the run's first record's."""
        if self.energy_origin is not None:
            return self.energy_origin
        m = self.model
        return energy_table(self.states[:1], m.arrays, m.armature_arrays)[0]

    # --- tables ---------------------------------------------------------------------------

    @property
    def energy_columns(self) -> dict:
        """Per record (numpy arrays): time, kinetic, elastic, potential (change), contact_stored,
        normal/friction/modal dissipation, spring_stored, load_dissipation, work_in, residual (J)."""
        if "energy_columns" not in self._cache:
            m = self.model
            E = energy_table(self.states, m.arrays, m.armature_arrays)
            qd = self.states[:, m.slices()["quad"]]
            first = E[0] if self.energy_origin is None else self.energy_origin
            c = {"time": self.t, **audit_terms(E, qd, first)}
            c["residual"] = audit_residual(E, qd, first) + self._projection_series()
            self._cache["energy_columns"] = c
        return self._cache["energy_columns"]

    @property
    def energy_table(self):
        """pandas DataFrame of ``energy_columns``."""
        if "energy" not in self._cache:
            self._cache["energy"] = _frame(self.energy_columns)
        return self._cache["energy"]

    def _projection_series(self) -> np.ndarray:
        # Kinetic energy removed by stick projections (below the stick tolerance), credited
        # so the residual measures integration error only. Spread as a step at the end.
        out = np.zeros(len(self.t))
        out[-1:] = self.projection_energy
        return out + self._seat_series()

    def _seat_series(self) -> np.ndarray:
        """J per record: seat_credit at the records' times."""
        return seat_credit(self.t, self.events)

    @property
    def history_columns(self) -> dict:
        """Time history at every accepted step (SI, world frame) as numpy arrays; the
        regime_i columns hold REGIME_NAMES codes."""
        if "history_columns" not in self._cache:
            m = self.model
            if not m.has_bar:  # an armature alone
                data = {"time": self.t, **self._armature_columns()}
                data.update({col: v for col, v in list(self.energy_columns.items())[1:]})
                self._cache["history_columns"] = data
                return data
            pos, quat, vel, omega = self._world()
            data = {"time": self.t,
                    "x": pos[:, 0], "y": pos[:, 1], "z": pos[:, 2],
                    "qw": quat[:, 0], "qx": quat[:, 1], "qy": quat[:, 2], "qz": quat[:, 3],
                    "vx": vel[:, 0], "vy": vel[:, 1], "vz": vel[:, 2],
                    "wx": omega[:, 0], "wy": omega[:, 1], "wz": omega[:, 2]}
            sl = m.slices()
            for j, (fam, order) in enumerate(zip(m.basis.families, m.basis.orders)):
                data[f"q_{fam}{order}"] = self.states[:, sl["q"]][:, j]
                data[f"eta_{fam}{order}"] = self.states[:, sl["eta"]][:, j]
            for i in range(m.rows):
                a = self.aux[:, i, :]
                ft = self._horizontal(a[:, [A_FTX, A_FTY]])
                vs = self._horizontal(a[:, [A_VTX, A_VTY]])
                data[f"tip_height_{i}"] = -a[:, A_Y]
                data[f"penetration_{i}"] = np.maximum(a[:, A_Y], 0.0)
                data[f"penetration_rate_{i}"] = a[:, A_YDOT]
                data[f"normal_force_{i}"] = a[:, A_FN]
                data[f"friction_x_{i}"] = ft[:, 0]
                data[f"friction_y_{i}"] = ft[:, 1]
                data[f"slip_vx_{i}"] = vs[:, 0]
                data[f"slip_vy_{i}"] = vs[:, 1]
                data[f"slip_speed_{i}"] = np.hypot(vs[:, 0], vs[:, 1])
                data[f"regime_{i}"] = self.regimes[:, i]
            if m.has_armature:
                data.update(self._armature_columns())
            en = self.energy_columns
            for col in list(en)[1:]:
                data[col] = en[col]
            self._cache["history_columns"] = data
        return self._cache["history_columns"]

    def _armature_columns(self) -> dict:
        """The armature's history columns: armature_position (q: m, or rad for a clapper, the
        travel from the rest stop), armature_velocity (m/s or rad/s), armature_stop_force
        (N or N m on the armature, + the rest stop's push, - the pole stop's) and, with a
        card, card_force (N, its push on the bar)."""
        a = armature_table(self.states, self.model.arrays, self.model.armature_arrays)
        out = {"armature_position": a[:, 0], "armature_velocity": a[:, 1], "armature_stop_force": a[:, 3]}
        if self.model.scene.armature.has_card:
            out["card_force"] = a[:, 2]
        return out

    @property
    def armature(self) -> dict | None:
        """The armature's motion as the run found it (None without an armature), from its
        pole-stop events: first_arrival (s, the first time it reached the pole stop),
        arrival_speed (m/s or rad/s, then), pole_bounces (how often it left the pole stop
        and came back), last_arrival (s, the last time it reached the pole stop), left_pole
        (s, when it left the pole stop after that; None if still on it at the end); the
        times None where the run does not reach them."""
        if not self.model.has_armature:
            return None
        pole = [e for e in self.events if e.get("stop") == "pole"]
        starts = [e for e in pole if e["kind"] == "armature_stop_start"]
        ends = [e for e in pole if e["kind"] == "armature_stop_end"]
        first = starts[0] if starts else None
        last = starts[-1] if starts else None
        left = [e["time"] for e in ends if last is not None and e["time"] >= last["time"]]
        return {
            "first_arrival": first["time"] if first else None,
            "arrival_speed": first["armature_velocity"] if first else None,
            "pole_bounces": max(len(starts) - 1, 0),
            "last_arrival": last["time"] if last else None,
            "left_pole": left[0] if left else None,
        }

    @property
    def history(self):
        """pandas DataFrame of ``history_columns`` (regimes as categoricals)."""
        if "history" not in self._cache:
            regimes = tuple(f"regime_{i}" for i in range(self.model.rows))
            self._cache["history"] = _frame(self.history_columns, regimes)
        return self._cache["history"]

    @property
    def contact_columns(self) -> dict:
        """One entry per contact interval (numpy arrays, by t_start): tip, t_start, t_end (s),
        peak_force (N), impulse (N s), normal speeds in/out (m/s), kinematic and energetic
        (Stronge) restitution, complete. A pair's first contact that was there from the start
        (touching or at gap 0 at t = 0, not approaching: a preloaded NC contact) is no
        impact: its restitutions are nan."""
        if "contact_columns" in self._cache:
            return self._cache["contact_columns"]
        rows = []
        quad0 = self.model.slices()["quad"].start
        for i in range(self.model.rows):
            start = None
            # touching or at gap 0 at the start, not approaching: the pair's first contact was
            # there from the start (a preloaded NC contact, a bar set down), not an impact
            resting = self.aux[0, i, A_Y] >= 0.0 and self.aux[0, i, A_YDOT] <= 0.0
            if self.aux[0, i, A_Y] > 0.0:
                start = dict(time=self.t[0], penetration_rate=self.aux[0, i, A_YDOT], from_start=resting)
            for ev in self.events:
                if ev["tip"] != i:
                    continue
                if ev["kind"] == "contact_start":
                    start = dict(ev, from_start=resting)
                    resting = False
                elif ev["kind"] == "contact_end" and start is not None:
                    rows.append(self._contact_row(i, start, ev, quad0))
                    start = None
            if start is not None:  # still in contact at the end of the run
                end = dict(time=self.t[-1], penetration_rate=self.aux[-1, i, A_YDOT], open=True)
                rows.append(self._contact_row(i, start, end, quad0))
        rows.sort(key=lambda r: r["t_start"])  # stable: tip 0 first at equal times
        kinds = {"tip": np.int64, "complete": bool}
        cols = {k: np.array([r[k] for r in rows], dtype=kinds.get(k, float)) for k in CONTACT_COLUMNS}
        self._cache["contact_columns"] = cols
        return cols

    @property
    def contacts(self):
        """pandas DataFrame of ``contact_columns``."""
        if "contacts" not in self._cache:
            self._cache["contacts"] = _frame(self.contact_columns)
        return self._cache["contacts"]

    def _state_at(self, t: float) -> np.ndarray:
        k = int(np.searchsorted(self.t, t - 1e-15))
        return self.states[min(k, len(self.t) - 1)]

    def _contact_row(self, tip: int, start: dict, end: dict, quad0: int) -> dict:
        t0, t1 = start["time"], end["time"]
        y0, y1 = self._state_at(t0), self._state_at(t1)
        mask = (self.t >= t0) & (self.t <= t1)
        peak = float(self.peak_force[mask, tip].max()) if mask.any() else 0.0
        q_comp, q_rest, q_imp = (quad0 + q for q in quadrature_rows(tip))
        impulse = y1[q_imp] - y0[q_imp]
        w_comp = y1[q_comp] - y0[q_comp]
        w_rest = y1[q_rest] - y0[q_rest]
        v_in = float(start["penetration_rate"])
        v_out = float(-end["penetration_rate"])
        complete = not end.get("open", False)
        impact = complete and not start.get("from_start", False)  # restitution is an impact's
        return dict(
            tip=tip, t_start=float(t0), t_end=float(t1), peak_force=peak, impulse=float(impulse),
            normal_speed_in=v_in, normal_speed_out=v_out,
            kinematic_restitution=v_out / v_in if (impact and v_in > 0) else float("nan"),
            energetic_restitution=math.sqrt(max(-w_rest, 0.0) / w_comp) if (impact and w_comp > 0) else float("nan"),
            complete=complete,
        )

    @property
    def phase_columns(self) -> dict:
        """Intervals of constant regime per tip (numpy arrays): tip, regime (name), t_start, t_end (s)."""
        if "phase_columns" in self._cache:
            return self._cache["phase_columns"]
        rows = []
        for i in range(self.model.rows):
            codes = self.regimes[:, i]
            start = 0
            for k in range(1, len(codes) + 1):
                if k == len(codes) or codes[k] != codes[start]:
                    t_start = self.t[start - 1] if start > 0 else self.t[0]
                    rows.append((i, REGIME_NAMES[codes[start]], float(t_start), float(self.t[k - 1])))
                    start = k
        kinds = (np.int64, object, float, float)
        cols = {k: np.array([r[j] for r in rows], dtype=kinds[j]) for j, k in enumerate(PHASE_COLUMNS)}
        self._cache["phase_columns"] = cols
        return cols

    @property
    def phases(self):
        """pandas DataFrame of ``phase_columns``."""
        if "phases" not in self._cache:
            self._cache["phases"] = _frame(self.phase_columns)
        return self._cache["phases"]

    @property
    def event_table(self):
        """pandas DataFrame of ``events`` (one row per event)."""
        import pandas as pd

        return pd.DataFrame(self.events)

    @property
    def restitution(self) -> dict:
        """Kinematic and energetic restitution of the first impact: the first complete contact
        that was not there from the start (nan if none)."""
        return self._first_restitution(np.ones(len(self.contact_columns["tip"]), bool))

    def _first_restitution(self, which: np.ndarray) -> dict:
        c = self.contact_columns
        impacts = np.isfinite(c["kinematic_restitution"]) | np.isfinite(c["energetic_restitution"])
        done = np.flatnonzero(c["complete"] & which & impacts)
        if not len(done):
            return {"kinematic": float("nan"), "energetic": float("nan")}
        k = done[0]
        return {"kinematic": float(c["kinematic_restitution"][k]), "energetic": float(c["energetic_restitution"][k])}

    @property
    def pairs(self) -> list[dict]:
        """One entry per contact pair (mech.solver.ImpactSolver.pairs), in the order of the
        contact rows (the ``_<i>`` columns, the contacts' ``tip``): index, point (the
        contact point's name), fixed (its fixed contact's name), facing ("up" or "down"),
        electrical, contacts (how many contact intervals), restitution (kinematic and
        energetic of its first complete contact; nan if none) and deepest_penetration (m;
        negative: its closest approach)."""
        tips = self.contact_columns["tip"]
        return [{"index": i, "point": p.point.name, "fixed": p.fixed, "facing": "up" if p.normal > 0.0 else "down",
                 "electrical": bool(p.electrical), "contacts": int(np.count_nonzero(tips == i)),
                 "restitution": self._first_restitution(tips == i),
                 "deepest_penetration": self._max_penetration(i) if len(self.aux) else float("nan")}
                for i, p in enumerate(self.model.pairs)]

    @property
    def energy(self) -> dict:
        """Energy audit at the end of the run (J), plus the largest relative residual."""
        en = self.energy_columns
        e0 = float(en["kinetic"][0] + en["elastic"][0] + en["contact_stored"][0])
        scale = self.energy_scale
        return {
            "initial": e0,
            "kinetic": float(en["kinetic"][-1]),
            "elastic": float(en["elastic"][-1]),
            "potential_change": float(en["potential"][-1]),
            "contact_stored": float(en["contact_stored"][-1]),
            "normal_dissipation": float(en["normal_dissipation"][-1]),
            "friction_dissipation": float(en["friction_dissipation"][-1]),
            "modal_dissipation": float(en["modal_dissipation"][-1]),
            "residual": float(en["residual"][-1]),
            "relative_residual": self.max_abs_residual / scale,
        }

    def _dropped(self, key: str, default: float) -> float:
        """An extreme of the rows thinned away (``thinning``), or ``default`` if none were."""
        return float(self.thinning[key]) if self.thinning else default

    @property
    def max_abs_residual(self) -> float:
        """J: the largest |energy residual| over the run (the rows thinned away included)."""
        return max(float(np.max(np.abs(self.energy_columns["residual"]))), self._dropped("max_abs_residual", 0.0))

    @property
    def max_kinetic(self) -> float:
        """J: the largest kinetic energy over the run (the rows thinned away included)."""
        return max(float(self.energy_columns["kinetic"].max()), self._dropped("max_kinetic", 0.0))

    @property
    def max_speed(self) -> float:
        """m/s: the largest speed of the frame's origin (a free bar's centre) over the run."""
        speed = float(np.max(np.linalg.norm(self.states[:, self.model.slices()["vel"]], axis=1)))
        return max(speed, self._dropped("max_speed", 0.0))

    def _max_penetration(self, i: int) -> float:
        """m: contact point i's deepest penetration (negative: its closest approach) over the run."""
        deepest = float(np.max(self.aux[:, i, A_Y])) if len(self.aux) else -math.inf
        return max(deepest, self.thinning["max_penetration"][i]) if self.thinning else deepest

    @property
    def energy_scale(self) -> float:
        """J: the energy the audit is judged against: what the scene brings in, its initial
        kinetic, elastic, contact- and spring-stored energy E_in, plus the most work its
        loads and drives can do, max(W_rest, min(W_run, W_all)):

        - W_run, what the run's loads and drives did: the most that the actuators and a
          moving clamp had put in (``work_in``), gravity had released and the springs and a
          pivot's preload torque had given up, at any time: the energy in motion, stored
          in the bar and dissipated, less E_in (a tight yardstick);
        - W_rest, bounded from the scene before the run, what the loads that act on a bar
          at rest can release: a free bar's centre can drop to its lowest resting height
          (lying flat on the block: the centre at the tip radius), m g (z_c0 - R_tip); a
          held bar's weight and a pivot's preload torque can do mech.model.load_work_bound
          within its range of motion (a sagging blade, a pendulum, a preloaded pivot). A
          bar at rest is judged against this, not against its near-zero motion;
        - W_all, also bounded from the scene, what every load can do (the actuator forces
          at their largest too), and the springs' energy: a run that gains energy by error
          does not enlarge its yardstick beyond it. A moving clamp and a free bar's forces
          have no such bound, nor has an armature's drive: their work is what the run measured."""
        en = self.energy_columns
        m = self.model
        # the centre's height, z up (planar: x, z); an armature alone has no bar to fall
        z0 = float(self.states[0, m.slices()["pos"]][-1]) if m.has_bar else 0.0
        s0 = float(en["spring_stored"][0])
        e_in = float(en["kinetic"][0] + en["elastic"][0] + en["contact_stored"][0]) + s0
        if "scene_bounds" not in self._cache:
            self._cache["scene_bounds"] = self._scene_bounds(e_in, z0)
        w_rest, w_all = self._cache["scene_bounds"]
        drive = en["work_in"] - en["potential"] - (en["spring_stored"] - s0)
        w_run = max(float(np.max(drive)), self._dropped("max_drive_work", -math.inf))
        return max(e_in + max(w_rest, min(w_run, w_all + s0), 0.0), 1e-300)

    def _scene_bounds(self, e_in: float, z0: float) -> tuple[float, float]:
        """(W_rest, W_all) of ``energy_scale``, J, from the scene alone."""
        m = self.model
        scene = m.scene
        if not m.has_bar:  # an armature alone: its drive's work is what the run measured
            return 0.0, math.inf
        # a force-travel spring can give up energy from rest (a dome snapping through)
        snap = sum(sp.releasable_energy() for sp in scene.springs)
        if not scene.mount.held:  # a free bar can drop its centre to the tip radius
            w_rest = m.basis.mass * scene.gravity * max(z0 - scene.bar.tip_radius, 0.0) + snap
            return w_rest, (math.inf if scene.forces else w_rest)
        from .model import load_work_bound

        w_rest = load_work_bound(m, e_in, forces=False) + snap
        if scene.mount.base_motion is not None or scene.armature.present:
            return w_rest, math.inf  # a moving clamp's or an armature drive's work: what the run measured
        return w_rest, (load_work_bound(m, e_in) if scene.forces else w_rest)

    @property
    def deepest_penetration(self) -> float:
        """m: the deepest penetration of any contact point into its fixed contact over the run (0: none)."""
        if not len(self.aux):
            return 0.0
        return max(*(self._max_penetration(i) for i in range(self.model.rows)), 0.0)

    @property
    def contact_depths(self) -> list[tuple[str, float, float]]:
        """(name, deepest penetration m, effective radius m) of each contact pair: the cap's
        radius, against a spherical fixed contact R1 R2 / (R1 + R2) (where Hertz's
        small-deformation law is judged). name: "contact point <i>", with [[fixed]] entries
        followed by the point and its fixed contact, "(<point> on <fixed>)"."""
        out = []
        for i, pair in enumerate(self.model.pairs):
            if self.model.cpar[i, C_ON] == 0.0 or not len(self.aux):
                continue
            name = f"contact point {i}" + ("" if pair.key == "block" else f" ({pair.point.name} on {pair.fixed})")
            out.append((name, self._max_penetration(i), pair.effective_radius))
        return out

    @property
    def flags(self) -> list[str]:
        """Warnings about this result (energy residual above tolerance, invalid contact geometry)."""
        out = []
        tol = self.model.scene.solver.energy_tolerance
        rel = self.energy["relative_residual"]
        if not rel <= tol:
            out.append(f"energy residual {rel:.3g} of the scene's energy scale exceeds "
                       f"solver.energy_tolerance = {tol:g}")
        for ev in self.events:
            if ev["kind"] == "invalid_contact_geometry":
                out.append(f"t = {ev['time']:.6g} s, tip {ev['tip']}: {ev['note']}")
        return out

    @property
    def solver(self) -> dict:
        m = self.model
        return dict(self.stats, model="planar" if m.planar else "3d", modes=m.n, states=m.state_size,
                    friction=("none", "exact", "regularized")[int(m.ipar[2])],
                    damping=m.contact.damping, stiffness=m.contact.stiffness,
                    modes_rule=m.mode_count.reason if m.mode_count is not None else "explicit",
                    history=self.history_resolution)

    @property
    def history_resolution(self) -> dict:
        """The history's resolution: rows (the records kept), resolution (s: one row per
        interval of this grid besides the event and regime-change rows, up to
        ``thinned_until``; 0: every step) and thinned_until (s: every step after it)."""
        th = self.thinning
        if not th:
            return {"rows": len(self.t), "resolution": 0.0, "thinned_until": 0.0}
        return {"rows": len(self.t), "resolution": float(th["resolution"]), "thinned_until": float(th["until"])}

    def to_summary(self) -> dict:
        """The JSON summary: contacts, restitution, energy, solver, flags."""
        c = self.contact_columns
        arm = {"armature": {k: _num(v) if isinstance(v, float) else v for k, v in self.armature.items()}} \
            if self.model.has_armature else {}
        pairs = {"pairs": [{k: (_num(v) if isinstance(v, float) else
                                {kk: _num(vv) for kk, vv in v.items()} if isinstance(v, dict) else v)
                            for k, v in p.items()} for p in self.pairs]} if self.model.scene.fixed else {}
        return {
            **arm,
            **pairs,
            "contacts": [
                {k: (int(c[k][j]) if k == "tip" else (bool(c[k][j]) if k == "complete" else _num(c[k][j])))
                 for k in CONTACT_COLUMNS}
                for j in range(len(c["tip"]))
            ],
            "restitution": {k: _num(v) for k, v in self.restitution.items()},
            "energy": {k: _num(v) for k, v in self.energy.items()},
            "solver": {k: (_num(v) if isinstance(v, float) else v) for k, v in self.solver.items()},
            "flags": self.flags,
        }

    def save(self, out_dir) -> Path:
        """Write summary.json, history.csv, contacts.csv, phases.csv, events.csv into out_dir."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        (out / "summary.json").write_text(json.dumps(self.to_summary(), indent=2))
        self.history.to_csv(out / "history.csv", index=False)
        self.contacts.to_csv(out / "contacts.csv", index=False)
        self.phases.to_csv(out / "phases.csv", index=False)
        self.event_table.to_csv(out / "events.csv", index=False)
        return out


def audit_terms(E: np.ndarray, qd: np.ndarray, first: np.ndarray) -> dict:
    """The energy audit's terms per record (J) from ``energy_table`` rows E (records, 5),
    the quadratures qd (records, nq) and the first record's energies ``first`` (5,)."""
    held = qd.shape[1] > Q_WIN  # quadratures of input work and load dissipation
    zero = np.zeros(len(E))
    return {
        "kinetic": E[:, 0],
        "elastic": E[:, 1],
        "potential": E[:, 2] - first[2],
        "contact_stored": E[:, 3],
        "normal_dissipation": qd[:, Q_DNORMAL],
        "friction_dissipation": qd[:, Q_DFRICTION],
        "modal_dissipation": qd[:, Q_DMODAL],
        "spring_stored": E[:, 4],
        "load_dissipation": qd[:, Q_DLOAD] if held else zero,
        "work_in": qd[:, Q_WIN] if held else zero,
    }


def audit_residual(E: np.ndarray, qd: np.ndarray, first: np.ndarray) -> np.ndarray:
    """J per record: the energy the audit cannot place, E0 less every term it names (module
    docstring; the stick projections' credit is added by the result, at its last record)."""
    c = audit_terms(E, qd, first)
    e0 = first[0] + first[1] + first[3] + first[4]
    total = (c["kinetic"] + c["elastic"] + c["potential"] + c["contact_stored"] + c["normal_dissipation"]
             + c["friction_dissipation"] + c["modal_dissipation"] + c["spring_stored"]
             + c["load_dissipation"] - c["work_in"])
    return e0 - total


def _rotated(R: np.ndarray, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(records, 3): R @ (x, y, z) of every record, each row's three products summed left to
    right. Element-wise, so a record's result does not depend on how many are computed at once
    (a matrix product hands the rows to BLAS, whose kernels may sum a row otherwise at another
    row count): the history written in pieces while a run goes on is the whole table's bytes."""
    out = np.empty((len(x), 3))
    for i in range(3):
        out[:, i] = x * R[i, 0] + y * R[i, 1] + z * R[i, 2]
    return out


def planar_quaternions(azimuth: float, angles: np.ndarray) -> np.ndarray:
    """(records, 4): ``matrix_to_quaternion(rotation_z(azimuth) @ rotation_y(angle))`` for every
    angle, bit for bit (the history's qw..qz of a planar run), without a Python call per record
    (~10 us each: 30 ms of writing a default run's history). The same operations in the same
    order: math's cos and sin, the product by np.matmul, Shepperd's four branches chosen by the
    same tests, and the norm as np.linalg.norm takes it (the row's own dot, then sqrt; held
    to the conversion record by record by tests/mech/test_planar_quaternions.py)."""
    phi = np.asarray(angles, dtype=float)
    n = len(phi)
    c = np.fromiter(map(math.cos, phi.tolist()), float, n)
    s = np.fromiter(map(math.sin, phi.tolist()), float, n)
    Ry = np.zeros((n, 3, 3))
    Ry[:, 0, 0] = c
    Ry[:, 0, 2] = s
    Ry[:, 1, 1] = 1.0
    Ry[:, 2, 0] = -s
    Ry[:, 2, 2] = c
    R = np.matmul(rotation_z(azimuth), Ry)
    r = {(i, j): R[:, i, j] for i in range(3) for j in range(3)}
    tr = np.trace(R, axis1=1, axis2=2)
    first = tr > 0
    second = ~first & (r[0, 0] > r[1, 1]) & (r[0, 0] > r[2, 2])
    third = ~first & ~second & (r[1, 1] > r[2, 2])
    fourth = ~(first | second | third)
    q = np.empty((n, 4))
    with np.errstate(all="ignore"):  # each branch is computed for every record, kept where it applies
        s = 2.0 * np.sqrt(tr + 1.0)
        q[first] = np.column_stack([0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s,
                                    (r[1, 0] - r[0, 1]) / s])[first]
        s = 2.0 * np.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q[second] = np.column_stack([(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s,
                                     (r[0, 2] + r[2, 0]) / s])[second]
        s = 2.0 * np.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q[third] = np.column_stack([(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s,
                                    (r[1, 2] + r[2, 1]) / s])[third]
        s = 2.0 * np.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q[fourth] = np.column_stack([(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s,
                                     0.25 * s])[fourth]
    # (np.vecdot's loop is the dtype's own dot, BLAS's ddot, row by row: each row's dot
    # product as ndarray.dot and np.linalg.norm take it, the same bits, without a Python
    # call per record: ~2.5 ms of a default relay's history)
    norm = np.sqrt(np.vecdot(q, q))
    return q / norm[:, None]


def _num(v):
    """JSON-safe float (NaN -> None)."""
    v = float(v)
    return None if not math.isfinite(v) else v
