/* What a step reports: its contacts (lc_world_get_contacts) and its work (lc_world_get_counters). */
#include <stdlib.h>
#include "world.h"

lc_contact *lc_new_contact(lc_world *w)
{
    if (w->contact_count == w->contact_cap) {
        int cap = w->contact_cap ? 2 * w->contact_cap : 32;
        void *p = realloc(w->contacts, (size_t)cap * sizeof *w->contacts);
        if (p == NULL) return NULL;
        w->contacts = p;
        w->contact_cap = cap;
    }
    return &w->contacts[w->contact_count++];
}

int lc_push_contact(lc_world *w, const lc_touch *t, lc_contact_kind kind)
{
    lc_contact *c = lc_new_contact(w);
    if (c == NULL) return -1;
    c->body_a = w->ids[t->a];
    c->body_b = w->ids[t->b];
    c->point = t->p;
    c->normal = t->n;
    c->gap = t->gap;
    c->time = w->time;
    c->kind = kind;
    if (kind == LC_CONTACT_COLLISION) {
        c->normal_velocity = t->vn_pre;
        c->impulse = t->value;
        c->tangent_impulse = t->tangent;
        c->force = 0.0;
    } else {
        c->normal_velocity = t->vn;
        c->impulse = 0.0;
        c->tangent_impulse = 0.0;
        c->force = t->value;
    }
    return 0;
}

void lc_counters_add(lc_counters *total, const lc_counters *last)
{
    total->steps += last->steps;
    total->force_evaluations += last->force_evaluations;
    total->analytic_advances += last->analytic_advances;
    total->broadphase_pairs += last->broadphase_pairs;
    total->brute_force_steps += last->brute_force_steps;
    total->sort_and_sweep_steps += last->sort_and_sweep_steps;
    total->grid_steps += last->grid_steps;
    total->collisions += last->collisions;
    total->impulses += last->impulses;
    total->toi_searches += last->toi_searches;
    total->toi_iterations += last->toi_iterations;
    total->serial_iterations += last->serial_iterations;
    total->inelastic_fallbacks += last->inelastic_fallbacks;
    total->resting_contacts += last->resting_contacts;
    total->contact_solves += last->contact_solves;
    total->contact_solve_iterations += last->contact_solve_iterations;
    total->solver_work += last->solver_work;
    total->impulse_solves += last->impulse_solves;
    total->position_projections += last->position_projections;
    total->quiet_advances += last->quiet_advances;
    total->islands += last->islands;
    total->island_retries += last->island_retries;
    total->contact_islands += last->contact_islands;
    total->contact_points += last->contact_points;
    total->contact_sweeps += last->contact_sweeps;
    total->contact_exact_solves += last->contact_exact_solves;
    total->contact_cuts += last->contact_cuts;
    total->contact_precise_retries += last->contact_precise_retries;
    total->energy_clamps += last->energy_clamps;
    total->contact_rests += last->contact_rests;
    total->contact_unresolved += last->contact_unresolved;
    if (last->max_unresolved_overlap > total->max_unresolved_overlap) total->max_unresolved_overlap = last->max_unresolved_overlap;
    if (last->max_unresolved_energy > total->max_unresolved_energy) total->max_unresolved_energy = last->max_unresolved_energy;
    if (last->max_contact_residual > total->max_contact_residual) total->max_contact_residual = last->max_contact_residual;
    if (last->max_lcp_residual > total->max_lcp_residual) total->max_lcp_residual = last->max_lcp_residual;
    total->time_step += last->time_step;
    total->time_detection += last->time_detection;
    total->time_integration += last->time_integration;
    total->time_toi_search += last->time_toi_search;
    total->time_impulses += last->time_impulses;
    total->time_projection += last->time_projection;
    total->time_contact_forces += last->time_contact_forces;
    total->time_contact_regime += last->time_contact_regime;
}

lc_status lc_world_get_contacts(const lc_world *w, const lc_contact **out, int *out_count)
{
    if (w == NULL) return LC_ERR_NULL;
    if (out == NULL || out_count == NULL) return lc_fail((lc_world *)w, LC_ERR_NULL, "out or out_count is NULL");
    *out = w->contacts;
    *out_count = w->contact_count;
    return LC_OK;
}

lc_status lc_world_get_counters(const lc_world *w, lc_counters *last, lc_counters *total)
{
    if (w == NULL) return LC_ERR_NULL;
    if (last) *last = w->last;
    if (total) *total = w->total;
    return LC_OK;
}
