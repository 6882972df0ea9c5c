/* How touching bodies respond to a push at a contact: the entries of A = J M^-1 J^T (change of
 * relative velocity along one direction at one touch per unit impulse along another at another),
 * and applying an equal and opposite push to the two bodies of a touch. Shared by impacts, resting
 * contact forces and the position projection, which differ only in what is pushed. */
#include <string.h>
#include "world.h"

double lc_response_dir(const lc_world *w, const lc_touch *ti, lc_vec2 di, const lc_touch *tj, lc_vec2 dj)
{
    double sum = 0.0;
    int bi[2], bj[2], x, y;
    bi[0] = ti->a; bi[1] = ti->b;
    bj[0] = tj->a; bj[1] = tj->b;
    for (x = 0; x < 2; ++x) {
        lc_vec2 ri = x == 0 ? ti->ra : ti->rb;
        if (w->is_static[bi[x]]) continue;
        for (y = 0; y < 2; ++y) {
            lc_vec2 rj = y == 0 ? tj->ra : tj->rb;
            if (bj[y] != bi[x]) continue;
            /* body a of a touch is pushed along +d, body b along -d */
            sum += (x == y ? 1.0 : -1.0) * (lc_dot(di, dj) * w->inv_mass[bi[x]] +
                                            lc_cross(ri, di) * lc_cross(rj, dj) * w->inv_inertia[bi[x]]);
        }
    }
    return sum;
}

void lc_response_matrix(const lc_world *w, const lc_touch *t, int n, double *A)
{
    int i, j;
    for (i = 0; i < n; ++i)
        for (j = i; j < n; ++j) {
            double v = lc_response_dir(w, &t[i], t[i].n, &t[j], t[j].n);
            A[i * n + j] = v;
            A[j * n + i] = v;
        }
}

void lc_touch_apply(const lc_world *w, const lc_touch *t, lc_vec2 push, double *dst, int stride)
{
    if (!w->is_static[t->a]) {
        double *d = &dst[t->a * stride];
        d[0] += push.x * w->inv_mass[t->a];
        d[1] += push.y * w->inv_mass[t->a];
        d[2] += lc_cross(t->ra, push) * w->inv_inertia[t->a];
    }
    if (!w->is_static[t->b]) {
        double *d = &dst[t->b * stride];
        d[0] -= push.x * w->inv_mass[t->b];
        d[1] -= push.y * w->inv_mass[t->b];
        d[2] -= lc_cross(t->rb, push) * w->inv_inertia[t->b];
    }
}

double lc_response_push(const lc_world *w, const lc_touch *t, lc_vec2 d, const double *acc)
{
    double v = 0.0;
    if (!w->is_static[t->a]) {
        const double *x = &acc[t->a * 3];
        v += lc_dot(d, lc_add(lc_v(x[0], x[1]), lc_wcross(x[2], t->ra)));
    }
    if (!w->is_static[t->b]) {
        const double *x = &acc[t->b * 3];
        v -= lc_dot(d, lc_add(lc_v(x[0], x[1]), lc_wcross(x[2], t->rb)));
    }
    return v;
}

void lc_response_rows(const lc_world *w, const lc_touch *t, int m, int from_tangent, const double *x,
                      int to_tangent, double *body, double *out)
{
    int i;
    /* only the touches' bodies are written and read: a small group in a large world clears just those */
    if (2 * m < w->count) {
        for (i = 0; i < m; ++i) {
            memset(&body[t[i].a * 3], 0, 3 * sizeof(double));
            memset(&body[t[i].b * 3], 0, 3 * sizeof(double));
        }
    } else {
        memset(body, 0, (size_t)w->count * 3 * sizeof(double));
    }
    for (i = 0; i < m; ++i)
        if (x[i] != 0.0)
            lc_touch_apply(w, &t[i], lc_scale(from_tangent ? lc_tangent_of(t[i].n) : t[i].n, x[i]), body, 3);
    for (i = 0; i < m; ++i) out[i] = lc_response_push(w, &t[i], to_tangent ? lc_tangent_of(t[i].n) : t[i].n, body);
}
