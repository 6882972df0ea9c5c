/* The event regime's detection: the vertices that entered another body during a trial interval, found
 * by the end-point test on the broad phase's pairs and by the swept check on pairs whose paths may have
 * dipped in and out again; crossings that are not impacts (stalled ones, a resting vertex's drift) are
 * left out, and after an impact in free flight the crossings of bodies it did not move are kept. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "event_crossings.h"
#include "tunables.h"

struct lc_event_crossings {
    lc_buf pairs;             /* the broad phase's pairs of the interval */
    lc_buf cross;             /* the crossings (count of them after the last search) */
    int count;
    lc_buf coupled, keys;     /* stamps of the bodies that touch another or are tied to one; drop_resting_drift's table */
    unsigned coupled_now;     /* coupled[row] == coupled_now: coupled in this search (older stamps: not) */
    int coupled_rows;         /* the rows coupled was cleared for (-1: none yet) */
    lc_buf in_cross;          /* the swept check's stamps of the bodies in a crossing, as coupled's */
    unsigned in_cross_now;
    int in_cross_rows;
    lc_buf sample0, sample1;  /* the swept check: an uncoupled pair's states at two sub-times */
    lc_buf samples;           /* and the whole world's at every sub-time */
    lc_buf part0, part1;      /* a pair tested in parts: its states at two part ends */
    lc_buf in_parts;          /* 1 for the pairs tested in parts (the swept check leaves them) */
};

lc_event_crossings *lc_event_crossings_create(void)
{
    lc_event_crossings *ec = calloc(1, sizeof(lc_event_crossings));
    if (ec != NULL) ec->coupled_rows = ec->in_cross_rows = -1;
    return ec;
}

/* A new stamp of a marks array of one unsigned per row (rows: the world size it was cleared for), or 0
 * without memory. A new stamp per use instead of clearing every mark: that was a pass over the world
 * per impact. All of them only for another world size, or when the stamps wrap. */
static unsigned new_stamp(lc_buf *marks, unsigned *now, int *rows, int count)
{
    unsigned *m = lc_buf_get(marks, (size_t)(count > 0 ? count : 1) * sizeof(unsigned));
    if (m == NULL) return 0;
    if (*rows != count || ++*now == 0) {
        memset(m, 0, (size_t)count * sizeof(unsigned));
        *rows = count;
        *now = 1;
    }
    return *now;
}

/* Stamps the bodies that touch another or are tied to another (coupled[row] = mark). */
static void mark_coupled(lc_world *w, unsigned *coupled, const lc_trial *tr, unsigned mark)
{
    int i;
    for (i = 0; i < tr->nrest; ++i) coupled[tr->rest[i].a] = coupled[tr->rest[i].b] = mark;
    for (i = 0; i < w->spring_count; ++i)
        if (w->springs[i].def.body_b != LC_WORLD_ANCHOR) {
            coupled[lc_world_body_index(w, w->springs[i].def.body_a)] = mark;
            coupled[lc_world_body_index(w, w->springs[i].def.body_b)] = mark;
        }
    /* the force callback may tie any body to any other */
    if (lc_force_callback_on(w))
        for (i = 0; i < w->count; ++i) coupled[i] = mark;
}

void lc_event_crossings_destroy(lc_event_crossings *ec)
{
    if (ec == NULL) return;
    lc_buf_free(&ec->pairs);
    lc_buf_free(&ec->cross);
    lc_buf_free(&ec->coupled);
    lc_buf_free(&ec->in_cross);
    lc_buf_free(&ec->keys);
    lc_buf_free(&ec->sample0);
    lc_buf_free(&ec->sample1);
    lc_buf_free(&ec->samples);
    lc_buf_free(&ec->part0);
    lc_buf_free(&ec->part1);
    lc_buf_free(&ec->in_parts);
    free(ec);
}

/* Key of a vertex against a body, for the hash table of drop_resting_drift. */
static uint32_t vertex_key(const lc_world *w, int a, int vertex, int b)
{
    uint32_t h = 2166136261u;
    h = (h ^ w->ids[a]) * 16777619u;
    h = (h ^ (uint32_t)vertex) * 16777619u;
    return (h ^ w->ids[b]) * 16777619u;
}

/* A crossing whose impact at time 0 had nothing to do (no point approaching: typically a resting point
 * that the contact forces did not hold exactly across the trial interval, crossing its own gap) would
 * stop time at that instant forever. Such a vertex is set aside for the rest of the step (the contact
 * forces and the end-of-step projection hold it), while every other vertex is still checked. */
static int drop_stalled_from(lc_event_crossings *ec, const lc_crossing *stalled, int nstalled, int from, int nc)
{
    lc_crossing *c = (lc_crossing *)ec->cross.p;
    int i, k, kept = from;
    if (nstalled == 0) return nc;   /* nothing to drop: no pass over every pending crossing */
    for (i = from; i < nc; ++i) {
        int skip = 0;
        for (k = 0; k < nstalled && !skip; ++k)
            skip = stalled[k].a == c[i].a && stalled[k].b == c[i].b && stalled[k].vertex == c[i].vertex;
        if (!skip) c[kept++] = c[i];
    }
    return kept;
}

static int drop_stalled(lc_event_crossings *ec, const lc_crossing *stalled, int nstalled, int nc)
{
    return drop_stalled_from(ec, stalled, nstalled, 0, nc);
}

/* A vertex held by a resting contact force can sink below its gap by what the force solver left
 * unresolved (a large pile, where the iterative solve stops at its sweep limit, leaves ~1e-2 m/s^2,
 * i.e. ~1e-6 m in a 1/60 s step). That is not an impact: the force still holds the vertex, and the
 * end-of-step projection lifts it back to the gap without touching velocities. Stopping time at it
 * would stop at every such vertex of the pile in turn, each stop re-solving the whole pile (a
 * 1275-box pyramid: thousands per step). A resting vertex that ends deeper than contact_distance is
 * more than solver residual and stays an impact. */
static int drop_resting_drift(const lc_world *w, lc_event_crossings *ec, const lc_touch *rest, int nrest, const double *s1,
                              int nc)
{
    lc_crossing *c = (lc_crossing *)ec->cross.p;
    int size = 1, i, kept = 0;
    int *table;
    if (nrest == 0 || nc == 0) return nc;
    while (size < 2 * nrest) size *= 2;
    table = lc_buf_get(&ec->keys, (size_t)size * sizeof(int));
    if (table == NULL) return -1;
    for (i = 0; i < size; ++i) table[i] = -1;
    for (i = 0; i < nrest; ++i) {
        uint32_t k = vertex_key(w, rest[i].a, rest[i].vertex, rest[i].b) & (uint32_t)(size - 1);
        while (table[k] >= 0) k = (k + 1) & (uint32_t)(size - 1);
        table[k] = i;
    }
    for (i = 0; i < nc; ++i) {
        uint32_t k = vertex_key(w, c[i].a, c[i].vertex, c[i].b) & (uint32_t)(size - 1);
        int resting = 0;
        while (table[k] >= 0 && !resting) {
            const lc_touch *r = &rest[table[k]];
            resting = r->a == c[i].a && r->vertex == c[i].vertex && r->b == c[i].b;
            k = (k + 1) & (uint32_t)(size - 1);
        }
        if (resting && lc_vertex_edge_gap(w, s1, c[i].a, c[i].vertex, c[i].b, c[i].edge) > -w->def.contact_distance)
            continue;
        c[kept++] = c[i];
    }
    return kept;
}

/* Crossings of the previous pass between two bodies the last impact did not touch, with their bracket
 * moved to the new start (tmin later). One whose bracket ended before the new start is dropped. */
static int keep_clean_crossings(lc_event_crossings *ec, const uint8_t *dirty, double tmin)
{
    lc_crossing *c = (lc_crossing *)ec->cross.p;
    int i, kept = 0, nc = ec->count;
    for (i = 0; i < nc; ++i) {
        double lo = c[i].t_lo - tmin, clear = c[i].clear_to - tmin;
        if (dirty[c[i].a] || dirty[c[i].b]) continue;
        c[i].t_hi -= tmin;
        /* fmax(x, 0.0) by comparison, the same bits (a NaN or either zero gives +0.0), without a call per
         * pending crossing at every impact */
        c[i].t_lo = lo > 0.0 ? lo : 0.0;
        c[i].clear_to = clear > 0.0 ? clear : 0.0;
        if (!(c[i].t_hi > 0.0)) continue;
        if (kept != i) c[kept] = c[i];   /* most stay where they are */
        kept++;
    }
    return kept;
}

/* How far a vertex of one body can stray, in the other's frame, from the straight chord between its
 * positions at the ends of an interval of length h: turning by dtheta bends the path by r dtheta^2 / 8,
 * and a change dv of the relative velocity by dv h / 8 (relative: two blocks falling side by side
 * under gravity move on parallel parabolas, straight lines in each other's frame). */
static double chord_deviation(const lc_world *w, const double *s0, const double *s1, double h, int a, int b)
{
    double turn = fabs(s1[a * 6 + SA] - s0[a * 6 + SA]) + fabs(s1[b * 6 + SA] - s0[b * 6 + SA]);
    double dvx = (s1[a * 6 + SVX] - s0[a * 6 + SVX]) - (s1[b * 6 + SVX] - s0[b * 6 + SVX]);
    double dvy = (s1[a * 6 + SVY] - s0[a * 6 + SVY]) - (s1[b * 6 + SVY] - s0[b * 6 + SVY]);
    return turn * turn * (w->shape[a].radius + w->shape[b].radius) / 8.0 + hypot(dvx, dvy) * h / 8.0;
}

/* Distance between the bodies' bounding circles (negative when they overlap). */
static double circle_gap(const lc_world *w, const double *s, int a, int b)
{
    return hypot(s[a * 6 + SX] - s[b * 6 + SX], s[a * 6 + SY] - s[b * 6 + SY]) - w->shape[a].radius - w->shape[b].radius;
}

/* 1 if a vertex of a or b may dip into the other and come back out between s0 and s1 (h apart):
 * the pair ends up closer than its chords can stray. free_flight: nothing rests (lc_trial.min_part). */
static int may_dip(lc_world *w, const double *s0, const double *s1, double h, int a, int b, int free_flight)
{
    double dev = chord_deviation(w, s0, s1, h, a, b), sep0;
    /* a path that strays from its chord by less than a quarter of the contact gap can dip at most
     * that far past what the end-point test sees: never into the other body (a settled pile) */
    if (dev < 0.25 * w->def.contact_gap) return 0;
    /* bounding circles apart by more than the paths can stray, at both ends: nothing can dip in
     * (the circles' distance is a lower bound of the bodies' distance, as the separation is) */
    if (circle_gap(w, s0, a, b) > dev + w->def.contact_distance && circle_gap(w, s1, a, b) > dev + w->def.contact_distance)
        return 0;
    if (lc_bounds_gap(w, s0, a, b) > dev + w->def.contact_distance &&
        lc_bounds_gap(w, s1, a, b) > dev + w->def.contact_distance)
        return 0;
    sep0 = lc_pair_separation(w, s0, a, b);
    /* touching at the start: resting contacts guard the pair. In free flight nothing rests, and a
     * pair touching there has just had an impact, which resolved only its vertices within
     * contact_distance of the other body: another vertex of the pair, turning in from farther out,
     * can dip in and back out within the interval unseen by the end points (a block spun by an
     * impact at one corner, its next corner passing 2 mm deep). That pair is swept as any other. */
    if (sep0 < w->def.contact_distance && !free_flight) return 0;
    return !(sep0 > dev + w->def.contact_distance && lc_pair_separation(w, s1, a, b) > dev + w->def.contact_distance);
}

/* The pair's moving rows (rows[0..nr)) at time t after s0 into dst; only the pair's two rows of dst are
 * written (a static one as at s0). */
static int pair_at(lc_world *w, const double *s0, double t, int a, int b, const int *rows, int nr, double *dst)
{
    memcpy(&dst[a * 6], &s0[a * 6], 6 * sizeof(double));
    memcpy(&dst[b * 6], &s0[b * 6], 6 * sizeof(double));
    return lc_integrate_rows(w, s0, t, rows, nr, NULL, 0, dst);
}

/* Vertices that dip into another body and come back out within the interval are invisible to the
 * end-point test. For pairs that end up closer than their chords can stray, the two bodies' motion is
 * sampled at LC_SWEEP_SAMPLES sub-times and every sub-interval is tested; a crossing found there
 * carries the sub-time by which it is inside as the upper end of its time-of-impact bracket.
 * A coupled pair (touching others, or tied by a spring) moves with the whole world, whose sub-time
 * states are computed once per interval and shared by every such pair: in a pile each of them costs
 * a contact-force solve of the whole pile per integrator stage, and a settling 1275-box pyramid has
 * hundreds of near pairs in one interval.
 * No crossing before index `from` has a body of any of the pairs (a local pass: those are the kept
 * crossings of bodies the impact did not move, and every pair has a moved body), so the crossings are
 * looked through from there: after each impact, not every crossing pending in the world. */
static int swept_check(lc_world *w, lc_event_crossings *ec, const double *s0, const double *s1, double h,
                       const int *pairs, int np, int from, int nc, const unsigned *coupled, unsigned coupled_now,
                       const int *all_rows, int n_all,
                       lc_touch *rest, int nrest, const uint8_t *in_parts)
{
    size_t count6 = (size_t)w->count * 6, bytes = count6 * sizeof(double);
    double *own[2], *world_at = NULL;
    int free_flight = in_parts != NULL;   /* in_parts: a free-flight trial's (lc_trial.min_part) */
    int have_world[LC_SWEEP_SAMPLES] = {0};
    int p, k, i;
    unsigned now = new_stamp(&ec->in_cross, &ec->in_cross_now, &ec->in_cross_rows, w->count), *in_cross;
    if (now == 0) return -1;
    in_cross = (unsigned *)ec->in_cross.p;
    /* the bodies of the crossings so far: a pair with a body in none has no crossing (the list of
     * crossings need not be searched for each of the interval's pairs) */
    for (i = from; i < nc; ++i)
        in_cross[((const lc_crossing *)ec->cross.p)[i].a] = in_cross[((const lc_crossing *)ec->cross.p)[i].b] = now;
    own[0] = own[1] = NULL;
    for (p = 0; p < np; ++p) {
        int a = pairs[2 * p], b = pairs[2 * p + 1], rows[2], nr = 0, have = 0, uncoupled;
        const double *prev, *cur;
        if (in_parts != NULL && in_parts[p]) continue;   /* swept part by part */
        if (in_cross[a] == now && in_cross[b] == now)
            for (i = from; i < nc; ++i) {
                const lc_crossing *c = &((const lc_crossing *)ec->cross.p)[i];
                if ((c->a == a && c->b == b) || (c->a == b && c->b == a)) have = 1;
            }
        /* the end-point test already bracketed this pair; if another vertex (a corner meeting a
         * corner) dipped in before that crossing's time, the pair's time of impact finds it */
        if (have || !may_dip(w, s0, s1, h, a, b, free_flight)) continue;
        if (!w->is_static[a]) rows[nr++] = a;
        if (!w->is_static[b]) rows[nr++] = b;
        uncoupled = coupled[a] != coupled_now && coupled[b] != coupled_now;
        prev = s0;
        for (k = 1; k <= LC_SWEEP_SAMPLES; ++k) {
            double tk = h * k / LC_SWEEP_SAMPLES;
            int before = nc;
            if (k == LC_SWEEP_SAMPLES) {
                cur = s1;
            } else if (uncoupled) {
                double *dst;
                if (own[0] == NULL) {
                    own[0] = lc_buf_get(&ec->sample0, bytes);
                    own[1] = lc_buf_get(&ec->sample1, bytes);
                    if (!own[0] || !own[1]) return -1;
                }
                dst = own[k & 1];   /* prev is the other one (or s0) */
                /* only the pair's two rows are read */
                if (pair_at(w, s0, tk, a, b, rows, nr, dst) != 0) return -1;
                cur = dst;
            } else {
                /* the whole world advanced with its resting contacts, exactly as in the trial */
                if (world_at == NULL) {
                    world_at = lc_buf_get(&ec->samples, (LC_SWEEP_SAMPLES - 1) * bytes);
                    if (world_at == NULL) return -1;
                }
                if (!have_world[k]) {
                    if (lc_integrate(w, s0, tk, all_rows, n_all, rest, nrest, world_at + (size_t)(k - 1) * count6) != 0)
                        return -1;
                    have_world[k] = 1;
                }
                cur = world_at + (size_t)(k - 1) * count6;
            }
            nc = lc_find_crossings(w, prev, cur, a, b, &ec->cross, nc);
            if (nc < 0) return -1;
            if (nc > before) {
                for (i = before; i < nc; ++i) {
                    lc_crossing *c = &((lc_crossing *)ec->cross.p)[i];
                    c->t_hi = tk;
                    in_cross[c->a] = in_cross[c->b] = now;
                }
                break;
            }
            prev = cur;
        }
    }
    return nc;
}

/* Parts a free-flight pair is tested over (tr->min_part > 0): vertex paths are straight lines in the
 * other body's frame while the bodies turn little, so the pair's faster spin (constant in closed form
 * without torque) sets its parts, not the fastest spin of the world. */
static int pair_parts(const lc_world *w, const lc_trial *tr, int a, int b)
{
    double spin = 0.0, part;
    if (!w->is_static[a]) spin = fabs(tr->s0[a * 6 + SW]);
    if (!w->is_static[b]) spin = fmax(spin, fabs(tr->s0[b * 6 + SW]));
    if (!(spin * tr->h > LC_MAX_TRIAL_ROTATION)) return 1;
    /* an absurd spin must not split the interval without end (the check is then coarser for it) */
    part = fmax(LC_MAX_TRIAL_ROTATION / spin, tr->min_part);
    return (int)fmin(ceil(tr->h / part), ceil(tr->h / tr->min_part));
}

/* The crossings of the free-flight pair (a, b) over m equal parts of the interval, each part tested as
 * a rotation-limited interval of its own (end points, then the swept check) and its crossings
 * bracketed within it. Every part is tested: the search of a part's crossing may find no impact (a
 * grazing vertex), and a later part's must then be there. The pair moves on its own (nothing couples
 * it in free flight), so its parts' states are its two rows advanced from s0. Returns the new count,
 * or -1 without memory. */
static int crossings_in_parts(lc_world *w, lc_event_crossings *ec, const lc_trial *tr, int a, int b, int m,
                              const lc_crossing *stalled, int nstalled, int nc)
{
    size_t bytes = (size_t)w->count * 6 * sizeof(double);
    double *part[2], *sample[2];
    const double *prev = tr->s0, *cur;
    int rows[2], nr = 0, j, k, i;
    part[0] = lc_buf_get(&ec->part0, bytes);
    part[1] = lc_buf_get(&ec->part1, bytes);
    sample[0] = lc_buf_get(&ec->sample0, bytes);
    sample[1] = lc_buf_get(&ec->sample1, bytes);
    if (!part[0] || !part[1] || !sample[0] || !sample[1]) return -1;
    if (!w->is_static[a]) rows[nr++] = a;
    if (!w->is_static[b]) rows[nr++] = b;
    for (j = 1; j <= m; ++j) {
        double t0 = tr->h * (j - 1) / m, t1 = j == m ? tr->h : tr->h * j / m, hp = t1 - t0;
        int before = nc;
        if (j == m) {
            cur = tr->s1;
        } else {
            if (pair_at(w, tr->s0, t1, a, b, rows, nr, part[j & 1]) != 0) return -1;   /* prev: the other one */
            cur = part[j & 1];
        }
        nc = lc_find_crossings(w, prev, cur, a, b, &ec->cross, nc);
        if (nc < 0) return -1;
        nc = drop_stalled_from(ec, stalled, nstalled, before, nc);
        if (nc == before && may_dip(w, prev, cur, hp, a, b, 1)) {
            const double *sp = prev, *sc;
            for (k = 1; k <= LC_SWEEP_SAMPLES && nc == before; ++k) {
                if (k == LC_SWEEP_SAMPLES) {
                    sc = cur;
                } else {
                    if (pair_at(w, tr->s0, t0 + hp * k / LC_SWEEP_SAMPLES, a, b, rows, nr, sample[k & 1]) != 0)
                        return -1;
                    sc = sample[k & 1];
                }
                nc = lc_find_crossings(w, sp, sc, a, b, &ec->cross, nc);
                if (nc < 0) return -1;
                nc = drop_stalled_from(ec, stalled, nstalled, before, nc);
                if (nc > before) t1 = k == LC_SWEEP_SAMPLES ? t1 : t0 + hp * k / LC_SWEEP_SAMPLES;
                sp = sc;
            }
        }
        if (nc > before) {
            for (i = before; i < nc; ++i) {
                ((lc_crossing *)ec->cross.p)[i].t_lo = t0;
                ((lc_crossing *)ec->cross.p)[i].t_hi = t1;
            }
        }
        prev = cur;
    }
    return nc;
}

int lc_event_crossings_find(lc_world *w, lc_event_crossings *ec, const lc_trial *tr, const lc_moved *moved,
                            const lc_crossing *stalled, int nstalled, lc_crossing **out)
{
    int np, nc = 0, nkept = 0, i, nstalled_kept = nstalled < LC_MAX_STALLED ? nstalled : LC_MAX_STALLED;
    unsigned *coupled;
    const int *pairs;
    uint8_t *in_parts = NULL;
    if (moved != NULL) {
        nc = nkept = keep_clean_crossings(ec, moved->marked, moved->since);
        np = lc_broad_phase_of(w, tr->s0, tr->s1, w->def.contact_distance, moved->marked, moved->rows, moved->n,
                               &ec->pairs);
    } else {
        np = lc_broad_phase(w, tr->s0, tr->s1, w->def.contact_distance, &ec->pairs);
    }
    if (np < 0) return -1;
    pairs = (const int *)ec->pairs.p;
    if (tr->min_part > 0.0) {
        in_parts = lc_buf_get(&ec->in_parts, (size_t)(np > 0 ? np : 1));
        if (in_parts == NULL) return -1;
        memset(in_parts, 0, (size_t)np);
    }
    for (i = 0; i < np && nstalled <= LC_MAX_STALLED; ++i) {
        int a = pairs[2 * i], b = pairs[2 * i + 1], before = nc, k, m = in_parts ? pair_parts(w, tr, a, b) : 1;
        if (m > 1) {
            in_parts[i] = 1;
            nc = crossings_in_parts(w, ec, tr, a, b, m, stalled, nstalled_kept, nc);
            if (nc < 0) return -1;
            continue;
        }
        nc = lc_find_crossings(w, tr->s0, tr->s1, a, b, &ec->cross, nc);
        if (nc < 0) return -1;
        for (k = before; k < nc; ++k) ((lc_crossing *)ec->cross.p)[k].t_hi = tr->h;
    }
    /* past LC_MAX_STALLED the list is full (and no crossing is looked for): only its entries */
    nc = drop_stalled(ec, stalled, nstalled_kept, nc);
    nc = drop_resting_drift(w, ec, tr->rest, tr->nrest, tr->s1, nc);
    if (nc < 0) return -1;
    /* a body touching nothing and tied by no spring (nor force callback) to another body moves on its
     * own: its time-of-impact evaluations (and swept samples) need only the two bodies */
    if (new_stamp(&ec->coupled, &ec->coupled_now, &ec->coupled_rows, w->count) == 0) return -1;
    coupled = (unsigned *)ec->coupled.p;
    mark_coupled(w, coupled, tr, ec->coupled_now);
    /* the kept crossings stay at the front unless a drop above went through them */
    nc = swept_check(w, ec, tr->s0, tr->s1, tr->h, pairs, np, nstalled_kept == 0 && tr->nrest == 0 ? nkept : 0, nc,
                     coupled, ec->coupled_now, tr->rows, tr->nrows, tr->rest, tr->nrest, in_parts);
    if (nc < 0) return -1;
    *out = (lc_crossing *)ec->cross.p;
    ec->count = nc;
    return nc;
}
