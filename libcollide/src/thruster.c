/* Thrusters: adding them to a dynamic body (one, or the seed's four keyboard thrusters), setting and
 * reading their levels and counting them. forces.c turns them into forces. */
#include <math.h>
#include "world.h"

lc_status lc_body_add_thruster(lc_world *w, lc_body_id id, const lc_thruster_def *d, int *out_index)
{
    int row, k;
    double len;
    lc_thruster *t;
    LC_GET_DYNAMIC_ROW(w, id, row);
    if (d == NULL) return lc_fail(w, LC_ERR_NULL, "thruster def is NULL");
    LC_TRY(lc_check_vec(w, d->point, 1e6, "thruster point"));
    LC_TRY(lc_check_vec(w, d->direction, 1e6, "thruster direction"));
    LC_CHECK_RANGE(w, d->magnitude, 0.0, 1e9, "thruster magnitude");
    len = sqrt(lc_dot(d->direction, d->direction));
    if (!(len > 1e-12)) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "thruster direction is zero");
    k = w->thruster_count[row];
    if (k >= LC_MAX_THRUSTERS) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body %u already has %d thrusters", (unsigned)id, LC_MAX_THRUSTERS);
    t = &w->thrusters[row][k];
    /* stored about the centre of mass so force evaluation needs no offset */
    t->point = lc_sub(d->point, w->shape[row].center_offset);
    t->direction = lc_scale(d->direction, 1.0 / len);
    t->magnitude = d->magnitude;
    t->level = 0.0;
    w->thruster_count[row] = k + 1;
    if (out_index) *out_index = k;
    return lc_changed(w);
}

lc_status lc_body_add_default_thrusters(lc_world *w, lc_body_id id, double thrust, int *out_first)
{
    int row, i, first;
    double top = 0.0, bottom = 0.0;
    lc_thruster_def d[4];
    LC_GET_DYNAMIC_ROW(w, id, row);
    LC_CHECK_RANGE(w, thrust, 0.0, 1e9, "thrust");
    if (w->thruster_count[row] + 4 > LC_MAX_THRUSTERS)
        return lc_fail(w, LC_ERR_OUT_OF_RANGE, "body %u has no room for 4 more thrusters", (unsigned)id);
    for (i = 0; i < w->shape[row].count; ++i) {
        top = fmax(top, w->shape[row].v[i].y);
        bottom = fmin(bottom, w->shape[row].v[i].y);
    }
    /* As the seed: side thrusters (0.4 of the thrust) act at 0.8 of the height so they also turn the
     * block; up/down act through the centre of mass. Points are given in the local-origin frame. */
    {
        lc_vec2 c = w->shape[row].center_offset;
        double side_y = bottom + 0.8 * (top - bottom);
        d[0].point = lc_add(c, lc_v(0.0, side_y)); d[0].direction = lc_v(-1, 0); d[0].magnitude = 0.4 * thrust;
        d[1].point = lc_add(c, lc_v(0.0, side_y)); d[1].direction = lc_v(1, 0);  d[1].magnitude = 0.4 * thrust;
        d[2].point = c;                            d[2].direction = lc_v(0, 1);  d[2].magnitude = thrust;
        d[3].point = c;                            d[3].direction = lc_v(0, -1); d[3].magnitude = thrust;
    }
    first = w->thruster_count[row];
    for (i = 0; i < 4; ++i) LC_TRY(lc_body_add_thruster(w, id, &d[i], NULL));
    if (out_first) *out_first = first;
    return lc_changed(w);
}

lc_status lc_body_set_thruster_level(lc_world *w, lc_body_id id, int index, double level)
{
    int row;
    LC_GET_DYNAMIC_ROW(w, id, row);
    if (index < 0 || index >= w->thruster_count[row])
        return lc_fail(w, LC_ERR_UNKNOWN_THRUSTER, "body %u has no thruster %d (it has %d)", (unsigned)id, index, w->thruster_count[row]);
    LC_CHECK_RANGE(w, level, 0.0, 1.0, "thruster level");
    w->thrusters[row][index].level = level;
    return lc_changed(w);
}

lc_status lc_body_set_thruster_mask(lc_world *w, lc_body_id id, uint32_t mask)
{
    int row, i;
    LC_GET_DYNAMIC_ROW(w, id, row);
    if (w->thruster_count[row] < 32 && (mask >> w->thruster_count[row]) != 0)
        return lc_fail(w, LC_ERR_UNKNOWN_THRUSTER, "mask 0x%x names thrusters body %u does not have (it has %d)", (unsigned)mask, (unsigned)id, w->thruster_count[row]);
    for (i = 0; i < w->thruster_count[row]; ++i) w->thrusters[row][i].level = (mask >> i) & 1u ? 1.0 : 0.0;
    return lc_changed(w);
}

lc_status lc_body_get_thruster_level(const lc_world *w, lc_body_id id, int index, double *out)
{
    int row = -1;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    if (index < 0 || index >= w->thruster_count[row])
        return lc_fail((lc_world *)w, LC_ERR_UNKNOWN_THRUSTER, "body %u has no thruster %d (it has %d)", (unsigned)id, index, w->thruster_count[row]);
    *out = w->thrusters[row][index].level;
    return LC_OK;
}

lc_status lc_body_get_thruster_mask(const lc_world *w, lc_body_id id, uint32_t *out)
{
    int row, i;
    uint32_t mask = 0;
    LC_TRY(lc_read_row(w, id, out != NULL, "out", &row));
    for (i = 0; i < w->thruster_count[row]; ++i)
        if (w->thrusters[row][i].level > 0.0) mask |= (uint32_t)1u << i;
    *out = mask;
    return LC_OK;
}

int lc_body_thruster_count(const lc_world *w, lc_body_id id)
{
    int row = lc_world_body_index(w, id);
    return row < 0 ? -1 : w->thruster_count[row];
}
