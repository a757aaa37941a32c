"""Plain settings object (no bpy): what one AOV computation needs.

``Options.from_props(props)`` copies the add-on's Scene PropertyGroup (or any
object with the same attribute names) so the engine never touches bpy.
"""
from dataclasses import dataclass, fields

PRESETS = ("PREVIEW", "BALANCED", "QUALITY")
DEFAULT_TEMPLATE = "{render_dir}/vsgl/{scene}_{view_layer}_####.exr"

# Advanced knobs, mirroring vsgl_render_settings (csrc/include/vsgl/render.h).
# name -> (enum items or None, default)
KNOBS = {
    "method": (("VSGL", "BRUTE_FORCE"), "VSGL"),
    "aa_samples": (None, 2),
    "rsm_resolution": (None, 256),
    "fit_mode": (("TWO", "FIS", "KMEANS", "LATTICE"), "LATTICE"),
    "vsgl_count": (None, 128),
    "fis_iterations": (None, 8),
    "sharpness_estimator": (("TOKSVIG", "BANERJEE"), "TOKSVIG"),
    "diffuse_mode": (("SG", "PULLED_OUT", "ACCURATE"), "PULLED_OUT"),
    "glossy_mode": (("ASG", "SG", "ASG2"), "ASG"),
    "visibility": (("NONE", "RAY"), "NONE"),
    "seed": (None, 0),
    "leak_correction": (("AUTO", "OFF", "ON"), "AUTO"),
    "sample_merging": (("AUTO", "OFF"), "AUTO"),
}


@dataclass
class Options:
    enabled: bool = False
    add_to_render: bool = True
    preset: str = "BALANCED"
    use_advanced: bool = False
    method: str = "VSGL"
    aa_samples: int = 2
    rsm_resolution: int = 256
    fit_mode: str = "LATTICE"
    vsgl_count: int = 128
    fis_iterations: int = 8
    sharpness_estimator: str = "TOKSVIG"
    diffuse_mode: str = "PULLED_OUT"
    glossy_mode: str = "ASG"
    visibility: str = "NONE"
    seed: int = 0
    leak_correction: str = "AUTO"
    sample_merging: str = "AUTO"
    output_path: str = DEFAULT_TEMPLATE
    threads: int = 0
    max_memory_gb: float = 0.0      # 0 = the memory the machine has available
    half_float: bool = False

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
