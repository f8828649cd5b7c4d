"""Shared test fixtures."""

from __future__ import annotations

import os
import signal

import pytest

# The suite solves the finite-element eigenproblems every time (mech.eigen_cache keeps their
# solutions between runs): its tests of the modes test the solver, not a stored answer; the
# cache's own tests turn it on
os.environ["SWITCHSIM_EIGEN_CACHE"] = "0"


@pytest.fixture
def sigint_raises():
    """SIGINT raises KeyboardInterrupt in this process for the test, as in an interactive
    shell. A suite started from a non-interactive shell's background job (``make test &``,
    nohup) inherits SIGINT ignored, and Python then neither raises on it nor lets
    ``_thread.interrupt_main`` deliver it; the Ctrl-C tests would fail for that reason alone."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)

