/* Shading: a VSGL's incident-radiance SG (Eq. 7) against the point-light
 * limit, and diffuse shading against exact irradiance from a small source. */
#include "harness.h"
#include "shade/shade.h"

#include <string.h>

#define PI 3.14159265358979323846

static vsgl_vsgl make_vsgl(float mx, float my, float mz, float var, float ax, float ay, float az, float sharp)
{
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.mean = v3_make(mx, my, mz);
    v.variance = var;
    v.axis = v3_normalize(v3_make(ax, ay, az));
    v.sharpness = sharp;
    v.power[0] = v.power[1] = v.power[2] = 1.0f;
    return v;
}

/* Exact: a point source of intensity I(w) = G(w; axis, l)/A(l) seen at distance d. */
static double point_intensity(const vsgl_vsgl *v, v3 x)
{
    v3 d = v3_sub(x, v->mean); /* emitted direction: from the VSGL towards x */
    double dist = v3_length(d);
    double c = v3_dot(v3_scale(d, (float)(1.0 / dist)), v->axis);
    double l = v->sharpness;
    double A = l > 0 ? 2 * PI * -expm1(-2 * l) / l : 4 * PI;
    return exp(l * (c - 1)) / A / (dist * dist);
}

VT_TEST(shade_incident_sg_integrates_to_point_light_limit)
{
    vt_rng rng = {5};
    for (int i = 0; i < 200; ++i) {
        float sharp = (float)(vt_uniform(&rng) * 20.0);
        vsgl_vsgl v = make_vsgl((float)vt_uniform(&rng), (float)vt_uniform(&rng), 2.0f + (float)vt_uniform(&rng),
                                1e-6f, (float)vt_uniform(&rng) - 0.5f, (float)vt_uniform(&rng) - 0.5f, -1.0f, sharp);
        v3 x = v3_make((float)vt_uniform(&rng) - 0.5f, (float)vt_uniform(&rng) - 0.5f, 0.0f);
        vsgl_sg in;
        VT_CHECK(vsgl__vsgl_incident_sg(&v, x, &in), "lobe");
        double got = vsgl_sg_lobe_integral(&in);
        double want = point_intensity(&v, x);
        VT_CHECK_REL(got, want, 2e-3, "sharpness %g", (double)sharp);
        v3 dir = v3_normalize(v3_sub(v.mean, x));
        VT_CHECK(v3_dot(in.axis, dir) > 0.9999f, "incident axis points at the VSGL (sharpness %g)", (double)sharp);
    }
}

VT_TEST(shade_incident_sg_survives_receiver_at_centre_and_zero_variance)
{
    vsgl_vsgl v = make_vsgl(1, 2, 3, 0.0f, 0, 0, 1, 5.0f);
    vsgl_sg in;
    /* at the centre with no spread there is nothing to integrate: rejected */
    VT_CHECK(!vsgl__vsgl_incident_sg(&v, v.mean, &in), "degenerate accepted");
    /* zero variance away from it: floored, finite */
    VT_CHECK(vsgl__vsgl_incident_sg(&v, v3_make(1, 2, 0), &in), "floored variance");
    VT_CHECK(isfinite(in.sharpness) && isfinite(in.log_amplitude), "sharp %g log amp %g",
             (double)in.sharpness, (double)in.log_amplitude);
    v.variance = 0.01f;
    VT_CHECK(vsgl__vsgl_incident_sg(&v, v.mean, &in), "at centre with spread");
    VT_CHECK(isfinite(vsgl_sg_lobe_integral(&in)) && vsgl_sg_lobe_integral(&in) > 0, "finite positive");
}

/* Diffuse shading of a small isotropic source: the accurate and pulled-out
 * cosine modes must give the exact irradiance I cos(theta) / d^2 when the
 * source is above the horizon. */
VT_TEST(shade_diffuse_modes_match_point_irradiance)
{
    const float angles_deg[5] = {0, 30, 60, 80, 89};
    for (int a = 0; a < 5; ++a) {
        float th = angles_deg[a] * (float)PI / 180.0f;
        vsgl_vsgl v = make_vsgl(2.0f * sinf(th), 0, 2.0f * cosf(th), 1e-5f, 0, 0, 1, 0.0f);
        v3 x = v3_make(0, 0, 0), n = v3_make(0, 0, 1);
        vsgl_sg in;
        vsgl__vsgl_incident_sg(&v, x, &in);
        double want = 1.0 / (4 * PI) * cos(th) / 4.0;
        double acc = vsgl_sg_cosine_integral(&in, &n, VSGL_COSINE_ACCURATE);
        double pulled = vsgl_sg_cosine_integral(&in, &n, VSGL_COSINE_PULLED_OUT);
        VT_CHECK_REL(acc, want, 1e-2, "accurate at %g deg", (double)angles_deg[a]);
        VT_CHECK_REL(pulled, want, 1e-2, "pulled-out at %g deg", (double)angles_deg[a]);
    }
}

/* The emitter clip's fade behind a cluster's plane: a planar cluster's
 * stays 2 % of a sigma wide (nothing reaches behind a wall), a curved
 * one's widens with its normals' spread and is centred on the plane, so
 * that a receiver 5 mm either side of it (the floor under a sphere, as the
 * sphere's cluster moves with the light) is not switched on and off: 17x
 * in one frame before (docs/accuracy.md). */
VT_TEST(emitter_clip_of_a_curved_cluster_fades_across_its_plane)
{
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.mean = v3_make(0.0f, 0.0f, 0.0f);
    v.normal = v3_make(0.0f, 0.0f, 1.0f);
    v.variance = 0.01f; /* sigma 0.1 m */
    v.lobe = VSGL__LOBE_SPECULAR;
    const v3 n = v3_make(-1.0f, 0.0f, 0.0f); /* facing the cluster sideways: no parallel clip */
    float f[2][2];
    for (int curved = 0; curved < 2; ++curved) {
        v.coherence = curved ? 0.96f : 1.0f;
        for (int side = 0; side < 2; ++side)
            f[curved][side] = vsgl__emitter_clip(&v, v3_make(0.3f, 0.0f, side ? 0.005f : -0.005f), n, 1);
    }
    VT_CHECK(f[0][0] < 1e-6f && f[0][1] > 0.999f, "planar: behind %g, in front %g (a sharp clip)", (double)f[0][0],
             (double)f[0][1]);
    VT_CHECK(f[1][1] / f[1][0] < 4.0f, "curved: behind %g, in front %g: more than 4x across 1 cm", (double)f[1][0],
             (double)f[1][1]);
    VT_CHECK(f[1][0] > 0.2f && f[1][1] < 0.8f, "curved: behind %g, in front %g: the fade is not centred on the plane",
             (double)f[1][0], (double)f[1][1]);
}
