"""EXR reading for the tests, through OpenImageIO (an independent reader of
every compression, single- and multi-part): Debian's python3-openimageio in
/usr/bin/python3 and Debian's Blender, the OpenImageIO wheel beside the bpy
wheels (tools/install_bpy.sh). Test helper only."""
import numpy as np

try:
    import OpenImageIO as oiio
except ImportError as e:  # no silent fallback: the tests need an independent reader
    raise ImportError("the tests read EXRs with OpenImageIO: install python3-openimageio "
                      "(tools/deps.sh test) or, in a pip bpy environment, tools/install_bpy.sh: %s" % e) from None


def read_exr(path):
    """Return (channels dict full name -> (H, W) float32, rows from the top;
    attributes dict of the first part). In a multi-part file (Blender 5's
    multilayer) a channel named without a layer takes its part's name."""
    inp = oiio.ImageInput.open(str(path))
    if not inp:
        raise RuntimeError("%s: %s" % (path, oiio.geterror()))
    out, attrs = {}, None
    try:
        sub = 0
        while inp.seek_subimage(sub, 0):
            spec = inp.spec()
            pixels = inp.read_image(sub, 0, 0, spec.nchannels, "float")
            if pixels is None:
                raise RuntimeError("%s: part %d: %s" % (path, sub, inp.geterror()))
            pixels = np.asarray(pixels, np.float32).reshape(spec.height, spec.width, spec.nchannels)
            part = spec.getattribute("oiio:subimagename") or ""
            for i, name in enumerate(spec.channelnames):
                full = "%s.%s" % (part, name) if part and "." not in name else name
                out[full] = pixels[..., i].copy()
            if attrs is None:
                attrs = {a.name: a.value for a in spec.extra_attribs}
            sub += 1
    finally:
        inp.close()
    return out, attrs


def read_pass(path, layer_pass, comps="RGB"):
    ch, _ = read_exr(path)
    return np.dstack([ch["%s.%s" % (layer_pass, c)] for c in comps])
