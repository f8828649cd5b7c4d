"""Mechanics scenes as TOML (SI units): parsing, validation of keys, the default scene.

Sections: [bar], [block], [mount], [[force]], [[spring]], [[rivet]], [[fixed]], [armature],
[initial], [contact], [friction], [solver], [environment]; each key is a field of the
section's dataclass in mech/parameters.py, declared there with its default, unit and meaning
(``scene_key``), and listed in docs/scene_keys.md (written from those fields). An omitted key
takes its field's default; ``DEFAULT_SCENE_TOML`` is one scene, not the defaults.

Unknown sections or keys are errors that name them (a typo must not silently fall back
to a default). A scene with an [armature] and no [bar] is an armature alone (no contact
spring, no contact): the sections that belong to the bar are then errors. Other packages
(coupling) add their own sections and pass them through ``extra_sections``. This module only maps the TOML structure onto the dataclasses of
mech/parameters.py, 1:1 (``bar.modes`` is the one key that sets two fields); the values are
checked by the dataclasses (mech/validation.py), and their errors are reported with the
file and the key as the scene wrote it.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib

from .parameters import (
    Armature, Bar, Block, Contact, FixedContact, Friction, Initial, MechScene, Mount, PointForce, Rivet,
    SolverOptions, Spring,
)
from .validation import check_file, check_keys

SECTIONS = {
    "bar": Bar,
    "block": Block,
    "initial": Initial,
    "contact": Contact,
    "friction": Friction,
    "solver": SolverOptions,
    "mount": Mount,
    "armature": Armature,
}
# arrays of tables ([[force]] ...): TOML name -> (MechScene field, dataclass)
LIST_SECTIONS = {
    "force": ("forces", PointForce),
    "spring": ("springs", Spring),
    "rivet": ("rivets", Rivet),
    "fixed": ("fixed", FixedContact),
}
# the field of an entry of an array of tables that holds its place ("force[0]", for the
# messages; not a scene key): ``name``, or ``key`` where ``name`` is a key the scene gives
PLACE_FIELDS = {"rivet": "key", "fixed": "key"}
ENVIRONMENT_KEYS = ("gravity",)
# what an armature alone (an [armature] and no [bar]) may not have: they belong to the bar
BAR_SECTIONS = ("block", "initial", "contact", "friction", "mount", "force", "spring", "rivet", "fixed")
# every top-level name a mechanics scene may hold (tables and arrays of tables)
SCENE_SECTIONS = tuple(SECTIONS) + tuple(LIST_SECTIONS) + ("environment",)

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


def _field_names(cls) -> list[str]:
    return [f.name for f in dataclasses.fields(cls)]


def entry_keys(section: str) -> list[str]:
    """The keys an entry of the array of tables ``section`` ([[force]], [[rivet]], ...) may
    hold: its dataclass's fields but the one that holds its place (PLACE_FIELDS)."""
    place = PLACE_FIELDS.get(section, "name")
    return [f for f in _field_names(LIST_SECTIONS[section][1]) if f != place]


def _section(name: str, cls, table: dict, where: str):
    """The dataclass of one section: each key one field; errors in the scene's words."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: [{name}]: expected a table of keys, got {table!r}")
    extra = ["modes"] if name == "bar" else []
    check_keys(f"{where}: [{name}]", table, _field_names(cls) + extra)
    kwargs = dict(table)
    renamed = {}
    if name == "bar" and "modes" in kwargs:
        for field_name in ("axial_modes", "bending_modes"):
            if field_name in kwargs:
                # (modes would have overridden it without a word: Scene.set("bar.axial_modes",
                # 3) on a scene with modes = "auto" ran at the auto count)
                raise ValueError(f"{where}: bar.{field_name} = {kwargs[field_name]!r} beside bar.modes = "
                                 f"{kwargs['modes']!r}: give the counts in one key, bar.modes = "
                                 "{axial = ..., bending = ...}")
        kwargs, renamed = _modes(kwargs, where)
    if name == "bar" and ("width" in kwargs or "thickness" in kwargs) and "diameter" not in kwargs:
        kwargs["diameter"] = None  # a rectangular section replaces the default round one
    if name == "contact" and "damping" in kwargs and "restitution" not in kwargs:
        kwargs["restitution"] = None  # c given directly replaces the default target restitution
    if name == "friction" and kwargs.get("max_ratio") == "inf":
        kwargs["max_ratio"] = math.inf  # how scene_to_dict writes an unbounded ratio
    try:
        return cls(**kwargs)
    except (TypeError, ValueError) as err:  # TypeError: a value of a type no check foresaw
        message = str(err)
        for field_name, key in renamed.items():
            message = message.replace(field_name, key)
        raise ValueError(f"{where}: {message}") from None


def _modes(kwargs: dict, where: str) -> tuple[dict, dict]:
    """`modes = 3` (every family), `modes = "auto"` (the default: chosen from the contact
    time, mech/mode_count.py) or `modes = {axial = 3, bending = 2}` (a family left out is
    "auto"), as the fields axial_modes and bending_modes; and the names of those fields in
    an error -> the key the user wrote (bar.modes, bar.modes.axial)."""
    kwargs = dict(kwargs)
    value = kwargs.pop("modes")
    if isinstance(value, dict):
        check_keys(f"{where}: bar.modes", value, ("axial", "bending"))
        kwargs.update(axial_modes=value.get("axial", "auto"), bending_modes=value.get("bending", "auto"))
        return kwargs, {"bar.axial_modes": "bar.modes.axial", "bar.bending_modes": "bar.modes.bending"}
    kwargs.update(axial_modes=value, bending_modes=value)
    return kwargs, {"bar.axial_modes": "bar.modes", "bar.bending_modes": "bar.modes"}


def scene_from_dict(doc: dict, *, where: str = "scene", extra_sections=()) -> MechScene:
    """Build a validated MechScene from a parsed TOML document.

    extra_sections: top-level tables another package handles; any other unknown table
    is an error.
    """
    if not isinstance(doc, dict):
        raise ValueError(f"{where}: expected a table of sections")
    check_keys(where, doc, set(SCENE_SECTIONS) | set(extra_sections), kind="section")
    doc = _held_defaults(doc)
    parts = {name: _section(name, cls, doc.get(name, {}), where) for name, cls in SECTIONS.items()
             if name in doc}
    if "armature" in doc and "bar" not in doc:
        for name in BAR_SECTIONS:
            if name in doc:
                shown = f"[[{name}]]" if name in LIST_SECTIONS else f"[{name}]"
                raise ValueError(f"{where}: {shown}: this scene has an [armature] and no [bar], an armature alone "
                                 f"without a contact; add the [bar] or remove {shown}")
        parts["bar"] = None
    for name, (fld, cls) in LIST_SECTIONS.items():
        if name not in doc:
            continue
        entries = doc[name]
        if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
            raise ValueError(f"{where}: [[{name}]]: expected an array of tables ([[{name}]] blocks)")
        items = []
        place = PLACE_FIELDS.get(name, "name")
        for k, entry in enumerate(entries):
            check_keys(f"{where}: {name}[{k}]", entry, entry_keys(name))
            items.append(_section(name, cls, dict(entry, **{place: f"{name}[{k}]"}), where))
        parts[fld] = tuple(items)
    env = doc.get("environment", {})
    if not isinstance(env, dict):
        raise ValueError(f"{where}: [environment]: expected a table of keys")
    check_keys(f"{where}: [environment]", env, ENVIRONMENT_KEYS)
    kwargs = dict(parts)
    if "gravity" in env:
        kwargs["gravity"] = env["gravity"]
    try:
        return MechScene(**kwargs)  # environment.gravity and the checks across sections
    except ValueError as err:
        raise ValueError(f"{where}: {err}") from None


def _held_defaults(doc: dict) -> dict:
    """A held bar starts at rest and level unless the scene says otherwise (the free
    drop's defaults, a moving, tilted bar, would contradict its mount)."""
    mount = doc.get("mount")
    if not isinstance(mount, dict) or mount.get("kind", "free") == "free":
        return doc
    initial = doc.get("initial", {})
    if not isinstance(initial, dict):
        return doc
    initial = dict(initial)
    initial.setdefault("velocity", [0.0, 0.0, 0.0])
    initial.setdefault("angle_deg", 0.0)
    return dict(doc, initial=initial)


def read_toml(path) -> dict:
    """The parsed TOML document of a scene file, or a one-line error: missing file, a folder
    or device instead of a file, text that is not UTF-8 (with line and column), bad TOML
    (nesting too deep for the parser included), an empty document (an empty scene would silently run every default: refused).
    A UTF-8 byte-order mark, as some Windows editors write, is accepted."""
    path = check_file("scene", path)
    name = str(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ValueError(f"scene file {name!r} cannot be read: {err.strerror or err}") from None
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        column = err.start - (data.rfind(b"\n", 0, err.start) + 1) + 1
        raise ValueError(f"{name}: line {line}, column {column}: byte 0x{data[err.start]:02x} is not UTF-8 text; "
                         "save the scene as UTF-8") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ValueError(f"{name}: not valid TOML: {err}") from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise ValueError(f"{name}: arrays or inline tables nested too deeply (a scene needs a few levels)") from None
    if not doc:
        raise ValueError(f"{name}: the scene is empty (no sections); an empty scene would silently run "
                         "every default: name the sections you mean (see docs/mechanics.md)")
    return doc


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
        if part is None or (scene.bar is None and name in BAR_SECTIONS):
            continue  # an armature alone: no bar, nor what belongs to it
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
            if isinstance(value, dict):  # armature.force_gain
                value = {k: list(v) for k, v in value.items()}
            table[f.name] = value
        out[name] = table
    out["environment"] = {"gravity": scene.gravity}
    if not scene.armature.present:
        del out["armature"]
    if scene.fixed and "block" in out:
        del out["block"]  # (its fixed contacts are the [[fixed]] entries)
    if not scene.mount.held and "mount" in out:
        del out["mount"]
    elif scene.mount.base_motion is not None:
        bm = scene.mount.base_motion
        out["mount"]["base_motion"] = {"time": list(bm["time"]), "displacement": [list(d) for d in bm["displacement"]],
                                       **({} if bm["interpolation"] == "linear" else {"interpolation": bm["interpolation"]})}
    for name, (fld, cls) in LIST_SECTIONS.items():
        items = getattr(scene, fld)
        keys = entry_keys(name)
        if items:
            out[name] = [{key: (list(v) if isinstance(v, tuple) else v)
                          for key in keys if (v := getattr(it, key)) is not None}
                         for it in items]
    return out
