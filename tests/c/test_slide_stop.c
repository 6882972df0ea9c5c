/* test_slide_stop: a block sliding on a flat floor with Coulomb friction stops where it must.
 * Scene: a static 100 m x 1 m floor (top face y = 0) and a 1 m x 0.5 m, 1 kg block lying flat on it,
 * its lower face exactly contact_gap (default 1e-7 m) above the floor (the resting position the
 * engine holds), moving along +x at v0; g = 9.81 m/s^2 vertical, elasticity 0.3 and friction mu on
 * both bodies (the default geometric-mean rule gives the pair mu), default settings otherwise.
 * Cases: v0 in {1, 3, 5} m/s x mu in {0.3, 0.5, 1.0} x three step sizes: 1/60 s, 1/240 s, and a
 * step of about 0.01 s chosen per case so that the stop time T = v0 / (mu g) falls exactly in the
 * middle of a step (dt = T / (n + 1/2)): a stop never found at a step end. Each case runs until
 * T + 1 s.
 * Physics: the normal force is m g, the friction mu m g against the slide, so the block decelerates
 * uniformly: vx(t) = v0 - mu g t until T = v0 / (mu g), where it stops after d = v0^2 / (2 mu g)
 * and stays (static friction needs no force on a flat floor). The friction's moment about the
 * centre, mu m g x 0.25 m, is balanced by moving the normal load to the front corner, which keeps
 * both corners loaded (mu m g x 0.25 <= m g x 0.5 for mu <= 2), so the block neither tips nor turns.
 * Assertions, per case:
 *  - every step returns LC_OK;
 *  - at every step end before T: vx = v0 - mu g t within 1e-9 m/s (t the engine's clock): a
 *    constant force is integrated exactly and the friction force is exactly mu m g while the block
 *    slides, so only round-off and the friction solve's converged residual remain; over at most
 *    1.7 s, 1e-9 m/s allows a mean force error of 6e-10 N on the 1 kg block;
 *  - the final displacement equals d within 1e-6 relative (d is 0.05-4.2 m, so 5e-8-4e-6 m): the
 *    stop is located inside its step (the friction acts only until vx reaches zero, never
 *    reverses the block and never stops it early), whatever the step. A stop not located, the
 *    speed taken to zero over the whole step instead of the part tau before T, errs by
 *    mu g tau (dt - tau) / 2, i.e. tau (dt - tau) / T^2 relative: 1.1e-6 to 2.8e-3 in these cases;
 *  - at every step end after T, from the end of the step in which it stops: |v| < 1e-9 m/s and
 *    |omega| < 1e-9 rad/s (at rest: the stop is located in its step, and once stopped nothing acts
 *    sideways, so static friction needs no force; round-off only);
 *  - at every step end: |angle| < 1e-9 rad and the block never overlaps the floor by more than
 *    1e-9 m (1 % of the contact gap: contacts are held at the gap, so a correct engine never goes
 *    below zero). */
#include "check.h"
#include "scenes.h"

#define G 9.81

static int g_cases, g_failed_cases;

static void run(double v0, double mu, double dt, const char *dt_label)
{
    lc_world_def def = lc_default_world_def();
    lc_world *w;
    lc_body_id floor_id, blk;
    const double T = v0 / (mu * G), d = v0 * v0 / (2.0 * mu * G);
    const double *r;
    double x0, v_final, dv_max = 0.0, rest_v = 0.0, rest_w = 0.0, ang_max = 0.0, worst = 0.0, disp, t_end = T + 1.0;
    int k, steps = (int)ceil(t_end / dt), ok = 1, fails0 = check_failures();
    char label[96];
    snprintf(label, sizeof label, "v0 %g mu %g dt %s", v0, mu, dt_label);
    w = sc_world(&def);
    if (!w) return;
    floor_id = sc_static_box(w, 100.0, 1.0, 0.0, -0.5, 0.3);
    blk = sc_box(w, 1.0, 0.5, 0.0, 0.25 + def.contact_gap, 0.0, v0, 0.0, 0.0, 1.0, 0.3);
    CHECK(lc_body_set_material(w, floor_id, 0.3, mu) == LC_OK, "%s", "floor material");
    CHECK(lc_body_set_material(w, blk, 0.3, mu) == LC_OK, "%s", "block material");
    x0 = sc_row(w, blk)[0];
    for (k = 0; k < steps; k++) {
        double t, sp;
        lc_status s = lc_world_step(w, dt);
        if (s != LC_OK) {
            CHECK(0, "%s: step at t = %.6f returned %s: %s", label, lc_world_get_time(w), lc_status_string(s),
                  lc_world_last_error(w));
            ok = 0;
            break;
        }
        r = sc_row(w, blk);
        t = lc_world_get_time(w);
        if (t < T) {
            double dv = fabs(r[3] - (v0 - mu * G * t));
            if (dv > dv_max) dv_max = dv;
        } else {
            double v = hypot(r[3], r[4]);
            if (v > rest_v) rest_v = v;
            if (fabs(r[5]) > rest_w) rest_w = fabs(r[5]);
        }
        if (fabs(r[2]) > ang_max) ang_max = fabs(r[2]);
        sp = sc_separation(w, blk, floor_id);
        if (-sp > worst) worst = -sp;
    }
    r = sc_row(w, blk);
    disp = r[0] - x0;
    v_final = hypot(r[3], r[4]);
    printf("%-24s T %.6f s (%6.2f steps) d %.9f m: disp %.9f rel err %.3e | max |vx - (v0 - mu g t)| %.3e m/s | "
           "after stop max |v| %.3e m/s (final %.3e), |omega| %.3e rad/s | max |angle| %.3e | worst overlap %.3e m\n",
           label, T, T / dt, d, disp, fabs(disp - d) / d, dv_max, rest_v, v_final, rest_w, ang_max, worst);
    if (ok) {
        CHECK_REL(disp, d, 1e-6, label);
        CHECK(dv_max <= 1e-9, "%s: vx left v0 - mu g t by %.3e m/s while sliding (bound 1e-9)", label, dv_max);
        CHECK(rest_v < 1e-9, "%s: moving at %.3e m/s after the stop (bound 1e-9)", label, rest_v);
        CHECK(rest_w < 1e-9, "%s: spinning at %.3e rad/s after the stop (bound 1e-9)", label, rest_w);
        CHECK(ang_max < 1e-9, "%s: turned by %.3e rad (bound 1e-9)", label, ang_max);
        CHECK(worst <= 1e-9, "%s: overlapped the floor by %.3e m (bound 1e-9)", label, worst);
    }
    g_cases++;
    if (check_failures() != fails0) g_failed_cases++;
    lc_world_destroy(w);
}

int main(void)
{
    static const double v0s[] = {1.0, 3.0, 5.0}, mus[] = {0.3, 0.5, 1.0};
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            double T = v0s[i] / (mus[j] * G), n = floor(T / 0.01 + 0.5), dt_mid = T / (n + 0.5);
            char lab[32];
            snprintf(lab, sizeof lab, "%.6f", dt_mid);
            run(v0s[i], mus[j], 1.0 / 60.0, "1/60");
            run(v0s[i], mus[j], 1.0 / 240.0, "1/240");
            run(v0s[i], mus[j], dt_mid, lab);
        }
    printf("%d of %d cases failed\n", g_failed_cases, g_cases);
    return CHECK_SUMMARY("test_slide_stop");
}
