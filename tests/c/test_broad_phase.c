/* test_broad_phase: sort-and-sweep and the grid propose exactly brute force's candidate pairs, in the
 * same order, whatever order the sweep starts from (white box: lc_broad_phase on a world's state
 * arrays).
 *
 * Sort-and-sweep keeps the last sweep's x order and insertion-sorts from it, and orders the pairs by a
 * radix sort (broad_phase.c). Its output must not depend on that history: 300 boxes of random sizes
 * and angles, with a long static floor as row 0 (one a with a hundred b's), are moved in five ways
 * between calls - small random moves, a mirror in x (the worst start for an insertion sort), a full
 * shuffle of positions, an interval with a different end state (swept boxes), and boxes stacked in
 * one column (every box overlaps every other in x) - and after each the pair list of sort-and-sweep
 * must equal brute force's entry for entry, with no tolerance: both test the same boxes. The grid's
 * list too (box_pairs.c: the floor is a wide box there, tested against the cells it covers; over an
 * interval, from the fat boxes it keeps between searches, checked over a run of intervals), and also
 * for boxes no grid cell holds (lc_broad_phase_boxes: a NaN, an infinite, an inverted box). So must the
 * pairs of lc_broad_phase_of (the pairs of a few listed bodies, after an impact) equal brute force's
 * pairs that have a listed body, also while the broad phase tracks an interval in its grid
 * (lc_broad_phase_track): at a state inside the interval, and after a hundred bodies changed paths
 * (lc_broad_phase_retrack: their new boxes in the cells' lists beside the table), and after every path
 * changed three times more (past the entries at which the grid is built anew). A search at one state
 * after a search over an interval takes the interval's pairs where it can (broad_phase_kept.c): at the
 * interval's end state, with a few bodies moved elsewhere while the interval is tracked, and with a
 * tracked body given a new path (retracked) but back at its end state, its pairs must be exactly brute
 * force's over the boxes at that state, in the same order, and no search of the world must have run;
 * with a third of the bodies moved, or a body moved and nothing tracked, the world is searched, with
 * the same pairs. The reach grid alone, with
 * two finite boxes near -1e308 and 1e308 beside two at the origin (bounds wider than a double spans, where
 * doubling the cell would never end): it is built, and each query finds exactly the boxes it overlaps. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scenes.h"
#include "white_box.h"
#include "reach_grid.h"

#define N_BOXES 300

/* The candidate pairs of mode `mode` between states s0 and s1, copied into out (count returned). */
static int pairs_of(lc_world *w, lc_broadphase mode, const double *s0, const double *s1, int *out)
{
    lc_buf buf = {0};
    int n;
    w->def.broadphase = mode;
    n = lc_broad_phase(w, s0, s1, w->def.contact_distance, &buf);
    CHECK(n >= 0, "%s", "lc_broad_phase failed");
    if (n > 0) memcpy(out, buf.p, (size_t)n * 2 * sizeof(int));
    lc_buf_free(&buf);
    return n;
}

static void compare(lc_world *w, const double *s0, const double *s1, const char *what, int *brute, int *sweep)
{
    int nb = pairs_of(w, LC_BROADPHASE_BRUTE_FORCE, s0, s1, brute);
    int ns = pairs_of(w, LC_BROADPHASE_SORT_AND_SWEEP, s0, s1, sweep);
    printf("%-34s %6d pairs (brute force) %6d (sort-and-sweep)\n", what, nb, ns);
    CHECK(nb > 0, "%s: the scene has candidate pairs", what);
    CHECK(nb == ns, "%s: %d pairs by brute force, %d by sort-and-sweep", what, nb, ns);
    if (nb == ns) CHECK(memcmp(brute, sweep, (size_t)nb * 2 * sizeof(int)) == 0, "%s: the same pairs in the same order", what);
    ns = pairs_of(w, LC_BROADPHASE_GRID, s0, s1, sweep);
    printf("%-34s %6d pairs (brute force) %6d (grid)\n", what, nb, ns);
    CHECK(nb == ns, "%s: %d pairs by brute force, %d by the grid", what, nb, ns);
    if (nb == ns) CHECK(memcmp(brute, sweep, (size_t)nb * 2 * sizeof(int)) == 0, "%s: the grid's pairs in the same order", what);
}

/* Given boxes (lc_broad_phase_boxes) with a few no grid cell can hold: a NaN box (meets none), an
 * infinite strip (meets every box in its band), an inverted box (x0 > x1: meets a box that spans it
 * under the closed-interval test), a point, and two boxes near -1e308 and 1e308 (their distance is no
 * double); the grid must list brute force's pairs. */
static void compare_odd_boxes(lc_world *w, const double *s0, int *brute, int *grid)
{
    int n = w->count, i, nb, ng;
    double *b4 = malloc((size_t)n * 4 * sizeof(double));
    lc_buf buf = {0};
    CHECK(b4 != NULL, "%s", "allocation");
    if (b4 == NULL) return;
    for (i = 0; i < n; i++) lc_swept_box(w, s0, s0, i, 0.0, &b4[4 * i]);
    b4[4 * 1 + 0] = NAN;
    b4[4 * 2 + 0] = -INFINITY; b4[4 * 2 + 2] = INFINITY; b4[4 * 2 + 1] = 2.0; b4[4 * 2 + 3] = 2.5;
    b4[4 * 3 + 0] = 5.0; b4[4 * 3 + 2] = 4.0; b4[4 * 3 + 1] = 0.0; b4[4 * 3 + 3] = 8.0;
    b4[4 * 4 + 0] = b4[4 * 4 + 2] = 1.0; b4[4 * 4 + 1] = b4[4 * 4 + 3] = 1.0;
    b4[4 * 5 + 0] = b4[4 * 5 + 2] = -1e308;   /* small and finite, but farther apart than a double spans */
    b4[4 * 6 + 0] = b4[4 * 6 + 2] = 1e308;
    w->def.broadphase = LC_BROADPHASE_BRUTE_FORCE;
    nb = lc_broad_phase_boxes(w, b4, &buf);
    if (nb > 0) memcpy(brute, buf.p, (size_t)nb * 2 * sizeof(int));
    w->def.broadphase = LC_BROADPHASE_GRID;
    ng = lc_broad_phase_boxes(w, b4, &buf);
    if (ng > 0) memcpy(grid, buf.p, (size_t)ng * 2 * sizeof(int));
    printf("%-34s %6d pairs (brute force) %6d (grid)\n", "NaN, infinite and inverted boxes", nb, ng);
    CHECK(nb > 0 && nb == ng, "odd boxes: %d pairs by brute force, %d by the grid", nb, ng);
    if (nb == ng && nb > 0) CHECK(memcmp(brute, grid, (size_t)nb * 2 * sizeof(int)) == 0, "%s", "odd boxes: the same pairs in the same order");
    for (i = 0; i < nb; i++)
        if (brute[2 * i] == 2 || brute[2 * i + 1] == 2) break;
    CHECK(i < nb, "%s", "the infinite strip meets a box (the case is live)");
    lc_buf_free(&buf);
    free(b4);
}

/* lc_broad_phase_of, which computes the boxes of unlisted bodies only when their centres' bound comes
 * near a listed one, against brute force's pairs with a listed body: the same pairs in the same order. */
static void compare_of(lc_world *w, const double *s0, const double *s1, const char *what, int *brute, int *sweep,
                       sc_rng *rng)
{
    lc_buf buf = {0};
    uint8_t *marked = calloc((size_t)w->count, 1);
    int list[8], nlist = 0, nb, ns, k, kept = 0;
    CHECK(marked != NULL, "%s", "allocation");
    if (marked == NULL) return;
    while (nlist < 8) {
        int r = 1 + (int)(sc_rand(rng) * (w->count - 1));
        if (!marked[r]) { marked[r] = 1; list[nlist++] = r; }
    }
    nb = pairs_of(w, LC_BROADPHASE_BRUTE_FORCE, s0, s1, brute);
    for (k = 0; k < nb; ++k)
        if (marked[brute[2 * k]] || marked[brute[2 * k + 1]]) {
            brute[2 * kept] = brute[2 * k];
            brute[2 * kept + 1] = brute[2 * k + 1];
            kept++;
        }
    ns = lc_broad_phase_of(w, s0, s1, w->def.contact_distance, marked, list, nlist, &buf);
    printf("%-34s %6d pairs with 8 listed bodies (brute force) %6d (lc_broad_phase_of)\n", what, kept, ns);
    CHECK(kept > 0, "%s: the listed bodies have candidate pairs", what);
    CHECK(ns == kept, "%s: %d pairs by brute force, %d by lc_broad_phase_of", what, kept, ns);
    if (ns == kept && ns > 0) {
        memcpy(sweep, buf.p, (size_t)ns * 2 * sizeof(int));
        CHECK(memcmp(brute, sweep, (size_t)ns * 2 * sizeof(int)) == 0, "%s: the same pairs in the same order", what);
    }
    lc_buf_free(&buf);
    free(marked);
}

/* Every pair a < b, not both static, whose boxes at state s (grown by contact_distance) overlap, in
 * (a, b) order: brute force written out, into out (count returned). */
static int pairs_at(lc_world *w, const double *s, int *out)
{
    int a, b, n = 0;
    double ba[4], bb[4];
    for (a = 0; a < w->count; ++a) {
        lc_swept_box(w, s, s, a, w->def.contact_distance, ba);
        for (b = a + 1; b < w->count; ++b) {
            if (w->is_static[a] && w->is_static[b]) continue;
            lc_swept_box(w, s, s, b, w->def.contact_distance, bb);
            if (ba[0] <= bb[2] && bb[0] <= ba[2] && ba[1] <= bb[3] && bb[1] <= ba[3]) {
                out[2 * n] = a;
                out[2 * n + 1] = b;
                n++;
            }
        }
    }
    return n;
}

/* lc_broad_phase at the one state s after a search over an interval: brute force's pairs at s, in
 * order, and a search of the world (a broadphase counted) only when `searched`. */
static void compare_kept(lc_world *w, const double *s, const char *what, int searched, int *brute, int *got)
{
    lc_buf buf = {0};
    uint64_t before = w->last.brute_force_steps + w->last.sort_and_sweep_steps + w->last.grid_steps, after;
    int nb = pairs_at(w, s, brute), n;
    w->def.broadphase = LC_BROADPHASE_GRID;
    n = lc_broad_phase(w, s, s, w->def.contact_distance, &buf);
    after = w->last.brute_force_steps + w->last.sort_and_sweep_steps + w->last.grid_steps;
    if (n > 0) memcpy(got, buf.p, (size_t)n * 2 * sizeof(int));
    printf("%-34s %6d pairs (brute force) %6d (%s)\n", what, nb, n, after > before ? "searched" : "kept pairs");
    CHECK(nb > 0, "%s: the scene has candidate pairs", what);
    CHECK(n == nb, "%s: %d pairs by brute force, %d found", what, nb, n);
    if (n == nb) CHECK(memcmp(brute, got, (size_t)nb * 2 * sizeof(int)) == 0, "%s: the same pairs in the same order", what);
    CHECK((after > before) == searched, "%s: the world %s searched", what, searched ? "must be" : "must not be");
    lc_buf_free(&buf);
}

static void check_reach_grid_far_apart(void)
{
    double boxes[16] = {-1.0, -1.0, 0.5, 0.5, 0.0, 0.0, 1.0, 1.0, -1.5e308, 0.0, -1.4e308, 1.0, 1.4e308, 0.0, 1.5e308, 1.0};
    double near[4] = {0.2, 0.2, 0.3, 0.3}, far[4] = {1.45e308, 0.5, 1.45e308, 0.5};
    int rows[4] = {0, 1, 2, 3}, n;
    const int *found;
    lc_reach_grid *g = lc_reach_grid_create();
    CHECK(g != NULL && lc_reach_grid_build(g, boxes, rows, 4, 4) == 0, "%s", "reach grid built over far-apart boxes");
    if (g == NULL) return;
    n = lc_reach_grid_query(g, near, &found);
    CHECK(n == 2 && found[0] == 0 && found[1] == 1, "query at the origin: %d rows (first %d)", n, n > 0 ? found[0] : -1);
    n = lc_reach_grid_query(g, far, &found);
    CHECK(n == 1 && found[0] == 3, "query near 1.45e308: %d rows (first %d)", n, n > 0 ? found[0] : -1);
    lc_reach_grid_destroy(g);
}

int main(void)
{
    lc_world_def d = lc_default_world_def();
    lc_world *w = sc_world(&d);
    sc_rng rng = {4242u};
    int i, *brute, *sweep, rows;
    double *s0, *s1;
    size_t max_pairs = (size_t)(N_BOXES + 1) * N_BOXES / 2 + 1;
    if (!w) return CHECK_SUMMARY("test_broad_phase");
    check_reach_grid_far_apart();
    sc_static_box(w, 60.0, 1.0, 0.0, -0.5, 0.0);   /* row 0 */
    for (i = 0; i < N_BOXES; i++)
        sc_box(w, sc_uniform(&rng, 0.2, 1.5), sc_uniform(&rng, 0.2, 1.5), sc_uniform(&rng, -28, 28),
               sc_uniform(&rng, 0.0, 8.0), sc_uniform(&rng, 0.0, SC_PI), 0, 0, 0, 1.0, 0.5);
    rows = w->count;
    brute = malloc(max_pairs * 2 * sizeof(int));
    sweep = malloc(max_pairs * 2 * sizeof(int));
    s0 = malloc((size_t)rows * 6 * sizeof(double));
    s1 = malloc((size_t)rows * 6 * sizeof(double));
    CHECK(brute && sweep && s0 && s1, "%s", "allocation");
    if (!(brute && sweep && s0 && s1)) return CHECK_SUMMARY("test_broad_phase");
    memcpy(s0, w->state, (size_t)rows * 6 * sizeof(double));
    compare(w, s0, s0, "first call (row order)", brute, sweep);
    for (i = 1; i < rows; i++) {
        s0[i * 6 + SX] += sc_uniform(&rng, -0.3, 0.3);
        s0[i * 6 + SY] += sc_uniform(&rng, -0.3, 0.3);
        s0[i * 6 + SA] += sc_uniform(&rng, -0.3, 0.3);
    }
    compare(w, s0, s0, "small moves", brute, sweep);
    for (i = 1; i < rows; i++) s0[i * 6 + SX] = -s0[i * 6 + SX];
    compare(w, s0, s0, "mirrored in x", brute, sweep);
    for (i = rows - 1; i > 1; i--) {
        int j = 1 + (int)(sc_rand(&rng) * i), k;
        for (k = 0; k < 3; k++) {
            double t = s0[i * 6 + k];
            s0[i * 6 + k] = s0[j * 6 + k];
            s0[j * 6 + k] = t;
        }
    }
    compare(w, s0, s0, "positions shuffled", brute, sweep);
    compare_of(w, s0, s0, "positions shuffled", brute, sweep, &rng);
    memcpy(s1, s0, (size_t)rows * 6 * sizeof(double));
    for (i = 1; i < rows; i++) s1[i * 6 + SX] += sc_uniform(&rng, -2.0, 2.0);
    compare(w, s0, s1, "swept over an interval", brute, sweep);
    compare_of(w, s0, s1, "swept over an interval", brute, sweep, &rng);
    {
        /* the grid keeps fat boxes from one interval search to the next: a run of intervals moving
         * every box a little (most stay inside their fat boxes), a tenth of them far (new fat boxes
         * and fat pairs), and once every box far (the fat boxes made anew) */
        double *a0 = malloc((size_t)rows * 6 * sizeof(double)), *a1 = malloc((size_t)rows * 6 * sizeof(double));
        int it, k;
        CHECK(a0 && a1, "%s", "allocation");
        if (a0 && a1) {
            memcpy(a0, s1, (size_t)rows * 6 * sizeof(double));
            for (it = 0; it < 12; ++it) {
                memcpy(a1, a0, (size_t)rows * 6 * sizeof(double));
                for (k = 1; k < rows; k++) {
                    double d = it == 6 ? 3.0 : (k % 10 == it % 10 ? 1.5 : 0.05);
                    a1[k * 6 + SX] += sc_uniform(&rng, -d, d);
                    a1[k * 6 + SY] += sc_uniform(&rng, -d, d);
                    a1[k * 6 + SA] += sc_uniform(&rng, -0.05, 0.05);
                }
                compare(w, a0, a1, "a run of intervals", brute, sweep);
                memcpy(a0, a1, (size_t)rows * 6 * sizeof(double));
            }
        }
        free(a0);
        free(a1);
    }
    {
        /* the interval's pairs taken at its end, then with bodies moved (the interval searched last) */
        int *dyn = malloc((size_t)rows * sizeof(int)), nd = 0, k;
        double *e = malloc((size_t)rows * 6 * sizeof(double));
        CHECK(dyn && e, "%s", "allocation");
        if (dyn && e) {
            for (k = 1; k < rows; k++) dyn[nd++] = k;
            memcpy(e, s1, (size_t)rows * 6 * sizeof(double));
            pairs_of(w, LC_BROADPHASE_GRID, s0, s1, sweep);
            compare_kept(w, e, "interval's end", 0, brute, sweep);
            CHECK(lc_broad_phase_track(w, s0, s1, 0.0, dyn, nd, w->def.contact_distance) == 0, "%s", "track");
            for (k = 1; k <= 20; k++) {
                e[k * 6 + SX] += sc_uniform(&rng, -3.0, 3.0);
                e[k * 6 + SA] += sc_uniform(&rng, -1.0, 1.0);
            }
            compare_kept(w, e, "tracked, 20 bodies moved", 0, brute, sweep);
            /* body 30 on a new path far off in the grid, yet at its end state, where moved body 5 now is:
             * their pair is not where the grid has body 30 */
            {
                double s2[6 * 31];
                memcpy(s2, s1, sizeof s2);
                s2[30 * 6 + SY] += 50.0;
                CHECK(lc_broad_phase_retrack(w, s2, s2, 0.0, &dyn[29], 1, w->def.contact_distance) == 0, "%s", "retrack");
                e[5 * 6 + SX] = e[30 * 6 + SX];
                e[5 * 6 + SY] = e[30 * 6 + SY];
            }
            compare_kept(w, e, "tracked, one path changed", 0, brute, sweep);
            for (k = 21; k <= rows / 3; k++) e[k * 6 + SY] += sc_uniform(&rng, -1.0, 1.0);
            compare_kept(w, e, "tracked, a third of bodies moved", 1, brute, sweep);
            lc_broad_phase_untrack(w);
            memcpy(e, s1, (size_t)rows * 6 * sizeof(double));
            e[7 * 6 + SX] += 1.0;
            compare_kept(w, e, "untracked, one body moved", 1, brute, sweep);
        }
        free(dyn);
        free(e);
    }
    {
        /* tracked: every dynamic body's reach from s0 to s1 (straight paths: h = 0, no parabola) */
        int *dyn = malloc((size_t)rows * sizeof(int)), nd = 0, k;
        double *sm = malloc((size_t)rows * 6 * sizeof(double)), *s2 = malloc((size_t)rows * 6 * sizeof(double));
        const int *near;
        CHECK(dyn && sm && s2, "%s", "allocation");
        if (dyn && sm && s2) {
            for (k = 1; k < rows; k++) dyn[nd++] = k;
            CHECK(lc_broad_phase_track(w, s0, s1, 0.0, dyn, nd, w->def.contact_distance) == 0, "%s", "track");
            compare_of(w, s0, s1, "tracked", brute, sweep, &rng);
            memcpy(sm, s0, (size_t)rows * 6 * sizeof(double));
            for (k = 1; k < rows; k++) sm[k * 6 + SX] = 0.5 * (s0[k * 6 + SX] + s1[k * 6 + SX]);
            compare_of(w, sm, s1, "tracked, mid-interval", brute, sweep, &rng);
            memcpy(s2, s1, (size_t)rows * 6 * sizeof(double));
            for (k = 1; k <= 100; k++) s2[k * 6 + SY] += sc_uniform(&rng, -3.0, 3.0);
            CHECK(lc_broad_phase_retrack(w, sm, s2, 0.0, dyn, 100, w->def.contact_distance) == 0, "%s", "retrack");
            compare_of(w, sm, s2, "tracked, 100 paths changed", brute, sweep, &rng);
            for (i = 0; i < 3; i++) {
                for (k = 1; k < rows; k++) s2[k * 6 + SX] += sc_uniform(&rng, -1.0, 1.0);
                CHECK(lc_broad_phase_retrack(w, sm, s2, 0.0, dyn, nd, w->def.contact_distance) == 0, "%s", "retrack all");
                compare_of(w, sm, s2, "tracked, all paths changed", brute, sweep, &rng);
            }
            lc_broad_phase_untrack(w);
            CHECK(lc_broad_phase_near(w, &s0[0], &near) == -2, "%s", "nothing is tracked after untrack");
        }
        free(dyn);
        free(sm);
        free(s2);
    }
    for (i = 1; i < rows; i++) {
        s0[i * 6 + SX] = sc_uniform(&rng, -0.1, 0.1);
        s0[i * 6 + SY] = 0.8 * i;
    }
    compare(w, s0, s0, "one column", brute, sweep);
    compare_odd_boxes(w, s0, brute, sweep);
    free(brute);
    free(sweep);
    free(s0);
    free(s1);
    lc_world_destroy(w);
    return CHECK_SUMMARY("test_broad_phase");
}
