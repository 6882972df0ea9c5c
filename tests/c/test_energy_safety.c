/* test_energy_safety: no allowed setting of the contact model lets a body gain energy.
 * Settings: contact_gap on a log grid over its whole range [1e-12, 1e-2] m (1e-12, 1e-9, 1e-7,
 * 1e-5, 1e-3, 1e-2) crossed with resting_speed over its whole range [0, 10] m/s (0, 1e-4, 1e-2, 0.1,
 * 1, 10): 36 settings. contact_distance, which must exceed contact_gap, is max(1e-5, 10 contact_gap)
 * (1e-5 is its default; 0.1 m at the largest gap) and toi_distance_tolerance, which must stay below
 * contact_gap, is min(1e-10, contact_gap / 10) (1e-10 is its default); everything else default
 * (g = 9.81 m/s^2 vertical, RK4, serial impacts, restitution_threshold 1e-2 m/s).
 * Scenes, each under every setting, dt = 1/60 s:
 *  (a) drop: four static walls whose inner faces bound [-5, 5] x [0, 10] m (1 m thick); a 1 m x
 *      0.5 m, 1 kg block with its centre 1 m above the floor, turned by 0.3 rad and spinning at
 *      1 rad/s, its centre at rest; elasticity 0.5 and friction 0.5 on every body; 3 s (it lands on a
 *      corner, bounces, and lies flat on the floor by the end at the default settings).
 *  (b) pile: the seed's scene of test_pile: walls bounding [-6, 6]^2 m, six 1 m x 3 m, 1 kg blocks at
 *      x = -5, -3, ..., 5 with heights, angles, velocities and spins drawn from sc_rng seed 42 (the
 *      same draws as test_pile); elasticity 0.5 and friction 0.5 on every body; 5 s (they collide,
 *      pile up on the floor and nearly stop: ~1e-6 m/s at the end at the default settings).
 * Energy: E = sum m |v|^2 / 2 + I omega^2 / 2 + m g y (zero at y = 0), computed here from the state
 * view. Nothing drives these scenes: impacts at e <= 1, Coulomb friction and contact forces only
 * take energy away (a contact force that holds a resting contact does no work on it; one that
 * stops an approach takes the approach's energy), so the exact E never rises. The engine must hold
 * that at every setting: a touch that closes at any speed, between resting_speed and the speed that
 * crosses contact_distance in one step included, is stopped by a force or an impact, and any
 * correction of positions that lifts a body is paid for out of its kinetic energy, never added.
 * Assertions, per scene and setting:
 *  - every step returns LC_OK (a setting inside its documented range is a valid input);
 *  - from one step end to the next, E rises by at most 1e-9 |E| + 1e-12 J (|E| the larger of the
 *    two): |E| is a few J in (a) and ~265 J in (b), and 1e-9 of it is seven orders above the
 *    round-off of the sum and of the states that make it (1e-16 relative), room enough for the
 *    converged residuals of iterative solves, and for nothing physical. A lift of a resting 1 kg
 *    block by half the default contact gap is 4.9e-7 J and breaks it; so does keeping the approach
 *    speed of a contact whose position was corrected;
 *  - at every step end no pair overlaps by more than 1e-6 m (sc_separation): a coarse guard, 1e-4
 *    of the largest gap and far above positional round-off (~1e-15 m at these coordinates), against
 *    a setting that trades the energy bound for missed crossings (test_pile holds 1e-9 m at the
 *    default gap);
 *  - no body's centre leaves the box (a tunnelled body would fall forever and gain nothing, but it
 *    is no valid answer). */
#include <time.h>
#include "check.h"
#include "scenes.h"

#define G 9.81
#define DT (1.0 / 60.0)
#define NGAP 6
#define NRS 6

static const double k_gaps[NGAP] = {1e-12, 1e-9, 1e-7, 1e-5, 1e-3, 1e-2};
static const double k_rs[NRS] = {0.0, 1e-4, 1e-2, 0.1, 1.0, 10.0};

typedef struct run_result {
    double max_gain;   /* J, largest rise of E over one step (may be negative: E fell every step) */
    double t_gain;     /* s, end of that step */
    double excess;     /* J, largest rise beyond the round-off allowance (0 if none) */
    int excess_steps;  /* steps whose rise broke the allowance */
    double worst;      /* m, deepest overlap at a step end */
    int outside;       /* step ends with a body centre outside the box */
    int steps_ok;
    int steps;
    lc_status status;  /* first failing status, LC_OK if none */
    double cpu;        /* s of CPU */
    char error[256];   /* lc_world_last_error of the failed step */
} run_result;

static double mech_energy(const lc_world *w)
{
    return sc_kinetic(w) + sc_potential(w, 0.0, -G);
}

static lc_world_def setting(double gap, double rs)
{
    lc_world_def d = lc_default_world_def();
    d.contact_gap = gap;
    d.contact_distance = 10.0 * gap > 1e-5 ? 10.0 * gap : 1e-5;
    d.toi_distance_tolerance = gap / 10.0 < 1e-10 ? gap / 10.0 : 1e-10;
    d.resting_speed = rs;
    return d;
}

static void simulate(lc_world *w, const lc_body_id *b, int nb, const lc_body_id *walls, double xmin, double xmax,
                     double ymin, double ymax, double T, run_result *res)
{
    double e_prev = mech_energy(w);
    int k, i, j;
    clock_t c0 = clock();
    memset(res, 0, sizeof *res);
    res->max_gain = -INFINITY;
    res->steps = (int)(T / DT + 0.5);
    res->status = LC_OK;
    for (k = 0; k < res->steps; k++) {
        double e, gain, scale, allow;
        lc_status s = lc_world_step(w, DT);
        if (s != LC_OK) {
            res->status = s;
            snprintf(res->error, sizeof res->error, "%s", lc_world_last_error(w));
            break;
        }
        res->steps_ok++;
        e = mech_energy(w);
        gain = e - e_prev;
        scale = fabs(e) > fabs(e_prev) ? fabs(e) : fabs(e_prev);
        allow = 1e-9 * scale + 1e-12;
        if (gain > res->max_gain) {
            res->max_gain = gain;
            res->t_gain = lc_world_get_time(w);
        }
        if (!(gain <= allow)) {
            res->excess_steps++;
            if (gain - allow > res->excess) res->excess = gain - allow;
        }
        e_prev = e;
        for (i = 0; i < nb; i++) {
            const double *r = sc_row(w, b[i]);
            if (!(r[0] > xmin && r[0] < xmax && r[1] > ymin && r[1] < ymax)) res->outside++;
            for (j = i + 1; j < nb; j++) {
                double sp = sc_separation(w, b[i], b[j]);
                if (!(-sp <= res->worst)) res->worst = -sp;
            }
            for (j = 0; j < 4; j++) {
                double sp = sc_separation(w, b[i], walls[j]);
                if (!(-sp <= res->worst)) res->worst = -sp;
            }
        }
    }
    res->cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
}

static void set_mu(lc_world *w, const lc_body_id *ids, int n, double e, double mu)
{
    int i;
    for (i = 0; i < n; i++) CHECK(lc_body_set_material(w, ids[i], e, mu) == LC_OK, "%s", "set_material");
}

static void drop(const lc_world_def *d, run_result *res)
{
    lc_world *w = sc_world(d);
    lc_body_id walls[4], b;
    memset(res, 0, sizeof *res);
    res->status = LC_ERR_NULL;
    if (!w) return;
    CHECK(lc_world_add_walls(w, -5.0, 0.0, 5.0, 10.0, 1.0, 0.5, walls) == LC_OK, "%s", "walls");
    set_mu(w, walls, 4, 0.5, 0.5);
    b = sc_box(w, 1.0, 0.5, 0.0, 1.0, 0.3, 0.0, 0.0, 1.0, 1.0, 0.5);
    set_mu(w, &b, 1, 0.5, 0.5);
    simulate(w, &b, 1, walls, -5.0, 5.0, 0.0, 10.0, 3.0, res);
    lc_world_destroy(w);
}

static void pile(const lc_world_def *d, run_result *res)
{
    lc_world *w = sc_world(d);
    lc_body_id walls[4], b[6];
    sc_rng rng = {42u};
    int i;
    memset(res, 0, sizeof *res);
    res->status = LC_ERR_NULL;
    if (!w) return;
    CHECK(lc_world_add_walls(w, -6.0, -6.0, 6.0, 6.0, 1.0, 0.5, walls) == LC_OK, "%s", "walls");
    set_mu(w, walls, 4, 0.5, 0.5);
    for (i = 0; i < 6; i++)
        b[i] = sc_box(w, 1.0, 3.0, -5.0 + 2.0 * i, sc_uniform(&rng, -1.5, 1.5), sc_uniform(&rng, -0.2, 0.2),
                      sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -3.0, 3.0), sc_uniform(&rng, -1.5, 1.5), 1.0, 0.5);
    set_mu(w, b, 6, 0.5, 0.5);
    simulate(w, b, 6, walls, -6.0, 6.0, -6.0, 6.0, 5.0, res);
    lc_world_destroy(w);
}

static void judge(const run_result *r, const char *scene, double gap, double rs)
{
    char label[96];
    snprintf(label, sizeof label, "%s, contact_gap %g, resting_speed %g", scene, gap, rs);
    printf("%-44s %3d/%3d steps ok, max step gain %+.3e J at t = %.3f s, %3d steps over the allowance (worst "
           "by %.3e J), worst overlap %.3e m, outside %d, %.2f s CPU\n", label, r->steps_ok, r->steps, r->max_gain,
           r->t_gain, r->excess_steps, r->excess, r->worst, r->outside, r->cpu);
    CHECK(r->status == LC_OK && r->steps_ok == r->steps, "%s: step %d returned %s: %s", label, r->steps_ok + 1,
          lc_status_string(r->status), r->error);
    CHECK(r->excess_steps == 0, "%s: E rose beyond 1e-9 |E| + 1e-12 J in %d steps, at most %.3e J in a step "
          "(t = %.3f s)", label, r->excess_steps, r->max_gain, r->t_gain);
    CHECK(r->worst <= 1e-6, "%s: bodies overlapped by %.3e m (bound 1e-6)", label, r->worst);
    CHECK(r->outside == 0, "%s: a body centre was outside the box at %d step ends", label, r->outside);
}

int main(void)
{
    static run_result res[2][NGAP][NRS];
    int i, j, s;
    for (i = 0; i < NGAP; i++)
        for (j = 0; j < NRS; j++) {
            lc_world_def d = setting(k_gaps[i], k_rs[j]);
            drop(&d, &res[0][i][j]);
            judge(&res[0][i][j], "(a) drop", k_gaps[i], k_rs[j]);
            pile(&d, &res[1][i][j]);
            judge(&res[1][i][j], "(b) pile", k_gaps[i], k_rs[j]);
        }
    for (s = 0; s < 2; s++) {
        printf("\n%s: largest rise of E over one step (J; * = over the allowance, F = a step failed)\n",
               s ? "(b) pile" : "(a) drop");
        printf("%-10s", "gap \\ rs");
        for (j = 0; j < NRS; j++) printf(" %12g", k_rs[j]);
        printf("\n");
        for (i = 0; i < NGAP; i++) {
            printf("%-10g", k_gaps[i]);
            for (j = 0; j < NRS; j++) {
                const run_result *r = &res[s][i][j];
                printf(" %+10.2e%c%c", r->max_gain, r->excess_steps ? '*' : ' ', r->status != LC_OK ? 'F' : ' ');
            }
            printf("\n");
        }
    }
    return CHECK_SUMMARY("test_energy_safety");
}
