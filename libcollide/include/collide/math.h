/* libcollide: 2D vector type shared by the public API. */
#ifndef COLLIDE_MATH_H
#define COLLIDE_MATH_H

/* A 2D vector or point, in metres (or m/s, N, ... as the field says). */
typedef struct lc_vec2 {
    double x;
    double y;
} lc_vec2;

#endif /* COLLIDE_MATH_H */
