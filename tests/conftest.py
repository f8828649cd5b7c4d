"""Shared test fixtures."""

from __future__ import annotations

import signal

import pytest


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

