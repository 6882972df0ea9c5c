/* The contact regime's view of one island: searches and rows (contact_island.h). */
#include <math.h>
#include "contact_island.h"

/* How far a pair's points can close on each other within h at most: the relative speed of their
 * farthest points and the relative applied acceleration (its term times acc_factor). */
static double closing_bound(const lc_contact_island *c, int a, int b, double h, double acc_factor)
{
    const lc_world *w = c->w;
    const double *sa = &w->state[a * 6], *sb = &w->state[b * 6];
    double dvx = sa[SVX] - sb[SVX], dvy = sa[SVY] - sb[SVY], v, acc = 0.0;
    int la = c->local[a], lb = c->local[b];
    v = sqrt(dvx * dvx + dvy * dvy) + fabs(sa[SW]) * w->shape[a].radius + fabs(sb[SW]) * w->shape[b].radius;
    {
        double ax = 0.0, ay = 0.0, al = 0.0;
        if (la >= 0) { ax += c->b.acc[la * 3]; ay += c->b.acc[la * 3 + 1]; al += fabs(c->b.acc[la * 3 + 2]) * w->shape[a].radius; }
        if (lb >= 0) { ax -= c->b.acc[lb * 3]; ay -= c->b.acc[lb * 3 + 1]; al += fabs(c->b.acc[lb * 3 + 2]) * w->shape[b].radius; }
        acc = sqrt(ax * ax + ay * ay) + al;
    }
    return h * v + 0.5 * h * h * acc * acc_factor;
}

double lc_contact_island_start_margin(const void *ctx, int a, int b)
{
    const lc_contact_island *c = ctx;
    return c->w->def.contact_distance + closing_bound(c, a, b, c->start_h, 1.0);
}

int lc_contact_island_collect(lc_contact_island *c, double h, lc_buf *buf, int mode, double reach, double *margin)
{
    lc_world *w = c->w;
    int k, n = 0;
    for (k = 0; k < c->isl->npairs; ++k) {
        int a = c->isl->pairs[2 * k], b = c->isl->pairs[2 * k + 1];
        double gap = w->def.contact_distance + reach +
                     (mode == LC_SEARCH_STEP ? closing_bound(c, a, b, h, 1.0)
                      : mode == LC_SEARCH_NEXT_STEP ? closing_bound(c, a, b, h, 2.0) : 0.0);
        if (margin != NULL) margin[k] = gap;
        n = lc_collect_touches_within(w, w->state, a, b, gap, w->def.contact_distance, buf, n);
        if (n < 0) return -1;
    }
    return n;
}

void lc_contact_island_row(const lc_contact_island *c, const lc_touch *t, lc_contact_row *r)
{
    const lc_world *w = c->w;
    lc_vec2 tg = lc_tangent_of(t->n);
    r->a = w->is_static[t->a] ? -1 : c->local[t->a];
    r->b = w->is_static[t->b] ? -1 : c->local[t->b];
    r->nx = t->n.x;
    r->ny = t->n.y;
    r->rna = lc_cross(t->ra, t->n);
    r->rnb = lc_cross(t->rb, t->n);
    r->rta = lc_cross(t->ra, tg);
    r->rtb = lc_cross(t->rb, tg);
    r->mu = t->friction;
    r->slip = 0;
    r->target_n = 0.0;
    r->lambda_n = r->lambda_t = 0.0;
}
