/* The baseline x86-64 (SSE2) copy of the shading kernel (see kernel_isa_v4.c). */
#include "kernel_isa.h"

#if KERNEL_ISA_CLONES
#  define KERNEL_ATTR __attribute__((target("arch=x86-64")))
#  define KERNEL_NAME test_kernel_isa_base
#  include "shade/kernel_impl.h"
#endif
