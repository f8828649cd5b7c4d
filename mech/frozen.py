"""Frozen dataclasses whose methods are closures, not generated source.

``@frozen`` makes the class ``@dataclasses.dataclass(frozen=True)`` makes (the same fields,
``dataclasses.fields``/``replace``/``asdict``, ``__init__`` with the same positional and
keyword arguments, defaults and factories, ``__post_init__``, ``__repr__``, ``__eq__``,
``__hash__``, ``__match_args__``, ``FrozenInstanceError`` on assignment), at a fraction
of its cost to define. Python 3.11's ``dataclass`` writes each method as source text and
compiles it with its own ``exec``: six compilations a frozen class, ~0.5 ms, and a run
defines ~90 such classes at its start (the parameters, the scene, the laws), 50-60 ms of
a coupled run's process (docs/benchmarks.md). Here ``dataclasses`` still collects the
fields (and checks them: mutable defaults, field order), and the methods are shared
functions over the field names.

Differences, none of which switchsim relies on: ``__dataclass_params__.frozen`` reads
False (``dataclasses.replace`` does not look at it; a standard frozen dataclass cannot
inherit from these classes, a class of this decorator can); ``inspect.signature`` of the
class shows ``(*args, **kwargs)``; a recursive ``repr`` raises RecursionError instead of
printing "...". ``InitVar`` fields are not supported (TypeError at the class).

The price is paid per instance: this ``__init__`` binds its arguments in Python, 2.0 us
for six fields against the generated one's 0.9 us; a class made in numbers (one per macro
step) is better left to ``dataclasses.dataclass``.

``@record`` is the same for a mutable dataclass (``@dataclasses.dataclass``: fields may be
assigned, ``__hash__`` is None as dataclass makes it): for the few results made once a run
(three generated methods, ~0.4 ms a class).
"""

from __future__ import annotations

import dataclasses
from dataclasses import MISSING, FrozenInstanceError
from operator import attrgetter

__all__ = ["frozen", "record"]


def frozen(cls=None, /, *, kw_only: bool = False):
    """Class decorator: ``dataclasses.dataclass(frozen=True, kw_only=kw_only)`` (see the
    module docstring). Usable bare (``@frozen``) or called (``@frozen(kw_only=True)``)."""
    if cls is None:
        return lambda c: frozen(c, kw_only=kw_only)
    return _dataclass(cls, kw_only, freeze=True)


def record(cls=None, /, *, kw_only: bool = False):
    """Class decorator: ``dataclasses.dataclass(kw_only=kw_only)``, a mutable dataclass, with
    ``frozen``'s closures for methods (see the module docstring)."""
    if cls is None:
        return lambda c: record(c, kw_only=kw_only)
    return _dataclass(cls, kw_only, freeze=False)


def _dataclass(cls, kw_only: bool, freeze: bool):
    body = cls.__dict__
    if freeze:
        for name in ("__setattr__", "__delattr__"):
            if name in body:
                raise TypeError(f"Cannot overwrite attribute {name} in class {cls.__name__}")
    # as dataclass decides: a class's own __eq__ without a __hash__ gets the generated hash
    explicit_hash = "__hash__" in body and not (body["__hash__"] is None and "__eq__" in body)
    own = {name for name in ("__init__", "__repr__", "__eq__") if name in body}
    cls = dataclasses.dataclass(cls, init=False, repr=False, eq=False, kw_only=kw_only)
    every = cls.__dataclass_fields__
    fields = dataclasses.fields(cls)
    names = tuple(f.name for f in fields)
    for name in set(every) - set(names):
        if "InitVar" in str(every[name].type):
            raise TypeError(f"{cls.__name__}.{name}: InitVar is not supported by mech.frozen")
    if "__init__" not in own:
        cls.__init__ = _init(cls, fields)
    if "__repr__" not in own:
        cls.__repr__ = _repr([f.name for f in fields if f.repr])
    if "__eq__" not in own:
        cls.__eq__ = _eq(_values([f.name for f in fields if f.compare]))
    if not freeze:
        if not explicit_hash:  # (eq without frozen: dataclass makes instances unhashable)
            cls.__hash__ = None
        return cls
    if not explicit_hash:
        cls.__hash__ = _hash(_values([f.name for f in fields if (f.compare if f.hash is None else f.hash)]))
    cls.__setattr__, cls.__delattr__ = _frozen_setters(cls, names)
    return cls


def _values(names: list[str]):
    """self -> the tuple of these attributes."""
    if not names:
        return lambda self: ()
    if len(names) == 1:
        get = attrgetter(names[0])
        return lambda self: (get(self),)
    return attrgetter(*names)


def _init(cls, fields):
    qualname = cls.__qualname__
    setter = object.__setattr__
    positional = tuple(f.name for f in fields if f.init and not f.kw_only)
    accepted = frozenset(f.name for f in fields if f.init)
    # (name, given by the caller, default, factory) in field order, as dataclass's __init__
    # sets them; a field with init=False gets its default or factory, or nothing
    plan = tuple((f.name, f.init, f.default, f.default_factory) for f in fields)
    post_init = hasattr(cls, "__post_init__")
    defaulted = False
    for f in fields:  # (dataclass's own check, made where it writes __init__)
        if f.init and not f.kw_only:
            if f.default is not MISSING or f.default_factory is not MISSING:
                defaulted = True
            elif defaulted:
                raise TypeError(f"non-default argument {f.name!r} follows default argument")

    def __init__(self, *args, **kwargs):
        if len(args) > len(positional):
            raise TypeError(f"{qualname}.__init__() takes {len(positional) + 1} positional arguments "
                            f"but {len(args) + 1} were given")
        given = dict(zip(positional, args))
        for key, value in kwargs.items():
            if key not in accepted:
                raise TypeError(f"{qualname}.__init__() got an unexpected keyword argument {key!r}")
            if key in given:
                raise TypeError(f"{qualname}.__init__() got multiple values for argument {key!r}")
            given[key] = value
        for name, init, default, factory in plan:
            if init and name in given:
                setter(self, name, given[name])
            elif default is not MISSING:
                setter(self, name, default)
            elif factory is not MISSING:
                setter(self, name, factory())
            elif init:
                raise TypeError(f"{qualname}.__init__() missing 1 required argument: {name!r}")
        if post_init:
            self.__post_init__()

    __init__.__qualname__ = f"{qualname}.__init__"
    return __init__


def _repr(names: list[str]):
    def __repr__(self):
        inner = ", ".join(f"{name}={getattr(self, name)!r}" for name in names)
        return f"{self.__class__.__qualname__}({inner})"
    return __repr__


def _eq(values):
    def __eq__(self, other):
        if other.__class__ is self.__class__:
            return values(self) == values(other)
        return NotImplemented
    return __eq__


def _hash(values):
    def __hash__(self):
        return hash(values(self))
    return __hash__


def _frozen_setters(cls, names: tuple[str, ...]):
    def __setattr__(self, name, value):
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self, name):
        if type(self) is cls or name in names:
            raise FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    return __setattr__, __delattr__
