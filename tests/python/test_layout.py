"""The ctypes mirrors of the C structs and prototypes match the headers:
sizeof/offsetof of every field from a compiled C program, field names and
order parsed from the headers, and every prototype's types."""

import ctypes
import os
import shutil
import subprocess

import pytest

import header_parse
import libvsgl

CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc") or shutil.which("clang")


def _c_name(field):
    return libvsgl.FIELD_C_NAMES.get(field, field)


def _have(header):
    return header == "vsgl.h" or os.path.exists(os.path.join(header_parse.INCLUDE, "vsgl", header))


def _structs_to_check():
    return {n: c for n, c in libvsgl.STRUCTS.items() if _have(libvsgl.header_of(n))}


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    if CC is None:
        pytest.fail("no C compiler (cc/gcc/clang) to measure the C layout (the build needs one)")
    structs = _structs_to_check()
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "vsgl.h"']
    for h in header_parse.headers():
        lines.append('#include "vsgl/%s"' % os.path.basename(h))
    lines.append("int main(void) {")
    for name, cls in structs.items():
        lines.append('printf("%s %%zu %%zu\\n", sizeof(%s), _Alignof(%s));' % (name, name, name))
        for field, _ in cls._fields_:
            c = _c_name(field)
            lines.append('printf("%s.%s %%zu %%zu\\n", offsetof(%s, %s), sizeof(((%s *)0)->%s));'
                         % (name, field, name, c, name, c))
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
        res[key] = (int(a), int(b))
    return res


@pytest.mark.parametrize("name", sorted(libvsgl.STRUCTS))
def test_struct_size_and_offsets_match_c(name, c_layout):
    if name not in _structs_to_check():
        pytest.fail("%s: %s not present" % (name, libvsgl.header_of(name)))
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


def test_struct_fields_match_header_order():
    parsed = header_parse.structs()
    for name, cls in _structs_to_check().items():
        assert name in parsed, "%s not found in the headers" % name
        py = [_c_name(f) for f, _ in cls._fields_]
        assert py == parsed[name], "%s: binding fields %s, header fields %s" % (
            name, py, parsed[name])
    # every public struct of the headers is mirrored
    unmirrored = sorted(set(parsed) - set(libvsgl.STRUCTS))
    assert not unmirrored, "structs in the headers without a ctypes mirror: %s" % unmirrored


OPAQUE = {"vsgl_context", "vsgl_scene", "vsgl_bundle", "vsgl_render_cache"}
SCALARS = {"float": ctypes.c_float, "double": ctypes.c_double, "int32_t": ctypes.c_int32,
           "uint32_t": ctypes.c_uint32, "size_t": ctypes.c_size_t, "vsgl_result": ctypes.c_int32,
           "uint64_t": ctypes.c_uint64}


def _expected_ctype(text):
    """ctypes type of a C type text from a header."""
    t = text.replace("const", " ").split()
    stars = "".join(t).count("*")
    base = "".join(t).replace("*", "")
    if stars == 0:
        return None if base == "void" else SCALARS[base]
    if stars == 1 and base == "char":
        return ctypes.c_char_p
    if stars == 1 and (base == "void" or base in OPAQUE):
        return ctypes.c_void_p
    if stars == 2 and base in OPAQUE:
        return ctypes.POINTER(ctypes.c_void_p)
    if stars == 1 and base in libvsgl.STRUCTS:
        return ctypes.POINTER(libvsgl.STRUCTS[base])
    if stars == 1 and base in SCALARS:
        return ctypes.POINTER(SCALARS[base])
    raise AssertionError("test does not know the C type %r" % text)


def test_prototypes_match_headers():
    parsed = header_parse.prototypes()
    bound = {name: (res, args) for name, res, args in libvsgl.PROTOTYPES}
    problems = []
    for name, (hdr, ret, params) in sorted(parsed.items()):
        if name not in bound:
            problems.append("%s (%s) is not bound" % (name, hdr))
            continue
        res, args = bound[name]
        want_res = _expected_ctype(ret)
        if res is not want_res:
            problems.append("%s: restype %s, header says %s" % (name, res, ret))
        want = [_expected_ctype(p) for p in params]
        if list(args) != want:
            problems.append("%s: argtypes %s, header says %s" % (name, args, params))
    for name in bound:
        if name not in parsed:
            if not _have(libvsgl.header_of(name)):
                continue
            problems.append("%s is bound but no header declares it" % name)
    assert not problems, "\n".join(problems)


ENUM_PREFIXES = [
    ("VSGL_LOG_", "LogLevel"), ("VSGL_COSINE_", "CosineMode"), ("VSGL_NDF_", "NDF"),
    ("VSGL_LIGHT_", "LightType"), ("VSGL_AREA_", "AreaShape"), ("VSGL_CAMERA_", "CameraType"),
    ("VSGL_SENSOR_FIT_", "SensorFit"), ("VSGL_METHOD_", "Method"), ("VSGL_FIT_", "FitMode"),
    ("VSGL_GLOSSY_", "GlossyMode"), ("VSGL_VISIBILITY_", "Visibility"),
    ("VSGL_PRESET_", "Preset"), ("VSGL_LEAK_", "LeakCorrection"),
    ("VSGL_MERGE_", "SampleMerging"),
]
SPECIAL = {
    "VSGL_SHARPNESS_TOKSVIG": ("SharpnessEstimator", "TOKSVIG"),
    "VSGL_SHARPNESS_BANERJEE": ("SharpnessEstimator", "BANERJEE"),
    "VSGL_EXR_FLOAT": ("ExrPixelType", "FLOAT"), "VSGL_EXR_HALF": ("ExrPixelType", "HALF"),
    "VSGL_EXR_ZIP": ("ExrCompression", "ZIP"), "VSGL_EXR_NONE": ("ExrCompression", "NONE"),
    "VSGL_EXR_ZIPS": ("ExrCompression", "ZIPS"), "VSGL_EXR_PIZ": ("ExrCompression", "PIZ"),
    "VSGL_OK": ("Result", "OK"),
}
SCALAR_CONSTANTS = {"VSGL_SHARPNESS_MAX": "SHARPNESS_MAX", "VSGL_ALPHA_MIN": "ALPHA_MIN",
                    "VSGL_MATERIAL_UNSUPPORTED": "MATERIAL_UNSUPPORTED",
                    "VSGL_EXR_MAX_CHANNELS": "EXR_MAX_CHANNELS",
                    "VSGL_LIGHT_FLAG_BLENDER_4": "LIGHT_FLAG_BLENDER_4", "VSGL_LIGHT_FLAGS_KNOWN": "LIGHT_FLAGS_KNOWN",
                    "VSGL_MATERIAL_FLAG_BLENDER_4": "MATERIAL_FLAG_BLENDER_4",
                    "VSGL_MATERIAL_FLAGS_KNOWN": "MATERIAL_FLAGS_KNOWN",
                    "VSGL_MATERIAL_FLAG_MULTISCATTER": "MATERIAL_FLAG_MULTISCATTER",
                    "VSGL_AA_SAMPLES_MAX": "AA_SAMPLES_MAX", "VSGL_RSM_RESOLUTION_MIN": "RSM_RESOLUTION_MIN",
                    "VSGL_RSM_RESOLUTION_MAX": "RSM_RESOLUTION_MAX", "VSGL_VSGL_COUNT_MAX": "VSGL_COUNT_MAX",
                    "VSGL_FIS_ITERATIONS_MAX": "FIS_ITERATIONS_MAX", "VSGL_SHADE_STRIDE_MAX": "SHADE_STRIDE_MAX",
                    "VSGL_REUSED_GBUFFER": "REUSED_GBUFFER", "VSGL_REUSED_FIT": "REUSED_FIT"}


def _binding_name(define):
    if define in SPECIAL:
        return SPECIAL[define]
    if define.startswith("VSGL_ERROR_"):
        return "Result", define[len("VSGL_"):]
    for prefix, cls in ENUM_PREFIXES:
        if define.startswith(prefix):
            return cls, define[len(prefix):]
    return None


def test_constants_match_header_defines():
    problems = []
    seen = set()
    for define, value in sorted(header_parse.defines().items()):
        if define in SCALAR_CONSTANTS:
            got = getattr(libvsgl, SCALAR_CONSTANTS[define])
            if abs(got - value) > 1e-6 * abs(value):
                problems.append("%s = %r, binding %r" % (define, value, got))
            continue
        target = _binding_name(define)
        if target is None:
            continue
        cls_name, member = target
        cls = getattr(libvsgl, cls_name)
        seen.add((cls_name, member))
        if member not in cls.__members__:
            problems.append("%s (= %r) missing from libvsgl.%s" % (define, value, cls_name))
        elif int(cls[member]) != value:
            problems.append("%s = %r, binding %s.%s = %d" % (define, value, cls_name, member,
                                                             int(cls[member])))
    for _, cls_name in ENUM_PREFIXES + [("", "SharpnessEstimator"), ("", "Result")]:
        for member in getattr(libvsgl, cls_name).__members__:
            if (cls_name, member) not in seen:
                problems.append("libvsgl.%s.%s has no #define in the headers" % (cls_name, member))
    assert not problems, "\n".join(problems)


def test_versions_match_header():
    d = header_parse.defines()
    assert libvsgl.BINDING_VERSION == (d["VSGL_VERSION_MAJOR"], d["VSGL_VERSION_MINOR"]), \
        "the headers are %d.%d: update BINDING_VERSION with the binding" % (
            d["VSGL_VERSION_MAJOR"], d["VSGL_VERSION_MINOR"])
    assert len(libvsgl.Result) == d["VSGL_RESULT_COUNT"]
    if "VSGL_BUNDLE_VERSION_MAJOR" in d:
        assert libvsgl.BUNDLE_VERSION == (d["VSGL_BUNDLE_VERSION_MAJOR"], d["VSGL_BUNDLE_VERSION_MINOR"])
