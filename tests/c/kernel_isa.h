/* Per-instruction-set copies of the shading kernel for the tests
 * (kernel_isa_*.c; GCC on x86-64 only, like the library's clones). */
#ifndef VSGL_TEST_KERNEL_ISA_H
#define VSGL_TEST_KERNEL_ISA_H

#include "shade/kernel.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#  define KERNEL_ISA_CLONES 1
size_t test_kernel_isa_v4(vsgl_kernel_block *b, const vsgl_kernel_light *L, size_t count, const float *visibility,
                          int32_t diffuse_mode, int32_t lobes, float faint);
size_t test_kernel_isa_v3(vsgl_kernel_block *b, const vsgl_kernel_light *L, size_t count, const float *visibility,
                          int32_t diffuse_mode, int32_t lobes, float faint);
size_t test_kernel_isa_base(vsgl_kernel_block *b, const vsgl_kernel_light *L, size_t count, const float *visibility,
                            int32_t diffuse_mode, int32_t lobes, float faint);
#else
#  define KERNEL_ISA_CLONES 0
#endif

#endif
