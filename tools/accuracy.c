/* Accuracy report: relMSE of every fit mode and VSGL count against
 * brute-force VPL gathering on the same RSMs, per scene, diffuse and glossy
 * separately, with shading time. Output: a Markdown table (docs/accuracy.md).
 * Build: tools/accuracy.sh. Usage: accuracy [width height rsm] */
#include "accuracy.h"

#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double mean(const float *v, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        s += v[i];
    return s / (double)n;
}

int main(int argc, char **argv)
{
    uint32_t W = argc > 1 ? (uint32_t)atoi(argv[1]) : 80, H = argc > 2 ? (uint32_t)atoi(argv[2]) : 60;
    uint32_t rsm = argc > 3 ? (uint32_t)atoi(argv[3]) : 64;
    const char *fit_names[4] = {"two", "fis", "kmeans", "lattice"};
    const char *diff_names[3] = {"accurate", "sg", "pulled"}; /* by VSGL_COSINE_* value */
    const uint32_t counts[6] = {2, 8, 32, 128, 512, 2048};
    printf("Image %ux%u, 1 sample/pixel, RSM %u^2, reference: brute-force gathering of every RSM texel.\n\n", W, H, rsm);
    for (int k = 0; k < ACC_SCENES; ++k) {
        fx_scene fx;
        const char *name;
        acc_scene(&fx, k, W, H, &name);
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
        s.visibility = VSGL_VISIBILITY_NONE;
        s.aa_samples = 1;
        s.rsm_resolution = rsm;
        s.method = VSGL_METHOD_BRUTE_FORCE;
        acc_planes ref, got;
        vsgl_render_stats st = {.size = sizeof st};
        double t0 = now();
        if (!acc_render(k, W, H, &s, &ref, &st))
            return 1;
        size_t n = (size_t)W * H * 3;
        printf("### Scene %d: %s\n\nreference %.2f s; mean diffuse %.4g, mean glossy %.4g\n\n", k, name, now() - t0,
               mean(ref.diffuse, n), mean(ref.glossy, n));
        printf("| fit | VSGLs/light | diffuse mode | estimator | leak corr. | VSGLs | relMSE diffuse | relMSE glossy | mean glossy | shade s |\n");
        printf("|---|---|---|---|---|---|---|---|---|---|\n");
        s.method = VSGL_METHOD_VSGL;
        for (int f = 0; f < 4; ++f)
            for (int c = 0; c < (f == 0 ? 1 : 6); ++c)
                for (int d = 0; d < 3; ++d)
                    for (int e = 0; e < 3; ++e) {
                        /* e: 0 Toksvig, 1 Banerjee, 2 Toksvig without leak correction */
                        if ((d != VSGL_COSINE_ACCURATE || e != 0) && !(f == 1 && c == 3) &&
                            !(e == 2 && d == VSGL_COSINE_ACCURATE && f > 0 && c >= 3))
                            continue; /* mode/estimator/leak sweep only at a few points */

                        s.leak_correction = e == 2 ? VSGL_LEAK_OFF : VSGL_LEAK_AUTO;
                        s.fit_mode = f;
                        s.vsgl_count = f == 0 ? 1 : counts[c];
                        s.diffuse_mode = d;
                        s.sharpness_estimator = e == 1 ? VSGL_SHARPNESS_BANERJEE : VSGL_SHARPNESS_TOKSVIG;
                        if (!acc_render(k, W, H, &s, &got, &st))
                            return 1;
                        printf("| %s | %u | %s | %s | %s | %u | %.4g | %.4g | %.4g | %.3f |\n", fit_names[f],
                               f == 0 ? 2 : counts[c], diff_names[d], e == 1 ? "banerjee" : "toksvig",
                               e == 2 ? "off" : "on", st.vsgl_count,
                               acc_relmse(got.diffuse, ref.diffuse, n), acc_relmse(got.glossy, ref.glossy, n),
                               mean(got.glossy, n), st.seconds_shade);
                        acc_free(&got);
                    }
        printf("\n");
        acc_free(&ref);
    }
    return 0;
}
