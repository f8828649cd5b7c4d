"""Mechanics scenes as TOML (SI units): parsing, validation of keys, the default scene.

Sections and keys (all optional; defaults are the documented default scene):

    [bar]       length, diameter | (width, thickness), tip_radius, youngs_modulus,
                poisson_ratio, density, modes (per family, or {axial = n, bending = n}),
                bending ("euler_bernoulli" | "paper_shear"), modal_damping
    [block]     youngs_modulus, poisson_ratio
    [initial]   height, angle_deg, azimuth_deg, velocity [3], angular_velocity [3]
    [contact]   law, restitution | damping, reference_speed, calibration, stiffness
    [friction]  mu, gamma, model, max_ratio, regularization_speed
    [solver]    rtol, t_end, model, max_step, stick_velocity_tol, energy_tolerance, max_steps
    [environment] gravity

Unknown sections or keys are errors that name them (a typo must not silently fall back
to a default). Other packages (coupling) add their own sections and pass them through
``extra_sections``.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
from pathlib import Path

from .parameters import Bar, Block, Contact, Friction, Initial, MechScene, SolverOptions

SECTIONS = {
    "bar": Bar,
    "block": Block,
    "initial": Initial,
    "contact": Contact,
    "friction": Friction,
    "solver": SolverOptions,
}
ENVIRONMENT_KEYS = ("gravity",)

# The default mechanics scene: the paper's steel link (L = 0.3 m) with a 10 mm round
# section and hemispherical 5 mm tips, released 1 mm above a steel block at 30 deg,
# moving down at 1 m/s and sideways out of its plane (a 3D scene), on an NbSe2 film.
DEFAULT_SCENE_TOML = """\
[bar]
length = 0.3
diameter = 0.01
tip_radius = 0.005
youngs_modulus = 210e9
poisson_ratio = 0.3
density = 7850.0
modes = "auto"

[block]
youngs_modulus = 210e9
poisson_ratio = 0.3

[initial]
height = 0.001
angle_deg = 30.0
velocity = [0.2, 0.1, -1.0]
angular_velocity = [0.0, 0.0, 0.0]

[contact]
law = "paper"
restitution = 0.8

[friction]
mu = 0.3
gamma = 0.7

[solver]
rtol = 1e-6
t_end = 0.05
"""


def _suggest(key: str, allowed) -> str:
    close = difflib.get_close_matches(key, list(allowed), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _field_names(cls) -> list[str]:
    return [f.name for f in dataclasses.fields(cls)]


def _section(name: str, cls, table: dict, where: str):
    if not isinstance(table, dict):
        raise ValueError(f"{where}[{name}]: expected a table of keys, got {table!r}")
    allowed = _field_names(cls)
    kwargs = {}
    for key, value in table.items():
        if name == "bar" and key == "modes":
            kwargs.update(_modes(value, where))
            continue
        if key not in allowed:
            extra = ["modes"] if name == "bar" else []
            raise ValueError(f"{where}[{name}]: unknown key {key!r}{_suggest(key, allowed + extra)}; "
                             f"allowed keys: {', '.join(sorted(allowed + extra))}")
        kwargs[key] = value
    if name == "bar" and ("width" in kwargs or "thickness" in kwargs) and "diameter" not in kwargs:
        kwargs["diameter"] = None  # a rectangular section replaces the default round one
    if name == "contact" and "damping" in kwargs and "restitution" not in kwargs:
        kwargs["restitution"] = None  # c given directly replaces the default target restitution
    if name == "friction" and isinstance(kwargs.get("max_ratio"), str):
        if kwargs["max_ratio"] != "inf":
            raise ValueError(f"{where}[friction]: max_ratio = {kwargs['max_ratio']!r}: a number > 0 or \"inf\"")
        kwargs["max_ratio"] = math.inf
    try:
        return cls(**kwargs)
    except TypeError as err:  # wrong value types reaching the constructor
        raise ValueError(f"{where}[{name}]: {err}") from None


def _modes(value, where: str) -> dict:
    """`modes = 3` (every family), `modes = "auto"` (the default: chosen from the contact
    time, mech/mode_count.py) or `modes = {axial = 3, bending = 2}` (a family left out is
    "auto")."""
    if isinstance(value, dict):
        unknown = set(value) - {"axial", "bending"}
        if unknown:
            raise ValueError(f"{where}[bar]: modes: unknown key(s) {sorted(unknown)}; allowed: axial, bending")
        return {"axial_modes": value.get("axial", "auto"), "bending_modes": value.get("bending", "auto")}
    return {"axial_modes": value, "bending_modes": value}


def scene_from_dict(doc: dict, *, where: str = "scene", extra_sections=()) -> MechScene:
    """Build a validated MechScene from a parsed TOML document.

    extra_sections: top-level tables another package handles; any other unknown table
    is an error.
    """
    if not isinstance(doc, dict):
        raise ValueError(f"{where}: expected a table of sections")
    known = set(SECTIONS) | {"environment"} | set(extra_sections)
    for name in doc:
        if name not in known:
            raise ValueError(f"{where}: unknown section [{name}]{_suggest(name, known)}; "
                             f"allowed sections: {', '.join(sorted(known))}")
    parts = {name: _section(name, cls, doc.get(name, {}), where) for name, cls in SECTIONS.items()
             if name in doc}
    env = doc.get("environment", {})
    if not isinstance(env, dict):
        raise ValueError(f"{where}[environment]: expected a table of keys")
    for key in env:
        if key not in ENVIRONMENT_KEYS:
            raise ValueError(f"{where}[environment]: unknown key {key!r}; allowed keys: gravity")
    kwargs = dict(parts)
    if "gravity" in env:
        kwargs["gravity"] = env["gravity"]
    return MechScene(**kwargs)


def read_toml(path) -> dict:
    """The parsed TOML document of a scene file, or a clear error (missing file, bad TOML)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"scene file {str(path)!r} not found")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{path}: not valid TOML: {err}") from None


def load_scene(path) -> MechScene:
    """Read a mechanics scene TOML file (SI units)."""
    return scene_from_dict(read_toml(path), where=str(path))


def default_scene() -> MechScene:
    """The built-in default mechanics scene (see DEFAULT_SCENE_TOML)."""
    return scene_from_dict(tomllib.loads(DEFAULT_SCENE_TOML), where="default scene")


def scene_to_dict(scene: MechScene) -> dict:
    """The scene as a TOML-ready dict (callables for mu are not representable and raise)."""
    out = {}
    for name, cls in SECTIONS.items():
        part = getattr(scene, name)
        table = {}
        for f in dataclasses.fields(cls):
            value = getattr(part, f.name)
            if value is None:
                continue
            if callable(value):
                raise ValueError(f"{name}.{f.name}: a callable cannot be written to a scene file")
            if isinstance(value, tuple):
                value = list(value)
            if isinstance(value, float) and math.isinf(value):
                value = "inf"
            table[f.name] = value
        out[name] = table
    out["environment"] = {"gravity": scene.gravity}
    return out
