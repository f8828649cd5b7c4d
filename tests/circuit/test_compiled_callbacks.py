"""The compiled ngspice callbacks (circuit/callbacks.c, circuit/compiled_callbacks.py): their
build, its fallback, and the declarations Python reads the library with.

The behaviour of the callbacks themselves -- both routes giving the same waveforms to the
bit -- is tested in test_compiled_callbacks_runs.py.
"""

from __future__ import annotations

import pytest

from circuit import compiled_callbacks
from circuit._callbacks_ffi import ffi


@pytest.fixture
def fresh(monkeypatch):
    """No library loaded yet in this process (as at a start), the Python route not forced."""
    monkeypatch.setattr(compiled_callbacks, "_LOADED", {})
    monkeypatch.delenv(compiled_callbacks.FORCE_PYTHON, raising=False)


def test_the_library_builds_into_its_folder_and_loads(tmp_path, fresh):
    library = compiled_callbacks.load(tmp_path)
    assert library is not None
    folder = compiled_callbacks.library_folder(tmp_path)
    assert (folder / compiled_callbacks.LIBRARY).is_file()
    assert compiled_callbacks.load(tmp_path) is library  # loaded once per process


def test_the_declarations_match_the_compiled_structures(tmp_path, fresh):
    """A field declared at another offset than the compiler put it would be read wrong, silently."""
    library = compiled_callbacks.load(tmp_path)
    out = ffi.new("long[]", 64)
    count = library.sw_layout(out, 64)
    expected = [ffi.sizeof("sw_channel"), ffi.sizeof("sw_arc"), ffi.sizeof("sw_state")]
    expected += [ffi.offsetof(struct, field) for struct, field in compiled_callbacks.LAYOUT]
    assert list(out[0:count]) == expected


def test_the_generated_module_holds_the_declarations(tmp_path):
    """Fails when DECLARATIONS was edited without `python -m circuit.compiled_callbacks`."""
    pytest.importorskip("pycparser")
    import importlib.util

    path = compiled_callbacks.write_module(tmp_path / "regenerated.py")
    spec = importlib.util.spec_from_file_location("regenerated", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for struct in ("sw_channel", "sw_arc", "sw_state"):
        assert module.ffi.sizeof(struct) == ffi.sizeof(struct)
        fresh = [(name, f.offset, module.ffi.getctype(f.type)) for name, f in module.ffi.typeof(struct).fields]
        kept = [(name, f.offset, ffi.getctype(f.type)) for name, f in ffi.typeof(struct).fields]
        assert fresh == kept, struct


def test_a_failed_build_falls_back_to_the_python_callbacks_and_says_why_once(tmp_path, fresh, monkeypatch, capsys):
    monkeypatch.setenv("CC", "/bin/false")
    assert compiled_callbacks.load(tmp_path) is None
    said = capsys.readouterr().err
    assert "using the Python ngspice callbacks: their C build failed" in said
    folder = compiled_callbacks.library_folder(tmp_path)
    assert folder.with_name(folder.name + ".failed").is_file()
    assert compiled_callbacks.load(tmp_path) is None
    assert capsys.readouterr().err == ""  # said once per process
    monkeypatch.setattr(compiled_callbacks, "_LOADED", {})  # (another process)
    assert compiled_callbacks.load(tmp_path) is None
    assert "failed before" in capsys.readouterr().err


def test_a_missing_compiler_falls_back(tmp_path, fresh, monkeypatch, capsys):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    assert compiled_callbacks.load(tmp_path) is None
    assert "no C compiler" in capsys.readouterr().err


def test_the_python_route_can_be_forced(tmp_path, fresh, monkeypatch):
    monkeypatch.setenv(compiled_callbacks.FORCE_PYTHON, "1")
    assert compiled_callbacks.load(tmp_path) is None
    assert not compiled_callbacks.library_folder(tmp_path).exists()  # nothing built
