"""ngspice's declarations (circuit/ngspice_api.py) against an independent copy of the header,
and the pre-parsed module a run loads against the declarations.

A wrong field offset in ``vector_info`` or a wrong callback signature would not fail
loudly: ngspice would read or write the wrong bytes. Two routes are compared here:
PySpice's copy of sharedspice.h (api.h, parsed by cffi's C parser) against switchsim's
declarations, and the generated out-of-line module (circuit/_ngspice_ffi.py, what a run
uses) against the same declarations parsed afresh, each with the same loaded library.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pycparser")
from cffi import FFI  # noqa: E402  (in-line mode: the C parser, only in this test)

from circuit import ngspice_api  # noqa: E402
from circuit._ngspice_ffi import ffi as generated  # noqa: E402
from circuit.ngspice import find_library  # noqa: E402

STRUCTS = {"ngcomplex_t": ("cx_real", "cx_imag"),
           "vector_info": ("v_name", "v_type", "v_flags", "v_realdata", "v_compdata", "v_length")}
#: ngSpice_Init's SendData and SendInitData arguments: always NULL in switchsim, declared void *
OPAQUE_ARGUMENTS = {("ngSpice_Init", 3), ("ngSpice_Init", 4)}


def _inline(text: str) -> FFI:
    ffi = FFI()
    ffi.cdef(text)
    return ffi


def _layout(ffi, struct: str) -> list[tuple]:
    fields = dict(ffi.typeof(struct).fields)
    return [ffi.sizeof(struct)] + [(name, ffi.offsetof(struct, name), fields[name].type.kind,
                                    ffi.sizeof(fields[name].type)) for name in STRUCTS[struct]]


def _signature(ffi, lib, name: str) -> tuple:
    kind = ffi.typeof(getattr(lib, name))
    return kind.result, kind.args, kind.ellipsis


def _canonical(ffi, kind) -> str:
    """A ctype's C spelling, comparable between two FFI instances (each has its own ctype
    objects); the out-of-line module spells a typedef'd struct "struct vector_info", the
    in-line parser "vector_info" (the same struct: its layout is compared field by field)."""
    return ffi.getctype(kind).replace("struct ", "")


def test_the_declarations_match_pyspices_copy_of_the_ngspice_header():
    import PySpice.Spice.NgSpice.Shared as shared

    header = _inline(Path(shared.__file__).with_name("api.h").read_text())
    ours = _inline(ngspice_api.DECLARATIONS)
    for struct in STRUCTS:
        assert _layout(ours, struct) == _layout(header, struct), struct
    library = find_library()
    lib_header, lib_ours = header.dlopen(library), ours.dlopen(library)
    for name in ngspice_api.FUNCTIONS:
        result_h, args_h, ellipsis_h = _signature(header, lib_header, name)
        result_o, args_o, ellipsis_o = _signature(ours, lib_ours, name)
        assert _canonical(ours, result_o) == _canonical(header, result_h), name
        assert ellipsis_o == ellipsis_h and len(args_o) == len(args_h), name
        for i, (a_o, a_h) in enumerate(zip(args_o, args_h)):
            if (name, i) in OPAQUE_ARGUMENTS:
                assert _canonical(ours, a_o) == "void *" and a_h.kind == "function", (name, i)
            else:
                assert _canonical(ours, a_o) == _canonical(header, a_h), (name, i)


def test_the_generated_module_holds_the_declarations():
    """Fails when DECLARATIONS was edited without `python -m circuit.ngspice_api`."""
    fresh = _inline(ngspice_api.DECLARATIONS)
    for struct in STRUCTS:
        assert _layout(generated, struct) == _layout(fresh, struct), struct
    library = find_library()
    lib_generated, lib_fresh = generated.dlopen(library), fresh.dlopen(library)
    assert sorted(dir(lib_generated)) == sorted(ngspice_api.FUNCTIONS)
    for name in ngspice_api.FUNCTIONS:
        g, f = _signature(generated, lib_generated, name), _signature(fresh, lib_fresh, name)
        assert _canonical(generated, g[0]) == _canonical(fresh, f[0]), name
        assert [_canonical(generated, a) for a in g[1]] == [_canonical(fresh, a) for a in f[1]], name
        assert g[2] == f[2], name


def test_write_module_writes_a_module_that_loads_the_same_declarations(tmp_path):
    import importlib.util

    path = ngspice_api.write_module(tmp_path / "regenerated.py")
    spec = importlib.util.spec_from_file_location("regenerated", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for struct in STRUCTS:
        assert _layout(module.ffi, struct) == _layout(generated, struct), struct


def test_pyspices_own_simulator_started_after_the_session_is_refused_at_the_next_load():
    """PySpice's NgSpiceShared loads the same library and replaces the session's callbacks
    (its ngSpice_Init): switchsim's next circuit must say so instead of running without
    its input channels. In a child process: this one's ngspice stays as it is."""
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        from circuit import find_library, get_session
        from circuit.errors import SessionBusyError
        session = get_session()
        deck = ["* t", "R1 1 0 1", "V1 1 0 1", ".end"]
        session.load(deck)  # fine while switchsim alone holds ngspice
        from PySpice.Spice.NgSpice.Shared import NgSpiceShared
        NgSpiceShared.LIBRARY_PATH = find_library()
        NgSpiceShared.new_instance()
        try:
            session.load(deck)
        except SessionBusyError as err:
            print("refused:", err)
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "refused: PySpice's own simulator has started ngspice" in done.stdout
