/* Time integration between impacts: closed form for bodies under constant forces, otherwise the
 * world's explicit integrator (Euler, midpoint or RK4) with resting contact forces in every evaluation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"

struct lc_integrator_state {
    lc_buf flags, rows;      /* rows in a resting touch; the rows advanced by the integrator */
    lc_buf written;          /* lc_integrate: the rows it advances (the others are copied) */
    lc_buf acc, tmp, k[4];   /* accelerations, and the stages' states and derivatives (count x 6) */
};

lc_integrator_state *lc_integrator_state_create(void) { return calloc(1, sizeof(lc_integrator_state)); }

void lc_integrator_state_destroy(lc_integrator_state *is)
{
    int i;
    if (is == NULL) return;
    lc_buf_free(&is->flags);
    lc_buf_free(&is->rows);
    lc_buf_free(&is->written);
    lc_buf_free(&is->acc);
    lc_buf_free(&is->tmp);
    for (i = 0; i < 4; ++i) lc_buf_free(&is->k[i]);
    free(is);
}

/* Derivative of the listed rows: d/dt (x, y, a, vx, vy, w) = (vx, vy, w, ax, ay, alpha). */
static int derivative(lc_world *w, const double *s, const int *rows, int n, lc_touch *t, int nt,
                      double *acc, double *k)
{
    int i;
    if (lc_applied_accelerations(w, s, rows, n, acc) != 0) return -1;
    if (nt > 0 && lc_contact_forces(w, s, t, nt, acc) != 0) return -1;
    w->last.force_evaluations++;
    for (i = 0; i < n; ++i) {
        int r = rows[i];
        const double *st = &s[r * 6];
        double *kr = &k[r * 6];
        kr[SX] = st[SVX];
        kr[SY] = st[SVY];
        kr[SA] = st[SW];
        kr[SVX] = acc[r * 3 + 0];
        kr[SVY] = acc[r * 3 + 1];
        kr[SW] = acc[r * 3 + 2];
    }
    return 0;
}

static void axpy_rows(double *out, const double *s, double h, const double *k, const int *rows, int n)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        int r = rows[i] * 6;
        for (j = 0; j < 6; ++j) out[r + j] = s[r + j] + h * k[r + j];
    }
}

/* Exact motion under constant acceleration: position quadratic, velocity linear in time. */
static void advance_closed_form(const lc_world *w, const double *s0, double h, int r, double *s1)
{
    const double *a = &s0[r * 6];
    double *b = &s1[r * 6];
    double ax = w->def.gravity.x + w->ext_force[r].x * w->inv_mass[r];
    double ay = w->def.gravity.y + w->ext_force[r].y * w->inv_mass[r];
    double al = w->ext_torque[r] * w->inv_inertia[r];
    b[SX] = a[SX] + h * a[SVX] + 0.5 * h * h * ax;
    b[SY] = a[SY] + h * a[SVY] + 0.5 * h * h * ay;
    b[SA] = a[SA] + h * a[SW] + 0.5 * h * h * al;
    b[SVX] = a[SVX] + h * ax;
    b[SVY] = a[SVY] + h * ay;
    b[SW] = a[SW] + h * al;
}

/* 1 when every listed row moves no faster than resting_speed (its centre and, through its spin, its
 * farthest vertex): a pile at rest, whose contact forces barely change over an interval. */
static int rows_quiet(const lc_world *w, const double *s, const int *rows, int n)
{
    double v = w->def.resting_speed;
    int i;
    if (!(v > 0.0)) return 0;
    for (i = 0; i < n; ++i) {
        const double *st = &s[rows[i] * 6];
        if (st[SVX] * st[SVX] + st[SVY] * st[SVY] > v * v || fabs(st[SW]) * w->shape[rows[i]].radius > v) return 0;
    }
    return 1;
}

/* A pile at rest: its accelerations (gravity against contact forces) are the same at both ends of the
 * interval up to the contact solver's tolerance, and RK4's four contact solves buy nothing over two.
 * k1 is known at s0; the rows are advanced under k1's accelerations held constant and evaluated again
 * there (k2). When no row's acceleration (a spin's at its farthest vertex) changed by more than
 * 2e-4 contact_gap / dt^2 (7.2e-8 m/s^2 at dt = 1/60 s and the default contact_gap; a resting pile's
 * solves converge to 9e-9), the interval (h <= dt) is taken with the acceleration linear between the
 * two, which puts a point less than h^2/2 of that, 1e-4 contact_gap, from where any higher-order
 * answer puts it; returns 1. Otherwise 0, and the caller goes on with RK4 from k1 (one evaluation
 * spent; tests/c/test_counters.c (5) checks that the step is then RK4's bit for bit). */
static int advance_quiet(lc_world *w, const double *s0, double h, const int *irows, int ni, lc_touch *t, int nt,
                         double *acc, double *tmp, const double *k1, double *k2, double *s1)
{
    double dt = w->step_dt > 0.0 ? w->step_dt : h, tol = 2e-4 * w->def.contact_gap / (dt * dt);
    int i;
    for (i = 0; i < ni; ++i) {
        int r = irows[i] * 6, j;
        for (j = 0; j < 3; ++j) {
            tmp[r + j] = s0[r + j] + h * s0[r + 3 + j] + 0.5 * h * h * k1[r + 3 + j];
            tmp[r + 3 + j] = s0[r + 3 + j] + h * k1[r + 3 + j];
        }
    }
    if (derivative(w, tmp, irows, ni, t, nt, acc, k2)) return -1;
    for (i = 0; i < ni; ++i) {
        int r = irows[i] * 6;
        double dx = k2[r + SVX] - k1[r + SVX], dy = k2[r + SVY] - k1[r + SVY];
        double dw = (k2[r + SW] - k1[r + SW]) * w->shape[irows[i]].radius;
        if (!(dx * dx + dy * dy <= tol * tol && fabs(dw) <= tol)) return 0;
    }
    for (i = 0; i < ni; ++i) {
        int r = irows[i] * 6, j;
        for (j = 0; j < 3; ++j) {
            double a0 = k1[r + 3 + j], a1 = k2[r + 3 + j];
            s1[r + j] = s0[r + j] + h * s0[r + 3 + j] + h * h * (a0 / 3.0 + a1 / 6.0);
            s1[r + 3 + j] = s0[r + 3 + j] + 0.5 * h * (a0 + a1);
        }
    }
    w->last.quiet_advances++;
    return 1;
}

/* copy_all: every row of s1 is written (the unlisted ones as in s0); otherwise only the listed rows. */
static int integrate(lc_world *w, const double *s0, double h, const int *rows, int nrows, lc_touch *touches, int nt,
                     double *s1, int copy_all)
{
    size_t bytes = (size_t)w->count * 6 * sizeof(double);
    int *flags, *irows, ni = 0, i;
    double *acc, *tmp, *k1, *k2, *k3, *k4;
    if (w->count == 0) return 0;
    flags = lc_buf_get(&w->integrator->flags, (size_t)w->count * sizeof(int));
    irows = lc_buf_get(&w->integrator->rows, (size_t)(nrows > 0 ? nrows : 1) * sizeof(int));
    acc = lc_buf_get(&w->integrator->acc, (size_t)w->count * 3 * sizeof(double));
    if (!flags || !irows || !acc) return -1;
    if (s1 != s0 && copy_all) {
        /* only the rows not advanced below come from s0 (in free flight, the static ones): a copy of the
         * whole state, then written over, is a pass over every body's state for nothing */
        uint8_t *written = h == 0.0 ? NULL : lc_buf_get(&w->integrator->written, (size_t)w->count);
        if (written == NULL) {
            memcpy(s1, s0, bytes);
        } else {
            memset(written, 0, (size_t)w->count);
            for (i = 0; i < nrows; ++i)
                if (!w->is_static[rows[i]]) written[rows[i]] = 1;
            for (i = 0; i < w->count; ++i)
                if (!written[i]) memcpy(&s1[i * 6], &s0[i * 6], 6 * sizeof(double));
        }
    }
    /* a moving row is written whole below when time passes; a static one only here */
    if (s1 != s0 && !copy_all)
        for (i = 0; i < nrows; ++i)
            if (h == 0.0 || w->is_static[rows[i]]) memcpy(&s1[rows[i] * 6], &s0[rows[i] * 6], 6 * sizeof(double));
    if (h == 0.0) return 0;   /* no time passes: no force evaluation (a pile's is a full contact solve) */
    /* without touches no row is flagged: a time-of-impact search of two bodies in a large world must
     * not clear a flag per body at each of its iterations */
    if (nt > 0) {
        memset(flags, 0, (size_t)w->count * sizeof(int));
        for (i = 0; i < nt; ++i) flags[touches[i].a] = flags[touches[i].b] = 1;
    }
    for (i = 0; i < nrows; ++i) {
        int r = rows[i];
        if (w->is_static[r]) continue;
        if ((nt == 0 || !flags[r]) && lc_body_forces_constant(w, r)) {
            advance_closed_form(w, s0, h, r, s1);
            w->last.analytic_advances++;
        } else {
            irows[ni++] = r;
        }
    }
    if (ni == 0) return 0;
    tmp = lc_buf_get(&w->integrator->tmp, bytes);
    k1 = lc_buf_get(&w->integrator->k[0], bytes);
    k2 = lc_buf_get(&w->integrator->k[1], bytes);
    k3 = lc_buf_get(&w->integrator->k[2], bytes);
    k4 = lc_buf_get(&w->integrator->k[3], bytes);
    if (!tmp || !k1 || !k2 || !k3 || !k4) return -1;
    /* tmp holds every row (others constant during the step) so springs and contacts can read them */
    memcpy(tmp, s0, bytes);
    if (derivative(w, s0, irows, ni, touches, nt, acc, k1)) return -1;
    switch (w->def.integrator) {
    case LC_INTEGRATOR_EULER:
        axpy_rows(s1, s0, h, k1, irows, ni);
        break;
    case LC_INTEGRATOR_MIDPOINT:
        axpy_rows(tmp, s0, 0.5 * h, k1, irows, ni);
        if (derivative(w, tmp, irows, ni, touches, nt, acc, k2)) return -1;
        axpy_rows(s1, s0, h, k2, irows, ni);
        break;
    case LC_INTEGRATOR_RK4:
    default:
        if (nt > 0 && rows_quiet(w, s0, irows, ni)) {
            int q = advance_quiet(w, s0, h, irows, ni, touches, nt, acc, tmp, k1, k2, s1);
            if (q != 0) return q < 0 ? -1 : 0;
        }
        axpy_rows(tmp, s0, 0.5 * h, k1, irows, ni);
        if (derivative(w, tmp, irows, ni, touches, nt, acc, k2)) return -1;
        axpy_rows(tmp, s0, 0.5 * h, k2, irows, ni);
        if (derivative(w, tmp, irows, ni, touches, nt, acc, k3)) return -1;
        axpy_rows(tmp, s0, h, k3, irows, ni);
        if (derivative(w, tmp, irows, ni, touches, nt, acc, k4)) return -1;
        for (i = 0; i < ni; ++i) {
            int r = irows[i] * 6, j;
            for (j = 0; j < 6; ++j)
                s1[r + j] = s0[r + j] + (h / 6.0) * (k1[r + j] + 2.0 * k2[r + j] + 2.0 * k3[r + j] + k4[r + j]);
        }
        break;
    }
    /* the last evaluation's contact forces describe the end of the interval closely enough for output;
     * re-evaluate at s1 so reported forces belong to the reported state */
    return 0;
}

int lc_integrate(lc_world *w, const double *s0, double h, const int *rows, int nrows,
                 lc_touch *touches, int nt, double *s1)
{
    return integrate(w, s0, h, rows, nrows, touches, nt, s1, 1);
}

int lc_integrate_rows(lc_world *w, const double *s0, double h, const int *rows, int nrows,
                      lc_touch *touches, int nt, double *s1)
{
    return integrate(w, s0, h, rows, nrows, touches, nt, s1, 0);
}
