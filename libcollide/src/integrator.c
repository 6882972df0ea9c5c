/* Time integration between impacts: closed form for bodies under constant forces, otherwise the
 * world's explicit integrator (Euler, midpoint or RK4) with resting contact forces in every evaluation. */
#include <string.h>
#include "world.h"

/* Derivative of the listed rows: d/dt (x, y, a, vx, vy, w) = (vx, vy, w, ax, ay, alpha). */
static int derivative(lc_world *w, const double *s, const int *rows, int n, lc_touch *t, int nt,
                      double *acc, double *k)
{
    int i;
    lc_applied_accelerations(w, s, rows, n, acc);
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

int lc_integrate(lc_world *w, const double *s0, double h, const int *rows, int nrows,
                 lc_touch *touches, int nt, double *s1)
{
    size_t bytes = (size_t)w->count * 6 * sizeof(double);
    int *flags, *irows, ni = 0, i;
    double *acc, *tmp, *k1, *k2, *k3, *k4;
    if (w->count == 0) return 0;
    flags = lc_buf_get(&w->b_flags, (size_t)w->count * sizeof(int));
    irows = lc_buf_get(&w->b_irows, (size_t)(nrows > 0 ? nrows : 1) * sizeof(int));
    acc = lc_buf_get(&w->b_acc, (size_t)w->count * 3 * sizeof(double));
    if (!flags || !irows || !acc) return -1;
    if (s1 != s0) memcpy(s1, s0, bytes);
    if (h == 0.0) return 0;   /* no time passes: no force evaluation (a pile's is a full contact solve) */
    memset(flags, 0, (size_t)w->count * sizeof(int));
    for (i = 0; i < nt; ++i) flags[touches[i].a] = flags[touches[i].b] = 1;
    for (i = 0; i < nrows; ++i) {
        int r = rows[i];
        if (w->is_static[r]) continue;
        if (!flags[r] && lc_body_forces_constant(w, r)) {
            advance_closed_form(w, s0, h, r, s1);
            w->last.analytic_advances++;
        } else {
            irows[ni++] = r;
        }
    }
    if (ni == 0) return 0;
    tmp = lc_buf_get(&w->b_tmp, bytes);
    k1 = lc_buf_get(&w->b_k[0], bytes);
    k2 = lc_buf_get(&w->b_k[1], bytes);
    k3 = lc_buf_get(&w->b_k[2], bytes);
    k4 = lc_buf_get(&w->b_k[3], bytes);
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
