"""Material mapping: Blender shader values -> ``vsgl_material`` fields.

Pure logic (no ``bpy``): the bpy glue in ``export.py`` reads a material's
node tree into a :class:`ShaderDesc` (plain values) and this module turns it
into the fields of ``vsgl_material`` (csrc/include/vsgl/scene.h) plus
warnings naming the material. Unit-testable with plain Python.
"""
import math

from . import textures

MATERIAL_UNSUPPORTED = 1  # VSGL_MATERIAL_UNSUPPORTED
MATERIAL_FLAG_BLENDER_4 = 2  # VSGL_MATERIAL_FLAG_BLENDER_4: Cycles 4.x+ GGX shadowing
MATERIAL_FLAG_MULTISCATTER = 4  # VSGL_MATERIAL_FLAG_MULTISCATTER: "Multiscatter GGX"
MATERIAL_FLAG_BURLEY = 8  # VSGL_MATERIAL_FLAG_BURLEY: Blender 3.x's Principled diffuse (Burley's)

# Node kinds the bpy glue reports.
PRINCIPLED = "PRINCIPLED"
DIFFUSE = "DIFFUSE"
GLOSSY = "GLOSSY"          # Glossy BSDF (4.x: also anisotropic)
ANISOTROPIC = "ANISOTROPIC"  # 3.x Anisotropic BSDF
EMISSION = "EMISSION"      # Emission shader: a light source (export.py), reflects nothing
NO_NODES = "NO_NODES"      # material.use_nodes is False: Cycles shades diffuse_color
OTHER = "OTHER"            # anything else: viewport values, flagged


class ShaderDesc:
    """What the glue read from one material (plain Python values).

    kind: one of the constants above; inputs: socket name -> default value
    (floats or RGB(A) tuples); linked: names of inputs driven by a link
    (textures etc.); node: name of the shader node found (for messages);
    viewport: (diffuse_color rgba, metallic, roughness) of the material;
    version: Blender version tuple (socket names differ at 4.0).
    """

    def __init__(self, name, kind, inputs=None, linked=(), node="",
                 viewport=((0.8, 0.8, 0.8, 1.0), 0.0, 0.5), version=(4, 0, 0), reason="",
                 multiscatter=False, exprs=None, images=None, extra_warnings=()):
        self.name = name
        self.kind = kind
        self.inputs = dict(inputs or {})
        self.linked = set(linked)
        self.node = node
        self.viewport = viewport
        self.version = tuple(version)
        self.reason = reason
        self.multiscatter = bool(multiscatter)  # the node's distribution is "Multiscatter GGX"
        # linked inputs the export can evaluate: socket name -> expression
        # (textures.py) and the Image Texture lookups they use (key -> ImageRef)
        self.exprs = dict(exprs or {})
        self.images = dict(images or {})
        self.extra_warnings = list(extra_warnings)  # found by the glue (transparency, holdout nodes, ...)
        self._plans = None


# Inputs evaluated with textures, per shader kind: socket -> (slot, scalar)
TEXTURED_INPUTS = {
    PRINCIPLED: {"Base Color": ("base_color", False), "Roughness": ("roughness", True),
                 "Metallic": ("metallic", True)},
    DIFFUSE: {"Color": ("base_color", False)},
    GLOSSY: {"Color": ("base_color", False), "Roughness": ("roughness", True)},
    ANISOTROPIC: {"Color": ("base_color", False), "Roughness": ("roughness", True)},
}


# Emission colour inputs (their textures are reduced to the mean colour)
EMISSION_INPUTS = {PRINCIPLED: ("Emission", "Emission Color"), EMISSION: ("Color",)}


def emission(desc):
    """(rgb, strength) of an emitting material, or None. Cycles' emission of
    strength S and colour C has radiance S C (W / m^2 / sr) on both sides of
    a face; a textured colour is taken as the texture's mean."""
    inp = desc.inputs
    if desc.kind == PRINCIPLED:
        strength = float(inp.get("Emission Strength", 1.0 if desc.version < (4, 0, 0) else 0.0))
        sock = "Emission" if desc.version < (4, 0, 0) else "Emission Color"
    elif desc.kind == EMISSION:
        strength = float(inp.get("Strength", 1.0))
        sock = "Color"
    else:
        return None
    col = inp.get(sock, (0.0, 0.0, 0.0))
    if sock in desc.exprs:
        pl = textures.plan_slot(desc.exprs[sock], desc.images, "material '%s' input '%s'" % (desc.name, sock))
        col = pl.constant if pl.texture is None else tuple(pl.texture["pixels"].reshape(-1, 4).mean(0)[:3])
    rgb = tuple(max(float(c), 0.0) for c in list(col)[:3])
    if not (strength > 0.0 and math.isfinite(strength)) or max(rgb) <= 0.0:
        return None
    return rgb, strength


def texture_plans(desc):
    """slot name -> textures.SlotPlan for the linked inputs of ``desc`` the
    export evaluates (computed once per description)."""
    if desc._plans is None:
        plans = {}
        for sock, (slot, scalar) in TEXTURED_INPUTS.get(desc.kind, {}).items():
            if sock in desc.linked and sock in desc.exprs:
                plans[slot] = textures.plan_slot(desc.exprs[sock], desc.images,
                                                 "material '%s' input '%s'" % (desc.name, sock), scalar)
        desc._plans = plans
    return desc._plans


def default_material():
    """Blender's default surface (no material): 0.8 grey, roughness 0.5, F0 0.04."""
    return dict(base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5,
                specular_f0=0.04, anisotropy=0.0, anisotropic_rotation=0.0, flags=0)


def _clamp01(x):
    x = float(x)
    if not math.isfinite(x):
        return 0.0
    return min(max(x, 0.0), 1.0)


def _rgb(v):
    try:
        seq = list(v)
    except TypeError:
        seq = [float(v)] * 3
    return tuple(_clamp01(c) for c in seq[:3])


def f0_from_ior(ior):
    """Fresnel reflectance at normal incidence of a dielectric, ((n-1)/(n+1))^2."""
    ior = float(ior)
    if not math.isfinite(ior) or ior <= 0.0:
        return 0.0
    return ((ior - 1.0) / (ior + 1.0)) ** 2


def principled_f0(inputs, version):
    """Dielectric F0 of a Principled BSDF.

    3.x: 0.08 * Specular. 4.x: F0(IOR) * 2 * "Specular IOR Level" (0.5 keeps
    the IOR's F0), as Cycles does, clamped to [0, 1].
    """
    if tuple(version) < (4, 0, 0):
        return _clamp01(0.08 * float(inputs.get("Specular", 0.5)))
    f0 = f0_from_ior(inputs.get("IOR", 1.5))
    level = float(inputs.get("Specular IOR Level", 0.5))
    return _clamp01(f0 * 2.0 * level)


def map_material(desc):
    """Return (fields, warnings): ``fields`` has the vsgl_material keys."""
    warnings = []
    m = default_material()
    inp = desc.inputs
    who = "material '%s'" % desc.name

    plans = texture_plans(desc)
    textured = {s for s, (slot, _) in TEXTURED_INPUTS.get(desc.kind, {}).items() if slot in plans}
    for pl in plans.values():
        warnings.extend(pl.warnings)
    warnings.extend(desc.extra_warnings)

    def note_links(names):
        used = sorted(n for n in names if n in desc.linked and n not in textured)
        if used:
            warnings.append("%s: %s input(s) %s are linked (the export does not evaluate what is linked there); "
                            "their unlinked values are used" % (who, desc.node or desc.kind,
                                                                ", ".join(repr(u) for u in used)))

    if desc.kind == PRINCIPLED:
        m["base_color"] = _rgb(inp.get("Base Color", (0.8, 0.8, 0.8)))
        m["metallic"] = _clamp01(inp.get("Metallic", 0.0))
        m["roughness"] = _clamp01(inp.get("Roughness", 0.5))
        m["specular_f0"] = principled_f0(inp, desc.version)
        m["anisotropy"] = _clamp01(inp.get("Anisotropic", 0.0))
        m["anisotropic_rotation"] = _clamp01(inp.get("Anisotropic Rotation", 0.0))
        spec = "Specular" if desc.version < (4, 0, 0) else "Specular IOR Level"
        note_links(["Base Color", "Metallic", "Roughness", spec, "IOR",
                    "Anisotropic", "Anisotropic Rotation"])
        if "Normal" in desc.linked:
            warnings.append("%s: its Normal input (normal or bump map) is not modelled; the mesh "
                            "normals are used" % who)
        if "Alpha" in desc.linked or float(inp.get("Alpha", 1.0)) < 1.0:
            warnings.append("%s: transparency (Alpha) is not modelled; the surface is opaque" % who)
        tw = "Transmission" if desc.version < (4, 0, 0) else "Transmission Weight"
        if float(inp.get(tw, 0.0)) > 0.0:
            warnings.append("%s: transmission is not modelled (treated as opaque)" % who)
        if desc.version < (4, 0, 0):  # Cycles 3.x's Principled diffuse is Burley's, 4.x's Lambert
            m["flags"] = int(m.get("flags", 0)) | MATERIAL_FLAG_BURLEY
    elif desc.kind == EMISSION:
        # pure emission reflects nothing; its light is exported as area lights
        m.update(base_color=(0.0, 0.0, 0.0), metallic=0.0, roughness=1.0, specular_f0=0.0)
    elif desc.kind in (DIFFUSE, NO_NODES):
        col = inp.get("Color", desc.viewport[0]) if desc.kind == DIFFUSE else desc.viewport[0]
        m.update(base_color=_rgb(col), metallic=0.0, roughness=1.0, specular_f0=0.0)
        if desc.kind == DIFFUSE:
            note_links(["Color"])
    elif desc.kind in (GLOSSY, ANISOTROPIC):
        # A Glossy BSDF is a conductor whose F0 is its colour.
        m.update(base_color=_rgb(inp.get("Color", (0.8, 0.8, 0.8))), metallic=1.0,
                 roughness=_clamp01(inp.get("Roughness", 0.5)), specular_f0=0.0)
        m["anisotropy"] = _clamp01(inp.get("Anisotropy", 0.0))
        m["anisotropic_rotation"] = _clamp01(inp.get("Rotation", 0.0))
        note_links(["Color", "Roughness", "Anisotropy", "Rotation"])
    else:
        col, metallic, rough = desc.viewport
        m.update(base_color=_rgb(col), metallic=_clamp01(metallic), roughness=_clamp01(rough),
                 specular_f0=0.04, flags=MATERIAL_UNSUPPORTED)
        why = (": " + desc.reason) if desc.reason else ""
        warnings.append("%s: unsupported shader%s; using its viewport display colour, "
                        "metallic and roughness" % (who, why))
    for slot, pl in plans.items():
        if slot == "base_color":
            m["base_color"] = _rgb(pl.constant)
        else:
            m[slot] = _clamp01(pl.constant)
    # Cycles 4.x+'s "Multiscatter GGX" (measured in 5.0.1; 3.x's random-walk
    # version was not measured and stays single-scatter)
    if desc.multiscatter and desc.kind in (PRINCIPLED, GLOSSY, ANISOTROPIC) and desc.version >= (4, 0, 0):
        m["flags"] = int(m.get("flags", 0)) | MATERIAL_FLAG_MULTISCATTER
    return m, warnings
