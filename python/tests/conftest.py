"""Shared fixtures of the tessera Python tests.

Run with Debian's /usr/bin/python3 (numpy, scipy, vtk, meshio from apt) and the
module on PYTHONPATH: ctest does both (test python.pytest); by hand,
``PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests``.
"""

import contextlib
import os
import signal
import threading

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _default_threads_env(monkeypatch):
    """Tests choose their thread counts; a TESSERA_NUM_THREADS set in the
    caller's shell must not change them."""
    monkeypatch.delenv("TESSERA_NUM_THREADS", raising=False)


@contextlib.contextmanager
def sigint_after(delay, handler):
    """SIGINT to this process `delay` seconds in, with `handler` installed for
    the block (a custom one in the tests, so that a signal arriving late could
    never stop the whole session); both undone after it."""
    old = signal.signal(signal.SIGINT, handler)
    timer = threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT))
    try:
        timer.start()
        yield
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, old)


def random_points(n, dim, seed=0):
    """n uniform points in the unit square/cube (general position)."""
    return np.random.default_rng(seed).random((n, dim))


UNIT_BOX = {2: (0.0, 1.0, 0.0, 1.0), 3: (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)}
