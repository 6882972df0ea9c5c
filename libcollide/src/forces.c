/* Applied forces: gravity, damping, thrusters, springs, external force/torque and the force callback
 * (force_callback.c), as accelerations. */
#include <math.h>
#include "world.h"

static void spring_force(const lc_world *w, const double *state, const lc_spring_def *d, int ra, int rb,
                         lc_vec2 *force_on_a, lc_vec2 *pa, lc_vec2 *pb, lc_vec2 *arm_a, lc_vec2 *arm_b)
{
    const double *sa = &state[ra * 6];
    double ca = cos(sa[SA]), sna = sin(sa[SA]);
    lc_vec2 va, vb, f, dlt;
    double len;
    *arm_a = lc_rot(ca, sna, lc_sub(d->point_a, w->shape[ra].center_offset));
    *pa = lc_add(lc_v(sa[SX], sa[SY]), *arm_a);
    va = lc_add(lc_v(sa[SVX], sa[SVY]), lc_wcross(sa[SW], *arm_a));
    if (rb < 0) {
        *pb = d->point_b;
        *arm_b = lc_v(0, 0);
        vb = lc_v(0, 0);
    } else {
        const double *sb = &state[rb * 6];
        double cb = cos(sb[SA]), snb = sin(sb[SA]);
        *arm_b = lc_rot(cb, snb, lc_sub(d->point_b, w->shape[rb].center_offset));
        *pb = lc_add(lc_v(sb[SX], sb[SY]), *arm_b);
        vb = lc_add(lc_v(sb[SVX], sb[SVY]), lc_wcross(sb[SW], *arm_b));
    }
    dlt = lc_sub(*pa, *pb);
    len = sqrt(lc_dot(dlt, dlt));
    /* Zero rest length needs no direction (F = -k * delta), which keeps the mouse spring smooth at 0. */
    if (d->rest_length == 0.0) f = lc_scale(dlt, -d->stiffness);
    else if (len > 0.0) f = lc_scale(dlt, -d->stiffness * (len - d->rest_length) / len);
    else f = lc_v(0, 0);
    /* Damping on the full relative velocity of the two points, as the seed's spring does. */
    f = lc_sub(f, lc_scale(lc_sub(va, vb), d->damping));
    *force_on_a = f;
}

int lc_applied_accelerations(lc_world *w, const double *state, const int *rows, int n, double *acc)
{
    int i, k;
    const lc_world_def *def = &w->def;
    const double *user = NULL;
    if (lc_force_callback_on(w) && lc_force_callback_eval(w, state, rows, n, &user) != 0) {
        for (i = 0; i < n; ++i) acc[rows[i] * 3] = acc[rows[i] * 3 + 1] = acc[rows[i] * 3 + 2] = NAN;
        return -1;
    }
    for (i = 0; i < n; ++i) {
        int r = rows[i];
        const double *s = &state[r * 6];
        double m = w->mass[r], fx, fy, tq;
        double *a = &acc[r * 3];
        if (w->is_static[r]) { a[0] = a[1] = a[2] = 0.0; continue; }
        fx = m * def->gravity.x + w->ext_force[r].x;
        fy = m * def->gravity.y + w->ext_force[r].y;
        tq = w->ext_torque[r];
        /* the callback's force right after the external one: a callback force F on a body without one
         * sums to the same bits as an external force F without a callback (x + 0 = x) */
        if (user != NULL) {
            fx += user[r * 3];
            fy += user[r * 3 + 1];
            tq += user[r * 3 + 2];
        }
        fx -= def->damping * s[SVX];
        fy -= def->damping * s[SVY];
        tq -= def->damping * def->damping_rotation_ratio * s[SW];
        if (w->thruster_count[r] > 0) {
            double c = cos(s[SA]), sn = sin(s[SA]);
            for (k = 0; k < w->thruster_count[r]; ++k) {
                const lc_thruster *t = &w->thrusters[r][k];
                lc_vec2 f, arm;
                if (t->level == 0.0) continue;
                f = lc_scale(lc_rot(c, sn, t->direction), t->magnitude * t->level);
                arm = lc_rot(c, sn, t->point);
                fx += f.x;
                fy += f.y;
                tq += lc_cross(arm, f);
            }
        }
        a[0] = fx;   /* forces first; divided by mass after springs are added */
        a[1] = fy;
        a[2] = tq;
    }
    /* Springs touch rows that may or may not be in the list; only listed rows are written. A row's
     * list membership is checked through a mark in acc: rows not listed are left untouched. */
    for (k = 0; k < w->spring_count; ++k) {
        const lc_spring_def *d = &w->springs[k].def;
        int ra = lc_world_body_index(w, d->body_a);
        int rb = d->body_b == LC_WORLD_ANCHOR ? -1 : lc_world_body_index(w, d->body_b);
        int in_a = 0, in_b = 0;
        lc_vec2 f, pa, pb, arm_a, arm_b;
        for (i = 0; i < n; ++i) {
            if (rows[i] == ra) in_a = 1;
            if (rb >= 0 && rows[i] == rb) in_b = 1;
        }
        if (!in_a && !in_b) continue;
        spring_force(w, state, d, ra, rb, &f, &pa, &pb, &arm_a, &arm_b);
        if (in_a) {
            acc[ra * 3 + 0] += f.x;
            acc[ra * 3 + 1] += f.y;
            acc[ra * 3 + 2] += lc_cross(arm_a, f);
        }
        if (in_b && !w->is_static[rb]) {
            acc[rb * 3 + 0] -= f.x;
            acc[rb * 3 + 1] -= f.y;
            acc[rb * 3 + 2] -= lc_cross(arm_b, f);
        }
    }
    for (i = 0; i < n; ++i) {
        int r = rows[i];
        if (w->is_static[r]) continue;
        acc[r * 3 + 0] *= w->inv_mass[r];
        acc[r * 3 + 1] *= w->inv_mass[r];
        acc[r * 3 + 2] *= w->inv_inertia[r];
    }
    return 0;
}

int lc_body_thrusting(const lc_world *w, int row)
{
    int k;
    for (k = 0; k < w->thruster_count[row]; ++k)
        if (w->thrusters[row][k].level != 0.0) return 1;
    return 0;
}

int lc_body_driven(const lc_world *w, int row)
{
    double f, tq;
    if (w->ext_force[row].x != 0.0 || w->ext_force[row].y != 0.0 || w->ext_torque[row] != 0.0 ||
        lc_body_thrusting(w, row))
        return 1;
    lc_force_callback_peak(w, row, &f, &tq);
    return f != 0.0 || tq != 0.0;
}

int lc_body_forces_constant(const lc_world *w, int row)
{
    int k;
    lc_body_id id = w->ids[row];
    /* the callback's force may change with any body's state */
    if (w->def.damping != 0.0 || lc_body_thrusting(w, row) || lc_force_callback_on(w)) return 0;
    for (k = 0; k < w->spring_count; ++k)
        if (w->springs[k].def.body_a == id || w->springs[k].def.body_b == id) return 0;
    return 1;
}

/* Potential energy of the springs (J), used by energy.c. */
double lc_spring_energy(const lc_world *w, const double *state);
double lc_spring_energy(const lc_world *w, const double *state)
{
    int k;
    double e = 0.0;
    for (k = 0; k < w->spring_count; ++k) {
        const lc_spring_def *d = &w->springs[k].def;
        int ra = lc_world_body_index(w, d->body_a);
        int rb = d->body_b == LC_WORLD_ANCHOR ? -1 : lc_world_body_index(w, d->body_b);
        lc_vec2 f, pa, pb, arm_a, arm_b, dl;
        double len, stretch;
        spring_force(w, state, d, ra, rb, &f, &pa, &pb, &arm_a, &arm_b);
        dl = lc_sub(pa, pb);
        len = sqrt(lc_dot(dl, dl));
        stretch = len - d->rest_length;
        e += 0.5 * d->stiffness * stretch * stretch;
    }
    return e;
}
