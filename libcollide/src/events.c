/* The impact event stream (events.h): a growable staging list for the step in progress and a ring of
 * unread events. The ring grows to the capacity as events come (a world that sees few impacts does not
 * hold capacity x 80 bytes); when it is full, or cannot grow, the oldest unread event goes: a reader
 * that fell behind gets the latest impacts, the ones that describe the world as it is now, and the
 * count of what it missed. */
#include <stdlib.h>
#include <string.h>
#include "events.h"

struct lc_events {
    lc_buf staged;               /* lc_impact_event, the step in progress's */
    int nstaged;
    lc_impact_event *ring;       /* slots allocated; unread events at head, head + 1, ... (mod slots) */
    int slots, head, count;
    int capacity;                /* most unread events kept */
    uint64_t dropped;            /* events dropped since the last read that reported drops */
};

lc_events *lc_events_create(int capacity)
{
    lc_events *ev = calloc(1, sizeof *ev);
    if (ev != NULL) ev->capacity = capacity;
    return ev;
}

void lc_events_destroy(lc_events *ev)
{
    if (ev == NULL) return;
    lc_buf_free(&ev->staged);
    free(ev->ring);
    free(ev);
}

int lc_record_impact(lc_world *w, const lc_touch *t, lc_impact_kind kind)
{
    lc_events *ev = w->events;
    lc_impact_event *e = lc_buf_get(&ev->staged, (size_t)(ev->nstaged + 1) * sizeof *e);
    if (e == NULL || lc_push_contact(w, t, LC_CONTACT_COLLISION) != 0) return -1;
    e += ev->nstaged++;
    memset(e, 0, sizeof *e);
    e->time = w->time;
    e->body_a = w->ids[t->a];
    e->body_b = w->ids[t->b];
    e->point = t->p;
    e->normal = t->n;
    e->gap = t->gap;
    e->normal_impulse = t->value;
    e->tangent_impulse = t->tangent;
    e->approach_speed = -t->vn_pre;
    e->kind = kind;
    return 0;
}

int lc_events_staged(const lc_events *ev) { return ev->nstaged; }

void lc_events_unstage(lc_events *ev, int keep)
{
    if (keep >= 0 && keep < ev->nstaged) ev->nstaged = keep;
}

/* The unread events moved to ring[0 .. count), in order (head = 0), without memory: three reversals. */
static void reverse(lc_impact_event *e, int lo, int hi)
{
    for (--hi; lo < hi; ++lo, --hi) {
        lc_impact_event x = e[lo];
        e[lo] = e[hi];
        e[hi] = x;
    }
}

static void linearize(lc_events *ev)
{
    if (ev->head == 0 || ev->slots == 0) return;
    reverse(ev->ring, 0, ev->head);
    reverse(ev->ring, ev->head, ev->slots);
    reverse(ev->ring, 0, ev->slots);
    ev->head = 0;
}

/* Room for one more unread event: the ring grown (up to the capacity) or, full, its oldest dropped. */
static void make_room(lc_events *ev)
{
    if (ev->count < ev->slots) return;
    if (ev->slots < ev->capacity) {
        int slots = ev->slots < 32 ? 64 : 2 * ev->slots;
        lc_impact_event *p;
        if (slots > ev->capacity) slots = ev->capacity;
        linearize(ev);
        p = realloc(ev->ring, (size_t)slots * sizeof *p);
        if (p != NULL) {
            ev->ring = p;
            ev->slots = slots;
            return;
        }
    }
    if (ev->slots == 0) return;   /* no memory for the first slot: lc_events_commit counts the event dropped */
    /* full, or no memory to grow: the oldest goes */
    ev->head = (ev->head + 1) % ev->slots;
    ev->count--;
    ev->dropped++;
}

void lc_events_commit(lc_events *ev)
{
    const lc_impact_event *e = (const lc_impact_event *)ev->staged.p;
    int i;
    for (i = 0; i < ev->nstaged; ++i) {
        if (ev->capacity == 0) {
            ev->dropped++;
            continue;
        }
        make_room(ev);
        if (ev->slots == 0) {   /* no memory for the first slot */
            ev->dropped++;
            continue;
        }
        ev->ring[(ev->head + ev->count) % ev->slots] = e[i];
        ev->count++;
    }
    ev->nstaged = 0;
}

void lc_events_set_capacity(lc_events *ev, int capacity)
{
    if (ev->count > capacity) {
        int drop = ev->count - capacity;
        ev->head = (ev->head + drop) % ev->slots;
        ev->count = capacity;
        ev->dropped += (uint64_t)drop;
    }
    if (ev->slots > capacity) {
        /* the unread ones to the front, the slots past the capacity unused */
        linearize(ev);
        ev->slots = capacity;
        if (capacity == 0) {
            free(ev->ring);
            ev->ring = NULL;
        }
    }
    ev->capacity = capacity;
}

lc_status lc_world_get_events(lc_world *w, lc_impact_event *out, int capacity, int *out_count, uint64_t *out_dropped)
{
    lc_events *ev;
    int n, k;
    if (w == NULL) return LC_ERR_NULL;
    ev = w->events;
    if (out_count == NULL) return lc_fail(w, LC_ERR_NULL, "out_count is NULL");
    if (capacity < 0) return lc_fail(w, LC_ERR_OUT_OF_RANGE, "capacity = %d must be >= 0", capacity);
    if (out == NULL && capacity > 0) return lc_fail(w, LC_ERR_NULL, "out is NULL with capacity %d", capacity);
    if (capacity == 0) {
        *out_count = ev->count;
        if (out_dropped) *out_dropped = ev->dropped;
        w->error[0] = '\0';
        return LC_OK;
    }
    n = capacity < ev->count ? capacity : ev->count;
    for (k = 0; k < n; ++k) out[k] = ev->ring[(ev->head + k) % ev->slots];
    if (n > 0) ev->head = (ev->head + n) % ev->slots;
    ev->count -= n;
    *out_count = n;
    if (out_dropped) {
        *out_dropped = ev->dropped;
        ev->dropped = 0;
    }
    w->error[0] = '\0';
    return LC_OK;
}
