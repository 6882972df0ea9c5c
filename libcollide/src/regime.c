/* The regime rule (regime.h). */
#include <math.h>
#include "regime.h"
#include "tunables.h"

int lc_regime_substeps(const lc_world *w, const lc_island *isl, double dt)
{
    double worst = 0.0;
    int i;
    for (i = 0; i < isl->nrows; ++i) {
        int r = isl->rows[i];
        const double *s = &w->state[r * 6];
        double reach = (sqrt(s[SVX] * s[SVX] + s[SVY] * s[SVY]) + fabs(s[SW]) * w->shape[r].radius) * dt;
        if (!(reach <= LC_CONTACT_MAX_SUBSTEPS * w->shape[r].min_edge)) return 0;
        worst = fmax(worst, reach / w->shape[r].min_edge);
    }
    return worst <= 1.0 ? 1 : (int)ceil(worst);
}

int lc_regime_too_fast(const lc_world *w, const lc_island *isl, double dt) { return lc_regime_substeps(w, isl, dt) == 0; }

lc_regime lc_regime_of(const lc_world *w, const lc_island *isl, double dt)
{
    int i;
    if (w->def.regime != LC_REGIME_AUTO) return w->def.regime;
    for (i = 0; i < isl->nrows; ++i)
        if (w->rests_dissipative[isl->rows[i]]) return lc_regime_too_fast(w, isl, dt) ? LC_REGIME_EVENT : LC_REGIME_CONTACT;
    return LC_REGIME_EVENT;
}

void lc_regime_mark(lc_world *w, const lc_touch *t, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (t[i].elasticity < 1.0) w->rests_dissipative[t[i].a] = w->rests_dissipative[t[i].b] = 1;
}

int lc_regime_refresh(lc_world *w)
{
    int np, i, n = 0;
    const int *pairs;
    if (w->regime_edits == w->edits) return 0;
    np = lc_broad_phase(w, w->state, w->state, w->def.contact_distance, &w->b_pairs);
    if (np < 0) return -1;
    pairs = (const int *)w->b_pairs.p;
    for (i = 0; i < np; ++i) {
        n = lc_collect_touches(w, w->state, pairs[2 * i], pairs[2 * i + 1], w->def.contact_distance, &w->b_touch, n);
        if (n < 0) return -1;
    }
    for (i = 0; i < w->count; ++i) w->rests_dissipative[i] = 0;
    lc_regime_mark(w, (const lc_touch *)w->b_touch.p, n);
    w->regime_edits = w->edits;
    return 0;
}
