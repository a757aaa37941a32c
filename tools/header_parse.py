"""Minimal parser of the public headers (csrc/include/vsgl.h and vsgl/*.h):
#define constants, typedefs, struct fields with their C types and doc
comments, and function prototypes. tools/gen_abi.py generates the binding's
ABI mirror from it; tests/python/test_layout.py checks the mirror with it.

It reads the headers' own plain style (one declaration per statement, no
nested structs or unions, no function-like macros beyond the export macro)
and raises ValueError on anything else rather than guess."""

import glob
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
INCLUDE = os.path.normpath(os.path.join(HERE, "..", "csrc", "include"))


def headers():
    """The public headers in vsgl.h's include order, then the ones vsgl.h
    does not include (debug.h, reference.h) by name."""
    umbrella = open(os.path.join(INCLUDE, "vsgl.h")).read()
    order = [os.path.join(INCLUDE, p) for p in re.findall(r'#include\s+"(vsgl/\w+\.h)"', umbrella)]
    rest = sorted(set(glob.glob(os.path.join(INCLUDE, "vsgl", "*.h"))) - set(order))
    return order + rest


def _blank_comments(text):
    """The text with every comment replaced by spaces (positions kept), and
    the doc comments as [(start, end, body)]."""
    comments = []

    def blank(m):
        comments.append((m.start(), m.end(), m.group(0)))
        return re.sub(r"[^\n]", " ", m.group(0))
    text = re.sub(r"/\*.*?\*/|//[^\n]*", blank, text, flags=re.S)
    return text, comments


def _strip(text):
    return _blank_comments(text)[0]


def _comment_text(raw):
    raw = re.sub(r"^/\*+<?|\*/$|^//", "", raw.strip())
    return " ".join(raw.split())


# --------------------------------------------------------------------------
# Prototypes
# --------------------------------------------------------------------------

def _split_decl(decl):
    """'const float *data[4]' -> ('const float *', 'data', '4');
    'float x' -> ('float', 'x', None)."""
    decl = " ".join(decl.split())
    m = re.match(r"^(.*?)(\w+)\s*(?:\[\s*([^\]]+?)\s*\])?$", decl)
    if not m or not m.group(1).strip():
        raise ValueError("cannot parse the declaration %r" % decl)
    return " ".join(m.group(1).replace("*", " * ").split()).replace("* *", "**"), m.group(2), m.group(3)


def prototypes():
    """{name: (header, return type text, [param type texts])} in header order."""
    out = {}
    for h in headers():
        text = _strip(open(h).read())
        for m in re.finditer(r"VSGL_API\s+([^;{}()]+?)\b(vsgl_\w+)\s*\(([^)]*)\)\s*;", text):
            ret, name, params = m.group(1), m.group(2), m.group(3)
            plist = [p.strip() for p in params.split(",")]
            if plist == ["void"]:
                plist = []
            types = []
            for p in plist:
                p = " ".join(p.split())
                # drop the parameter name (last identifier)
                mm = re.match(r"(.*?)(\w+)$", p)
                types.append(" ".join(mm.group(1).split()) if mm else p)
            out[name] = (os.path.basename(h), " ".join(ret.split()), types)
    return out


# --------------------------------------------------------------------------
# Structs
# --------------------------------------------------------------------------

def struct_fields():
    """{struct name: [(field, C type text, array length text or None, doc
    comment)]} for every typedef'd struct with a body, in header order.
    'float x, y, z' gives three fields of type 'float'; a pointer star binds
    to the type ('const float *')."""
    out = {}
    for h in headers():
        raw = open(h).read()
        text, comments = _blank_comments(raw)
        for m in re.finditer(r"typedef\s+struct\s+(\w+)\s*\{(.*?)\}\s*(\w+)\s*;", text, flags=re.S):
            name, alias = m.group(1), m.group(3)
            if name != alias:
                raise ValueError("%s: typedef struct %s ... %s: the names differ" % (h, name, alias))
            fields = []
            pos = m.start(2)
            for decl in m.group(2).split(";"):
                end = pos + len(decl)      # the ';' ending this declaration
                pos = end + 1
                if not decl.strip():
                    continue
                if "(" in decl or "{" in decl:
                    raise ValueError("%s: %s: function pointer or nested field %r: use a typedef"
                                     % (h, name, " ".join(decl.split())))
                # its doc comment: the first comment after the ';' on the same line
                doc = ""
                line_end = raw.find("\n", end)
                for cs, ce, body in comments:
                    if end < cs < line_end:
                        doc = _comment_text(body)
                        # a comment continued on the next lines is one comment already
                        break
                head, *more = decl.split(",")
                ctype, first, dim = _split_decl(head)
                fields.append((first, ctype, dim, doc))
                base = ctype.replace("*", "").strip()
                for extra in more:
                    stars = extra.count("*")
                    _, fname, fdim = _split_decl(base + " " + extra.replace("*", ""))
                    fields.append((fname, (base + " " + "*" * stars).strip(), fdim, doc))
            out[name] = fields
    return out


def structs():
    """{struct name: [field names in order]} for every typedef'd struct with a body."""
    return {name: [f[0] for f in fields] for name, fields in struct_fields().items()}


def typedefs():
    """{'opaque': [names of 'typedef struct X X;'], 'scalar': {name: C type},
    'function': {name: (return type text, [param type texts])}}."""
    out = {"opaque": [], "scalar": {}, "function": {}}
    for h in headers():
        text = _strip(open(h).read())
        for m in re.finditer(r"typedef\s+struct\s+(\w+)\s+(\w+)\s*;", text):
            out["opaque"].append(m.group(2))
        for m in re.finditer(r"typedef\s+((?:unsigned\s+)?\w+)\s+(\w+)\s*;", text):
            if m.group(1) != "struct":
                out["scalar"][m.group(2)] = m.group(1)
        for m in re.finditer(r"typedef\s+([\w\s*]+?)\s*\(\s*\*\s*(\w+)\s*\)\s*\(([^)]*)\)\s*;", text):
            params = [p.strip() for p in m.group(3).split(",")]
            params = [] if params == ["void"] else [_split_decl(p)[0] for p in params]
            out["function"][m.group(2)] = (" ".join(m.group(1).split()), params)
    return out


# --------------------------------------------------------------------------
# #defines
# --------------------------------------------------------------------------

def define_list():
    """[(name, value, header, doc comment)] of every '#define VSGL_*' with a
    value that is a number or an integer expression of earlier ones (header
    guards, the export macro and defines of other kinds are left out), in
    header order. Integer literals give int, others float."""
    known = {}
    out = []
    for h in headers():
        raw = open(h).read()
        for m in re.finditer(r"^#\s*define\s+(VSGL_\w+)[ \t]+([^\n]*)$", raw, re.M):
            name, rest = m.group(1), m.group(2)
            cm = re.search(r"/\*.*?(\*/|$)|//.*$", rest)
            doc = _comment_text(cm.group(0)) if cm else ""
            expr = (rest[:cm.start()] if cm else rest).strip()
            value = _evaluate(expr, known)
            if value is None:
                continue
            known[name] = value
            out.append((name, value, os.path.basename(h), doc))
    return out


def _evaluate(expr, known):
    """The value of a #define's text: a literal or an expression of ints,
    earlier defines, | + - * ( ); None for anything else."""
    if not expr:
        return None
    lit = re.fullmatch(r"([-+]?)(0[xX][0-9a-fA-F]+|\d+)[uU]?", expr)
    if lit:
        return int(lit.group(1) + lit.group(2), 0)
    flt = re.fullmatch(r"[-+]?(\d+\.\d*|\.\d+|\d+)([eE][-+]?\d+)?[fF]?", expr)
    if flt:
        return float(expr.rstrip("fF"))
    tokens = re.findall(r"\s*(VSGL_\w+|0[xX][0-9a-fA-F]+[uU]?|\d+[uU]?|[|+\-*()])", expr)
    if "".join(t.strip() for t in tokens) != "".join(expr.split()):
        return None
    py = []
    for t in tokens:
        t = t.strip()
        if t.startswith("VSGL_"):
            if t not in known or not isinstance(known[t], int):
                return None
            py.append(str(known[t]))
        elif t[0].isdigit():
            py.append(str(int(t.rstrip("uU"), 0)))
        else:
            py.append(t)
    return int(eval(" ".join(py), {"__builtins__": {}}))  # digits and | + - * ( ) only


def defines():
    """{name: value} of every #define VSGL_* with a numeric value (define_list)."""
    return {name: value for name, value, _, _ in define_list()}
