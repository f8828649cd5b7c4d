"""mech.frozen against the standard library's frozen dataclass, class for class (and
mech.frozen.record against the standard mutable dataclass).

Each case is declared twice, once with ``dataclasses.dataclass(frozen=True)`` and once with
``mech.frozen.frozen``, and the two must behave the same: construction (positional,
keyword, defaults, factories, keyword-only fields, init=False fields, __post_init__),
the errors a bad call raises, repr, equality, hashing, frozenness, fields, replace, asdict,
pickling and copying, subclassing, and a class's own __eq__/__repr__/__hash__ kept.
"""

from __future__ import annotations

import copy
import dataclasses
import pickle
from dataclasses import field

import pytest

from mech.frozen import frozen, record


def _declare(decorate, name):
    class Base:
        x: float
        y: int = 2
        tags: list = field(default_factory=list, compare=False)
        note: str = field(default="n", repr=False)
        derived: float = field(init=False, default=0.0)
        counter: int = field(init=False, default_factory=lambda: 7, hash=False)

        def __post_init__(self):
            if self.x < 0.0:
                raise ValueError(f"x = {self.x!r}: must be >= 0")
            object.__setattr__(self, "derived", 2.0 * self.x)

    Base.__name__ = Base.__qualname__ = name
    return decorate(Base)


StdBase = _declare(dataclasses.dataclass(frozen=True), "StdBase")
OurBase = _declare(frozen, "OurBase")


@dataclasses.dataclass(frozen=True)
class StdChild(StdBase):
    z: tuple = (1, 2)


@frozen
class OurChild(OurBase):
    z: tuple = (1, 2)


def _keyword_only(decorate, name):
    class Kw:
        a: int
        b: int = 3

    Kw.__name__ = Kw.__qualname__ = name
    return decorate(Kw)


def _own_methods(decorate, name):
    class Own:
        a: int

        def __eq__(self, other):
            return isinstance(other, type(self)) and abs(self.a - other.a) <= 1

        def __repr__(self):
            return "own"

    Own.__name__ = Own.__qualname__ = name
    return decorate(Own)


StdKw = _keyword_only(dataclasses.dataclass(frozen=True, kw_only=True), "StdKw")
OurKw = _keyword_only(frozen(kw_only=True), "OurKw")
StdOwn = _own_methods(dataclasses.dataclass(frozen=True), "StdOwn")
OurOwn = _own_methods(frozen, "OurOwn")


def _outcome(call):
    """(the result's class name without its Std/Our prefix, None) or (exception type, None)."""
    try:
        value = call()
    except Exception as exc:  # noqa: BLE001 -- the exception's type is what is compared
        return type(exc), None
    return type(value).__name__.replace("Std", "").replace("Our", ""), None


CALLS = [
    ((1.5,), {}),
    ((1.5, 4), {}),
    ((1.5,), {"y": 4, "tags": [1], "note": "m"}),
    ((), {"x": 0.0}),
    ((), {}),  # missing x
    ((1.0, 2, [], "s", 9), {}),  # too many positional
    ((1.0,), {"x": 2.0}),  # twice
    ((1.0,), {"derived": 3.0}),  # not an init field
    ((1.0,), {"nope": 1}),
    ((-1.0,), {}),  # __post_init__'s ValueError
]


@pytest.mark.parametrize("kind", ["frozen", "record"])
@pytest.mark.parametrize("args, kwargs", CALLS)
def test_construction_matches_the_standard_dataclass(args, kwargs, kind):
    Std, Our = (StdBase, OurBase) if kind == "frozen" else (StdRecord, OurRecord)
    assert _outcome(lambda: Our(*args, **kwargs)) == _outcome(lambda: Std(*args, **kwargs))
    try:
        std = Std(*args, **kwargs)
    except Exception:  # noqa: BLE001
        return
    ours = Our(*args, **kwargs)
    assert dataclasses.asdict(ours) == dataclasses.asdict(std)
    assert repr(ours).replace("Our", "Std") == repr(std)


def test_equality_hash_and_fields():
    a, b = OurBase(1.0, 2, [1]), OurBase(1.0, 2, [2])  # tags do not compare
    sa, sb = StdBase(1.0, 2, [1]), StdBase(1.0, 2, [2])
    assert (a == b) == (sa == sb) is True
    assert (OurBase(1.0) == OurBase(2.0)) == (StdBase(1.0) == StdBase(2.0)) is False
    assert (a == sa) is False and a.__eq__(sa) is NotImplemented  # another class: not equal
    # the hash covers the compared fields (not tags, not counter): equal objects hash alike
    assert hash(a) == hash(b)
    assert hash(OurBase(1.0, 5)) != hash(OurBase(1.0, 6))  # (ints hash to themselves)
    assert [f.name for f in dataclasses.fields(OurBase)] == [f.name for f in dataclasses.fields(StdBase)]
    assert OurBase.__match_args__ == StdBase.__match_args__
    assert dataclasses.replace(a, y=9) == OurBase(1.0, 9)
    assert dataclasses.replace(a, x=3.0).derived == 6.0  # __post_init__ runs again
    with pytest.raises(ValueError):
        dataclasses.replace(a, derived=1.0)  # init=False: as for the standard class


def test_frozen():
    a = OurBase(1.0)
    for action in (lambda: setattr(a, "x", 2.0), lambda: setattr(a, "other", 1), lambda: delattr(a, "x")):
        with pytest.raises(dataclasses.FrozenInstanceError):
            action()
    assert a.x == 1.0
    with pytest.raises(TypeError):
        frozen(type("Bad", (), {"__annotations__": {"a": "int"}, "__setattr__": lambda s, n, v: None}))


def test_pickle_copy_and_subclass():
    a = OurChild(1.0, 3, [1], "m", (5,))
    assert pickle.loads(pickle.dumps(a)) == a
    assert copy.deepcopy(a) == a and copy.copy(a) == a
    assert repr(a).replace("Our", "Std") == repr(StdChild(1.0, 3, [1], "m", (5,)))
    assert a != OurBase(1.0, 3)  # another class
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.z = ()


def test_keyword_only_and_own_methods():
    assert _outcome(lambda: OurKw(1)) == _outcome(lambda: StdKw(1))
    assert OurKw(a=1) == OurKw(a=1, b=3) and repr(OurKw(a=1)) == repr(StdKw(a=1)).replace("Std", "Our")
    # a class's own __eq__ and __repr__ stay; its hash is then the fields' (as dataclass does)
    assert OurOwn(1) == OurOwn(2) and repr(OurOwn(1)) == "own"
    assert hash(OurOwn(4)) == hash(StdOwn(4)) == hash((4,))


def test_field_order_is_checked():
    with pytest.raises(TypeError):
        frozen(type("Order", (), {"__annotations__": {"a": "int", "b": "int"}, "a": 1}))


StdRecord = _declare(dataclasses.dataclass, "StdRecord")
OurRecord = _declare(record, "OurRecord")
StdRecordOwn = _own_methods(dataclasses.dataclass, "StdRecordOwn")
OurRecordOwn = _own_methods(record, "OurRecordOwn")


@record
class OurRecordChild(OurRecord):
    z: tuple = (1, 2)


def test_a_record_may_be_assigned_and_is_unhashable_as_the_standard_one():
    a, std = OurRecord(1.0, 2, [1]), StdRecord(1.0, 2, [1])
    a.x, std.x = 3.0, 3.0
    a.extra = "kept"
    assert a.x == 3.0 and a.extra == "kept" and dataclasses.asdict(a) == dataclasses.asdict(std)
    del a.extra
    b = OurRecord(1.0, 2, [5])
    b.x = 3.0
    assert a == b and (a == std) is False  # tags do not compare; another class
    assert OurRecord.__hash__ is StdRecord.__hash__ is None
    with pytest.raises(TypeError):
        hash(a)
    assert [f.name for f in dataclasses.fields(OurRecord)] == [f.name for f in dataclasses.fields(StdRecord)]
    assert OurRecord.__match_args__ == StdRecord.__match_args__
    assert dataclasses.replace(a, x=4.0).derived == 8.0
    child = OurRecordChild(1.0, 3, [1], "m", (5,))
    child.z = ()
    assert pickle.loads(pickle.dumps(child)) == child and copy.deepcopy(child) == child
    # a class's own __eq__ and __repr__ stay; it is unhashable, as the standard one
    assert OurRecordOwn(1) == OurRecordOwn(2) and repr(OurRecordOwn(1)) == "own"
    assert OurRecordOwn.__hash__ is StdRecordOwn.__hash__ is None
