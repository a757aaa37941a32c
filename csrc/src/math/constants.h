/* Numeric constants shared by every stage (one definition each). */
#ifndef VSGL_MATH_CONSTANTS_H
#define VSGL_MATH_CONSTANTS_H

#define VSGL__PI_D     3.14159265358979323846
#define VSGL__PI       3.14159265358979323846f
#define VSGL__2PI      6.28318530717958647692f
#define VSGL__INV_PI   0.31830988618379067154f
#define VSGL__LOG_2PI  1.83787706640934548356f
#define VSGL__LOG_PI   1.14472988584940017414f

/* The smallest value a divisor, a squared length or a variance is clamped
 * to before it divides or goes under a root: far below any physical
 * quantity of a scene in metres and watts, far above FLT_MIN. */
#define VSGL__TINY     1e-30f

#endif
