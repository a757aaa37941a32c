/* The shading kernel alone on one thread (make bench): one block of 64
 * receivers (glossy floor-like lanes with a diffuse lobe) against 256
 * random VSGLs above it, for each diffuse form, diffuse only, glossy only
 * and both; pixel-VSGL pairs per second, the best of 5 runs. The VSGLs
 * are the sharp kind a room's k-means clusters give (|m| >= 32 on most
 * lanes), so the short forms are exercised; docs/performance.md. Denormals
 * are flushed as in the library's shading workers.
 *
 * Usage: bench_kernel [repeats] */
#include "shade/kernel.h"
#include "vsgl/sg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__x86_64__) || defined(__i386__)
#  include <xmmintrin.h>
#endif

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static float uniform(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (float)(*s >> 40) * (1.0f / 16777216.0f);
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? atoi(argv[1]) : 3000;
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(_mm_getcsr() | 0x8040u); /* FTZ | DAZ, as the library's shading workers */
#endif
    enum { NL = 256 };
    static vsgl_kernel_light L[NL];
    static vsgl_kernel_block b;
    unsigned long long s = 1;
    for (int k = 0; k < NL; ++k) {
        vsgl_kernel_light *l = &L[k];
        memset(l, 0, sizeof *l);
        l->mx = 2.0f * uniform(&s) - 1.0f;
        l->my = 2.0f * uniform(&s) - 1.0f;
        l->mz = 2.0f * uniform(&s);
        l->var = 0.001f + 0.05f * uniform(&s);
        l->pvar = 2.0f * l->var;
        l->planar = 1.0f; /* the lattice's coherent diffuse clusters: the planar glossy model */
        l->u1x = 1.0f; l->u2y = 1.0f;
        l->var2 = 2.0f * l->var;
        l->ivar = 1.0f / l->var;
        l->valid = 1.0f;
        float ax = uniform(&s) - 0.5f, ay = uniform(&s) - 0.5f, az = -1.0f, n = sqrtf(ax * ax + ay * ay + az * az);
        l->ax = ax / n; l->ay = ay / n; l->az = az / n;
        l->lv = 3.0f * uniform(&s);
        l->lax = l->lv * l->ax; l->lay = l->lv * l->ay; l->laz = l->lv * l->az;
        l->c0 = 1.0f / (6.2831853f * vsgl_sg_integral(l->lv));
        l->pr = l->pg = l->pb = 1.0f;
        l->nz = 1.0f;
        l->clip = 0.5f;
        l->conv = 1.0f;
        l->fore = 1.0f; /* their plane spread (kernel.h, vsgl__plane_spread) */
        l->ibehind = 1.0f / (0.02f * sqrtf(l->var));
    }
    for (int i = 0; i < VSGL__KERNEL_BLOCK; ++i) {
        b.x[i] = uniform(&s); b.y[i] = uniform(&s); b.z[i] = -1.0f;
        b.nz[i] = 1.0f;
        b.diffuse[i] = 1.0f;
        b.Xx[i] = 1.0f; b.Yy[i] = 1.0f; b.Zz[i] = 1.0f;
        b.lam[i] = 10.0f + 100.0f * uniform(&s);
        b.mu[i] = 10.0f + 100.0f * uniform(&s);
        b.camp[i] = 1.0f;
        b.f0r[i] = b.f0g[i] = b.f0b[i] = 0.5f;
        b.fa[i] = 1.0f; /* no Fresnel ratio (scene/material.h vsgl__fresnel_ratio) */
    }
    const char *mode_name[3] = {"accurate", "SG (poster)", "pulled-out"};
    const char *lobe_name[4] = {"", "diffuse only", "glossy only", "diffuse + glossy"};
    printf("kernel alone, one thread, one block of %d receivers x %d VSGLs, best of 5:\n", VSGL__KERNEL_BLOCK, NL);
    for (int lobes = 1; lobes <= 3; ++lobes)
        for (int mode = 0; mode < 3; ++mode) {
            if (lobes == VSGL__KERNEL_GLOSSY && mode > 0)
                continue;
            double best = 1e30;
            for (int t = 0; t < 5; ++t) {
                memset(b.ld, 0, sizeof b.ld);
                memset(b.ls, 0, sizeof b.ls);
                double t0 = now();
                for (int r = 0; r < reps; ++r)
                    vsgl__kernel_shade(&b, L, NL, NULL, mode, lobes, 0.0f);
                double dt = now() - t0;
                best = dt < best ? dt : best;
            }
            double pairs = (double)reps * NL * VSGL__KERNEL_BLOCK;
            printf("kernel  %-16s %-12s %.3g pairs/s  (%.2f ns per pair)\n", lobe_name[lobes],
                   lobes == VSGL__KERNEL_GLOSSY ? "" : mode_name[mode], pairs / best, 1e9 * best / pairs);
            if (!(b.ld[0][0] >= 0.0f && b.ls[0][0] >= 0.0f)) /* keep the sums alive */
                printf("kernel  unexpected sum\n");
        }
    return 0;
}
