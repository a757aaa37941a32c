"""Loading the library: lookup order, version check, clear errors, lazily
bound symbols."""

import ctypes
import re
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

import libvsgl
from conftest import ADDON, REPO

CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")


def test_library_loads_and_version_matches():
    lib = libvsgl.library()  # fails (not skips) if the library is missing or mismatched
    assert lib.version[:2] == libvsgl.BINDING_VERSION, lib.version
    assert libvsgl.version_string() == "%d.%d.%d" % lib.version
    assert os.path.isfile(lib.path)
    assert libvsgl.library() is lib, "the library must be loaded once"


def test_result_strings(lib):
    assert libvsgl.result_string(0) == "success"
    assert libvsgl.result_string(libvsgl.Result.ERROR_INVALID_ARGUMENT) == "invalid argument"
    assert libvsgl.result_string(12345) == "unknown result code"
    assert libvsgl.result_string(-1) == "unknown result code"


def _run(code, env_extra, cwd=None):
    env = dict(os.environ)
    env.pop("VSGL_LIBRARY", None)
    env.update(env_extra)
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, env=env, cwd=cwd or REPO)


def test_env_override_bogus_path_gives_clear_error(tmp_path):
    bogus = str(tmp_path / "nowhere" / "libvsgl.so")
    r = _run("""
        import sys; sys.path.insert(0, %r)
        import libvsgl
        try:
            libvsgl.version()
        except libvsgl.VsglLibraryError as e:
            print("ERROR:", e)
        """ % ADDON, {"VSGL_LIBRARY": bogus})
    assert r.returncode == 0, r.stderr
    assert "ERROR:" in r.stdout, r.stdout
    assert bogus in r.stdout and "make" in r.stdout, r.stdout


def test_import_never_loads_the_library():
    # the add-on must be importable (to show an error in its panel) without a library
    r = _run("""
        import sys; sys.path.insert(0, %r)
        import libvsgl
        print(libvsgl._lib is None)
        """ % ADDON, {"VSGL_LIBRARY": "/nonexistent/libvsgl.so"})
    assert r.returncode == 0 and r.stdout.strip() == "True", (r.stdout, r.stderr)


def test_env_override_is_used(lib, tmp_path):
    copy = tmp_path / "copy_of_libvsgl.so"
    shutil.copy(lib.path, copy)
    r = _run("""
        import sys; sys.path.insert(0, %r)
        import libvsgl
        print(libvsgl.library().path)
        """ % ADDON, {"VSGL_LIBRARY": str(copy)})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(copy)


def test_library_beside_module_is_preferred(lib, tmp_path):
    # the layout of an installed add-on: libvsgl.py with lib/libvsgl.so
    # (a libvsgl.so right beside libvsgl.py would shadow the module on import)
    for f in ("libvsgl.py", "_libvsgl_abi.py", "_libvsgl_struct.py"):  # the binding, its ABI mirror
        shutil.copy(os.path.join(ADDON, f), tmp_path / f)
    (tmp_path / "lib").mkdir()
    shutil.copy(lib.path, tmp_path / "lib" / "libvsgl.so")
    r = _run("""
        import sys; sys.path.insert(0, %r)
        import libvsgl
        print(libvsgl.library().path)
        """ % str(tmp_path), {})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(tmp_path / "lib" / "libvsgl.so")


def test_missing_library_message_says_make(tmp_path):
    for f in ("libvsgl.py", "_libvsgl_abi.py", "_libvsgl_struct.py"):  # the binding, its ABI mirror
        shutil.copy(os.path.join(ADDON, f), tmp_path / f)
    r = _run("""
        import sys; sys.path.insert(0, %r)
        import libvsgl
        try:
            libvsgl.library()
        except libvsgl.VsglLibraryError as e:
            print("ERROR:", e)
        """ % str(tmp_path), {})
    assert "ERROR:" in r.stdout and "make" in r.stdout and "VSGL_LIBRARY" in r.stdout, r.stdout


def _fake_library(tmp_path, version):
    """A tiny shared library exporting only vsgl_version (and result strings)."""
    if CC is None:
        pytest.fail("no C compiler to build a fake library (the build needs one)")
    src = tmp_path / "fake.c"
    src.write_text(textwrap.dedent("""
        #include <stdint.h>
        int32_t vsgl_version(void) { return %d; }
        const char *vsgl_version_string(void) { return "fake"; }
        const char *vsgl_result_string(int32_t c) { (void)c; return "fake result"; }
        """ % version))
    so = tmp_path / ("libfake%d.so" % version)
    subprocess.run([CC, "-shared", "-fPIC", str(src), "-o", str(so)], check=True)
    return str(so)


def test_version_mismatch_names_both_versions(tmp_path):
    so = _fake_library(tmp_path, 9 * 10000 + 7 * 100 + 3)
    with pytest.raises(libvsgl.VsglLibraryError) as e:
        libvsgl.load_library(so)
    msg = str(e.value)
    assert so in msg and "9.7.3" in msg and "%d.%d" % libvsgl.BINDING_VERSION in msg, msg
    assert "make" in msg, msg


def test_a_library_lacking_functions_is_refused_naming_them(tmp_path):
    """A libvsgl of the right version that lacks bound functions (built from
    another checkout) is a load error that names them, not a later crash."""
    maj, mnr = libvsgl.BINDING_VERSION
    so = _fake_library(tmp_path, maj * 10000 + mnr * 100 + 9)
    with pytest.raises(libvsgl.VsglLibraryError) as e:
        libvsgl.load_library(so)
    msg = str(e.value)
    assert so in msg and "vsgl_sg_integral" in msg and "vsgl_render" in msg and "make" in msg, msg


def test_not_a_library_gives_clear_error(tmp_path):
    junk = tmp_path / "libvsgl.so"
    junk.write_bytes(b"not an ELF file")
    with pytest.raises(libvsgl.VsglLibraryError) as e:
        libvsgl.load_library(str(junk))
    assert str(junk) in str(e.value)


def test_missing_dependency_names_it_and_its_package(tmp_path):
    """Issue 10: a libvsgl whose dependency is absent gave 'cannot load ...
    (rebuild it with `make`)', which a zip user cannot do. The message names
    the missing library and the package that provides it."""
    if CC is None:
        pytest.fail("no C compiler (the build needs one)")
    dep, user = tmp_path / "dep.c", tmp_path / "user.c"
    dep.write_text("int vsgl_test_dep(void) { return 1; }\n")
    user.write_text("int vsgl_test_dep(void);\nint vsgl_version(void) { return vsgl_test_dep(); }\n")
    so_dep = tmp_path / "libvsgl_test_dep.so.1"
    subprocess.run([CC, "-shared", "-fPIC", str(dep), "-o", str(so_dep), "-Wl,-soname,libvsgl_test_dep.so.1"],
                   check=True)
    so = tmp_path / "libvsgl.so"
    subprocess.run([CC, "-shared", "-fPIC", str(user), "-o", str(so), str(so_dep)], check=True)
    os.unlink(str(so_dep))
    with pytest.raises(libvsgl.VsglLibraryError) as e:
        libvsgl.load_library(str(so))
    msg = str(e.value)
    assert "it needs libvsgl_test_dep.so.1, which is not installed" in msg, msg
    # the sonames libvsgl really needs map to their Debian packages
    for soname, pkg in (("libembree3.so.3", "libembree3-3"), ("libtbb.so.12", "libtbb12"),
                        ("libOpenEXRCore-3_1.so.30", "libopenexr-3-1-30"), ("libdeflate.so.0", "libdeflate0")):
        m = libvsgl.load_error_message("/x/libvsgl.so", "%s: cannot open shared object file: "
                                       "No such file or directory" % soname)
        assert ("it needs %s" % soname) in m and ("apt-get install %s" % pkg) in m, m
    # inside the add-on (lib/ beside libvsgl.py) the fix is the zip, not `make`
    inside = os.path.join(os.path.dirname(os.path.abspath(libvsgl.__file__)), "lib", "libvsgl.so")
    m = libvsgl.load_error_message(inside, "libtbb.so.12: cannot open shared object file: x")
    assert "make" not in m and "vsgl_indirect/lib/" in m, m


def test_argtypes_are_set_once_on_load(lib):
    # every exported prototype carries its types; ctypes rejects wrong arguments
    for name, restype, argtypes in libvsgl.PROTOTYPES:
        if lib.has(name):
            fn = getattr(lib, name)
            assert fn.argtypes == argtypes and fn.restype == restype, name
    if lib.has("vsgl_sg_integral"):
        with pytest.raises(ctypes.ArgumentError):
            lib.vsgl_sg_integral("not a float")


def test_binding_does_not_import_bpy_or_use_star_imports():
    src = open(os.path.join(ADDON, "libvsgl.py")).read()
    assert "import bpy" not in src and "from ctypes import *" not in src
    # one relative import, of the generated ABI, taken only inside the add-on package
    relative = re.findall(r"^\s*from \.(\w*) import", src, re.M)
    assert set(relative) <= {"_libvsgl_abi", "_libvsgl_struct"}, "relative imports: the tests import it directly"
