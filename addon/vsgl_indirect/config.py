"""Plain settings object (no bpy): what one AOV computation needs.

``Options.from_props(props)`` copies the add-on's Scene PropertyGroup (or any
object with the same attribute names) so the engine never touches bpy.
"""
from dataclasses import dataclass, fields

PRESETS = ("PREVIEW", "BALANCED", "QUALITY", "AUTO")
DEFAULT_TEMPLATE = "{render_dir}/vsgl/{scene}_{view_layer}_####.exr"

# Advanced knobs, mirroring vsgl_render_settings (csrc/include/vsgl/render.h).
# name -> (enum items or None, default). The defaults are the BALANCED
# preset's values, so ticking "Advanced" never changes the result by itself.
KNOBS = {
    "method": (("VSGL", "BRUTE_FORCE"), "VSGL"),
    "aa_samples": (None, 2),
    "aa_pixel_limit": (None, 76800),
    "shade_stride": (None, 2),
    "stride_pixels": (None, 76800),
    "edge_samples": (None, 12),
    "sample_merging": (("AUTO", "OFF"), "AUTO"),
    "visibility": (("NONE", "RAY"), "RAY"),
    "visibility_budget": (None, 0.02),
    "visibility_spread": (None, 2.0),
    "dominant_rays": (None, 4),
    "seed": (None, 0),
    "rsm_resolution": (None, 256),
    "fit_mode": (("TWO", "FIS", "KMEANS", "LATTICE"), "LATTICE"),
    "vsgl_count": (None, 192),
    "fis_iterations": (None, 8),
    "sharpness_estimator": (("TOKSVIG", "BANERJEE"), "TOKSVIG"),
    "leak_correction": (("AUTO", "OFF", "ON", "CLIP"), "AUTO"),
    "diffuse_mode": (("SG", "PULLED_OUT", "ACCURATE"), "PULLED_OUT"),
    "glossy_mode": (("ASG", "SG", "ASG2", "MRP", "HYBRID"), "ASG2"),
    "glossy_lobes": (None, 4),
    "mrp_min_area": (None, 0.25),
}

# The presets' knob values: vsgl_render_settings_preset (csrc/src/shade/
# settings.c), mirrored so the panel can show them without the library;
# tests/blender/addon/test_addon_ui.py checks the two agree.
_COMMON = dict(method="VSGL", sharpness_estimator="TOKSVIG", glossy_mode="ASG", fis_iterations=8,
               seed=0, leak_correction="AUTO", sample_merging="AUTO", fit_mode="LATTICE",
               diffuse_mode="PULLED_OUT", mrp_min_area=0.25, glossy_lobes=4, visibility_budget=0.02,
               visibility_spread=2.0, dominant_rays=4,
               aa_pixel_limit=76800, stride_pixels=76800)
PRESET_VALUES = {
    "PREVIEW": dict(_COMMON, aa_samples=1, rsm_resolution=128, vsgl_count=32, visibility="RAY",
                    shade_stride=2, edge_samples=8, glossy_mode="ASG2"),
    "BALANCED": dict(_COMMON, aa_samples=2, rsm_resolution=256, vsgl_count=192, visibility="RAY",
                     shade_stride=2, edge_samples=12, glossy_mode="ASG2"),
    "QUALITY": dict(_COMMON, aa_samples=3, rsm_resolution=512, vsgl_count=256, visibility="RAY",
                    shade_stride=2, edge_samples=12, glossy_mode="ASG2", glossy_lobes=5),
}
# AUTO: balanced's knobs as ceilings; the library chooses within them (auto_target, render.h)
PRESET_VALUES["AUTO"] = dict(PRESET_VALUES["BALANCED"])
assert all(PRESET_VALUES["BALANCED"][k] == v[1] for k, v in KNOBS.items())


def preset_knobs(preset):
    """The knob values of ``preset`` (a dict; BALANCED for an unknown name)."""
    return dict(PRESET_VALUES.get(preset, PRESET_VALUES["BALANCED"]))


def knobs_of(obj):
    """The knob values of ``obj`` (an Options, the PropertyGroup, any object)."""
    return {k: getattr(obj, k) for k in KNOBS}


def same_knob_value(a, b):
    """Knob values equal; floats within float32 rounding (Blender's
    FloatProperty and the library's settings hold 0.02 as 0.0199999996)."""
    if isinstance(a, float) or isinstance(b, float):
        try:
            return abs(float(a) - float(b)) <= 1e-6 * max(1.0, abs(float(b)))
        except (TypeError, ValueError):
            return False
    return a == b


def differing_knobs(obj, preset=None):
    """Names of the knobs of ``obj`` that differ from ``preset`` (default:
    ``obj.preset``), in KNOBS order."""
    want = preset_knobs(preset or obj.preset)
    return [k for k in KNOBS if not same_knob_value(getattr(obj, k), want[k])]


def matching_preset(obj):
    """The preset whose values ``obj``'s knobs equal, or None."""
    for p in PRESETS:
        if not differing_knobs(obj, p):
            return p
    return None


def inactive_knobs(obj):
    """Knobs that do not apply with ``obj``'s other knobs (the library
    ignores them): greyed out in the panel."""
    out = set()
    if obj.method == "BRUTE_FORCE":   # every RSM texel with the exact BRDF: no fit, no lobes
        out |= {"fit_mode", "vsgl_count", "fis_iterations", "seed", "sharpness_estimator",
                "leak_correction", "diffuse_mode", "glossy_mode", "shade_stride",
                "sample_merging"}
    if obj.fit_mode == "TWO":
        out |= {"vsgl_count", "fis_iterations", "seed"}
    elif obj.fit_mode == "LATTICE":
        out |= {"fis_iterations", "seed"}
    elif obj.fit_mode == "KMEANS":
        out |= {"fis_iterations"}
    if obj.aa_samples <= 1:
        out |= {"sample_merging", "aa_pixel_limit"}
    if obj.shade_stride <= 1 or obj.method == "BRUTE_FORCE":  # every pixel at every size
        out.add("stride_pixels")
    if obj.glossy_mode not in ("MRP", "HYBRID") or obj.method == "BRUTE_FORCE":
        out.add("mrp_min_area")
    if obj.glossy_mode != "ASG2" or obj.method == "BRUTE_FORCE":
        out.add("glossy_lobes")
    if obj.visibility != "RAY" or obj.method == "BRUTE_FORCE":
        out |= {"visibility_budget", "visibility_spread", "dominant_rays"}
    return out


@dataclass
class Options:
    enabled: bool = False
    add_to_render: bool = True
    preset: str = "BALANCED"
    use_advanced: bool = False
    method: str = "VSGL"
    aa_samples: int = 2
    aa_pixel_limit: int = 76800
    shade_stride: int = 2
    stride_pixels: int = 76800
    edge_samples: int = 12
    rsm_resolution: int = 256
    fit_mode: str = "LATTICE"
    vsgl_count: int = 192
    fis_iterations: int = 8
    sharpness_estimator: str = "TOKSVIG"
    diffuse_mode: str = "PULLED_OUT"
    glossy_mode: str = "ASG"
    mrp_min_area: float = 0.25      # m^2: the smallest face made a rectangle proxy (MRP, HYBRID)
    glossy_lobes: int = 4           # GGX's lobes in the half-vector model (ASG2): 4 or 5
    visibility: str = "RAY"
    visibility_budget: float = 0.02  # Visibility Rays: the weakest VSGLs' share of a receiver's light without a ray
    visibility_spread: float = 2.0  # Visibility Rays: the disk each VSGL's rays aim over, in its sigmas
    dominant_rays: int = 4          # Visibility Rays: rays per pair where a VSGL carries >= 0.5 % of a pixel's light
    seed: int = 0
    leak_correction: str = "AUTO"
    sample_merging: str = "AUTO"
    output_path: str = DEFAULT_TEMPLATE
    threads: int = 0
    max_memory_gb: float = 0.0      # 0 = the memory the machine has available
    half_float: bool = True         # Blender's own EXR default; 2x smaller, faster to write
    color_passes: bool = False      # EXR: also DiffCol and GlossCol (the compositor setup reads neither)
    fail_render: bool = False       # farms: a frame without its AOV fails the render
    strength: float = 1.0           # compositor: factor of the added indirect light
    use_diffuse: bool = True        # compositor: add the Diff pass
    use_glossy: bool = True         # compositor: add the Gloss pass
    use_cycles_colors: bool = False  # compositor: DiffInd x Cycles' DiffCol (+ glossy) instead of Diff/Gloss
    export_passes: bool = False     # compositor: render passes + VSGL passes in one EXR
    export_path: str = "{render_dir}/passes/{scene}_"

    def max_memory_bytes(self):
        return max(int(float(self.max_memory_gb) * (1 << 30)), 0)

    @classmethod
    def from_props(cls, props):
        kw = {}
        for f in fields(cls):
            if hasattr(props, f.name):
                kw[f.name] = getattr(props, f.name)
        return cls(**kw)

    def render_settings(self):
        """``(preset_name, knobs)``: knobs is None when the preset is used as is,
        else a dict of vsgl_render_settings fields (enum members by name)."""
        if not self.use_advanced:
            return self.preset, None
        return self.preset, {k: getattr(self, k) for k in KNOBS}
