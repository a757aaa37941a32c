"""Shared fixtures of the libvsgl binding tests.

The binding is imported the way the tests of the add-on do it
(``addon/vsgl_indirect`` on sys.path). The library is the one the binding
finds ($VSGL_LIBRARY, else build/libvsgl.so); build it with ``make``.
Nothing here skips: a missing symbol or an unloadable library fails
(tools/run_tests.sh fails the run on any skip of this suite).
"""

import os

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
ADDON = os.path.join(REPO, "addon", "vsgl_indirect")

import libvsgl  # noqa: E402  (addon/vsgl_indirect is on setup.cfg's pythonpath)


@pytest.fixture(scope="session")
def lib():
    try:
        return libvsgl.library()
    except libvsgl.VsglLibraryError as e:
        pytest.fail("libvsgl not loadable (test_library.py says why): %s" % e)


def require(lib, *names):
    """Every symbol a test calls must be exported (a missing one fails)."""
    missing = [n for n in names if not lib.has(n)]
    assert not missing, "libvsgl does not export: %s" % ", ".join(missing)


@pytest.fixture
def rng(request):
    """A generator seeded from the test's name: reproducible and independent."""
    seed = sum(map(ord, request.node.name)) * 7919 + 12345
    return np.random.default_rng(seed)


@pytest.fixture
def ctx(lib):
    with libvsgl.Context(thread_count=2) as c:
        yield c
