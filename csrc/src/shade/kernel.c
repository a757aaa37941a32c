/* Vectorised shading kernel: GCC vectorises the loop over receivers; the
 * function is cloned for AVX-512, AVX2 and baseline x86-64 and the best
 * clone is picked at load time (ifunc), so the shipped library runs on
 * any x86-64 machine. Built with -O3 -fno-math-errno (Makefile). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#  define KERNEL_ATTR __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#  define KERNEL_ATTR
#endif
#define KERNEL_NAME vsgl__kernel_shade
#include "shade/kernel_impl.h"
