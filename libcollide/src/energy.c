/* Energy split as on the seed's bar graph (translational, rotational, gravitational, spring), the force
 * callback's potential, and momentum (lc_world_get_energy), and the energy balances that tell a step
 * which has blown up. */
#include <math.h>
#include "world.h"

double lc_spring_energy(const lc_world *w, const double *state);

void lc_compute_energy(const lc_world *w, const double *state, lc_energy *out)
{
    int i;
    double g = sqrt(lc_dot(w->def.gravity, w->def.gravity));
    lc_vec2 up = g > 0.0 ? lc_scale(w->def.gravity, -1.0 / g) : lc_v(0.0, 1.0);
    out->translational = out->rotational = out->gravitational = 0.0;
    out->linear_momentum = lc_v(0.0, 0.0);
    out->angular_momentum = 0.0;
    for (i = 0; i < w->count; ++i) {
        const double *s = &state[i * 6];
        double m = w->mass[i], I = w->inertia[i];
        if (w->is_static[i]) continue;
        out->translational += 0.5 * m * (s[SVX] * s[SVX] + s[SVY] * s[SVY]);
        out->rotational += 0.5 * I * s[SW] * s[SW];
        /* height along -gravity; zero_energy_level is measured along that same axis */
        out->gravitational += m * g * (s[SX] * up.x + s[SY] * up.y - w->def.zero_energy_level);
        out->linear_momentum.x += m * s[SVX];
        out->linear_momentum.y += m * s[SVY];
        out->angular_momentum += m * (s[SX] * s[SVY] - s[SY] * s[SVX]) + I * s[SW];
    }
    out->spring = lc_spring_energy(w, state);
    out->callback = 0.0;
    out->total = out->translational + out->rotational + out->gravitational + out->spring;
}

/* The step's balances above leave the callback's potential out (its work is bounded like an external
 * force's, from the largest force it gave); the caller's reading includes it. */
lc_status lc_world_get_energy(const lc_world *w, lc_energy *out)
{
    lc_energy e;
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out is NULL");
    lc_compute_energy(w, w->state, &e);
    LC_TRY(lc_force_callback_potential(w, w->state, &e.callback));
    e.total += e.callback;
    *out = e;
    return LC_OK;
}

/* Contact forces do no work beyond round-off; a trial interval in which the bodies they act on gain
 * more than their kinetic energy again (plus 1 J), gravity's work counted, has blown up: a point
 * driven by forces of 1e23 N against an edge turning at 1e6 rad/s (fuzzer inputs), never a real
 * scene. Bodies with thrust, torque or a spring can gain energy legitimately: then no verdict. */
int lc_contact_energy_blew_up(const lc_world *w, const double *s0, const double *s1, const lc_touch *rest,
                               int nrest, uint8_t *mark)
{
    double ke0 = 0.0, gain = 0.0;
    int i, verdict = 1;
    for (i = 0; i < nrest; ++i) mark[rest[i].a] = mark[rest[i].b] = 1;
    for (i = 0; i < w->spring_count && verdict; ++i) {
        int a = lc_world_body_index(w, w->springs[i].def.body_a);
        int b = w->springs[i].def.body_b == LC_WORLD_ANCHOR ? -1 : lc_world_body_index(w, w->springs[i].def.body_b);
        if ((a >= 0 && mark[a]) || (b >= 0 && mark[b])) verdict = 0;
    }
    for (i = 0; i < w->count; ++i) {
        const double *a = &s0[i * 6], *b = &s1[i * 6];
        double m, in;
        if (!mark[i]) continue;
        mark[i] = 0;
        if (w->is_static[i]) continue;
        if (lc_body_driven(w, i)) verdict = 0;   /* thrusters too: a 100 N thruster on a block resting on
                                                   * the floor failed its first step here */
        m = w->inv_mass[i] > 0.0 ? 1.0 / w->inv_mass[i] : 0.0;
        in = w->inv_inertia[i] > 0.0 ? 1.0 / w->inv_inertia[i] : 0.0;
        ke0 += 0.5 * m * (a[SVX] * a[SVX] + a[SVY] * a[SVY]) + 0.5 * in * a[SW] * a[SW];
        gain += 0.5 * m * (b[SVX] * b[SVX] + b[SVY] * b[SVY] - a[SVX] * a[SVX] - a[SVY] * a[SVY]) +
                0.5 * in * (b[SW] * b[SW] - a[SW] * a[SW]) -
                m * (w->def.gravity.x * (b[SX] - a[SX]) + w->def.gravity.y * (b[SY] - a[SY]));
    }
    return verdict && !(gain <= ke0 + 1.0);
}

/* Impacts (e <= 1), contact forces, damping and springs (their energy counted) take energy out or keep
 * it; only external forces, torques, thrusters and the force callback (its largest force in the step)
 * put it in, at most |F| |v| dt. A step that ends with more energy than it started with, beyond 1 J +
 * 1e-3 of it plus ten times that bound on the driving forces' work (with |v| the larger of the body's
 * speeds at the step's two ends, and the |F|^2 dt^2 / m a force adds from rest), has blown up: a
 * 1e-12 m, 10 kg polygon at 1e6 m/s pushed by an external force in a 12 m box went to 5.7e21 m/s
 * within one 22 ms step and left the box (regression input
 * fuzz/corpus/step-regressions/energy-pushed-1e-12m-polygon-1e6ms-leaves-box; no single trial
 * interval doubled its energy, which the per-interval check above looks for). A real driving force's
 * work grows with the speed, the blow-up's energy with its square. Measured before the end-of-step
 * projection, which may lift overlapping bodies against gravity; a step that starts with bodies deep
 * in each other is left to the projection. */
int lc_step_energy_blew_up(const lc_world *w, const double *backup, double dt, int started_deep)
{
    lc_energy e0, e1;
    double drive = 0.0;
    int i, k;
    /* a step of integration alone (no impact, no contact force) is checked by its finite state; the
     * balance costs ~5 % of a 20-block step and is kept for the steps where contacts acted */
    if (started_deep || (w->last.collisions == 0 && w->last.contact_solves == 0 && w->last.contact_islands == 0)) return 0;
    for (i = 0; i < w->count; ++i) {
        const double *a = &backup[i * 6], *b = &w->state[i * 6];
        double f, tau, v, om;
        if (w->is_static[i]) continue;
        lc_force_callback_peak(w, i, &f, &tau);
        f += sqrt(lc_dot(w->ext_force[i], w->ext_force[i]));
        tau += fabs(w->ext_torque[i]);
        for (k = 0; k < w->thruster_count[i]; ++k) {
            const lc_thruster *t = &w->thrusters[i][k];
            double thrust = fabs(t->magnitude * t->level);
            f += thrust;
            tau += thrust * sqrt(lc_dot(t->point, t->point));
        }
        if (f == 0.0 && tau == 0.0) continue;
        v = fmax(sqrt(a[SVX] * a[SVX] + a[SVY] * a[SVY]), sqrt(b[SVX] * b[SVX] + b[SVY] * b[SVY]));
        om = fmax(fabs(a[SW]), fabs(b[SW]));
        drive += 10.0 * (f * v + tau * om) * dt + f * f * dt * dt * w->inv_mass[i] + tau * tau * dt * dt * w->inv_inertia[i];
    }
    lc_compute_energy(w, backup, &e0);
    lc_compute_energy(w, w->state, &e1);
    return !(e1.total <= e0.total + 1.0 + 1e-3 * fabs(e0.total) + drive);
}
