"""Shared fixtures of the libvsgl binding tests.

The binding is imported the way the tests of the add-on do it
(``addon/vsgl_indirect`` on sys.path). The library is the one the binding
finds ($VSGL_LIBRARY, else build/libvsgl.so); build it with ``make``.
Tests of functions the library does not export yet are skipped with the
symbol's name, so the suite gets stricter as the C code lands.
"""

import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
ADDON = os.path.join(REPO, "addon", "vsgl_indirect")
for p in (ADDON, HERE):
    if p not in sys.path:
        sys.path.insert(0, p)

import libvsgl  # noqa: E402


@pytest.fixture(scope="session")
def lib():
    try:
        return libvsgl.library()
    except libvsgl.VsglLibraryError as e:
        pytest.skip("libvsgl not loadable (test_library.py reports why): %s" % e)


def require(lib, *names):
    """Skip the calling test unless every symbol is exported."""
    missing = [n for n in names if not lib.has(n)]
    if missing:
        pytest.skip("not implemented in libvsgl yet: %s" % ", ".join(missing))


def require_complete(lib):
    """Skip unless the library has no undefined vsgl_ references (calls into
    the pipeline of an incomplete build would abort the process)."""
    if lib.undefined:
        pytest.skip("libvsgl build is incomplete (undefined: %s)" % ", ".join(lib.undefined))


@pytest.fixture
def rng(request):
    """A generator seeded from the test's name: reproducible and independent."""
    seed = sum(map(ord, request.node.name)) * 7919 + 12345
    return np.random.default_rng(seed)


@pytest.fixture
def ctx(lib):
    with libvsgl.Context(thread_count=2) as c:
        yield c
