"""The binding's ABI mirror (addon/vsgl_indirect/_libvsgl_abi.py) is what
tools/gen_abi.py makes of the headers today, and the C compiler agrees with
it: sizeof/alignment/offsetof of every struct and field and the value of
every #define, printed by a compiled C program."""

import ctypes
import os
import shutil
import subprocess

import pytest

import gen_abi
import header_parse
import libvsgl

CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")


def test_generated_abi_is_current():
    with open(gen_abi.OUTPUT) as f:
        current = f.read()
    assert current == gen_abi.generate(), (
        "addon/vsgl_indirect/_libvsgl_abi.py is not what tools/gen_abi.py makes of the headers: run `make abi`")


def _c_name(field):
    return libvsgl.FIELD_C_NAMES.get(field, field)


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    if CC is None:
        pytest.fail("no C compiler (cc/gcc/clang) to measure the C layout (the build needs one)")
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "vsgl.h"']
    for h in header_parse.headers():
        lines.append('#include "vsgl/%s"' % os.path.basename(h))
    lines.append("int main(void) {")
    for name, cls in libvsgl.STRUCTS.items():
        lines.append('printf("%s %%zu %%zu\\n", sizeof(%s), _Alignof(%s));' % (name, name, name))
        for field, _ in cls._fields_:
            c = _c_name(field)
            lines.append('printf("%s.%s %%zu %%zu\\n", offsetof(%s, %s), sizeof(((%s *)0)->%s));'
                         % (name, field, name, c, name, c))
    for define, _, _, _ in header_parse.define_list():
        lines.append('printf("#%s %%.17g 0\\n", (double)(%s));' % (define, define))
    lines += ["return 0;", "}"]
    d = tmp_path_factory.mktemp("layout")
    src, exe = d / "layout.c", d / "layout"
    src.write_text("\n".join(lines) + "\n")
    r = subprocess.run([CC, "-std=c11", "-I", header_parse.INCLUDE, str(src), "-o", str(exe)],
                       capture_output=True, text=True)
    assert r.returncode == 0, ("a Python field does not exist in C (or a header does not "
                               "compile):\n" + r.stderr)
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    res = {}
    for line in out.splitlines():
        key, a, b = line.split()
        res[key] = (float(a), 0) if key.startswith("#") else (int(a), int(b))
    return res


@pytest.mark.parametrize("name", sorted(libvsgl.STRUCTS))
def test_struct_size_and_offsets_match_c(name, c_layout):
    cls = libvsgl.STRUCTS[name]
    size, align = c_layout[name]
    assert ctypes.sizeof(cls) == size, "%s: ctypes sizeof %d, C sizeof %d" % (
        name, ctypes.sizeof(cls), size)
    assert ctypes.alignment(cls) == align, "%s: alignment %d vs C %d" % (
        name, ctypes.alignment(cls), align)
    for field, ftype in cls._fields_:
        off, fsize = c_layout["%s.%s" % (name, field)]
        assert getattr(cls, field).offset == off, "%s.%s: offset %d, C %d" % (
            name, field, getattr(cls, field).offset, off)
        assert ctypes.sizeof(ftype) == fsize, "%s.%s: size %d, C %d" % (
            name, field, ctypes.sizeof(ftype), fsize)


def test_every_header_struct_and_prototype_is_mirrored():
    assert sorted(header_parse.structs()) == sorted(libvsgl.STRUCTS)
    assert [p[0] for p in libvsgl.PROTOTYPES] == list(header_parse.prototypes())


def test_constants_have_the_c_compilers_values(c_layout):
    """Each #define's value in the binding (an enum member or a module
    constant) is the value the C compiler gives it."""
    enums, constants = gen_abi.classify_defines(header_parse.define_list())
    problems = []
    for cls_name, members in enums.items():
        cls = getattr(libvsgl, cls_name)
        for member, _, define in members:
            want = c_layout["#" + define][0]
            if int(cls[member]) != want:
                problems.append("%s: binding %s.%s = %d, C %r" % (define, cls_name, member, int(cls[member]), want))
    for name, _, define in constants:
        got, want = getattr(libvsgl, name), c_layout["#" + define][0]
        if abs(got - want) > 1e-6 * abs(want):
            problems.append("%s: binding %s = %r, C %r" % (define, name, got, want))
    assert not problems, "\n".join(problems)


def test_versions_match_header():
    d = header_parse.defines()
    assert libvsgl.BINDING_VERSION == (d["VSGL_VERSION_MAJOR"], d["VSGL_VERSION_MINOR"])
    assert len(libvsgl.Result) == d["VSGL_RESULT_COUNT"]
    assert libvsgl.BUNDLE_VERSION == (d["VSGL_BUNDLE_VERSION_MAJOR"], d["VSGL_BUNDLE_VERSION_MINOR"])
