/* The same kernel as kernel.c built without vectorisation: the baseline
 * of `make bench` and a cross-check in the tests. */
#pragma GCC optimize("no-tree-vectorize")
#define KERNEL_ATTR
#define KERNEL_NAME vsgl__kernel_shade_scalar
#include "shade/kernel_impl.h"
