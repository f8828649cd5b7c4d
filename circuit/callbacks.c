/* ngspice's per-point source and step callbacks answered in C where they need no Python.

   Compiled once into a shared library by circuit/compiled_callbacks.py (the flags keep
   IEEE double arithmetic as Python does it: -O2 -ffp-contract=off, no -ffast-math) and
   installed by circuit/ngspice.py in place of its Python callbacks for the EXTERNAL
   voltage sources (the input channels) and current sources (the arcs' states).

   - An input channel answers a repeated time (ngspice asks again at each Newton
     iteration) with its last value, and so does an arc's gap channel at a new time while
     nothing ngspice computes reads it (sw_held); a constant channel and a table channel
     (a piecewise polynomial in time, below) are evaluated here; any other channel calls
     its Python function through one trampoline (sw_state.evaluate), which also makes the
     error for a value that is not finite and >= 0 (a table channel's bad value goes there too:
     the Python function behind it gives the same value and raises its error).
   - An arc's EXTERNAL current source reads the double that its ArcState writes.
   - SendData (sw_data, given to ngspice once, at its init, when the library is there)
     calls Python's only for the accepted point that pauses the run, or for every point on
     the Python route.
   - GetSyncData (sw_sync) applies NgspiceSession._on_sync's rules, calling it for the
     cases that need Python (below): it logs a rejected step's redo in a buffer Python
     reads, and answers an arc's ArcState.accepted where only the arc's filtered closed
     indicator moves (sw_arc_plain).
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
typedef int (*sw_data_fn)(void *values, int count, int ident, void *user);

typedef struct sw_channel {
    char *name;           /* ngspice's name string of the source (its pointer), NULL: not seen yet */
    int kind;             /* SW_PYTHON, SW_CONSTANT or SW_TABLE */
    double last_t;        /* the time of the last value (NaN: none in this macro step) */
    double last_value;
    long long calls;      /* evaluations (repeats, held answers and calls after a failure not counted) */
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
    /* an arc's gap channel (the arc without a breakdown voltage): held (sw_held) while the
       arc whose ArcState cells these are is idle and the channel gate_conductance (its
       contact's conductance) is the constant 0; NULL: never held */
    const double *gate_arc;
    int gate_conductance;
} sw_channel;

typedef struct sw_arc {
    char *name;
    const double *value;
} sw_arc;

/* An ArcState's cells (ArcState.cells, shared with Python, which keeps the arc's state in
   them on both routes), by index */
#define SW_ARC_T 0          /* s: the last accepted point (-inf: none yet) */
#define SW_ARC_LEVEL 1      /* the filtered closed indicator */
#define SW_ARC_CLOSED 2     /* 1.0 or 0.0: the contact at that point */
#define SW_ARC_BURNING 3    /* 1.0 or 0.0 */
#define SW_ARC_PLAIN 4      /* 1.0: sw_arc_plain may answer (set by Python after each of its answers) */
#define SW_ARC_TAU 5        /* s: the filter's time constant */
#define SW_ARC_TOLERANCE 6  /* of the level, at its crossing of 1/2 */
#define SW_ARC_IDLE 7       /* 1.0: out over the step to the last point and after it (sw_held) */

typedef struct sw_arc_rule {
    double *cells;      /* the ArcState's cells (above) */
    int conductance;    /* the input channel whose last value is G at an accepted point, -1: none */
} sw_arc_rule;

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
    int arc_rules_used;         /* the session's arcs (all of them: Python's _arcs), for sw_sync */
    sw_arc_rule *arc_rules;
    /* rejected steps logged here, (t, 1.0 if Newton failed else 0.0) pairs, until Python
       moves them into its rejections list (a full buffer: Python's _on_sync logs it) */
    int rejections_used, rejections_size;
    double *rejections;
    double pause_at;            /* s: the accepted point at or after this time pauses the run (sw_data) */
    int python_data;            /* 1: the Python callbacks' route, every SendData to Python */
} sw_state;

static sw_state *state = NULL;
static sw_data_fn data_python = NULL;  /* Python's SendData (NgspiceSession._on_data) */

void sw_install(sw_state *s) { state = s; }
void sw_install_data(sw_data_fn fn) { data_python = fn; }

/* SendData, after each accepted point is stored: Python's _on_data pauses the run at the
   first accepted point at or after pause_at (it switches back to transient()'s caller);
   with a failure it does nothing. Before a compiled state is installed, and on the
   Python route, every call is Python's. */
int sw_data(void *values, int count, int ident, void *user)
{
    sw_state *s = state;
    if (s == NULL || s->python_data || (s->accepting >= s->pause_at && !s->failed))
        return data_python(values, count, ident, user);
    return 0;
}

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

/* The arc that gates ch reads it nowhere: it is idle (out, neither burning nor armed,
   over the step to its last accepted point and after it, so V(arc_on) is 0 in the solution
   that Newton starts from as in every iterate, and the path's current and its derivatives
   but d/dV(arc_on) are 0 times the gap's finite terms; d/dV(arc_on) multiplies V(arc_on) = 0)
   and its contact's conductance is the constant 0 for this macro step (it cannot arm);
   without a breakdown voltage nothing else reads the gap (ArcState reads it only to test a
   breakdown). The channel's last value (finite and >= 0) serves: ngspice's solution is the
   same bits. (Out only after the last point is not enough: the first trial's Newton starts
   from that point's solution, V(arc_on) = 1, and its linearised path reads the new gap;
   held there, one near-zero current of five scenes moved by an ulp.) */
static int sw_held(const sw_channel *ch)
{
    const sw_channel *g = state->channels + ch->gate_conductance;
    return ch->gate_arc[SW_ARC_IDLE] != 0.0 && g->kind == SW_CONSTANT && g->constant == 0.0;
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
    if (ch->gate_arc != NULL && sw_held(ch)) {  /* (not an evaluation: not counted) */
        ch->last_t = t;
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
   compiled_callbacks.DECLARATIONS to it: sizes, then the offset of each field in order,
   then the ArcState cells' indices (circuit.arc's ARC_CELLS). */
#define SW_PUT(x) do { if (k < size) out[k] = (long)(x); k++; } while (0)
int sw_layout(long *out, int size)
{
    int k = 0;
    SW_PUT(sizeof(sw_channel)); SW_PUT(sizeof(sw_arc)); SW_PUT(sizeof(sw_arc_rule)); SW_PUT(sizeof(sw_state));
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
    SW_PUT(offsetof(sw_channel, gate_arc)); SW_PUT(offsetof(sw_channel, gate_conductance));
    SW_PUT(offsetof(sw_arc, name)); SW_PUT(offsetof(sw_arc, value));
    SW_PUT(offsetof(sw_arc_rule, cells)); SW_PUT(offsetof(sw_arc_rule, conductance));
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
    SW_PUT(offsetof(sw_state, landings)); SW_PUT(offsetof(sw_state, arc_rules_used));
    SW_PUT(offsetof(sw_state, arc_rules)); SW_PUT(offsetof(sw_state, rejections_used));
    SW_PUT(offsetof(sw_state, rejections_size)); SW_PUT(offsetof(sw_state, rejections));
    SW_PUT(offsetof(sw_state, pause_at)); SW_PUT(offsetof(sw_state, python_data));
    SW_PUT(SW_ARC_T); SW_PUT(SW_ARC_LEVEL); SW_PUT(SW_ARC_CLOSED); SW_PUT(SW_ARC_BURNING);
    SW_PUT(SW_ARC_PLAIN); SW_PUT(SW_ARC_TAU); SW_PUT(SW_ARC_TOLERANCE); SW_PUT(SW_ARC_IDLE);
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

/* ArcState.accepted at the accepted point t, where nothing but the arc's filtered closed
   indicator moves: the arc keeps burning (armed and closed) or stays out without arming,
   the contact's conductance at t known from its input channel and the contact as it was
   at the arc's last point, no breakdown to test, no current to follow (SW_ARC_PLAIN: Python
   sets it after each of its own answers). 1 with (step, land) and, if *moved, the new
   level (nothing written); 0: Python's rules answer. ArcState.accepted's operations. */
static int sw_arc_plain(const sw_arc_rule *rule, double t, double *step, double *land, double *level, int *moved)
{
    const double *c = rule->cells;
    *moved = 0;
    if (!(t > c[SW_ARC_T])) {  /* the same point again (a resume after a pause) */
        *step = *land = INFINITY;
        return 1;
    }
    if (c[SW_ARC_PLAIN] == 0.0 || rule->conductance < 0)
        return 0;
    const sw_channel *ch = state->channels + rule->conductance;
    if (!(ch->last_t == t))
        return 0;
    double closed = ch->last_value > 0.0 ? 1.0 : 0.0;
    if (closed != c[SW_ARC_CLOSED])
        return 0;  /* made or broken since: the switch instant is among Python's breakpoints */
    double tau = c[SW_ARC_TAU];
    double value = closed + (c[SW_ARC_LEVEL] - closed) * exp(-(t - c[SW_ARC_T]) / tau);
    int armed = closed != 0.0 ? value > 0.5 - c[SW_ARC_TOLERANCE] : value > 0.5 + c[SW_ARC_TOLERANCE];
    int burning = c[SW_ARC_BURNING] != 0.0;
    if (armed != burning || (burning && closed == 0.0))
        return 0;  /* ignites, goes out or needs the arc's current */
    *step = INFINITY;
    *land = closed != 0.0 && !armed ? t + tau * log(2.0 * (1.0 - value)) : INFINITY;
    *level = value;
    *moved = 1;
    return 1;
}

#define SW_ARCS_MAX 16  /* arcs sw_sync answers for at once (more: Python) */

/* GetSyncData: NgspiceSession._on_sync's rules, rule for rule. Python's own _on_sync
   answers a run with a failure, a wall-clock deadline passed, a redo when the rejections'
   buffer is full, and the point after an accepted one when an arc needs more than
   sw_arc_plain (ArcState.accepted); which it is is decided before anything is written.
   The landings are one list: Python drops from its _landings what this copy popped
   before it answers, and sets landings_head after; the rejections logged here are moved
   into its list first. */
int sw_sync(double ckttime, double *pdelta, double olddelta, int redostep, int ident, int location, void *user)
{
    sw_state *s = state;
    if (s->failed || (redostep && s->rejections_used >= s->rejections_size) ||
            (s->deadline < INFINITY && monotonic() > s->deadline))
        return s->sync_python(ckttime, pdelta, olddelta, redostep, ident, location, user);
    int arcs = s->has_arcs && location == 0 ? s->arc_rules_used : 0;
    double steps[SW_ARCS_MAX], lands[SW_ARCS_MAX], levels[SW_ARCS_MAX];
    int moved[SW_ARCS_MAX];
    if (arcs > SW_ARCS_MAX)
        return s->sync_python(ckttime, pdelta, olddelta, redostep, ident, location, user);
    for (int i = 0; i < arcs; i++)
        if (!sw_arc_plain(s->arc_rules + i, ckttime, steps + i, lands + i, levels + i, moved + i))
            return s->sync_python(ckttime, pdelta, olddelta, redostep, ident, location, user);
    if (redostep) {
        int k = 2 * s->rejections_used++;
        s->rejections[k] = ckttime;
        s->rejections[k + 1] = *pdelta == 0.125 * olddelta ? 1.0 : 0.0;
    } else if (location) {
        s->accepting = ckttime;
    }
    if (*pdelta > s->max_step)
        *pdelta = s->max_step;
    if (s->has_arcs && location == 0) {
        double step = INFINITY, land = INFINITY;
        for (int i = 0; i < arcs; i++) {
            if (moved[i]) {
                double *c = s->arc_rules[i].cells;
                c[SW_ARC_T] = ckttime;
                c[SW_ARC_LEVEL] = levels[i];
                c[SW_ARC_IDLE] = c[SW_ARC_BURNING] == 0.0 ? 1.0 : 0.0;  /* (burning unchanged) */
            }
            if (steps[i] < step) step = steps[i];  /* Python's min(step, arc_step) */
            if (lands[i] < land) land = lands[i];
        }
        s->arc_step = step;
        s->arc_land = land;
        s->arc_from = ckttime;
    }
    double target = s->target;
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
