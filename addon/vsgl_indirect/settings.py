"""Scene settings of the add-on (``scene.vsgl_indirect``).

Every property and enum item carries a tooltip saying what it costs and
buys; the figures are from docs/accuracy.md (error against brute-force
gathering and against Cycles), docs/performance.md and docs/quality.md.
"""
import os

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty,
                       StringProperty)

from . import config
from .libvsgl import (AA_SAMPLES_MAX, FIS_ITERATIONS_MAX, RSM_RESOLUTION_MAX, RSM_RESOLUTION_MIN,
                      SHADE_STRIDE_MAX, VSGL_COUNT_MAX)


def _update_compositor(self, context):
    """Keep the compositor in step with the settings (main thread, UI edits)."""
    from . import compositor, engine, handlers
    scene = self.id_data
    if not isinstance(scene, bpy.types.Scene):
        return
    try:
        if not self.enabled:
            compositor.remove(scene)
        elif engine.can_render():
            handlers.setup_scene(scene)
    except Exception as e:  # never break a property edit
        print("VSGL WARNING: compositor update failed: %r" % (e,))


def _update_grading(self, context):
    """Strength, Diffuse, Glossy: only the Add nodes' factors change."""
    from . import compositor, config
    scene = self.id_data
    if not isinstance(scene, bpy.types.Scene) or not self.enabled:
        return
    try:
        if not compositor.update_grading(scene, config.Options.from_props(self)):
            _update_compositor(self, context)
    except Exception as e:  # never break a property edit
        print("VSGL WARNING: compositor update failed: %r" % (e,))


def load_preset_knobs(props, preset=None):
    """Copy ``preset``'s (default: the selected preset's) values into the knobs."""
    for k, v in config.preset_knobs(preset or props.preset).items():
        if getattr(props, k) != v:
            setattr(props, k, v)


def _update_preset(self, context):
    # The knobs follow the preset: greyed out with its values while Advanced
    # is off, and reloaded as the starting point when a preset is picked
    # with Advanced on (an explicit choice; "Reset to Preset" does the same).
    load_preset_knobs(self)


def _update_advanced(self, context):
    # Advanced starts from the selected preset's values, never from other
    # defaults. Knobs someone already edited (matching no preset) are kept.
    if self.use_advanced and config.matching_preset(self) is not None:
        load_preset_knobs(self)


# Only inside the Blender application: the pip bpy module has no UI to keep
# in step (render_init sets the compositor up), and its 4.2 LTS build
# segfaults at exit (status 139, after every render) while an update=
# callback is registered, even after unregistering it (issue 10; 5.0 does
# not). The handlers are removed at exit by __init__._unregister_at_exit.
IN_APPLICATION = "blender" in os.path.basename(bpy.app.binary_path or "").lower()
_UPDATE = {"update": _update_compositor} if IN_APPLICATION else {}


def _upd(fn):
    return {"update": fn} if IN_APPLICATION else {}


# Blender 4.5+ warns about '//' in path properties unless they opt in.
_PATH_OPTIONS = ({"options": {"PATH_SUPPORTS_BLEND_RELATIVE"}}
                 if bpy.app.version >= (4, 5, 0) else {})

# Labels and tooltips of the enum items: (identifier, label, description).
ITEMS = {
    # Times: tools/curve.sh's gather room at 80x60 (docs/accuracy.md), rerun
    # with the current presets on a 2-core machine, where Cycles took
    # 0.70 s for 256 spp (relMSE 0.0133); compare them with each other.
    "preset": [
        ("PREVIEW", "Preview",
         "Fastest: lattice 32 VSGLs per light, RSM 128, 1 sample (8 x 8 rays at edges), one "
         "pixel in 2 x 2 shaded, "
         "no indirect shadows. Within 21 % of Cycles per pass on the bundled scenes; the gather "
         "room in 0.03 s at relMSE 0.078 (light leaks past occluders). For stills and light "
         "edits: with 1 sample a moving camera makes glossy rims and sunlit edges shimmer "
         "(use Balanced for camera animations)"),
        ("BALANCED", "Balanced",
         "Lattice 192 VSGLs per light, RSM 256, 2 x 2 AA (8 x 8 rays at edges), one pixel in 2 x 2 "
         "shaded, visibility "
         "rays, GGX as two lobes: the gather room in 0.24 s at relMSE 0.0050, below Cycles at 256 "
         "spp (0.0133 in 0.59 s); within 5 % of Cycles per pass on every bundled scene. Per 1080p "
         "frame on 2 cores: 2.4-4 s in the bundled empty rooms (no rays: nothing can block), 12-33 s "
         "where objects cast indirect shadows (sun room, sphere); Preview 0.9-1.5 s"),
        ("QUALITY", "Quality",
         "Lattice 256 VSGLs per light, RSM 512, 2 x 2 AA (8 x 8 rays at edges), one pixel in 2 x 2 "
         "shaded, visibility "
         "rays: within 5 % of Cycles per pass on every bundled scene; the gather room in 0.39 s "
         "at relMSE 0.0047, about 1.6x Balanced's time"),
        ("AUTO", "Auto",
         "Balanced's error at less cost: Balanced's knobs as ceilings, and the library chooses for "
         "the scene 1 sample per pixel from 320 x 240 pixels, one glossy lobe where nothing sharper "
         "than roughness 0.5 is seen, and each light's RSM from the part of it that lights what the "
         "camera sees (85 texels per VSGL there). Spot room at 320 x 240 (one run each, load 5): 0.41 s "
         "at relMSE 0.0019 against Balanced's 1.11 s at 0.0019. The last-run box says what it chose "
         "and why; docs/trade.md, \"The auto preset\", measures it on every bundled scene"),
    ],
    "method": [
        ("VSGL", "VSGL",
         "Virtual spherical Gaussian lights: clusters of each light's RSM texels shaded "
         "analytically (every preset)"),
        ("BRUTE_FORCE", "Brute Force",
         "Every RSM texel as a point light with the exact BRDF: the reference VSGL is measured "
         "against. ~50x slower (4.99 s vs 0.10 s at 80x60, docs/accuracy.md) for relMSE 0.0084 "
         "vs 0.011; the fit and lobe knobs do not apply"),
    ],
    "fit_mode": [
        ("TWO", "Two per Light",
         "Two VSGLs per light (diffuse + glossy), as in the VSGL paper: cheapest, the smooth look "
         "of indirect light without its detail (diffuse relMSE 0.017 / 0.098 / 0.083 on the spot, "
         "point and area scenes against 0.0003 / 0.005 / 0.005 for the lattice at 128)"),
        ("FIS", "FIS",
         "Filtered importance sampling: N clusters drawn from the RSM. Diffuse relMSE 0.0031 / "
         "0.017 / 0.018 at N = 128; its random draws flicker as a light moves"),
        ("KMEANS", "k-means",
         "k-means clusters of the RSM texels: 0.00063 / 0.0098 / 0.012 at N = 128; random centres "
         "flicker in animation"),
        ("LATTICE", "Lattice",
         "World-space lattice (every preset): 0.00033 / 0.0047 / 0.0052 at N = 128, and the light "
         "changes smoothly as lights move (no flicker, no blotches)"),
    ],
    "sharpness_estimator": [
        ("TOKSVIG", "Toksvig", "Lobe sharpness from the mean direction's length (Toksvig)"),
        ("BANERJEE", "Banerjee", "Banerjee et al.'s estimator; differs from Toksvig by less than 5 %"),
    ],
    "diffuse_mode": [
        ("SG", "SG",
         "The receiver's cosine as a spherical Gaussian: cheapest shading, 1.7x the pulled-out "
         "form's error (relMSE 0.0048 vs 0.0028, FIS 128 on the spot scene)"),
        ("PULLED_OUT", "Pulled Out",
         "The cosine taken out of the integral at the lobe's axis (every preset): with the "
         "emitter clip as accurate as Accurate at half its shading cost"),
        ("ACCURATE", "Accurate",
         "The clamped cosine integrated against the lobe: about 2x the shading cost of Pulled "
         "Out (3.7 vs 7.7 x 10^8 pixel-VSGL pairs/s at 1080p) for no measurable gain with the "
         "emitter clip on"),
    ],
    "glossy_mode": [
        ("ASG", "ASG",
         "The receiver's GGX lobe as one anisotropic SG (Preview): handles grazing views and "
         "anisotropic materials, but puts the half of GGX's energy that is in its tail into its "
         "core: a metal floor's reflection of a lit wall is too bright in its middle and too dark "
         "around it"),
        ("SG", "SG (reference path, slow)",
         "An isotropic SG, shaded by the scalar reference path that checks the fast kernel: "
         "every pixel (Shade Stride ignored), a visibility ray per pair; Balanced with it took "
         "45-85x Balanced's time at 960 x 540. Wrong at grazing views and for anisotropic "
         "materials: for checking, not for renders"),
        ("ASG2", "Two ASGs",
         "GGX as two ASGs, core and tail (Balanced, Quality): the spot room's glossy structured "
         "error 0.0049 -> 0.0004 and never worse on the bundled rooms, for 1.2-1.5x the shading "
         "time"),
        ("MRP", "Rectangle Proxies",
         "Experimental: the glossy light of the large planar faces (walls, floors, 0.25 m^2 and "
         "up) as lit rectangles reflected in closed form (the MRP paper, docs/mrp.md): lower glossy "
         "relMSE than k-means 256 in the red-wall and sun rooms, higher than Two ASGs (balanced) "
         "in every quality room; light from curved or small surfaces is not in the glossy pass"),
        ("HYBRID", "Hybrid",
         "Experimental: Two ASGs, except on sharp glossy surfaces (roughness up to 0.5) where "
         "Rectangle Proxies find more than twice the light of the clusters on the walls; in the "
         "metal-floor rooms no pixel does, so it renders as Two ASGs with the proxy pass's time "
         "on top (docs/mrp.md)"),
    ],
    "visibility": [
        ("NONE", "None",
         "No indirect shadows: light leaks past occluders (gather room relMSE 0.076 without "
         "rays against 0.0057 with them, lattice 128)"),
        ("RAY", "Rays",
         "One shadow ray per pixel and VSGL: indirect shadows (Balanced and Quality). The "
         "gather room (lattice 128, 2 x 2 AA) took 0.07 s without, 0.32 s with them; shading "
         "one pixel in 2 x 2 pays most of it back (Balanced: 1.1-1.5x)"),
    ],
    "leak_correction": [
        ("AUTO", "Auto (On)", "The emitter clip and the near field, on (the library's default)"),
        ("OFF", "Off", "The papers' model: light also leaves behind a cluster's surface "
                       "(8.6x / 1.6x / 3.0x the lattice's diffuse error at N = 128)"),
        ("ON", "On", "The emitter clip: no light behind or within a cluster's own surface; within "
                     "2 % of a lit plane's exact irradiance in the far field. And the near field: "
                     "beside a junction a lattice cluster is its cell's exact form factor (no dark "
                     "seam along a wall's foot)"),
        ("CLIP", "Clip Only", "The emitter clip without the near field (0.3's On): the box room's "
                              "junctions 10-25 % dark"),
    ],
    "sample_merging": [
        ("AUTO", "Auto (On)",
         "Samples of a pixel on one surface are shaded once, at their centroid: with 3 x 3 AA "
         "3.5x fewer shading pairs at 1.6 % relative RMS difference"),
        ("OFF", "Off", "Shade every AA sample: exact AA at up to N^2 times the shading cost"),
    ],
}


def _enum(name, label, description, default=None, **kw):
    return EnumProperty(name=label, items=ITEMS[name], description=description,
                        default=default or config.KNOBS.get(name, (None, None))[1], **kw)


class VSGLIndirectSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="VSGL Indirect Light", default=False, **_UPDATE,
        description="Compute the one-bounce indirect-light AOV of every rendered frame (F12, -f, "
                    "-a) before the compositor runs. Costs the preset's time per frame and view "
                    "layer (Balanced at 1080p on 2 cores: 2.4-4 s in the bundled empty rooms, 12-33 s "
                    "with indirect shadows; Preview 0.9-1.5 s) plus the EXR write")
    add_to_render: BoolProperty(
        name="Add to Render", default=True, **_UPDATE,
        description="Add the AOV onto the render in the compositor (Render Layers + Strength x "
                    "(Diff + Gloss)). Render Cycles with direct light only (see the panel's "
                    "warning) or its own indirect light is counted twice. Off: only the Image "
                    "node with the passes is set up")
    preset: EnumProperty(
        name="Preset", default="BALANCED", items=ITEMS["preset"], **_upd(_update_preset),
        description="Speed against accuracy. The gather room at 80x60 (docs/accuracy.md): "
                    "Preview 0.024 s, Balanced 0.23 s, Quality 0.91 s, where Cycles needs 1.75 s "
                    "for 256 spp and is still noisier than Balanced. The advanced knobs start "
                    "from the selected preset's values")
    use_advanced: BoolProperty(
        name="Advanced", default=False, **_upd(_update_advanced),
        description="Render with the knobs below instead of the preset. They start from the "
                    "selected preset's values (picking a preset loads its values again); knobs "
                    "that differ from it show the preset's value beside them")
    method: _enum("method", "Method", "How the light of each reflective shadow map is gathered")
    aa_samples: IntProperty(
        name="AA Samples", default=config.KNOBS["aa_samples"][1], min=1, max=AA_SAMPLES_MAX,
        description="N x N camera samples per pixel (1 from AA Pixel Limit pixels up): anti-aliased edges "
                    "in the AOV. G-buffer cost "
                    "x N^2 (shading less with sample merging); the gather room's relMSE 0.0088 "
                    "-> 0.0057 from 1 to 2 (lattice 128, rays), 0.21 s -> 0.32 s")
    aa_pixel_limit: IntProperty(
        name="AA Pixel Limit", default=config.KNOBS["aa_pixel_limit"][1], min=0,
        description="From this many pixels up, one sample per pixel whatever AA Samples says (edge "
                    "pixels keep their Edge Samples rays); 0: no limit. Every preset: 76800 (320 x 240): "
                    "at 960 x 540 a Balanced frame takes 0.64-0.91x the time of 2 x 2 samples at about "
                    "the same error against Cycles (docs/pipeline.md)")
    shade_stride: IntProperty(
        name="Shade Stride", default=config.KNOBS["shade_stride"][1], min=1, max=SHADE_STRIDE_MAX,
        description="Shade one pixel in S x S and interpolate between them where neighbours "
                    "share a surface (edges are shaded directly). 2: a quarter of the shading "
                    "pairs for an error within 1-3 % of shading every pixel; 4: 1/16, 5.8 % "
                    "relative RMSE; 1: every pixel. Scaled up in images larger than Stride "
                    "Pixels")
    stride_pixels: IntProperty(
        name="Stride Pixels", default=config.KNOBS["stride_pixels"][1], min=0,
        description="The image size (pixels) Shade Stride is meant for: a larger image scales the "
                    "stride by the square root of its size over this, up to 8, so the shaded "
                    "pixels lie as far apart across the image (Shade Stride 1 is never scaled); 0: "
                    "the stride at every size. Every preset: 76800 (320 x 240), which shades one "
                    "pixel in 5 x 5 at 960 x 540: a Balanced frame 1.4-2x faster for a change "
                    "well under 5 % of its error against Cycles (docs/pipeline.md)")
    edge_samples: IntProperty(
        name="Edge Samples", default=config.KNOBS["edge_samples"][1], min=0, max=AA_SAMPLES_MAX,
        description="N x N camera rays in pixels that a geometric edge crosses (0 or N <= AA "
                    "Samples: off). Coverage only: such a pixel still shades one sample per "
                    "surface it sees, weighted by the rays that saw it, so silhouettes move "
                    "smoothly with the camera: frame-to-frame flicker 0.012-0.11 -> 0.006-0.07 "
                    "at 80 x 60 (docs/quality.md) for 5-35 % more time at that size")
    rsm_resolution: IntProperty(
        name="RSM Resolution", default=config.KNOBS["rsm_resolution"][1], min=RSM_RESOLUTION_MIN,
        max=RSM_RESOLUTION_MAX,
        description="Texels per side of each light's reflective shadow map (per cube face for "
                    "point lights): the density of virtual point lights. RSM and fit time grow "
                    "with its square (Preview 128, Balanced 256, Quality 512)")
    fit_mode: _enum("fit_mode", "Fit",
                    "How each light's RSM texels are clustered into VSGLs: error at equal count "
                    "and steadiness in animation (docs/accuracy.md, docs/quality.md)")
    vsgl_count: IntProperty(
        name="VSGLs per Light", default=config.KNOBS["vsgl_count"][1], min=1, max=VSGL_COUNT_MAX,
        description="Clusters per light (the lattice: its spacing over the light's bright area). "
                    "Shading cost grows with N; the lattice's diffuse relMSE on the spot room "
                    "is 0.00099 at 32, 0.00033 at 128, 0.00009 at 512. Not used by Two per Light")
    fis_iterations: IntProperty(
        name="FIS Iterations", default=config.KNOBS["fis_iterations"][1], min=1,
        max=FIS_ITERATIONS_MAX,
        description="Bisection steps sizing each FIS cluster's filter to its share of the "
                    "light; fit time only (8 is converged). FIS only")
    sharpness_estimator: _enum("sharpness_estimator", "Sharpness",
                               "How a VSGL's lobe sharpness is estimated from its texels' "
                               "directions; no cost difference, results within 5 %")
    diffuse_mode: _enum("diffuse_mode", "Diffuse Cosine",
                        "How the receiver's cosine is modelled in the diffuse integral")
    glossy_mode: _enum("glossy_mode", "Glossy Lobe",
                       "How the receiver's GGX lobe is modelled in the glossy integral")
    glossy_lobes: IntProperty(
        name="GGX Lobes", default=config.KNOBS["glossy_lobes"][1], min=4, max=5,
        description="Two ASGs only (GGX Core + Tail): GGX as 4 or 5 Gaussian lobes where a small lit "
                    "surface is reflected. 5 (Quality) follows GGX's peak closer (0.96 of it, 0.85 "
                    "with 4) for one lobe more per such pair: the spot room's glossy structured "
                    "error 0.000024 -> 0.000018 (docs/quality.md)")
    mrp_min_area: FloatProperty(
        name="Proxy Min Area", default=config.KNOBS["mrp_min_area"][1], min=0.0, soft_max=10.0,
        description="Rectangle Proxies and Hybrid: the smallest planar face (m^2, the rectangle fitted "
                    "to its coplanar triangles) reflected as a lit rectangle; the light of smaller "
                    "faces is not in the glossy pass (Hybrid: their VSGLs carry it). 0.25 in every "
                    "preset; the quality rooms' walls and floors (18-36 m^2) give the same image from "
                    "0.25 to 10 (docs/mrp.md)")
    visibility: _enum("visibility", "Visibility", "Indirect shadows between VSGLs and receivers")
    visibility_budget: FloatProperty(
        name="Ray Budget", default=config.KNOBS["visibility_budget"][1], min=-1.0, max=0.5, soft_min=0.0,
        description="Visibility Rays only: at each pixel, the weakest VSGLs, whose light there sums to at "
                    "most this fraction of all of theirs, trace no ray and take the others' visibility. "
                    "0.02 in every preset (the sphere room: 5.8x fewer rays, the same image within "
                    "0.001 FLIP); 0 = 0.02; negative: a ray for every VSGL")
    visibility_spread: FloatProperty(
        name="Ray Spread", default=config.KNOBS["visibility_spread"][1], min=-1.0, max=4.0, soft_min=0.0,
        description="Visibility Rays only: each VSGL's rays aim over a disk of this many of its cluster's "
                    "sigmas (each pixel at one of 16 points), so a shadow edge is a soft ramp as wide as "
                    "the lit patch's penumbra instead of one hard edge per VSGL (stripes where many "
                    "VSGLs stand behind one object). 2 in every preset (a disk with the cluster's own "
                    "spread); 0 = 2; negative: rays at each cluster's centre (hard edges)")
    dominant_rays: IntProperty(
        name="Dominant Rays", default=config.KNOBS["dominant_rays"][1], min=1, max=16,
        description="Visibility Rays only: rays per pixel and VSGL where that VSGL carries 0.5 % or more of "
                    "the pixel's light and a shadow's edge is near (a nearby pixel found it hidden): its "
                    "visibility is their mean instead of one ray's 0 or 1, so a soft indirect shadow is "
                    "smooth instead of grainy. 4 in every preset (0.9-1.1x the time); 1: one ray per pair")
    seed: IntProperty(
        name="Seed", default=0, min=0,
        description="Seed of the FIS and k-means cluster draws: moves where their clusters fall, "
                    "not the mean. The lattice and Two per Light draw nothing")
    leak_correction: _enum("leak_correction", "Leak Correction",
                           "Clip a VSGL's light to the front of its surface (the emitter clip)")
    sample_merging: _enum("sample_merging", "Sample Merging",
                          "Share the light between a pixel's samples on one surface "
                          "(needs AA Samples > 1)")
    output_path: StringProperty(
        name="Output", subtype="FILE_PATH", default=config.DEFAULT_TEMPLATE,
        **_PATH_OPTIONS, **_UPDATE,
        description="Per-frame multilayer EXR of the AOV. {render_dir} = the render output's "
                    "folder, {scene}, {view_layer}; #### = frame number (must be the last "
                    "digits). One file per frame and view layer: keep it off /tmp for renders "
                    "you keep")
    threads: IntProperty(
        name="Threads", default=0, min=0, max=1024,
        description="Worker threads of the library (0 = all cores; with Render > Threads set "
                    "to Fixed, that count). Time falls about linearly with cores")
    max_memory_gb: FloatProperty(
        name="Max Memory (GiB)", default=0.0, min=0.0, soft_max=256.0, precision=1,
        description="Refuse a frame whose estimated memory is above this, with a message "
                    "naming its size, instead of swapping (0 = the memory this machine has "
                    "available)")
    half_float: BoolProperty(
        name="Half Float", default=True, **_UPDATE,
        description="Write 16-bit half floats, like Blender's own EXR default: smaller files, "
                    "faster writes (a 1080p AOV of the test room: 1.6 MB in 2-3 s instead of "
                    "33 MB in 6 s; noise that does not compress: 38 MB instead of 157 MB) with "
                    "3 significant digits, plenty for light added in the compositor")
    color_passes: BoolProperty(
        name="Colour Passes", default=False, **_UPDATE,
        description="Also write the library's DiffCol and GlossCol (the receivers' Principled "
                    "colours) into the AOV EXR. Off: DiffInd, GlossInd, Diff, Gloss and Combined, "
                    "all the compositor setup reads (Diff = DiffInd x DiffCol; Cycles Colours uses "
                    "Cycles' own), 16 channels instead of 22 and a write about a quarter shorter")
    fail_render: BoolProperty(
        name="Fail Render Without AOV", default=False,
        description="For farms: when a frame's AOV cannot be computed, stop the render. "
                    "In the background (blender -b ... -f/-a) Blender exits with status 1 before "
                    "writing that frame, so the task fails and is retried; in the UI the error is "
                    "shown. Off: the frame renders without indirect light and the log says "
                    "VSGL ERROR")
    strength: FloatProperty(
        name="Strength", default=1.0, min=0.0, max=1.0, precision=3, subtype="FACTOR",
        **_upd(_update_grading),
        description="Factor of the indirect light added in the compositor (1 = physical, with "
                    "Cycles rendering direct light only; lower it to grade the bounce down). "
                    "It is the Add nodes' factor, so it costs nothing and needs no new AOV")
    use_diffuse: BoolProperty(
        name="Diffuse", default=True, **_upd(_update_grading),
        description="Add the diffuse indirect light (pass Diff = DiffInd x DiffCol); off mutes "
                    "its Add node")
    use_glossy: BoolProperty(
        name="Glossy", default=True, **_upd(_update_grading),
        description="Add the glossy indirect light (pass Gloss = GlossInd x GlossCol); off "
                    "mutes its Add node")
    use_cycles_colors: BoolProperty(
        name="Cycles Colours", default=False, **_UPDATE,
        description="Multiply the light-only passes (DiffInd, GlossInd) by Cycles' own DiffCol and "
                    "GlossCol of the same render instead of adding Diff and Gloss: exact receiver "
                    "colours for any node setup (turns the view layer's colour passes on)")
    export_passes: BoolProperty(
        name="Export Passes", default=False, **_UPDATE,
        description="Also write one multilayer EXR per frame with the render's passes and the "
                    "VSGL passes side by side (a File Output node), for grading in Nuke, Resolve "
                    "or Fusion. Costs one more EXR write per frame")
    export_path: StringProperty(
        name="Passes File", subtype="FILE_PATH", default="{render_dir}/passes/{scene}_",
        **_PATH_OPTIONS, **_UPDATE,
        description="Prefix of the passes EXR: the frame number and .exr are appended "
                    "({render_dir}, {scene} as for Output)")
    cycles_saved: StringProperty(
        name="Saved Cycles Bounces", default="", options={"HIDDEN"},
        description="Cycles' light path bounces before 'Cycles: Direct Light Only', for "
                    "'Restore Bounces' (internal)")


classes = (VSGLIndirectSettings,)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.vsgl_indirect = PointerProperty(type=VSGLIndirectSettings)


def unregister():
    del bpy.types.Scene.vsgl_indirect
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
