/* test_determinism_levels: one scripted scene (SCRIPT below: six blocks of several sizes in the walled
 * box, gravity, damping, friction, thrusters firing, a mouse spring and a block-to-block spring, a
 * gravity change, a velocity kick, a switch to simultaneous impacts, two step sizes) gives the same
 * lc_world_state_hash after every step
 *   - in two runs in this process, and
 *   - when the library sources and this file are compiled again with -O0, -O2 and -O3 into separate
 *     executables (the compiler is $CC, default cc; only -ffp-contract=off is added, the flag the
 *     library builds with) and each prints its hashes.
 * No tolerance: bit equality of every step's hash is the requirement (docs/hardening.md).
 *
 * Modes:  (no argument)  the test above;
 *         --print        print "<step> <hash as 16 hex digits>" per step (a worker; also used by
 *                        tests/python/test_determinism_c_python.py);
 *         --script       print SCRIPT, which that Python test runs through `collide`.
 * The source tree is found from __FILE__ (CMake passes absolute paths) or $LIBCOLLIDE_SOURCE_DIR;
 * the build tree's generated headers (collide/version.h, which world.c includes) from
 * LC_GENERATED_INCLUDE_DIR, which tests/c/CMakeLists.txt defines. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "collide/collide.h"

/* One command per line; numbers are read with strtod. Body and spring indices count from 0 in the
 * order the script adds them (walls are not counted); spring body b = -1 is a world anchor. */
static const char SCRIPT[] =
    "world 0 -9.81 0.05 0.1\n"                     /* gravity gx gy, damping k, rotation ratio */
    "walls -6 -6 6 6 1 0.8\n"                      /* xmin ymin xmax ymax thickness elasticity */
    "box 1 3 -2.5 0 0 1.5 0 0.3 2 0.8 0\n"         /* w h x y angle vx vy omega mass e friction */
    "box 1 3 2.5 0 0 -1 0.5 -0.2 1 0.8 0.2\n"
    "box 1 3 0 3.5 1.5707963267948966 0 0 0 1 0.8 0\n"
    "box 1 3 0 -3.5 1.5707963267948966 2 0 0 1 0.8 0.5\n"
    "box 0.8 0.8 -4.75 0.5 0.3 0 -3 1 1.5 0.6 0\n"
    "box 0.5 1.2 4.75 0.5 0 0 0 4 0.7 1 0\n"
    "thrusters 0 1.5\n"                            /* body thrust: the four default thrusters */
    "thrusters 1 1.5\n"
    "spring 2 0.2 1 -1 0 3 3 0 0\n"                /* a pax pay b pbx pby stiffness damping rest */
    "spring 3 0 0.5 4 0 0 2 0.1 1.5\n"
    "step 40 0.01\n"                               /* n dt */
    "mask 0 5\n"                                   /* body thruster-mask */
    "mask 1 10\n"
    "step 60 0.01\n"
    "target 0 2 -2\n"                              /* spring x y (world-anchored end) */
    "gravity 0.5 -3\n"
    "step 50 0.01\n"
    "velocity 5 3 3 -2\n"                          /* body vx vy omega */
    "mask 0 0\n"
    "simultaneous\n"                               /* impact_mode = LC_IMPACT_SIMULTANEOUS */
    "step 100 0.005\n";

#ifndef LC_GENERATED_INCLUDE_DIR
#define LC_GENERATED_INCLUDE_DIR "" /* e.g. the worker of tests/python/test_determinism_c_python.py */
#endif

#define MAX_HASHES 1024
#define MAX_ITEMS 32

typedef struct run_result {
    uint64_t hash[MAX_HASHES];
    int steps;
    int ok;
    unsigned long long collisions;
} run_result;

static int parse_doubles(const char *s, double *out, int max)
{
    int n = 0;
    char *end;
    while (n < max) {
        double v = strtod(s, &end);
        if (end == s) break;
        out[n++] = v;
        s = end;
    }
    return n;
}

/* Runs SCRIPT; records the hash after every step. Any failed call fails a CHECK and stops the run. */
static void run_script(run_result *r)
{
    lc_world_def def = lc_default_world_def();
    lc_world *w = NULL;
    lc_body_id bodies[MAX_ITEMS];
    lc_spring_id springs[MAX_ITEMS];
    int nb = 0, ns = 0;
    const char *line = SCRIPT;
    char err[256];
    lc_counters tot;
    r->steps = 0;
    r->ok = 0;
    while (*line) {
        const char *eol = strchr(line, '\n');
        char cmd[32];
        double a[16];
        int n = 0, len = 0;
        lc_status s = LC_OK;
        if (sscanf(line, "%31s%n", cmd, &len) != 1) break;
        n = parse_doubles(line + len, a, 16);
        if (strcmp(cmd, "world") == 0 && n == 4) {
            def.gravity.x = a[0];
            def.gravity.y = a[1];
            def.damping = a[2];
            def.damping_rotation_ratio = a[3];
            w = lc_world_create(&def, err, sizeof err);
            CHECK(w != NULL, "world: %s", err);
            if (w == NULL) return;
        } else if (w == NULL) {
            CHECK(0, "script: %s before world", cmd);
            return;
        } else if (strcmp(cmd, "walls") == 0 && n == 6) {
            s = lc_world_add_walls(w, a[0], a[1], a[2], a[3], a[4], a[5], NULL);
        } else if (strcmp(cmd, "box") == 0 && n == 11 && nb < MAX_ITEMS) {
            lc_vec2 v[4];
            lc_body_def bd = lc_default_body_def();
            s = lc_make_rectangle(a[0], a[1], v);
            bd.vertices = v;
            bd.vertex_count = 4;
            bd.position.x = a[2];
            bd.position.y = a[3];
            bd.angle = a[4];
            bd.velocity.x = a[5];
            bd.velocity.y = a[6];
            bd.angular_velocity = a[7];
            bd.mass = a[8];
            bd.elasticity = a[9];
            bd.friction = a[10];
            if (s == LC_OK) s = lc_world_add_body(w, &bd, &bodies[nb++]);
        } else if (strcmp(cmd, "thrusters") == 0 && n == 2 && (int)a[0] < nb) {
            s = lc_body_add_default_thrusters(w, bodies[(int)a[0]], a[1], NULL);
        } else if (strcmp(cmd, "spring") == 0 && n == 9 && ns < MAX_ITEMS && (int)a[0] < nb && (int)a[3] < nb) {
            lc_spring_def sd = lc_default_spring_def();
            sd.body_a = bodies[(int)a[0]];
            sd.point_a.x = a[1];
            sd.point_a.y = a[2];
            sd.body_b = a[3] < 0 ? LC_WORLD_ANCHOR : bodies[(int)a[3]];
            sd.point_b.x = a[4];
            sd.point_b.y = a[5];
            sd.stiffness = a[6];
            sd.damping = a[7];
            sd.rest_length = a[8];
            s = lc_world_add_spring(w, &sd, &springs[ns++]);
        } else if (strcmp(cmd, "mask") == 0 && n == 2 && (int)a[0] < nb) {
            s = lc_body_set_thruster_mask(w, bodies[(int)a[0]], (uint32_t)a[1]);
        } else if (strcmp(cmd, "target") == 0 && n == 3 && (int)a[0] < ns) {
            lc_vec2 t;
            t.x = a[1];
            t.y = a[2];
            s = lc_spring_set_target(w, springs[(int)a[0]], t);
        } else if (strcmp(cmd, "gravity") == 0 && n == 2) {
            lc_vec2 g;
            g.x = a[0];
            g.y = a[1];
            s = lc_world_set_gravity(w, g);
        } else if (strcmp(cmd, "velocity") == 0 && n == 4 && (int)a[0] < nb) {
            lc_vec2 v;
            v.x = a[1];
            v.y = a[2];
            s = lc_body_set_velocity(w, bodies[(int)a[0]], v, a[3]);
        } else if (strcmp(cmd, "simultaneous") == 0 && n == 0) {
            s = lc_world_get_def(w, &def);
            def.impact_mode = LC_IMPACT_SIMULTANEOUS;
            if (s == LC_OK) s = lc_world_set_def(w, &def);
        } else if (strcmp(cmd, "step") == 0 && n == 2) {
            int k;
            for (k = 0; k < (int)a[0] && s == LC_OK && r->steps < MAX_HASHES; ++k) {
                s = lc_world_step(w, a[1]);
                r->hash[r->steps++] = lc_world_state_hash(w);
            }
        } else {
            CHECK(0, "script: cannot read the line starting with '%s' (%d numbers)", cmd, n);
            lc_world_destroy(w);
            return;
        }
        CHECK(s == LC_OK, "script '%s': %s: %s", cmd, lc_status_string(s), lc_world_last_error(w));
        if (s != LC_OK) {
            lc_world_destroy(w);
            return;
        }
        if (eol == NULL) break;
        line = eol + 1;
    }
    if (w == NULL) return;
    lc_world_get_counters(w, NULL, &tot);
    r->collisions = (unsigned long long)tot.collisions;
    lc_world_destroy(w);
    r->ok = 1;
}

static void print_hashes(const run_result *r)
{
    int k;
    for (k = 0; k < r->steps; ++k) printf("%d %016llx\n", k, (unsigned long long)r->hash[k]);
}

/* Root of the source tree: $LIBCOLLIDE_SOURCE_DIR or three levels above this file. */
static int source_root(char *out, size_t cap)
{
    const char *env = getenv("LIBCOLLIDE_SOURCE_DIR");
    const char *file = __FILE__, *p;
    size_t n;
    if (env && env[0]) {
        n = strlen(env);
        return n + 2 <= cap && snprintf(out, cap, "%s%s", env, env[n - 1] == '/' ? "" : "/") > 0;
    }
    p = strstr(file, "tests/c/test_determinism_levels.c");
    if (p == NULL || file[0] != '/') return 0;
    n = (size_t)(p - file);
    if (n >= cap) return 0;
    memcpy(out, file, n);
    out[n] = '\0';
    return 1;
}

/* Builds SCRIPT's worker at -O<level>, runs it, compares its hashes with ref. */
static void check_level(const char *root, const char *level, const run_result *ref)
{
    char exe[64], cmd[16384], out[64];
    const char *cc = getenv("CC");
    FILE *f;
    int k = 0, step, rc, first_diff = -1, len;
    unsigned long long h;
    len = snprintf(exe, sizeof exe, "./determinism_levels%s", level);
    CHECK(len > 0 && (size_t)len < sizeof exe, "%s", "executable name too long");
    len = snprintf(out, sizeof out, "./determinism_levels%s.out", level);
    CHECK(len > 0 && (size_t)len < sizeof out, "%s", "output name too long");
    CHECK(LC_GENERATED_INCLUDE_DIR[0] != '\0', "%s", "built without LC_GENERATED_INCLUDE_DIR (collide/version.h)");
    len = snprintf(cmd, sizeof cmd,
             "%s -std=c99 %s -ffp-contract=off -I'%slibcollide/include' -I'%s' -I'%slibcollide/src' -I'%stests/c' "
             "'%slibcollide/src/'*.c '%stests/c/test_determinism_levels.c' -lm -o '%s' && '%s' --print > '%s'",
             cc && cc[0] ? cc : "cc", level, root, LC_GENERATED_INCLUDE_DIR, root, root, root, root, exe, exe, out);
    CHECK(len > 0 && (size_t)len < sizeof cmd, "%s", "compile command too long (source path?)");
    if (check_failures() > 0) return;
    rc = system(cmd);
    CHECK(rc == 0, "building or running the %s worker failed (exit %d): %s", level, rc, cmd);
    if (rc != 0) return;
    f = fopen(out, "r");
    CHECK(f != NULL, "cannot read %s", out);
    if (f == NULL) return;
    while (fscanf(f, "%d %llx", &step, &h) == 2 && k < MAX_HASHES) {
        if (step != k || h != (unsigned long long)ref->hash[k]) {
            if (first_diff < 0) first_diff = k;
        }
        k++;
    }
    fclose(f);
    CHECK(k == ref->steps, "%s worker printed %d hashes, expected %d", level, k, ref->steps);
    CHECK(first_diff < 0, "%s build differs from this build first at step %d", level, first_diff);
    printf("%s: %d step hashes identical to this build's\n", level, k);
}

int main(int argc, char **argv)
{
    static run_result a, b;
    static const char *levels[] = {"-O0", "-O2", "-O3"};
    char root[2048];
    int k, diff = -1;
    if (argc > 1 && strcmp(argv[1], "--script") == 0) {
        fputs(SCRIPT, stdout);
        return 0;
    }
    run_script(&a);
    if (argc > 1 && strcmp(argv[1], "--print") == 0) {
        if (!a.ok) return 1;
        print_hashes(&a);
        return 0;
    }
    CHECK(a.ok, "%s", "the script runs to the end");
    CHECK(a.steps == 250, "the script makes 250 steps, made %d", a.steps);
    CHECK(a.collisions > 10, "the scene exercises collisions (%llu)", a.collisions);
    run_script(&b);
    for (k = 0; k < a.steps && diff < 0; ++k)
        if (a.hash[k] != b.hash[k]) diff = k;
    CHECK(b.steps == a.steps && diff < 0, "two runs in one process differ first at step %d", diff);
    printf("scripted scene: %d steps, %llu collisions, final hash %016llx\n", a.steps, a.collisions,
           (unsigned long long)a.hash[a.steps - 1]);
    CHECK(source_root(root, sizeof root), "%s", "source tree not found (set LIBCOLLIDE_SOURCE_DIR)");
    if (a.ok && check_failures() == 0)
        for (k = 0; k < 3; ++k) check_level(root, levels[k], &a);
    return CHECK_SUMMARY("test_determinism_levels");
}
