/* VSGL accuracy against brute-force VPL gathering on the same RSMs (which
 * isolates the VSGL approximation from the RSM discretisation): on three
 * scenes (spot, point, area light), the error of FIS falls as the number
 * of VSGLs grows, and every mode stays within a bound of the reference. */
#include "harness.h"
#include "accuracy.h"

VT_TEST(accuracy_fis_error_falls_with_vsgl_count_on_three_scenes)
{
    const uint32_t W = 40, H = 30;
    const uint32_t counts[4] = {1, 8, 64, 512};
    for (int k = 0; k < ACC_SCENES; ++k) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.aa_samples = 1;
        s.rsm_resolution = 32;
        s.method = VSGL_METHOD_BRUTE_FORCE;
        acc_planes ref, got;
        if (!acc_render(k, W, H, &s, &ref, NULL)) {
            VT_CHECK(0, "scene %d reference failed", k);
            continue;
        }
        s.method = VSGL_METHOD_VSGL;
        s.fit_mode = VSGL_FIT_FIS;
        double err[4][2];
        for (int i = 0; i < 4; ++i) {
            s.vsgl_count = counts[i];
            VT_CHECK(acc_render(k, W, H, &s, &got, NULL), "scene %d N=%u", k, counts[i]);
            err[i][0] = acc_relmse(got.diffuse, ref.diffuse, (size_t)W * H * 3);
            err[i][1] = acc_relmse(got.glossy, ref.glossy, (size_t)W * H * 3);
            acc_free(&got);
        }
        for (int lobe = 0; lobe < 2; ++lobe) {
            VT_CHECK(err[3][lobe] < err[0][lobe],
                     "scene %d %s: relMSE N=512 %.4g not below N=1 %.4g (N=8 %.4g, N=64 %.4g)", k,
                     lobe ? "glossy" : "diffuse", err[3][lobe], err[0][lobe], err[1][lobe], err[2][lobe]);
            VT_CHECK(err[2][lobe] < err[0][lobe], "scene %d %s: relMSE N=64 %.4g not below N=1 %.4g", k,
                     lobe ? "glossy" : "diffuse", err[2][lobe], err[0][lobe]);
        }
        /* with many VSGLs the diffuse AOV is close to the reference */
        VT_CHECK(err[3][0] < 0.05, "scene %d: diffuse relMSE %.4g at N=512", k, err[3][0]);
        acc_free(&ref);
    }
}
