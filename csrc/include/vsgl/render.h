/**
 * @file vsgl/render.h
 * @brief One-bounce indirect light of a scene as Cycles-compatible planes:
 * settings (every approximation has a knob), outputs, statistics.
 *
 * Pipeline: G-buffer (camera samples) -> one RSM per light (texel = VPL)
 * -> VSGL fit (2 per light | FIS | k-means) -> SG/ASG shading -> planes.
 * The brute-force method shades with every RSM texel instead of VSGLs (the
 * internal ground truth).
 */
#ifndef VSGL_RENDER_H
#define VSGL_RENDER_H

#include "scene.h"
#include "sg.h" /* VSGL_COSINE_*, VSGL_SHARPNESS_* */

#ifdef __cplusplus
extern "C" {
#endif

#define VSGL_METHOD_VSGL        0  /**< VSGL fit + SG/ASG product integrals */
#define VSGL_METHOD_BRUTE_FORCE 1  /**< every RSM texel as a point light, exact BRDF */

#define VSGL_FIT_TWO    0  /**< poster: one diffuse + one specular VSGL per light (one cluster cannot
                                tell a sunlit roof from the floor under it: a sun room renders 9-16x
                                too bright, docs/quality.md; the presets use the lattice) */
#define VSGL_FIT_FIS    1  /**< filtered importance sampling over RSM mips */
#define VSGL_FIT_KMEANS 2  /**< k-means in image + world space */
#define VSGL_FIT_LATTICE 3 /**< world-space lattice with tent weights, one cluster per surface orientation:
                                continuous in the light's motion (no flicker), overlapping (no blotches) */

#define VSGL_GLOSSY_ASG  0 /**< receiver lobe as a warped ASG (the zero default; the viewport's Live quality) */
#define VSGL_GLOSSY_SG   1 /**< receiver lobe as a warped SG (reference path) */
#define VSGL_GLOSSY_ASG2 2 /**< receiver lobe as two warped ASGs, GGX's core and tail (balanced, quality):
                               one Gaussian puts the 40 % of GGX's energy that is in its tail into its
                               core, so a metal floor's reflection of a lit wall is too bright in its
                               middle and too dark around it; the two lobes follow GGX within 18 % up to
                               3 alpha (tools/fit_ggx_lobes.py). Spot room at 80x60: glossy structured
                               error 0.0049 -> 0.0004, no bundled room worse (docs/quality.md); the
                               glossy stage at twice the cost */
#define VSGL_GLOSSY_MRP  3 /**< experimental: glossy light from rectangle proxies (the MRP paper,
                               docs/mrp.md): the scene's large planar faces (>= mrp_min_area), lit by this
                               frame's RSMs, reflected by each receiver's warped ASG lobe in closed form;
                               light from anything else (curved or small surfaces) is not in the glossy
                               pass; 0.9-1.5x the one-thread CPU of k-means 256 in the quality rooms,
                               with a glossy error above ASG2's (balanced) in all of them (docs/mrp.md
                               §4). Diffuse as ASG */
#define VSGL_GLOSSY_HYBRID 4 /**< experimental: ASG2, except where every glossy receiver of a pixel is
                               sharp (roughness <= 0.5) and MRP (above) finds more than twice the
                               on-proxy VSGLs' estimate of the proxies' light: there MRP's light plus
                               the VSGLs whose clusters lie on no proxy (nothing counts twice). Since
                               the half-vector model no pixel of the quality suite's metal floors
                               qualifies: the same glossy pass as ASG2 at the cost of the MRP pass on
                               top (docs/mrp.md §4). Diffuse as ASG2 */

#define VSGL_VISIBILITY_NONE 0
#define VSGL_VISIBILITY_RAY  1  /**< one ray from the shading point to each VSGL centre / VPL */

/* Emitter-hemisphere clip (the light-leak correction): VPLs on a surface
 * emit only in front of it, with a clamped cosine; the papers' SG lobe
 * leaks ~9 % of a cluster's light behind its surface (a sunlit roof lights
 * the ceiling under it, a floor lights itself) and is 15-25 % off in the
 * far field. With the clip, a cluster gives nothing behind or in its own
 * plane, nothing to receivers facing its way, the clamped cosine's falloff
 * far away, and a lattice cluster's glossy light comes from its plane seen
 * foreshortened. Weighted by how coherent the cluster's normals are (the
 * lattice's clusters: fully). docs/accuracy.md measures it.
 * The near field (ON): within a lattice cluster's own extent the SG model
 * breaks (its Gaussian spills past the junction where its surface ends, a
 * dark seam along every junction of a room); within one to two lattice
 * spacings of a cell and one of its plane, the cluster is its cell of
 * uniform radiosity, truncated to its VPLs' extent, and its diffuse light
 * the cell's exact polygon form factor. docs/quality.md measures it. */
#define VSGL_LEAK_AUTO 0  /**< on */
#define VSGL_LEAK_OFF  1  /**< the papers' model */
#define VSGL_LEAK_ON   2  /**< the clip and the lattice's near field */
#define VSGL_LEAK_CLIP 3  /**< the clip alone: the far-field model everywhere (0.3's ON) */

/* Sample merging: within a pixel, samples on the same surface (same
 * material, normals within 5 degrees, no step along the normal; sharp
 * glossy materials, roughness < 0.5, never merge) share the light shaded
 * at their centroid, weighted by their own colours; edges keep every
 * sample. About aa^2 times fewer shading pairs; the error it
 * adds is measured in docs/accuracy.md. */
#define VSGL_MERGE_AUTO 0 /**< on */
#define VSGL_MERGE_OFF  1 /**< shade every sample */

#define VSGL_PRESET_PREVIEW  0
#define VSGL_PRESET_BALANCED 1
#define VSGL_PRESET_QUALITY  2
#define VSGL_PRESET_AUTO     3 /**< balanced's knobs with auto_target BALANCED: chosen per scene at render time */

/* The auto budget (vsgl_render_settings.auto_target): at render time the
 * library chooses knobs for the scene by rules measured against Cycles on
 * the bundled scenes (docs/trade.md, "The auto preset"), from what the
 * per-light budget's probe sees (a 32-wide grid of camera rays, each
 * light's 16^2 probe RSM): the glossy lobe model from the sharpest glossy
 * material the camera sees, and each
 * light's RSM side from its footprint (the probe texels whose light
 * reaches what the camera sees); anti-aliasing follows the image size as
 * in every render (aa_pixel_limit, which the auto preset takes from
 * balanced). Never more than the knobs as set. The stats' `budget` text
 * and the log say what it chose and why. */
#define VSGL_AUTO_OFF      0 /**< the knobs as set (the default) */
#define VSGL_AUTO_BALANCED 1 /**< the error of the balanced preset, at less cost where the scene allows */

/* Valid ranges of the numeric settings (zero selects the default). One
 * source for the library, the CLI (--help, docs/cli.md) and the add-on's
 * property limits (libvsgl.py mirrors them; tests check the mirror). */
#define VSGL_AA_SAMPLES_MAX        16
#define VSGL_RSM_RESOLUTION_MIN    2
#define VSGL_RSM_RESOLUTION_MAX    8192
#define VSGL_VSGL_COUNT_MAX        65536
#define VSGL_FIS_ITERATIONS_MAX    32
#define VSGL_SHADE_STRIDE_MAX      8

/**
 * Render settings. Zero-initialised means "default" for every field, so
 * the default of each is stated. @p size: sizeof(vsgl_render_settings) or 0.
 */
typedef struct vsgl_render_settings {
    uint32_t size;
    int32_t method;              /**< VSGL_METHOD_*, default VSGL */
    uint32_t aa_samples;         /**< samples per pixel per axis (N x N), default 1 */
    uint32_t rsm_resolution;     /**< RSM side in texels (cube faces: per face), default 256 */
    int32_t fit_mode;            /**< VSGL_FIT_*, default TWO (the presets: LATTICE) */
    uint32_t vsgl_count;         /**< VSGLs per light for FIS/k-means; lattice: about this many per light
                                      (more where surfaces of several orientations share the lit area), default 64 */
    uint32_t fis_iterations;     /**< bisection steps of the mip level, default 8 */
    int32_t sharpness_estimator; /**< VSGL_SHARPNESS_*, default TOKSVIG */
    int32_t diffuse_mode;        /**< VSGL_COSINE_*, default ACCURATE */
    int32_t glossy_mode;         /**< VSGL_GLOSSY_*, default ASG */
    int32_t visibility;          /**< VSGL_VISIBILITY_*, default NONE */
    uint32_t seed;               /**< for FIS / k-means sampling, default 0 */
    int32_t leak_correction;     /**< VSGL_LEAK_*, default AUTO */
    int32_t sample_merging;      /**< VSGL_MERGE_*, default AUTO (on) */
    uint32_t shade_stride;       /**< shade one pixel in S x S and interpolate the light between them where
                                      neighbours share a surface (joint bilateral on the G-buffer; edges
                                      are shaded), 1..VSGL_SHADE_STRIDE_MAX; default 1 (every pixel) */
    uint32_t edge_samples;       /**< samples per axis traced in a pixel where a geometric edge crosses it
                                      (E x E rays, E in 0..VSGL_AA_SAMPLES_MAX): the pixel still shades at
                                      most aa x aa samples, one per surface it sees, each weighted by the
                                      fraction of the E x E rays that saw it, so silhouettes move smoothly
                                      with the camera instead of in steps of 1/aa^2 (with aa_samples 1 a
                                      pixel gets three slots, for up to three surfaces); 0, or E <=
                                      aa_samples, is off (the default) */
    int32_t auto_target;         /**< VSGL_AUTO_*: OFF (the default) renders with the knobs as set;
                                      BALANCED aims at the balanced preset's error at less cost:
                                      rsm_resolution and glossy_mode are chosen for the scene, at
                                      most as set; the other knobs are taken as set (aa_samples
                                      follows aa_pixel_limit, as in every render) */
    float mrp_min_area;          /**< glossy_mode MRP and HYBRID: the smallest planar face (m^2, the area of
                                      the rectangle fitted to its coplanar triangles) made a rectangle
                                      proxy. Larger: fewer proxies, less time, fewer surfaces reflected;
                                      smaller: more. 0 means VSGL_MRP_MIN_AREA_DEFAULT; finite, >= 0
                                      (docs/mrp.md §4) */
    uint32_t glossy_lobes;       /**< glossy_mode ASG2: the Gaussian lobes GGX is taken as where a small lit
                                      surface is reflected (the half-vector model, docs/pipeline.md): 4 (0
                                      means 4; the balanced preset) or 5 (the quality preset: 0.96 of
                                      GGX's peak instead of 0.85, one lobe more per such pair) */
    float visibility_budget;     /**< visibility RAY: at each receiver, the VSGLs whose light there (radiant
                                      intensity over squared distance times the receiver's cosine, no BRDF)
                                      sums to at most this fraction of all of theirs, the weakest first, trace
                                      no ray and take the visibility of the others, weighted by that light:
                                      fewer rays (5.8x fewer in a room with a sphere at 0.02) for an error of
                                      at most the fraction times how unevenly the VSGLs are shadowed. 0 means
                                      VSGL_VISIBILITY_BUDGET_DEFAULT; negative: a ray for every pair; at most
                                      0.5 */
    uint32_t aa_pixel_limit;     /**< an image of at least this many pixels takes one sample per pixel
                                      whatever aa_samples says (edge pixels keep their edge_samples rays):
                                      there a pixel is small against how fast indirect light changes, and
                                      aa x aa samples buy little for their time (every preset:
                                      VSGL_AA_PIXEL_LIMIT_PRESETS). The log and the stats' `skipped` say
                                      when it applied. 0: no limit (the default) */
    uint32_t stride_pixels;      /**< the image size, in pixels, that shade_stride is meant for: an image of
                                      P > stride_pixels pixels shades one pixel in S' x S', S' = shade_stride
                                      x sqrt(P / stride_pixels) rounded down, at most VSGL_SHADE_STRIDE_MAX,
                                      so the shaded pixels lie as far apart across the image as at
                                      stride_pixels (indirect light is no less smooth in a larger image;
                                      the interpolation test still shades every pixel where the light
                                      between shaded ones is not smooth). Every preset:
                                      VSGL_STRIDE_PIXELS_PRESETS. The log and the stats' `skipped` say when
                                      it applied. shade_stride 1 (every pixel) is never scaled. 0:
                                      shade_stride at every size (the default) */
    float visibility_spread;     /**< visibility RAY: where a VSGL's rays aim. Its cluster is a lit patch, not a
                                      point: 16 points over a disk of radius spread x the cluster's in-plane
                                      sigma (2: a uniform disk with the cluster's own variance), pulled in
                                      where a surface is in the way, and each receiver aims at one of them,
                                      picked by a hash of its pixel. A shadow edge then becomes a dithered
                                      ramp as wide as the cluster's penumbra instead of one hard edge per
                                      VSGL (parallel stripes where many clusters stand behind one
                                      occluder), at one ray per pair as before. 0 means
                                      VSGL_VISIBILITY_SPREAD_DEFAULT; negative: every ray aims at the
                                      cluster's centre (hard edges); at most VSGL_VISIBILITY_SPREAD_MAX */
    uint32_t dominant_rays;      /**< visibility RAY: rays per pair for the pairs that carry a share of a
                                      receiver's light (at least VSGL_DOMINANT_SHARE of it by the
                                      visibility budget's weights, faded in from half that) where another
                                      receiver of its block of 64 found that VSGL blocked: their
                                      visibility is the mean over that many of the cluster's points, not
                                      one point's 0 or 1. Without them a soft indirect shadow is grain
                                      (the preview's floor beside a sphere: the pixel-scale noise 3x
                                      smaller at 4; balanced's wall behind a sun room's cabinet 4.5x;
                                      every preset: 4, for 0.9-1.1x the time at 960 x 540;
                                      docs/pipeline.md). 0 means 1 (one ray per pair); at most
                                      VSGL_DOMINANT_RAYS_MAX */
} vsgl_render_settings;

/** vsgl_render_settings.aa_pixel_limit of every preset: 320 x 240. */
#define VSGL_AA_PIXEL_LIMIT_PRESETS (320u * 240u)
/** vsgl_render_settings.stride_pixels of every preset: 320 x 240 (960 x 540: 2 -> 5, 1920 x 1080: 2 -> 8). */
#define VSGL_STRIDE_PIXELS_PRESETS (320u * 240u)

/** vsgl_render_settings.visibility_spread when it is 0, and its largest value. */
#define VSGL_VISIBILITY_SPREAD_DEFAULT 2.0f
#define VSGL_VISIBILITY_SPREAD_MAX 4.0f

/** vsgl_render_settings.dominant_rays: its largest value, and the share of a receiver's light from
 *  which a pair takes them all (from half of it, a mix of one ray and all of them). */
#define VSGL_DOMINANT_RAYS_MAX 16u
#define VSGL_DOMINANT_SHARE 0.005f

/** vsgl_render_settings.visibility_budget when it is 0. */
#define VSGL_VISIBILITY_BUDGET_DEFAULT 0.02f

/** vsgl_render_settings.mrp_min_area when it is 0 (m^2). */
#define VSGL_MRP_MIN_AREA_DEFAULT 0.25f

/** @brief Fill @p out with a preset (VSGL_PRESET_*); unknown presets give BALANCED. */
VSGL_API void vsgl_render_settings_preset(int32_t preset, vsgl_render_settings *out);

/**
 * Output planes, caller-owned, each width*height*3 floats (RGB), rows from
 * the top of the image down, or NULL if not wanted. Names follow Cycles:
 * DiffInd/GlossInd are light only (divided by colour); the coloured
 * contribution is DiffInd*DiffCol + GlossInd*GlossCol = @p combined.
 */
typedef struct vsgl_render_output {
    uint32_t size;               /**< sizeof(vsgl_render_output) or 0 */
    uint32_t width, height;      /**< must equal the camera's */
    float *diffuse_light;        /**< DiffInd */
    float *glossy_light;         /**< GlossInd */
    float *diffuse_color;        /**< DiffCol */
    float *glossy_color;         /**< GlossCol */
    float *diffuse;              /**< DiffInd * DiffCol */
    float *glossy;               /**< GlossInd * GlossCol */
    float *combined;             /**< diffuse + glossy */
    float *alpha;                /**< width*height floats: pixel coverage */
} vsgl_render_output;

/**
 * What a render did, for logs and the add-on's panel. Set @p size to
 * sizeof(vsgl_render_stats) or 0 (or zero the struct) before the call: the
 * render fills that many bytes (an older caller's shorter struct gets the
 * fields it knows) and leaves @p size as it was.
 */
typedef struct vsgl_render_stats {
    uint32_t size;               /**< sizeof(vsgl_render_stats) or 0; read, not written */
    double seconds_total;
    double seconds_scene_prep;   /**< settings, memory estimate, output checks: everything before the G-buffer */
    double seconds_gbuffer;
    double seconds_rsm;
    double seconds_fit;
    double seconds_shade;
    uint32_t lights_used;
    uint32_t lights_skipped;
    uint32_t vsgl_count;         /**< VSGLs shaded, all lights */
    uint64_t shading_pairs;      /**< sample x VSGL evaluations */
    char skipped[1024];          /**< what was skipped and why, one item per line; when they do not all
                                      fit, the last line says so (the log has every item) */
    uint32_t reused;             /**< stages taken from a vsgl_render_cache: VSGL_REUSED_* bits */
    char budget[512];            /**< with two or more lights that light something: what each light got
                                      and why, one line per light ("light 1: 36 % of the light on what the
                                      camera sees: 152 VSGLs, RSM 213 (uniform 192, 256)"). vsgl_count and
                                      rsm_resolution are then a budget per light: each light's share
                                      follows the square root of the light it sends onto what the camera
                                      sees (a 16^2 probe RSM gathered at a 32-wide grid of camera rays),
                                      with a floor of a quarter of the uniform share; the totals stay the
                                      settings' (docs/pipeline.md). Empty with one light (the settings
                                      apply as they are) unless auto_target chose knobs: then its first
                                      lines say what was chosen and why */
} vsgl_render_stats;

#define VSGL_REUSED_GBUFFER 1u /**< the G-buffer (same scene, camera, AA) */
#define VSGL_REUSED_FIT     2u /**< the RSMs' VSGLs (same scene, lights, settings) */

/**
 * What a render will allocate, in bytes, before it allocates anything
 * (see ::vsgl_render_estimate). Upper estimates of the peak: the G-buffer,
 * the planes and the scratch of every stage are alive at once while the
 * largest of rsm and fit is.
 */
typedef struct vsgl_memory_estimate {
    uint64_t output;         /**< the caller's output planes (width x height x output floats per pixel) */
    uint64_t gbuffer;        /**< camera samples: width x height x aa^2 x 56; with edge refinement
                                  (edge_samples > aa_samples) x 64, + 1 per pixel, and at aa 1 two
                                  slots per pixel; + 12 per sample in a scene with smooth-shaded
                                  triangles (where visibility rays start) */
    uint64_t planes;         /**< the library's own accumulation planes: 52 per pixel */
    uint64_t rsm;            /**< reflective shadow maps alive at once (one; every light's with brute force), 72 per texel */
    uint64_t fit;            /**< moment grids and cluster labels of the largest light's fit */
    uint64_t shade;          /**< shading scratch of every worker thread and the VSGL table */
    uint64_t total;          /**< the sum of the fields above */
    uint64_t limit;          /**< the context's max_memory, or what the machine has available if that is 0 */
} vsgl_memory_estimate;

/**
 * @brief Validate @p settings exactly as ::vsgl_render does and estimate
 * the memory a render of @p scene with them needs; refuse what exceeds
 * the context's memory limit. ::vsgl_render makes the same check before
 * allocating, so a render that cannot fit fails at once with a message
 * naming the image size, the estimate and the limit.
 * @param[in] output_floats_per_pixel floats per pixel of the output planes the
 *        caller will pass (7 RGB planes + alpha = 22); counted in @p out->output.
 * @param[out] out filled whenever the settings are valid (also on
 *        ::VSGL_ERROR_OUT_OF_MEMORY). May be NULL.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (settings; message names
 *         the field), ::VSGL_ERROR_OUT_OF_MEMORY (the estimate is above the limit).
 */
VSGL_API vsgl_result vsgl_render_estimate(vsgl_context *ctx, const vsgl_scene *scene,
                                          const vsgl_render_settings *settings,
                                          uint32_t output_floats_per_pixel,
                                          vsgl_memory_estimate *out);

/**
 * @brief Render the indirect AOV planes.
 * @param[in,out] out planes to fill; every non-NULL plane is written
 *        completely on success and left untouched on failure.
 * @param[out] stats may be NULL; its size must be set (sizeof or 0).
 * A scene without lights, or whose every light is skipped, renders black
 * planes and logs a warning saying why.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (settings or output
 *         sizes; message names the field), ::VSGL_ERROR_OUT_OF_MEMORY (also
 *         up front, before anything is allocated, when ::vsgl_render_estimate
 *         exceeds the context's memory limit), ::VSGL_ERROR_CANCELLED.
 */
VSGL_API vsgl_result vsgl_render(vsgl_context *ctx, const vsgl_scene *scene,
                                 const vsgl_render_settings *settings,
                                 vsgl_render_output *out, vsgl_render_stats *stats);

/** Stage results kept between renders (see ::vsgl_render_cached). */
typedef struct vsgl_render_cache vsgl_render_cache;

/** @brief An empty render cache. @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT, ::VSGL_ERROR_OUT_OF_MEMORY. */
VSGL_API vsgl_result vsgl_render_cache_create(vsgl_context *ctx, vsgl_render_cache **out);

/** @brief Release a cache and what it holds. NULL is allowed. */
VSGL_API void vsgl_render_cache_destroy(vsgl_render_cache *cache);

/**
 * @brief ::vsgl_render, reusing the stages whose inputs did not change
 * since the last render through @p cache (the live viewport: a light moved,
 * or the camera).
 *
 * The G-buffer is reused while the scene (the same ::vsgl_scene, its
 * geometry and materials: a scene is identified by its address and its
 * creation, so a new scene at a destroyed one's address is never taken
 * for it), its camera and the AA samples are unchanged; the VSGLs while the
 * scene, its lights and the settings are unchanged. Both are compared
 * bytewise, so a render through a cache is bit-identical to one without.
 * @p stats: reused stages report 0 seconds, and `reused` says which.
 * A render that fails once started (e.g. cancelled) leaves the cache
 * empty; one refused up front (bad settings or sizes) leaves it as it was.
 * With shade_stride > 1 the cache also keeps the G-buffer's shading plan
 * (what shading needs that no light changes: each anchor's lobe, each
 * sample's interpolation weights and colours), which a render with
 * the same G-buffer, stride and glossy mode replays instead of
 * recomputing it (a light edit), bit-identically as well. The cache holds
 * memory (the G-buffer: vsgl_memory_estimate.gbuffer; the plan: about 40
 * bytes per sample, 28 per pixel, 190 per anchor and 100 per sample shaded
 * itself, plus 32 per sample of a batch of rows once replayed; the pixel
 * planes of the VSGL method, 52 bytes per pixel; none of it in the
 * estimate) until the next render through it or its destruction; one
 * cache must not be used by two calls at once.
 * @p cache NULL is ::vsgl_render.
 */
VSGL_API vsgl_result vsgl_render_cached(vsgl_context *ctx, const vsgl_scene *scene,
                                        const vsgl_render_settings *settings, vsgl_render_cache *cache,
                                        vsgl_render_output *out, vsgl_render_stats *stats);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_RENDER_H */
