/* Internal: the EXR writer's float -> half packing (exr.c). */
#ifndef VSGL_IO_HALF_H
#define VSGL_IO_HALF_H

#include <stddef.h>
#include <stdint.h>

/* Non-zero when this CPU and OS can run the F16C conversion (x86-64 with
 * F16C, AVX and the AVX state saved by the OS); 0 elsewhere. */
int vsgl__exr_cpu_has_f16c(void);

/* w finite samples, `stride` floats apart from row, to half floats (2
 * bytes each, native order) at d: rounded to nearest even, beyond +/-65504
 * clamped to it. With the F16C instruction when `f16c` is non-zero (only
 * pass vsgl__exr_cpu_has_f16c()'s answer), else one sample at a time; both
 * give the same bits (tests/c/test_exr.c compares them with an exact
 * reference). */
void vsgl__exr_row_to_half(const float *row, size_t stride, uint32_t w, unsigned char *d, int f16c);

#endif
