/* Copies of the shading kernel compiled for each instruction set the
 * library's clones target (x86-64-v4 = AVX-512, v3 = AVX2, baseline), so
 * that a test on one machine checks every clone's arithmetic, not only the
 * one its loader picks. Each is the same source as csrc/src/shade/kernel.c;
 * only the target differs; the Makefile builds them with kernel.c's flags.
 * One copy per file: the kernel's helpers are static. */
#include "kernel_isa.h"

#if KERNEL_ISA_CLONES
#  define KERNEL_ATTR __attribute__((target("arch=x86-64-v4")))
#  define KERNEL_NAME test_kernel_isa_v4
#  include "shade/kernel_impl.h"
#endif
