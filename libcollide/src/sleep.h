/* Sleep: an island at rest costs nothing (docs/contact_regime.md, "Sleep").
 *
 * With lc_world_def.allow_sleep and no force callback set (its force could reach a sleeping body, which
 * no step evaluates), a dynamic body rests while its centre moves slower than sleep_speed
 * and its farthest point turns slower than that, no thruster or external force drives it and no spring
 * holds it. An island (islands.h) whose bodies have all rested for sleep_time falls asleep at the end of
 * a step: their velocities become exactly 0, the step stops advancing them, and their resting contacts
 * of that step are reported again at every step they sleep. A sleeping body wakes (and its whole island
 * with it) when an awake body's swept bounds reach its island, or when the world changes through the
 * API (a body, force, thruster, spring or setting; every body wakes then). A world that never rests
 * takes exactly the same steps with sleep on and off: the bookkeeping reads the state, never writes it,
 * until an island falls asleep. */
#ifndef LC_SLEEP_H
#define LC_SLEEP_H

#include <stdint.h>
#include "islands.h"

struct lc_world;

typedef struct lc_sleep lc_sleep;   /* owned by the world */

lc_sleep *lc_sleep_create(void);
void lc_sleep_destroy(lc_sleep *s);

/* The start of a step: wakes every body if sleep is off (or a force callback is set) or the world
 * changed through the API since the last step. Returns 1 when every dynamic body sleeps (nothing to
 * advance), 0 otherwise, -1 without memory. */
int lc_sleep_begin_step(lc_sleep *s, struct lc_world *w);
/* Per row, 1 if the body sleeps (NULL when sleep is off or the world has no body). */
const uint8_t *lc_sleep_asleep(const lc_sleep *s);
/* An island of this step: 1 if every body of it sleeps (it is not advanced), else 0, after waking
 * those of its bodies that slept (counted in lc_counters.islands_woken). */
int lc_sleep_island(lc_sleep *s, struct lc_world *w, const lc_island *isl);
/* The end of a step of dt that is kept: updates the rest timers of the awake bodies, puts to sleep the
 * islands of the step (is; NULL: the step built none) whose bodies all rested long enough, and appends
 * the kept contacts of every sleeping body to the step's contacts. 0, or -1 without memory. */
int lc_sleep_end_step(lc_sleep *s, struct lc_world *w, const struct lc_islands *is, double dt);
/* Snapshots (snapshot.c): who sleeps, the rest timers and the sleeping contacts, written, and read back
 * into a new world's (w: its bodies already loaded). Load: 0, or -1 without memory (bad input: in->bad). */
struct lc_writer;
struct lc_reader;
void lc_sleep_save(const lc_sleep *s, struct lc_writer *out);
int lc_sleep_load(lc_sleep *s, const struct lc_world *w, struct lc_reader *in);
#endif
