/* A starting guess for the sparse solves of a cold pile (no touch has a force yet): each body's own
 * load plus everything resting on it, shared among the touches it rests on by the lever rule.
 *
 * Why: from zero forces, MPRGP (sparse_lcp.c) must first free thousands of rows one expansion step at
 * a time, and each expansion restarts its conjugate gradients. A 1275-box pyramid needed 26 000
 * products in its first step and still ended 0.008 m/s^2 off; a 5050-box one 2 m/s^2 off, which set
 * off hundreds of time-of-impact searches (22 s for the first step, more than 14 minutes for the
 * second). Shared equally, the guess cut that to 300 and 720 products; by the lever rule it is the
 * exact static answer for those pyramids, and the first solves stop at their start (residual 1e-11
 * m/s^2, 32 products, 12 of them the first estimate of ||A||).
 *
 * "Rests on": a touch whose normal is within 60 degrees of the up direction (against gravity). The
 * order is found on the graph of those touches (Kahn's algorithm), top down for loads and bottom up
 * for lifts, so no sort by height is needed and a leaning body is handled where its supports are.
 * Bodies on a cycle of such touches (possible only with odd shapes) are done last in row order: the
 * guess is only a start, the solve corrects it. Without gravity there is no up and no guess. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "tunables.h"

struct lc_static_load_state {
    lc_buf loads, graph;   /* per-body loads (or lifts), and the graph of who rests on whom */
};

lc_static_load_state *lc_static_load_state_create(void) { return calloc(1, sizeof(lc_static_load_state)); }

void lc_static_load_state_destroy(lc_static_load_state *sl)
{
    if (sl == NULL) return;
    lc_buf_free(&sl->loads);
    lc_buf_free(&sl->graph);
    free(sl);
}


/* The body a touch holds up (its upper body), or -1 when the touch is too steep or that body is static.
 * A touch's force pushes a along n and b along -n. */
static int held_body(const lc_world *w, const lc_touch *t, lc_vec2 up, double *c)
{
    double d = lc_dot(t->n, up);
    *c = fabs(d);
    if (d > LC_SUPPORT_COS) return w->is_static[t->a] ? -1 : t->a;
    if (d < -LC_SUPPORT_COS) return w->is_static[t->b] ? -1 : t->b;
    return -1;
}

static int holder_of(const lc_touch *t, int held)
{
    return t->a == held ? t->b : t->a;
}

/* The bodies the graph is over: every row (local NULL, n = w->count), or the rows that `local` maps to
 * 0..n-1 (an island's; static rows map to -1), so the work follows the touches, not the world. */
typedef struct nodes {
    const int *local;
    const int *rows;   /* node -> row, when local is set */
    int n;
} nodes;

static int node_of(const nodes *nd, int row) { return nd->local ? nd->local[row] : row; }
static int row_of_node(const nodes *nd, int k) { return nd->local ? nd->rows[k] : k; }

/* Scratch: per body (node) the touches it rests on (CSR: first[n + 1], list), the count of bodies
 * resting on it still unprocessed, and the processing order (nodes). */
typedef struct support_graph {
    int *first, *list, *pending, *order;
    int n_order;
} support_graph;

static int build_graph(lc_world *w, const lc_touch *t, int m, lc_vec2 up, const nodes *nd, support_graph *g)
{
    int n = nd->n, i, head = 0;
    int *mem = lc_buf_get(&w->static_load->graph, ((size_t)n * 3 + 1 + (size_t)m) * sizeof(int));
    if (mem == NULL) return -1;
    g->first = mem;
    g->pending = mem + n + 1;
    g->order = g->pending + n;
    g->list = g->order + n;
    memset(mem, 0, ((size_t)n * 3 + 1) * sizeof(int));
    for (i = 0; i < m; ++i) {
        double c;
        int held = held_body(w, &t[i], up, &c), h;
        if (held < 0) continue;
        g->first[node_of(nd, held) + 1]++;
        h = holder_of(&t[i], held);
        if (!w->is_static[h]) g->pending[node_of(nd, h)]++;
    }
    for (i = 0; i < n; ++i) g->first[i + 1] += g->first[i];
    /* fill with order[] as the cursor, then reuse order[] for the topological order */
    for (i = 0; i < n; ++i) g->order[i] = g->first[i];
    for (i = 0; i < m; ++i) {
        double c;
        int held = held_body(w, &t[i], up, &c);
        if (held >= 0) g->list[g->order[node_of(nd, held)]++] = i;
    }
    /* Kahn: bodies nothing rests on first, then each holder once all it holds are done */
    g->n_order = 0;
    for (i = 0; i < n; ++i)
        if (!w->is_static[row_of_node(nd, i)] && g->pending[i] == 0) g->order[g->n_order++] = i;
    while (head < g->n_order) {
        int b = g->order[head++], k;
        for (k = g->first[b]; k < g->first[b + 1]; ++k) {
            int h = holder_of(&t[g->list[k]], row_of_node(nd, b));
            if (!w->is_static[h] && --g->pending[node_of(nd, h)] == 0) g->order[g->n_order++] = node_of(nd, h);
        }
    }
    for (i = 0; i < n; ++i)   /* cycles: whatever is left, in row order */
        if (!w->is_static[row_of_node(nd, i)] && g->pending[i] > 0) g->order[g->n_order++] = i;
    return 0;
}

static int up_direction(const lc_world *w, lc_vec2 *up)
{
    double gl = sqrt(lc_dot(w->def.gravity, w->def.gravity));
    if (!(gl > 0.0) || !isfinite(gl)) return 0;
    *up = lc_scale(w->def.gravity, -1.0 / gl);
    return 1;
}

/* The centre of mass of held body b, from one of the touches it rests on. */
static lc_vec2 centre_of(const lc_touch *t, int b)
{
    return lc_sub(t->p, t->a == b ? t->ra : t->rb);
}

/* Top down: load[b] (own load on entry, N or kg*m along up, acting at b's centre) grows by what rests
 * on b, where it rests. The touches b rests on share load[b] by the lever rule: the shares sum to
 * the load and their moment about any point equals the load's (so a box under an off-centre load is
 * not guessed to turn); among such shares the most nearly equal one (least squares), negative shares
 * cut to zero. A touch gets its share's part along its normal (c * share: a body on a slope is
 * pressed by its weight's normal part) and passes the share on to its holder at the touch point. */
static void spread_loads(const lc_world *w, const lc_touch *t, lc_vec2 up, const nodes *nd, const support_graph *g,
                         double *load, double *moment, double *out)
{
    lc_vec2 across = lc_v(up.y, -up.x);
    int j, k;
    for (j = 0; j < g->n_order; ++j) {
        int b = g->order[j], k0 = g->first[b], k1 = g->first[b + 1], nk = k1 - k0, rb = row_of_node(nd, b);
        double mean = 0.0, spread = 0.0, lever, sum = 0.0;
        if (nk == 0 || !(load[b] > 0.0)) continue;
        for (k = k0; k < k1; ++k) mean += lc_dot(t[g->list[k]].p, across) / (double)nk;
        for (k = k0; k < k1; ++k) {
            double d = lc_dot(t[g->list[k]].p, across) - mean;
            spread += d * d;
        }
        /* the load's point across up, less the supports' mean; supports at one point share equally */
        lever = moment[b] / load[b] - mean;
        if (!(spread > 1e-12 * (1.0 + mean * mean))) lever = 0.0, spread = 1.0;
        for (k = k0; k < k1; ++k) {
            double d = lc_dot(t[g->list[k]].p, across) - mean;
            double share = load[b] / (double)nk + load[b] * lever * d / spread;
            out[g->list[k]] = share > 0.0 ? share : 0.0;
            sum += out[g->list[k]];
        }
        for (k = k0; k < k1; ++k) {
            const lc_touch *tk = &t[g->list[k]];
            double c, share = sum > 0.0 ? out[g->list[k]] * load[b] / sum : load[b] / (double)nk;
            int h = holder_of(tk, rb);
            (void)held_body(w, tk, up, &c);
            out[g->list[k]] = c * share;
            if (!w->is_static[h]) {
                load[node_of(nd, h)] += share;
                moment[node_of(nd, h)] += share * lc_dot(tk->p, across);
            }
        }
    }
}

/* moment[b] = own load[b] times b's centre across up (0 for a body that rests on nothing: unused) */
static void own_moments(const lc_touch *t, lc_vec2 up, const nodes *nd, const support_graph *g, const double *load,
                        double *moment)
{
    lc_vec2 across = lc_v(up.y, -up.x);
    int b;
    for (b = 0; b < nd->n; ++b)
        moment[b] = g->first[b + 1] > g->first[b]
                        ? load[b] * lc_dot(centre_of(&t[g->list[g->first[b]]], row_of_node(nd, b)), across)
                        : 0.0;
}

static int load_forces(lc_world *w, const lc_touch *t, int m, const nodes *nd, double *f)
{
    double *load;
    lc_vec2 up;
    support_graph g;
    int i;
    if (!up_direction(w, &up)) return 0;
    if (build_graph(w, t, m, up, nd, &g) != 0) return -1;
    load = lc_buf_get(&w->static_load->loads, (size_t)(nd->n > 0 ? nd->n : 1) * 2 * sizeof(double));
    if (load == NULL) return -1;
    for (i = 0; i < nd->n; ++i) {
        int r = row_of_node(nd, i);
        load[i] = w->is_static[r] ? 0.0 : lc_dot(w->def.gravity, up) * -w->mass[r];
    }
    own_moments(t, up, nd, &g, load, load + nd->n);
    spread_loads(w, t, up, nd, &g, load, load + nd->n, f);
    return 0;
}

int lc_static_load_forces(lc_world *w, const lc_touch *t, int m, double *f)
{
    nodes nd;
    nd.local = NULL;
    nd.rows = NULL;
    nd.n = w->count;
    return load_forces(w, t, m, &nd, f);
}

int lc_static_load_forces_of(lc_world *w, const lc_touch *t, int m, const int *local, const int *rows, int n,
                             double *f)
{
    nodes nd;
    nd.local = local;
    nd.rows = rows;
    nd.n = n;
    return load_forces(w, t, m, &nd, f);
}

int lc_static_load_lifts(lc_world *w, const lc_touch *t, int m, const double *deficit, double *lam)
{
    double *load;
    lc_vec2 up;
    support_graph g;
    nodes nd;
    int i, j, k;
    nd.local = NULL;
    nd.rows = NULL;
    nd.n = w->count;
    if (!up_direction(w, &up)) return 0;
    if (build_graph(w, t, m, up, &nd, &g) != 0) return -1;
    load = lc_buf_get(&w->static_load->loads, (size_t)w->count * 2 * sizeof(double));
    if (load == NULL) return -1;
    /* bottom up (the reverse order): a body must rise as far as the highest of its holders plus what
     * its own touch is short of the gap; as a load, that rise times its mass */
    memset(load, 0, (size_t)w->count * sizeof(double));
    for (j = g.n_order - 1; j >= 0; --j) {
        int b = g.order[j];
        double rise = 0.0;
        for (k = g.first[b]; k < g.first[b + 1]; ++k) {
            const lc_touch *tk = &t[g.list[k]];
            double c, need;
            int h = holder_of(tk, b);
            (void)held_body(w, tk, up, &c);
            need = (w->is_static[h] ? 0.0 : load[h]) + (deficit[g.list[k]] > 0.0 ? deficit[g.list[k]] / c : 0.0);
            if (need > rise) rise = need;
        }
        load[b] = rise;
    }
    for (i = 0; i < w->count; ++i) load[i] *= w->is_static[i] ? 0.0 : w->mass[i];
    own_moments(t, up, &nd, &g, load, load + w->count);
    spread_loads(w, t, up, &nd, &g, load, load + w->count, lam);
    return 0;
}
