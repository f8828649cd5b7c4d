"""The part of ngspice's shared-library API (sharedspice.h) that switchsim calls, and its cffi module.

switchsim talks to libngspice through cffi in its out-of-line ABI mode: the declarations
below are parsed once, by ``write_module``, into ``circuit/_ngspice_ffi.py`` (kept in
the repository), which holds them pre-parsed. A run then loads that module and the
library without cffi's C parser: PySpice's own ``NgSpiceShared`` declares its header in
cffi's in-line mode, which imports pycparser and parses the header and every callback
type at each start (~30 ms of every coupled run, benchmarks/bench_startup.py). PySpice
still builds the netlists (``PySpice.Spice.Netlist``).

The declarations are those of ngspice's sharedspice.h (ngspice 26 and later; the
synchronous-source and breakpoint calls since ngspice 26): the vector layout and the
callback signatures must match the library exactly. tests/circuit/test_ngspice_api.py
checks them against PySpice's copy of the header and the generated module against them.

Regenerate after editing ``DECLARATIONS``: ``python -m circuit.ngspice_api``.
"""

from __future__ import annotations

from pathlib import Path

#: Module name of the generated, pre-parsed declarations (cffi out-of-line ABI mode).
MODULE = "circuit._ngspice_ffi"

DECLARATIONS = """
typedef struct ngcomplex {
    double cx_real;
    double cx_imag;
} ngcomplex_t;

typedef struct vector_info {
    char *v_name;
    int v_type;
    short v_flags;
    double *v_realdata;
    ngcomplex_t *v_compdata;
    int v_length;
} vector_info, *pvector_info;

typedef struct vecvalues {
    char *name;
    double creal;
    double cimag;
    bool is_scale;
    bool is_complex;
} vecvalues, *pvecvalues;

typedef struct vecvaluesall {
    int veccount;
    int vecindex;
    pvecvalues *vecsa;
} vecvaluesall, *pvecvaluesall;

typedef int (SendChar) (char *, int, void *);
typedef int (SendStat) (char *, int, void *);
typedef int (ControlledExit) (int, bool, bool, int, void *);
typedef int (BGThreadRunning) (bool, int, void *);
typedef int (GetVSRCData) (double *, double, char *, int, void *);
typedef int (GetISRCData) (double *, double, char *, int, void *);
typedef int (GetSyncData) (double, double *, double, int, int, int, void *);

int ngSpice_Init(SendChar *, SendStat *, ControlledExit *, void *, void *, BGThreadRunning *, void *);
int ngSpice_Init_Sync(GetVSRCData *, GetISRCData *, GetSyncData *, int *, void *);
int ngSpice_Command(char *);
pvector_info ngGet_Vec_Info(char *);
int ngSpice_Circ(char **);
bool ngSpice_SetBkpt(double);
"""
# (ngSpice_Init's fourth and fifth arguments, the SendData and SendInitData callbacks, are
# declared as void *: switchsim passes its callbacks cast to void *. SendData marks where a
# pause falls, after each accepted point is stored; at the pause its vecvaluesall, the last
# point of every vector, gives a macro step's last values (NgspiceSession.last_values);
# the vectors themselves are read through ngGet_Vec_Info. SendInitData's structure is not read.)

#: Functions of ``DECLARATIONS`` (the test compares each with PySpice's header).
FUNCTIONS = ("ngSpice_Init", "ngSpice_Init_Sync", "ngSpice_Command", "ngGet_Vec_Info", "ngSpice_Circ",
             "ngSpice_SetBkpt")


def write_module(path: Path | None = None) -> Path:
    """Parse ``DECLARATIONS`` with cffi (this imports pycparser) and write the out-of-line
    module to ``path`` (default: circuit/_ngspice_ffi.py beside this file)."""
    from cffi import FFI

    builder = FFI()
    builder.cdef(DECLARATIONS)
    builder.set_source(MODULE, None)
    target = Path(path) if path is not None else Path(__file__).with_name(MODULE.rsplit(".", 1)[1] + ".py")
    builder.emit_python_code(str(target))
    return target


if __name__ == "__main__":
    print(write_module())
