/* The user's force law (collide/force.h): setting and reading the callback, evaluating it for the applied
 * forces (forces.c), the largest force it put on each body in a step (what makes a body driven: forces.c,
 * energy.c), the failure that undoes the step (step.c), and its potential energy (energy.c). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"

struct lc_force_callback {
    lc_force_fn force;
    lc_potential_fn potential;
    void *user;
    lc_buf b_out;     /* count x 3 doubles: the last evaluation's forces and torques */
    lc_buf b_rows;    /* the dynamic rows a force evaluation lists */
    lc_buf b_prows;   /* those of a potential evaluation: its own, so that reading the energy inside a
                         force callback cannot move the rows that callback was given */
    lc_buf b_peak;    /* count x 2 doubles: the largest |force| and |torque| per row in the step */
    int npeak;        /* rows b_peak describes (0: the step recorded none) */
    lc_status failed; /* LC_OK, or why the step in progress cannot go on */
    char why[200];
};

lc_force_callback *lc_force_callback_create(void) { return calloc(1, sizeof(lc_force_callback)); }

void lc_force_callback_destroy(lc_force_callback *fc)
{
    if (fc == NULL) return;
    lc_buf_free(&fc->b_out);
    lc_buf_free(&fc->b_rows);
    lc_buf_free(&fc->b_prows);
    lc_buf_free(&fc->b_peak);
    free(fc);
}

lc_status lc_world_set_force_callback(lc_world *w, lc_force_fn force, lc_potential_fn potential, void *user)
{
    lc_force_callback *fc;
    if (w == NULL) return LC_ERR_NULL;
    if (force == NULL && potential != NULL)
        return lc_fail(w, LC_ERR_NULL, "force is NULL but potential is not (a potential belongs to a force law)");
    fc = w->force_callback;
    fc->force = force;
    fc->potential = force != NULL ? potential : NULL;
    fc->user = force != NULL ? user : NULL;
    fc->npeak = 0;
    return lc_changed(w);
}

lc_status lc_world_get_force_callback(const lc_world *w, lc_force_fn *force, lc_potential_fn *potential, void **user)
{
    if (w == NULL) return LC_ERR_NULL;
    if (force == NULL || potential == NULL || user == NULL)
        return lc_fail((lc_world *)w, LC_ERR_NULL, "force, potential or user output is NULL");
    *force = w->force_callback->force;
    *potential = w->force_callback->potential;
    *user = w->force_callback->user;
    return LC_OK;
}

int lc_force_callback_on(const lc_world *w) { return w->force_callback->force != NULL; }

int lc_force_callback_begin_step(lc_world *w)
{
    lc_force_callback *fc = w->force_callback;
    double *peak;
    fc->failed = LC_OK;
    fc->why[0] = '\0';
    fc->npeak = 0;
    if (fc->force == NULL || w->count == 0) return 0;
    peak = lc_buf_get(&fc->b_peak, (size_t)w->count * 2 * sizeof(double));
    if (peak == NULL) return -1;
    memset(peak, 0, (size_t)w->count * 2 * sizeof(double));
    fc->npeak = w->count;
    return 0;
}

/* Records why the step cannot go on; every later evaluation in the step fails at once, so a callback
 * that failed is not called again before the step is undone. Returns -1. */
static int fail(lc_force_callback *fc, lc_status s, const char *fmt, ...)
{
    va_list ap;
    fc->failed = s;
    va_start(ap, fmt);
    vsnprintf(fc->why, sizeof fc->why, fmt, ap);
    va_end(ap);
    return -1;
}

static void fill_query(const lc_world *w, const double *state, const int *rows, int n, lc_force_query *q)
{
    q->bodies.count = w->count;
    q->bodies.ids = w->ids;
    q->bodies.state = state;
    q->bodies.mass = w->mass;
    q->bodies.inertia = w->inertia;
    q->bodies.is_static = w->is_static;
    q->rows = rows;
    q->row_count = n;
}

int lc_force_callback_eval(lc_world *w, const double *state, const int *rows, int n, const double **forces)
{
    lc_force_callback *fc = w->force_callback;
    size_t cells = (size_t)(w->count > 0 ? w->count : 1) * 3;
    double *out, *peak = fc->npeak == w->count ? (double *)fc->b_peak.p : NULL;
    int *dyn, m = 0, i, rc;
    lc_force_query q;
    if (fc->failed != LC_OK) return -1;
    out = lc_buf_get(&fc->b_out, cells * sizeof(double));
    dyn = lc_buf_get(&fc->b_rows, (size_t)(n > 0 ? n : 1) * sizeof(int));
    if (out == NULL || dyn == NULL) return fail(fc, LC_ERR_NO_MEMORY, "out of memory evaluating the force callback");
    memset(out, 0, cells * sizeof(double));
    *forces = out;
    for (i = 0; i < n; ++i)
        if (!w->is_static[rows[i]]) dyn[m++] = rows[i];
    if (m == 0) return 0;
    fill_query(w, state, dyn, m, &q);
    rc = fc->force(fc->user, &q, out);
    if (rc != 0) return fail(fc, LC_ERR_CALLBACK, "the force callback failed (it returned %d)", rc);
    for (i = 0; i < m; ++i) {
        int r = dyn[i];
        const double *f = &out[r * 3];
        if (!isfinite(f[0]) || !isfinite(f[1]) || !isfinite(f[2]))
            return fail(fc, LC_ERR_CALLBACK, "the force callback gave body %u a non-finite force (%g, %g) or torque (%g)",
                        (unsigned)w->ids[r], f[0], f[1], f[2]);
        if (peak != NULL) {
            peak[r * 2] = fmax(peak[r * 2], sqrt(f[0] * f[0] + f[1] * f[1]));
            peak[r * 2 + 1] = fmax(peak[r * 2 + 1], fabs(f[2]));
        }
    }
    return 0;
}

void lc_force_callback_peak(const lc_world *w, int row, double *force, double *torque)
{
    const lc_force_callback *fc = w->force_callback;
    const double *peak = (const double *)fc->b_peak.p;
    *force = *torque = 0.0;
    if (fc->force == NULL || row < 0 || row >= fc->npeak || fc->npeak != w->count) return;
    *force = peak[row * 2];
    *torque = peak[row * 2 + 1];
}

const char *lc_force_callback_failure(const lc_world *w, lc_status *status)
{
    const lc_force_callback *fc = w->force_callback;
    if (fc->failed == LC_OK) return NULL;
    *status = fc->failed;
    return fc->why;
}

lc_status lc_force_callback_potential(const lc_world *w, const double *state, double *out)
{
    /* the rows buffer is scratch, written through a const world like the trig cache */
    lc_force_callback *fc = w->force_callback;
    lc_force_query q;
    double e = 0.0;
    int *dyn, m = 0, i, rc;
    *out = 0.0;
    if (fc->potential == NULL) return LC_OK;
    dyn = lc_buf_get(&fc->b_prows, (size_t)(w->count > 0 ? w->count : 1) * sizeof(int));
    if (dyn == NULL) return lc_fail((lc_world *)w, LC_ERR_NO_MEMORY, "out of memory evaluating the potential");
    for (i = 0; i < w->count; ++i)
        if (!w->is_static[i]) dyn[m++] = i;
    fill_query(w, state, dyn, m, &q);
    rc = fc->potential(fc->user, &q, &e);
    if (rc != 0) return lc_fail((lc_world *)w, LC_ERR_CALLBACK, "the potential callback failed (it returned %d)", rc);
    if (!isfinite(e)) return lc_fail((lc_world *)w, LC_ERR_CALLBACK, "the potential callback gave a non-finite energy (%g)", e);
    *out = e;
    return LC_OK;
}
