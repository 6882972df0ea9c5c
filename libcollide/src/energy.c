/* Energy split as on the seed's bar graph (translational, rotational, gravitational, spring) and momentum. */
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
    out->total = out->translational + out->rotational + out->gravitational + out->spring;
}
