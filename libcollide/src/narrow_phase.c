/* Narrow phase: vertex-against-edge geometry. Touches (resting contacts and impact points) and
 * crossings (a vertex whose path entered another body during a step), as in the seed's vertex tests. */
#include <math.h>
#include "world.h"

typedef struct frame { double x, y, c, s; } frame;

static frame frame_of(const lc_world *w, const double *state, int row)
{
    frame f;
    const double *s = &state[row * 6];
    f.x = s[SX];
    f.y = s[SY];
    lc_body_trig(w, row, s[SA], &f.c, &f.s);
    return f;
}

/* World point of body-frame point p. */
static lc_vec2 to_world(frame f, lc_vec2 p) { return lc_add(lc_v(f.x, f.y), lc_rot(f.c, f.s, p)); }
/* Body-frame coordinates of world point p. */
static lc_vec2 to_local(frame f, lc_vec2 p) { return lc_rot_inv(f.c, f.s, lc_v(p.x - f.x, p.y - f.y)); }

static double edge_distance(const lc_shape *sh, int k, lc_vec2 local)
{
    return lc_dot(sh->n[k], lc_sub(local, sh->v[k]));
}

/* Position along edge k as a fraction of its length (0 at v[k], 1 at v[k+1]). */
static double edge_param(const lc_shape *sh, int k, lc_vec2 local, double *len_out)
{
    lc_vec2 a = sh->v[k], b = sh->v[(k + 1) % sh->count];
    lc_vec2 e = lc_sub(b, a);
    double len2 = lc_dot(e, e);
    *len_out = sqrt(len2);
    return lc_dot(lc_sub(local, a), e) / len2;
}

double lc_vertex_edge_gap(const lc_world *w, const double *state, int a, int vertex, int b, int edge)
{
    frame fa = frame_of(w, state, a), fb = frame_of(w, state, b);
    lc_vec2 p = to_world(fa, w->shape[a].v[vertex]);
    return edge_distance(&w->shape[b], edge, to_local(fb, p));
}

/* lc_touch_update with the frames of t->a and t->b at state already at hand. */
static void touch_update(const lc_world *w, const double *state, frame fa, frame fb, lc_touch *t)
{
    const double *sa = &state[t->a * 6], *sb = &state[t->b * 6];
    lc_vec2 va, vb;
    t->ra = lc_rot(fa.c, fa.s, w->shape[t->a].v[t->vertex]);
    t->p = lc_add(lc_v(fa.x, fa.y), t->ra);
    t->n = lc_rot(fb.c, fb.s, w->shape[t->b].n[t->edge]);
    t->rb = lc_sub(t->p, lc_v(fb.x, fb.y));
    t->gap = lc_dot(t->n, lc_sub(t->p, to_world(fb, w->shape[t->b].v[t->edge])));
    va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], t->ra));
    vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], t->rb));
    t->vn = lc_dot(t->n, lc_sub(va, vb));
}

void lc_touch_update(const lc_world *w, const double *state, lc_touch *t)
{
    touch_update(w, state, frame_of(w, state, t->a), frame_of(w, state, t->b), t);
}

int lc_touch_refresh(const lc_world *w, const double *state, lc_touch *t, double extent)
{
    frame fa = frame_of(w, state, t->a), fb = frame_of(w, state, t->b);
    const lc_shape *sb = &w->shape[t->b];
    lc_vec2 local = to_local(fb, to_world(fa, w->shape[t->a].v[t->vertex]));
    double len, u, grow, deepest = -INFINITY;
    int k, least = t->edge;
    for (k = 0; k < sb->count; ++k) {
        double d = edge_distance(sb, k, local);
        if (d > deepest) {
            deepest = d;
            least = k;
        }
    }
    /* inside b: the edge it is least deep behind, as the vertex-in-body test finds it */
    if (deepest < 0.0) t->edge = least;
    touch_update(w, state, fa, fb, t);
    if (deepest < 0.0) return 1;
    /* outside b but behind its edge's line: beside the edge, not in it */
    if (t->gap < 0.0) return 0;
    /* as face_touches keeps a vertex: over the edge, the edge grown by extent for one within extent */
    u = edge_param(sb, t->edge, local, &len);
    grow = t->gap < extent ? extent : 0.0;
    return !(u * len < -grow || (u - 1.0) * len > grow);
}

static double mix(lc_mix_rule r, double x, double y)
{
    switch (r) {
    case LC_MIX_MIN: return x < y ? x : y;
    case LC_MIX_MAX: return x > y ? x : y;
    case LC_MIX_MEAN: return 0.5 * (x + y);
    case LC_MIX_GEOMETRIC: return sqrt(x * y);
    }
    return x < y ? x : y;
}

/* fa, fb: the frames of a and b at state. */
static int push_touch(const lc_world *w, const double *state, frame fa, frame fb, lc_buf *buf, int count,
                      int first_of_pair, int a, int vertex, int b, int edge, double max_gap)
{
    lc_touch *t = (lc_touch *)buf->p;
    lc_vec2 p = to_world(fa, w->shape[a].v[vertex]);
    /* A point already recorded for this pair at (nearly) the same place is the same contact. "Nearly"
     * is max_gap, but never more than a quarter of either body's shortest edge, so two corners of one
     * body are never one contact. A contact_distance of 0.5 m (the API allows up to 1 m) would
     * otherwise merge the two corners of a 5 cm box's end, and a corner sinking into a wall would be
     * dropped for its neighbour on the surface, so the end-of-step projection never sees the overlap.
     * A bound by the body's radius instead of its edge is not enough for a thin box (5 cm x 90 cm:
     * a quarter of its radius is 11 cm). Regression inputs: fuzz/corpus/step-regressions/
     * overlap-merged-corners-large-contact-distance, overlap-merged-corners-thin-box-contact-distance-0.5. */
    double merge = fmin(max_gap, 0.25 * fmin(w->shape[a].min_edge, w->shape[b].min_edge));
    int j;
    for (j = first_of_pair; j < count; ++j) {
        lc_vec2 d = lc_sub(t[j].p, p);
        if (lc_dot(d, d) < merge * merge) return count;
    }
    t = lc_buf_get(buf, (size_t)(count + 1) * sizeof(lc_touch));
    if (t == NULL) return -1;
    t += count;
    t->a = a;
    t->b = b;
    t->vertex = vertex;
    t->edge = edge;
    t->elasticity = mix(w->def.elasticity_rule, w->elasticity[a], w->elasticity[b]);
    t->friction = mix(w->def.friction_rule, w->friction[a], w->friction[b]);
    t->value = 0.0;
    t->vn_pre = 0.0;
    t->target_vn = 0.0;
    t->tangent = 0.0;
    touch_update(w, state, fa, fb, t);
    return count + 1;
}

/* Body a's vertices in the frame of body b (fa, fb: their frames), into local[]. */
static void vertices_in(const lc_shape *sa, frame fa, frame fb, lc_vec2 *local)
{
    int i;
    for (i = 0; i < sa->count; ++i) local[i] = to_local(fb, to_world(fa, sa->v[i]));
}

/* Largest separation of a body's vertices (local[0..count), in the frame of the body of shape sb)
 * along the outward normals of sb's edges (the separating axis test): returns it and the edge in *edge. */
static double max_separation(const lc_shape *sb, const lc_vec2 *local, int count, int *edge)
{
    double best = -INFINITY;
    int i, k;
    *edge = 0;
    for (k = 0; k < sb->count; ++k) {
        double sep = INFINITY;
        for (i = 0; i < count; ++i) {
            double d = edge_distance(sb, k, local[i]);
            if (d < sep) sep = d;
        }
        if (sep > best) { best = sep; *edge = k; }
    }
    return best;
}

/* Vertices of body `inc` (local[]: in the frame of `ref`; fi, fr: the two frames) within max_gap of edge
 * `edge` of body `ref` and over its extent, grown by `extent` for the vertices within `extent` of the
 * edge's line: a vertex farther out that lies beyond the edge's end passes the end rather than hitting
 * the edge (a corner sliding over a seam between two slabs, 1e-7 m above the second slab's side). */
static int face_touches(const lc_world *w, const double *state, int inc, int ref, frame fi, frame fr,
                        const lc_vec2 *local, int edge, double max_gap, double extent, lc_buf *buf, int count,
                        int first_of_pair)
{
    const lc_shape *si = &w->shape[inc], *sr = &w->shape[ref];
    int i;
    for (i = 0; i < si->count && count >= 0; ++i) {
        double d = edge_distance(sr, edge, local[i]), len, u, grow;
        if (!(d < max_gap)) continue;
        u = edge_param(sr, edge, local[i], &len);
        grow = d < extent ? extent : 0.0;
        if (u * len < -grow || (u - 1.0) * len > grow) continue;
        count = push_touch(w, state, fi, fr, buf, count, first_of_pair, inc, i, ref, edge, max_gap);
    }
    return count;
}

double lc_pair_separation_axis(const lc_world *w, const double *state, int a, int b, int *ref, int *edge)
{
    frame fa = frame_of(w, state, a), fb = frame_of(w, state, b);
    lc_vec2 a_in_b[LC_MAX_POLYGON_VERTICES], b_in_a[LC_MAX_POLYGON_VERTICES];
    int ka, kb;
    double sb, sa;
    vertices_in(&w->shape[a], fa, fb, a_in_b);
    vertices_in(&w->shape[b], fb, fa, b_in_a);
    sb = max_separation(&w->shape[b], a_in_b, w->shape[a].count, &kb);
    sa = max_separation(&w->shape[a], b_in_a, w->shape[b].count, &ka);
    *ref = sa > sb ? a : b;
    *edge = sa > sb ? ka : kb;
    return sa > sb ? sa : sb;
}

double lc_pair_separation(const lc_world *w, const double *state, int a, int b)
{
    int ref, edge;
    return lc_pair_separation_axis(w, state, a, b, &ref, &edge);
}

int lc_collect_touches(const lc_world *w, const double *state, int a, int b, double max_gap,
                       lc_buf *buf, int count)
{
    return lc_collect_touches_within(w, state, a, b, max_gap, max_gap, buf, count);
}

int lc_collect_touches_within(const lc_world *w, const double *state, int a, int b, double max_gap, double extent,
                              lc_buf *buf, int count)
{
    int first = count, ka, kb, ref, inc, kref, kinc, k;
    double sep_a, sep_b, best = INFINITY;
    lc_vec2 n, a_in_b[LC_MAX_POLYGON_VERTICES], b_in_a[LC_MAX_POLYGON_VERTICES];
    frame fa, fb, fref, finc;
    if (w->is_static[a] && w->is_static[b]) return count;
    {
        /* bounding circles farther apart than max_gap: no touch, without the separating-axis test */
        double dx = state[a * 6 + SX] - state[b * 6 + SX], dy = state[a * 6 + SY] - state[b * 6 + SY];
        double r = w->shape[a].radius + w->shape[b].radius + max_gap;
        if (dx * dx + dy * dy > r * r) return count;
    }
    /* nor bounding boxes (a block near a long wall, whose bounding circle reaches everything) */
    if (lc_bounds_gap(w, state, a, b) > max_gap) return count;
    /* The contact normal of a pair comes from its separating axis: the face of either body along
     * which they are farthest apart (least overlap). At coincident corners of side-by-side boxes this
     * picks the shared vertical faces, never the collinear top or bottom faces. */
    fa = frame_of(w, state, a);
    fb = frame_of(w, state, b);
    vertices_in(&w->shape[a], fa, fb, a_in_b);
    vertices_in(&w->shape[b], fb, fa, b_in_a);
    sep_b = max_separation(&w->shape[b], a_in_b, w->shape[a].count, &kb);   /* a's vertices against b's faces */
    sep_a = max_separation(&w->shape[a], b_in_a, w->shape[b].count, &ka);   /* b's vertices against a's faces */
    if (!(sep_a < max_gap) && !(sep_b < max_gap)) return count;
    /* ties (within a hundredth of the gap) go to b's face so the choice does not flicker */
    if (sep_a > sep_b + 0.01 * w->def.contact_gap) { ref = a; kref = ka; inc = b; }
    else { ref = b; kref = kb; inc = a; }
    if (!(sep_a < max_gap) || !(sep_b < max_gap)) {
        /* separated along one body's face by more than max_gap: not touching */
        if ((ref == a ? sep_a : sep_b) >= max_gap) return count;
    }
    fref = ref == a ? fa : fb;
    finc = ref == a ? fb : fa;
    /* incident face: the face of the other body most opposed to the reference normal */
    n = lc_rot(fref.c, fref.s, w->shape[ref].n[kref]);
    kinc = 0;
    for (k = 0; k < w->shape[inc].count; ++k) {
        double d = lc_dot(n, lc_rot(finc.c, finc.s, w->shape[inc].n[k]));
        if (d < best) { best = d; kinc = k; }
    }
    count = face_touches(w, state, inc, ref, finc, fref, inc == a ? a_in_b : b_in_a, kref, max_gap, extent, buf,
                         count, first);
    if (count < 0) return count;
    /* the reference body's corners under the incident face (offset boxes: one point each way) */
    return face_touches(w, state, ref, inc, fref, finc, ref == a ? a_in_b : b_in_a, kinc, max_gap, extent, buf,
                        count, first);
}

static int crossings_one_way(const lc_world *w, int a, int b, frame fa0, frame fb0, frame fa1, frame fb1,
                             lc_buf *buf, int count)
{
    const lc_shape *sa = &w->shape[a], *sb = &w->shape[b];
    /* Penetrations shallower than half the contact gap are round-off around a resting contact (held at
     * contact_gap), not impacts; a vertex deeper than that at the start is an old overlap left to
     * stabilisation. */
    double start_tol = -0.5 * w->def.contact_gap;
    /* entering the contact-gap band from outside it is an impact too: impacts are handled at contact_gap */
    double band = w->def.contact_gap - w->def.toi_distance_tolerance;
    int i, k;
    for (i = 0; i < sa->count; ++i) {
        lc_vec2 l0 = to_local(fb0, to_world(fa0, sa->v[i]));
        lc_vec2 l1 = to_local(fb1, to_world(fa1, sa->v[i]));
        double dmax0 = -INFINITY, dmax1 = -INFINITY, first_s = INFINITY;
        int hit = -1, deepest = -1;
        for (k = 0; k < sb->count; ++k) {
            double d0 = edge_distance(sb, k, l0), d1 = edge_distance(sb, k, l1);
            if (d0 > dmax0) dmax0 = d0;
            if (d1 > dmax1) { dmax1 = d1; deepest = k; }
            /* the path (straight in b's frame) crosses edge k's line inward within the edge */
            /* a vertex resting near contact_gap wobbles by round-off; only one clearly outside the band
             * (beyond twice the gap) is caught entering it */
            double level = d0 > 2.0 * w->def.contact_gap ? band : start_tol;
            if (d0 >= start_tol && d1 < level) {
                double s = (d0 - level) / (d0 - d1), len, u;
                lc_vec2 x = lc_add(l0, lc_scale(lc_sub(l1, l0), s));
                u = edge_param(sb, k, x, &len);
                /* strictly within the edge: a corner gliding just over the end of a neighbour's face
                 * (a seam in the floor) does not hit that face; a path that really enters through the
                 * corner ends inside and is caught below by the least-penetrated edge */
                if (u >= 0.0 && u <= 1.0 && s < first_s) {
                    first_s = s;
                    hit = k;
                }
            }
        }
        if (dmax0 < start_tol) continue;          /* started inside */
        if (hit < 0) {
            if (!(dmax1 < start_tol)) continue;   /* ended outside and never crossed an edge */
            if (deepest < 0) continue;            /* non-finite coordinates: nothing to test */
            hit = deepest;                        /* rotation carried it in: least-penetrated edge */
        } else if (!(dmax1 < start_tol)) {
            /* crossed an edge line but ended outside: only a tunnel if it went through the body,
             * i.e. the crossing point was inside every other edge's half-plane */
            double s = first_s;
            lc_vec2 x = lc_add(l0, lc_scale(lc_sub(l1, l0), s));
            int inside = 1;
            for (k = 0; k < sb->count; ++k)
                if (k != hit && edge_distance(sb, k, x) > w->def.contact_distance) { inside = 0; break; }
            if (!inside) continue;
        }
        {
            lc_crossing *c = lc_buf_get(buf, (size_t)(count + 1) * sizeof(lc_crossing));
            if (c == NULL) return -1;
            c[count].a = a;
            c[count].b = b;
            c[count].vertex = i;
            c[count].edge = hit;
            c[count].t_lo = 0.0;
            c[count].toi = -1.0;
            c[count].clear_to = 0.0;
            c[count].by_pair = 0;
            c[count].t_hi = -1.0;   /* the caller knows the interval */
            count++;
        }
    }
    return count;
}

int lc_find_crossings(const lc_world *w, const double *s0, const double *s1, int a, int b,
                      lc_buf *buf, int count)
{
    frame fa0, fb0, fa1, fb1;
    if (w->is_static[a] && w->is_static[b]) return count;
    fa0 = frame_of(w, s0, a);
    fb0 = frame_of(w, s0, b);
    fa1 = frame_of(w, s1, a);
    fb1 = frame_of(w, s1, b);
    count = crossings_one_way(w, a, b, fa0, fb0, fa1, fb1, buf, count);
    if (count < 0) return count;
    return crossings_one_way(w, b, a, fb0, fa0, fb1, fa1, buf, count);
}
