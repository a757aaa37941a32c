"""Minimal parser of the public headers (csrc/include/vsgl/*.h): function
prototypes and struct fields, to check the binding against them."""

import glob
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
INCLUDE = os.path.normpath(os.path.join(HERE, "..", "..", "csrc", "include"))


def headers():
    return sorted(glob.glob(os.path.join(INCLUDE, "vsgl", "*.h")))


def _strip(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return text


def prototypes():
    """{name: (header, return type text, [param type texts])}."""
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


def structs():
    """{struct name: [field names in order]} for every typedef'd struct with a body."""
    out = {}
    for h in headers():
        text = _strip(open(h).read())
        for m in re.finditer(r"typedef\s+struct\s+(\w+)\s*\{(.*?)\}\s*(\w+)\s*;", text, flags=re.S):
            name, body = m.group(1), m.group(2)
            fields = []
            for decl in body.split(";"):
                decl = " ".join(decl.split())
                if not decl:
                    continue
                # "float x, y, z" / "float base_color[3]" / "const float *data[4]" / "void (*fn)(...)"
                fm = re.match(r"^[\w\s]*?\(\s*\*\s*(\w+)\s*\)", decl)
                if fm:
                    fields.append(fm.group(1))
                    continue
                head, _, rest = decl.partition(",")
                first = re.search(r"(\w+)\s*(\[[^\]]*\])?\s*$", head).group(1)
                fields.append(first)
                for extra in rest.split(",") if rest else []:
                    fields.append(re.match(r"\s*\**\s*(\w+)", extra).group(1))
            out[name] = fields
    return out


def defines():
    """{name: value} of every integer/float #define VSGL_* in the headers."""
    import re as _re
    out = {}
    for h in headers():
        for m in _re.finditer(r"^#define\s+(VSGL_\w+)\s+([-+0-9.eExXa-fA-Fu]+)f?\b", open(h).read(), _re.M):
            txt = m.group(2).rstrip("uU")
            try:
                out[m.group(1)] = int(txt, 0)
            except ValueError:
                try:
                    out[m.group(1)] = float(txt.rstrip("fF"))
                except ValueError:
                    pass
    return out
