/* ngspice's per-point source and step callbacks answered in C where they need no Python.

   Compiled once into a shared library by circuit/compiled_callbacks.py (the flags keep
   IEEE double arithmetic as Python does it: -O2 -ffp-contract=off, no -ffast-math) and
   installed by circuit/ngspice.py in place of its Python callbacks for the EXTERNAL
   voltage sources (the input channels) and current sources (the arcs' states).

   - An input channel answers a repeated time (ngspice asks again at each Newton
     iteration) with its last value; a constant channel and a table channel (a piecewise
     polynomial in time, below) are evaluated here; any other channel calls its Python
     function through one trampoline (sw_state.evaluate), which also makes the error for
     a value that is not finite and >= 0 (a table channel's bad value goes there too:
     the Python function behind it gives the same value and raises its error).
   - An arc's EXTERNAL current source reads the double that its ArcState writes.
   - GetSyncData (sw_sync) applies NgspiceSession._on_sync's rules, calling it for the
     cases that need Python (below).
   A source met for the first time is learned through Python (by name), by its name
   pointer after that. The arithmetic of the table channel is that of its Python twin
   (coupling's CoilLink.inputs over mech's Segment.armature), operation for operation,
   so that both routes give the same bits. */

#include <math.h>
#include <stddef.h>
#include <time.h>

#define SW_PYTHON 0
#define SW_CONSTANT 1
#define SW_TABLE 2

typedef int (*sw_evaluate_fn)(int index, double t, double *out);
typedef int (*sw_learn_fn)(char *name);
typedef int (*sw_sync_fn)(double ckttime, double *pdelta, double olddelta, int redostep, int ident,
                          int location, void *user);

typedef struct sw_channel {
    char *name;           /* ngspice's name string of the source (its pointer), NULL: not seen yet */
    int kind;             /* SW_PYTHON, SW_CONSTANT or SW_TABLE */
    double last_t;        /* the time of the last value (NaN: none in this macro step) */
    double last_value;
    long long calls;      /* evaluations (repeats and calls after a failure not counted) */
    double constant;
    /* table: value(t) = max(offset - scale * p(u), 0) with u = clamp(t, lo, hi) after
       the left-limit windows, p(u) = start for u <= lo or no pieces, else piece
       k = min(bisect_left(ends, u), n - 1): th = (u - t0[k]) / h[k], t1 = 1 - th,
       c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4))) with c = coefficients[5 k ...] */
    double lo, hi, start, offset, scale;
    long n;
    const double *ends, *t0, *h, *coefficients;
    /* left-limit windows (circuit.contact.left_limited): i = bisect_right(lows, t) - 1;
       if i >= 0 and t <= highs[i], t is replaced by befores[i] */
    long windows;
    const double *lows, *highs, *befores;
} sw_channel;

typedef struct sw_arc {
    char *name;
    const double *value;
} sw_arc;

typedef struct sw_state {
    int failed;                 /* the session holds a failure: answer last values, call nothing */
    sw_evaluate_fn evaluate;    /* Python: channel index, t -> value (0) or failure (1) */
    sw_learn_fn learn;          /* Python: name -> channel index (binds the name pointer), -1 none */
    sw_learn_fn learn_arc;      /* Python: name -> 1 if an arc's (binds arcs[]), 0 not an arc */
    int channels_used;
    sw_channel *channels;
    int arcs_used, arcs_size;
    sw_arc *arcs;
    /* the step control (sw_sync): NgspiceSession's fields of the same names, written by
       Python (accepting by both); landings[head:used] its _landings, popped here or there */
    sw_sync_fn sync_python;     /* Python's _on_sync, for the calls sw_sync does not answer */
    int has_arcs;
    double accepting, target, max_step, deadline, arc_from, arc_step, arc_land, landing_tolerance;
    int landings_head, landings_used, landings_size;
    double *landings;
} sw_state;

static sw_state *state = NULL;

void sw_install(sw_state *s) { state = s; }

static long bisect_left(const double *a, long n, double x)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = (lo + hi) / 2;
        if (a[mid] < x) lo = mid + 1; else hi = mid;
    }
    return lo;
}

static long bisect_right(const double *a, long n, double x)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = (lo + hi) / 2;
        if (x < a[mid]) hi = mid; else lo = mid + 1;
    }
    return lo;
}

double sw_table_value(const sw_channel *ch, double t)
{
    if (ch->windows > 0) {
        long i = bisect_right(ch->lows, ch->windows, t) - 1;
        if (i >= 0 && t <= ch->highs[i])
            t = ch->befores[i];
    }
    double u = t < ch->lo ? ch->lo : (t > ch->hi ? ch->hi : t);
    double q;
    if (ch->n == 0 || u <= ch->lo) {
        q = ch->start;
    } else {
        long k = bisect_left(ch->ends, ch->n, u);
        if (k > ch->n - 1) k = ch->n - 1;
        const double *c = ch->coefficients + 5 * k;
        double th = (u - ch->t0[k]) / ch->h[k];
        double t1 = 1.0 - th;
        q = c[0] + th * (c[1] + t1 * (c[2] + th * (c[3] + t1 * c[4])));
    }
    double g = ch->offset - ch->scale * q;
    return 0.0 > g ? 0.0 : g;  /* Python's max(g, 0.0): g unless 0.0 > g (NaN and -0.0 kept) */
}

static sw_channel *find_channel(char *name)
{
    sw_channel *ch = state->channels;
    for (int i = 0; i < state->channels_used; i++)
        if (ch[i].name == name) return ch + i;
    return NULL;
}

int sw_vsrc(double *out, double t, char *name, int ident, void *user)
{
    (void)ident; (void)user;
    sw_channel *ch = find_channel(name);
    int index;
    if (ch == NULL) {
        index = state->learn(name);
        if (index < 0 || index >= state->channels_used) {  /* (the Python side failed) */
            state->failed = 1;
            *out = 0.0;
            return 0;
        }
        ch = state->channels + index;  /* (learn may have moved the array) */
    }
    if (t == ch->last_t || state->failed) {
        *out = ch->last_value;
        return 0;
    }
    ch->calls++;
    double value;
    if (ch->kind == SW_CONSTANT)
        value = ch->constant;
    else if (ch->kind == SW_TABLE)
        value = sw_table_value(ch, t);
    else
        value = NAN;
    if (ch->kind == SW_PYTHON || !(0.0 <= value && value < INFINITY)) {
        index = (int)(ch - state->channels);
        int failed = state->evaluate(index, t, &value);
        ch = state->channels + index;
        if (failed) {
            state->failed = 1;
            *out = ch->last_value;
            return 0;
        }
    }
    ch->last_t = t;
    ch->last_value = value;
    *out = value;
    return 0;
}

int sw_isrc(double *out, double t, char *name, int ident, void *user)
{
    (void)t; (void)ident; (void)user;
    for (int pass = 0; pass < 2; pass++) {
        sw_arc *arc = state->arcs;
        for (int i = 0; i < state->arcs_used; i++)
            if (arc[i].name == name) {
                *out = *arc[i].value;
                return 0;
            }
        if (pass == 0 && !state->learn_arc(name))
            break;
    }
    *out = 0.0;
    return 0;
}

/* The structures' layout as this compiler lays them out, for the test that holds
   compiled_callbacks.DECLARATIONS to it: sizes, then the offset of each field in order. */
#define SW_PUT(x) do { if (k < size) out[k] = (long)(x); k++; } while (0)
int sw_layout(long *out, int size)
{
    int k = 0;
    SW_PUT(sizeof(sw_channel)); SW_PUT(sizeof(sw_arc)); SW_PUT(sizeof(sw_state));
    SW_PUT(offsetof(sw_channel, name)); SW_PUT(offsetof(sw_channel, kind));
    SW_PUT(offsetof(sw_channel, last_t)); SW_PUT(offsetof(sw_channel, last_value));
    SW_PUT(offsetof(sw_channel, calls)); SW_PUT(offsetof(sw_channel, constant));
    SW_PUT(offsetof(sw_channel, lo)); SW_PUT(offsetof(sw_channel, hi));
    SW_PUT(offsetof(sw_channel, start)); SW_PUT(offsetof(sw_channel, offset));
    SW_PUT(offsetof(sw_channel, scale)); SW_PUT(offsetof(sw_channel, n));
    SW_PUT(offsetof(sw_channel, ends)); SW_PUT(offsetof(sw_channel, t0));
    SW_PUT(offsetof(sw_channel, h)); SW_PUT(offsetof(sw_channel, coefficients));
    SW_PUT(offsetof(sw_channel, windows)); SW_PUT(offsetof(sw_channel, lows));
    SW_PUT(offsetof(sw_channel, highs)); SW_PUT(offsetof(sw_channel, befores));
    SW_PUT(offsetof(sw_arc, name)); SW_PUT(offsetof(sw_arc, value));
    SW_PUT(offsetof(sw_state, failed)); SW_PUT(offsetof(sw_state, evaluate));
    SW_PUT(offsetof(sw_state, learn)); SW_PUT(offsetof(sw_state, learn_arc));
    SW_PUT(offsetof(sw_state, channels_used)); SW_PUT(offsetof(sw_state, channels));
    SW_PUT(offsetof(sw_state, arcs_used)); SW_PUT(offsetof(sw_state, arcs_size));
    SW_PUT(offsetof(sw_state, arcs)); SW_PUT(offsetof(sw_state, sync_python));
    SW_PUT(offsetof(sw_state, has_arcs)); SW_PUT(offsetof(sw_state, accepting));
    SW_PUT(offsetof(sw_state, target)); SW_PUT(offsetof(sw_state, max_step));
    SW_PUT(offsetof(sw_state, deadline)); SW_PUT(offsetof(sw_state, arc_from));
    SW_PUT(offsetof(sw_state, arc_step)); SW_PUT(offsetof(sw_state, arc_land));
    SW_PUT(offsetof(sw_state, landing_tolerance)); SW_PUT(offsetof(sw_state, landings_head));
    SW_PUT(offsetof(sw_state, landings_used)); SW_PUT(offsetof(sw_state, landings_size));
    SW_PUT(offsetof(sw_state, landings));
    return k;
}

/* circuit.ngspice.stop_margin: max(1e-12 |target|, 1e-300) (Python's max: the first unless
   the second is greater) */
static double stop_margin(double target)
{
    double a = 1e-12 * fabs(target);
    return 1e-300 > a ? 1e-300 : a;
}

static double monotonic(void)  /* Python's time.monotonic() on POSIX: CLOCK_MONOTONIC */
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* GetSyncData: NgspiceSession._on_sync's common path, rule for rule. Python's own
   _on_sync answers a rejected step's redo (the rejections log), a run with a failure, a
   wall-clock deadline passed, and the point after an accepted one when there are arcs
   (their ArcState.accepted). The landings are one list: Python drops from its _landings
   what this copy popped before it answers, and sets landings_head after. */
int sw_sync(double ckttime, double *pdelta, double olddelta, int redostep, int ident, int location, void *user)
{
    sw_state *s = state;
    if (redostep || s->failed || (s->has_arcs && location == 0) ||
            (s->deadline < INFINITY && monotonic() > s->deadline))
        return s->sync_python(ckttime, pdelta, olddelta, redostep, ident, location, user);
    if (location)
        s->accepting = ckttime;
    double target = s->target;
    if (*pdelta > s->max_step)
        *pdelta = s->max_step;
    if (s->has_arcs && ckttime == s->arc_from) {  /* the step (or its retry) from that accepted point */
        if (*pdelta > s->arc_step)
            *pdelta = s->arc_step;
        if (s->arc_land < target)
            target = s->arc_land;
    }
    while (s->landings_head < s->landings_used &&
           s->landings[s->landings_head] <= ckttime + stop_margin(s->landings[s->landings_head]))
        s->landings_head++;
    if (s->landings_head < s->landings_used && s->landings[s->landings_head] < target)
        target = s->landings[s->landings_head];
    double remaining = target - ckttime;
    if (remaining > stop_margin(target)) {
        double delta = *pdelta;
        if (delta >= remaining * (1.0 - s->landing_tolerance))
            *pdelta = remaining;
        else if (remaining < 2.0 * delta)
            *pdelta = 0.5 * remaining;
    }
    return 0;
}
