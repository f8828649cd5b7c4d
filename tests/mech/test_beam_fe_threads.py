"""The held bar's FE modes, and so a whole run, do not depend on the BLAS thread count.

Threaded BLAS kernels sum in another order than the serial ones; the FE eigenproblem's
modes then differed in their last digits between a process with one BLAS thread (the
command line sets it) and one with the machine's default, and a run's bounce times moved
by 2e-10 s and its macro step count by 3. The eigenproblem now runs on one thread whatever
the process's setting: the same machine must give the same bits. (Across machines or BLAS
builds the last digits may differ; this compares one machine with itself.)
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PROBE = """
import hashlib, numpy as np
from mech.beam_fe import FEBeam, beam_basis
beam = FEBeam(length=0.015, youngs_modulus=128e9, density=8250.0, area=9e-7, i22=6.75e-13, i33=6.75e-15,
              support="clamp", support_position=0.015)
modes = beam_basis(beam, 3, 30, elements=255)
h = hashlib.sha256()
for m in modes:
    h.update(np.ascontiguousarray(m.frequencies).tobytes()); h.update(np.ascontiguousarray(m.coefficients).tobytes())
print(h.hexdigest())
"""


def digest(threads: str) -> str:
    env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-1]


def test_the_fe_modes_are_the_same_bits_on_one_and_on_four_blas_threads():
    assert digest("1") == digest("4")
