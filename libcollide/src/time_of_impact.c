/* Time of impact: the instant inside a step at which a crossing vertex reaches contact_gap from its
 * edge. The gap function is evaluated by re-integrating the involved bodies from the step's start,
 * so the impact state is the one the integrator would have produced, not an interpolation. */
#include <math.h>
#include <string.h>
#include "world.h"

/* Gap of the crossing's vertex at time tau after s0, minus the target gap. */
static double gap_at(lc_world *w, const double *s0, double tau, const lc_crossing *c, const int *rows,
                     int nrows, lc_touch *touches, int nt, double *scratch, double target)
{
    if (tau > 0.0) {
        /* only the listed rows are integrated into scratch: a static body's row is copied once below */
        if (lc_integrate_rows(w, s0, tau, rows, nrows, touches, nt, scratch) != 0) return NAN;
        w->last.toi_iterations++;
        return lc_vertex_edge_gap(w, scratch, c->a, c->vertex, c->b, c->edge) - target;
    }
    return lc_vertex_edge_gap(w, s0, c->a, c->vertex, c->b, c->edge) - target;
}

/* d/dt of the gap at s0: the relative normal velocity of the vertex against the edge. */
static double gap_rate(const lc_world *w, const double *s0, const lc_crossing *c)
{
    lc_touch t;
    t.a = c->a;
    t.b = c->b;
    t.vertex = c->vertex;
    t.edge = c->edge;
    lc_touch_update(w, s0, &t);
    return t.vn;
}

double lc_time_of_impact(lc_world *w, const double *s0, double h, const lc_crossing *c,
                         const int *rows, int nrows, lc_touch *touches, int nt, double *scratch)
{
    const lc_world_def *d = &w->def;
    double a = 0.0, b = h, fa, fb, m = 0.0, fm, target = d->contact_gap;
    int it, side = 0;
    double va;
    w->last.toi_searches++;
    /* the crossing's rows as at s0 (a static body is not integrated), the others not read */
    memcpy(&scratch[c->a * 6], &s0[c->a * 6], 6 * sizeof(double));
    memcpy(&scratch[c->b * 6], &s0[c->b * 6], 6 * sizeof(double));
    fa = gap_at(w, s0, 0.0, c, rows, nrows, touches, nt, scratch, target);
    va = gap_rate(w, s0, c);
    if (!(fa > d->toi_distance_tolerance)) {
        /* already within the contact gap: approaching is an impact now; hardly moving is a resting
         * contact, which the contact forces hold, not an impact */
        if (va < -d->resting_speed) return 0.0;
        if (!(va > 0.0)) return -1.0;
    }
    fb = gap_at(w, s0, h, c, rows, nrows, touches, nt, scratch, target);
    if (!isfinite(fb)) return -1.0;
    if (!(fa > d->toi_distance_tolerance)) {
        /* The vertex is leaving the gap (it just bounced) and comes back within the step: g has a root
         * at 0 and the one we want later. Start the bracket at the apex of the parabola through
         * g(0), g'(0) and g(h), where the gap is open. */
        double acc;
        /* A weak bounce from inside the gap band may never rise to contact_gap: then the impact is
         * where the vertex comes back to the gap it left from. */
        double start_gap = fa + target;
        if (start_gap - d->toi_distance_tolerance < target) {
            target = start_gap - d->toi_distance_tolerance;
            fa = d->toi_distance_tolerance;
            fb = gap_at(w, s0, h, c, rows, nrows, touches, nt, scratch, target);
            if (!isfinite(fb)) return -1.0;
        }
        acc = 2.0 * (fb - fa - va * h) / (h * h);
        double apex = acc < 0.0 ? -va / acc : 0.5 * h;
        int k;
        if (!(apex < h)) apex = 0.5 * h;
        for (k = 0; k < 30; ++k, apex *= 0.5) {
            double fx = gap_at(w, s0, apex, c, rows, nrows, touches, nt, scratch, target);
            if (!isfinite(fx)) return -1.0;
            if (fx > fa) { a = apex; fa = fx; break; }
        }
        if (k == 30) return 0.0;                  /* never opens: treat as touching now */
    }
    if (fb > 0.0) {
        /* the vertex crossed and came back out within the step (rotation): find a sample inside */
        int k;
        for (k = 1; k < 8 && fb > 0.0; ++k) {
            b = a + (h - a) * k / 8.0;
            fb = gap_at(w, s0, b, c, rows, nrows, touches, nt, scratch, target);
        }
        if (!(fb <= 0.0)) return -1.0;            /* no impact in this step */
    }
    for (it = 0; it < d->toi_max_iterations; ++it) {
        if (d->toi_method == LC_TOI_BINARY_SEARCH) {
            m = 0.5 * (a + b);
        } else {
            /* Illinois false position: superlinear, and halving the stale end keeps it from stalling */
            m = (a * fb - b * fa) / (fb - fa);
            if (!(m > a && m < b)) m = 0.5 * (a + b);
        }
        fm = gap_at(w, s0, m, c, rows, nrows, touches, nt, scratch, target);
        if (!isfinite(fm)) return -1.0;
        if (fabs(fm) <= d->toi_distance_tolerance && d->toi_method == LC_TOI_ROOT_FINDER) return m;
        if (fm > 0.0) {
            a = m;
            fa = fm;
            if (side == 1) fb *= 0.5;
            side = 1;
        } else {
            b = m;
            fb = fm;
            if (side == -1) fa *= 0.5;
            side = -1;
        }
        if (b - a <= d->toi_time_tolerance) break;
        if (d->toi_method == LC_TOI_BINARY_SEARCH && fa <= d->toi_distance_tolerance) break;
    }
    /* the early end keeps the gap on the positive side of contact_gap: never a penetrating state */
    return a;
}

/* A vertex-against-edge root is the first contact of that vertex only. Where two corners meet, the
 * other body's corner can dip in first, entering near the end of an edge and so along a path none of
 * the crossing tests sees, and be inside at that root. The separating-axis distance of the pair is
 * continuous in time and negative exactly when the two overlap, so bisecting on it from a separated
 * start finds a time at which the pair touches at the contact gap and nothing overlaps. */
double lc_pair_time_of_impact(lc_world *w, const double *s0, double h, int a, int b, const int *rows, int nrows,
                              lc_touch *touches, int ntouches, double reach, double *scratch)
{
    const lc_world_def *d = &w->def;
    double lo = 0.0, hi = h, g_lo = reach < INFINITY ? lc_pair_separation(w, s0, a, b) - d->contact_gap : 0.0;
    int it;
    w->last.toi_searches++;
    /* the pair's rows as at s0 (a static body is not integrated), the others not read */
    memcpy(&scratch[a * 6], &s0[a * 6], 6 * sizeof(double));
    memcpy(&scratch[b * 6], &s0[b * 6], 6 * sizeof(double));
    for (it = 0; it < 200 && (hi - lo > d->toi_time_tolerance || g_lo > reach); ++it) {
        double m = 0.5 * (lo + hi), g;
        if (lc_integrate_rows(w, s0, m, rows, nrows, touches, ntouches, scratch) != 0) return -1.0;
        w->last.toi_iterations++;
        g = lc_pair_separation(w, scratch, a, b) - d->contact_gap;
        if (!isfinite(g)) return -1.0;
        if (g > 0.0) {
            lo = m;
            g_lo = g;
        } else {
            hi = m;
        }
        if (g > 0.0 && g <= d->toi_distance_tolerance) break;
    }
    return lo;
}
