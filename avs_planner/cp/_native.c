/* Compiled search core of the continual planner: the search of avs_planner/cp/search.py with
 * the relaxed heuristics of avs_planner/cp/heuristics.py, on a task packed by
 * avs_planner/cp/native.py.
 *
 * Exactness: it is a port, not a re-design. Every floating-point expression is evaluated in
 * the same order as the Python code (built with -ffp-contract=off so no fused multiply-add),
 * Python's sum() is reproduced (plain left-to-right before 3.12, Neumaier-compensated from
 * 3.12 on), heaps are ordered on the same keys ((f, h, node) for the open lists, (d, fact)
 * for the relaxed Dijkstra; keys are unique, so any binary heap pops in the same order), and
 * action loops run in index order. The search therefore returns the same plan and the same
 * expanded/generated counts as the Python engine; only TIMEOUT depends on the clock.
 *
 * States are fixed-width uint64 bitsets; an open-addressing hash table maps a state to its
 * record (Pareto labels, cached estimate, helpful actions). The GIL is released while the
 * search runs; the packed task object is immutable and kept alive by the caller's reference.
 * On large tasks the new states of each expansion are evaluated on two threads (a worker
 * started per search, see evaluate_batch); estimates are pure functions of the state and are
 * recorded in generation order, so the result is the same on one thread or two.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef uint64_t word;

enum { H_BLIND = 0, H_MAX = 1, H_ADD = 2, H_FF = 3 };
enum { ST_SOLVED = 0, ST_UNSOLVABLE = 1, ST_THRESHOLD = 2, ST_TIMEOUT = 3, ST_NODE_LIMIT = 4 };
enum { ST_INTERRUPTED = -2 };
/* why a search returned its best plan so far instead of a proven one (native.py STOP_NAMES) */
enum { STOP_NONE = 0, STOP_TIMEOUT = 1, STOP_NODE_LIMIT = 2, STOP_PATIENCE = 3 };

#define BIT(s, f) (((s)[(f) >> 6] >> ((f) & 63)) & 1u)

#include "_native_axioms.h" /* derived predicates' rules: the closure of a state */

/* ------------------------------------------------------------------------------------------ */
/* Python's sum() over floats, started from the int 0                                          */

typedef struct {
    double hi, lo;
} PySum;

static inline void pysum_add(PySum *s, double x)
{
#if PY_VERSION_HEX >= 0x030C0000
    /* CPython >= 3.12 builtin sum: Neumaier compensated summation */
    double t = s->hi + x;
    if (fabs(s->hi) >= fabs(x))
        s->lo += (s->hi - t) + x;
    else
        s->lo += (x - t) + s->hi;
    s->hi = t;
#else
    s->hi += x;
#endif
}

static inline double pysum_value(const PySum *s)
{
#if PY_VERSION_HEX >= 0x030C0000
    if (s->lo != 0.0 && isfinite(s->lo))
        return s->hi + s->lo;
#endif
    return s->hi;
}

/* ------------------------------------------------------------------------------------------ */
/* The packed task (immutable; built once per GroundTask action table)                         */

/* Relaxed actions (relaxed_merge.py): the task's actions 0..n_actions-1, of which the merged
 * ones take no part in the relaxation, then merged and auxiliary ones up to n_rel; auxiliary
 * facts n_facts..n_rfacts-1 are never in a state. */
enum { K_REAL = 0, K_AWAY = 1, K_MERGED = 2, K_AUX = 3 };

typedef struct {
    PyObject_HEAD
    Py_ssize_t n_facts, n_actions, W;
    Py_ssize_t n_rfacts, n_rel; /* with the merge's auxiliary facts, extra actions */
    /* An action's bitsets are kept by their non-zero words only (a 320-place AVS task has
     * 57,000 actions over 110 words, of which an action touches a few: dense rows were 200 MB
     * to fill, copy and scan). pre and pre_neg: per action (CSR pw_off), the index and bits
     * of each non-zero word, pre's first (pw_n_pre of them; the one with the most bits
     * first), then pre_neg's; what successor generation tests instead of 2W words. */
    int32_t *pw_off, *pw_n_pre, *pw_idx;
    word *pw_mask;
    /* effects: per action (CSR ew_off), the words its add or delete effects touch, in
     * ascending index, with the bits each sets and clears */
    int32_t *ew_off, *ew_idx;
    word *ew_add, *ew_del;
    /* reads: per action (CSR rw_off), the words of every fact its applicability depends on
     * (pre, pre_neg, clauses, facts read through derived predicates), ascending */
    int32_t *rw_off, *rw_idx;
    word *rw_mask;
    double *cost, *prob, *neglog; /* per relaxed action (extra: a member's, aux: 0, 0, 1) */
    int8_t *kind;                 /* K_* per relaxed action */
    int32_t *link;                /* merged: its fact X; aux: its position among X's */
    int32_t *member_off, *members; /* per merged action: the task action per X position */
    int32_t *pre_off, *pre_facts; /* relaxed preconditions (pre_facts), CSR per rel. action */
    int32_t *add_off, *add_facts;
    int32_t *cl_off;              /* clauses (pos, neg) per action, CSR */
    word *cl_pos, *cl_neg;        /* n_clauses * W */
    /* unit clauses (one positive fact, some negative facts) in RelaxedTask._unit_clauses
     * order, grouped by action; each maps to a distinct (action, fact) "pair" unless the fact
     * is already a base precondition of the action (pair -1) */
    Py_ssize_t n_unit, n_pairs;
    int32_t *unit_off;            /* per action, CSR into unit_* */
    int32_t *unit_fact, *unit_clause, *unit_pair;
    int32_t *unit_neg_off, *unit_neg; /* per unit clause, its negative facts (CSR): what
                                       * clause_variant tests, one bit each, not W words */
    int32_t *pair_action;
    /* precondition classes (derive_classes) and their pre_of lists */
    int32_t n_cls;
    int32_t *cls_of, *cls_off, *cls_members, *cls_len;
    int32_t *cof_off, *cof;                  /* base: classes with f in pre */
    int32_t *xcof_off, *xcof_cls, *xcof_pair; /* clause variants: pair -1 = base entry */
    int32_t *no_pre;              /* actions with no pre_facts, ascending */
    int32_t *pre_len;             /* number of pre_facts of each action */
    Py_ssize_t n_no_pre;
    int32_t *n_pairs_of;          /* number of pairs of each action */
    Py_ssize_t total_add;
    Axioms ax; /* derived predicates' rules (n_rules 0: none); successors are closed */
} TaskObject;

static void task_free_arrays(TaskObject *t)
{
    void *ptrs[] = {t->ew_off, t->ew_idx, t->ew_add, t->ew_del, t->rw_off, t->rw_idx,
                    t->rw_mask, t->cost, t->prob, t->neglog,
                    t->pre_off, t->pre_facts, t->add_off, t->add_facts, t->cl_off, t->cl_pos,
                    t->cl_neg, t->unit_off, t->unit_fact, t->unit_clause, t->unit_pair,
                    t->unit_neg_off, t->unit_neg,
                    t->pair_action, t->cls_of, t->cls_off, t->cls_members, t->cls_len,
                    t->cof_off, t->cof, t->xcof_off, t->xcof_cls, t->xcof_pair, t->no_pre,
                    t->n_pairs_of, t->pre_len, t->kind, t->link, t->member_off, t->members,
                    t->pw_off, t->pw_n_pre, t->pw_idx, t->pw_mask};
    for (size_t i = 0; i < sizeof(ptrs) / sizeof(ptrs[0]); i++)
        free(ptrs[i]);
    axioms_free(&t->ax);
}

static void task_dealloc(TaskObject *t)
{
    task_free_arrays(t);
    Py_TYPE(t)->tp_free((PyObject *)t);
}

static void *xcalloc(size_t n, size_t size)
{
    return calloc(n ? n : 1, size ? size : 1);
}

/* Copy a buffer of `count` items of `size` bytes; ValueError naming `what` if the length is
 * off. */
static void *copy_buffer(Py_buffer *b, Py_ssize_t count, size_t size, const char *what)
{
    if (count < 0 || (size_t)b->len != (size_t)count * size) {
        PyErr_Format(PyExc_ValueError, "native task: %s has %zd bytes, expected %zd", what,
                     b->len, count < 0 ? (Py_ssize_t)-1 : (Py_ssize_t)(count * (Py_ssize_t)size));
        return NULL;
    }
    void *out = xcalloc((size_t)count, size);
    if (!out) {
        PyErr_NoMemory();
        return NULL;
    }
    if (count)
        memcpy(out, b->buf, (size_t)count * size);
    return out;
}

/* int64 CSR (offsets n+1, values) -> int32, checking monotone offsets and value range */
static int copy_csr(Py_buffer *off_b, Py_buffer *val_b, Py_ssize_t n, Py_ssize_t limit,
                    int32_t **off_out, int32_t **val_out, const char *what)
{
    if ((size_t)off_b->len != (size_t)(n + 1) * 8 || val_b->len % 8) {
        PyErr_Format(PyExc_ValueError, "native task: %s offsets/values have wrong sizes", what);
        return -1;
    }
    const int64_t *off = off_b->buf, *val = val_b->buf;
    Py_ssize_t m = val_b->len / 8;
    if (off[0] != 0 || off[n] != m) {
        PyErr_Format(PyExc_ValueError, "native task: %s offsets do not cover the values", what);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++)
        if (off[i + 1] < off[i]) {
            PyErr_Format(PyExc_ValueError, "native task: %s offsets decrease", what);
            return -1;
        }
    if (m > INT32_MAX || n > INT32_MAX) {
        PyErr_Format(PyExc_ValueError, "native task: %s too large", what);
        return -1;
    }
    for (Py_ssize_t i = 0; i < m; i++)
        if (val[i] < 0 || (limit >= 0 && val[i] >= limit)) {
            PyErr_Format(PyExc_ValueError, "native task: %s value %lld out of range", what,
                         (long long)val[i]);
            return -1;
        }
    *off_out = xcalloc((size_t)n + 1, sizeof(int32_t));
    *val_out = xcalloc((size_t)m, sizeof(int32_t));
    if (!*off_out || !*val_out) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i <= n; i++)
        (*off_out)[i] = (int32_t)off[i];
    for (Py_ssize_t i = 0; i < m; i++)
        (*val_out)[i] = (int32_t)val[i];
    return 0;
}

static int popcount_words(const word *x, Py_ssize_t W, int32_t *single)
{
    int n = 0;
    for (Py_ssize_t i = 0; i < W; i++)
        if (x[i]) {
            int c = __builtin_popcountll(x[i]);
            if (c == 1)
                *single = (int32_t)(i * 64 + __builtin_ctzll(x[i]));
            n += c;
        }
    return n;
}

static int any_word(const word *x, Py_ssize_t W)
{
    for (Py_ssize_t i = 0; i < W; i++)
        if (x[i])
            return 1;
    return 0;
}

static int same_pre(const TaskObject *t, int32_t a, int32_t b)
{
    int32_t la = t->pre_off[a + 1] - t->pre_off[a], lb = t->pre_off[b + 1] - t->pre_off[b];
    return la == lb && !memcmp(t->pre_facts + t->pre_off[a], t->pre_facts + t->pre_off[b],
                               sizeof(int32_t) * (size_t)la);
}

/* Precondition classes: actions with the same pre_facts and no clause pairs have the same
 * h^max/h^add precondition value and remaining count at every step of the relaxed Dijkstra,
 * so they share one counter (p20: 6,019 actions, 3,329 classes, a third fewer list entries).
 * An action with clause pairs is a class of its own. Classes are numbered by first member.
 * cof[f]: classes with f in their pre (base); xcof[f]: the same plus (class, pair) entries of
 * the clause variants. Order within these lists does not matter (see relaxed_costs). */
static int derive_classes(TaskObject *t, const int32_t *pair_fact)
{
    Py_ssize_t A = t->n_rel, F = t->n_rfacts, np = t->n_pairs;
    size_t ns = 2;
    while (ns < 2 * (size_t)A + 2)
        ns <<= 1;
    int32_t *slot = malloc(ns * sizeof(int32_t)), *rep = xcalloc((size_t)A, sizeof(int32_t));
    int32_t *fill = xcalloc((size_t)F + 1, sizeof(int32_t));
    t->cls_of = xcalloc((size_t)A, sizeof(int32_t));
    if (!slot || !rep || !fill || !t->cls_of)
        goto nomem;
    memset(slot, 0xff, ns * sizeof(int32_t));
    int32_t n = 0;
    for (Py_ssize_t a = 0; a < A; a++) {
        int32_t c = -1;
        if (t->kind[a] == K_AWAY) {
            t->cls_of[a] = -1;
            continue;
        }
        if (a >= t->n_actions || t->n_pairs_of[a] == 0) {
            uint64_t h = 1469598103934665603ull;
            for (int32_t j = t->pre_off[a]; j < t->pre_off[a + 1]; j++)
                h = (h ^ (uint64_t)t->pre_facts[j]) * 1099511628211ull;
            size_t i = (size_t)(h ^ (h >> 29)) & (ns - 1);
            while (slot[i] >= 0 && !same_pre(t, rep[slot[i]], (int32_t)a))
                i = (i + 1) & (ns - 1);
            if (slot[i] >= 0)
                c = slot[i];
            else
                slot[i] = c = n;
        }
        if (c < 0 || c == n)
            rep[c = n++] = (int32_t)a;
        t->cls_of[a] = c;
    }
    t->n_cls = n;
    t->cls_off = xcalloc((size_t)n + 1, sizeof(int32_t));
    t->cls_members = xcalloc((size_t)A, sizeof(int32_t));
    t->cls_len = xcalloc((size_t)n, sizeof(int32_t));
    t->cof_off = xcalloc((size_t)F + 1, sizeof(int32_t));
    t->xcof_off = xcalloc((size_t)F + 1, sizeof(int32_t));
    if (!t->cls_off || !t->cls_members || !t->cls_len || !t->cof_off || !t->xcof_off)
        goto nomem;
    for (Py_ssize_t a = 0; a < A; a++)
        if (t->cls_of[a] >= 0)
            t->cls_off[t->cls_of[a] + 1]++;
    for (int32_t c = 0; c < n; c++)
        t->cls_off[c + 1] += t->cls_off[c];
    int32_t *cfill = xcalloc((size_t)n, sizeof(int32_t));
    if (!cfill)
        goto nomem;
    for (Py_ssize_t a = 0; a < A; a++) {
        int32_t c = t->cls_of[a];
        if (c >= 0)
            t->cls_members[t->cls_off[c] + cfill[c]++] = (int32_t)a;
    }
    free(cfill);
    Py_ssize_t n_entries = 0;
    for (int32_t c = 0; c < n; c++) {
        int32_t a = rep[c];
        t->cls_len[c] = t->pre_off[a + 1] - t->pre_off[a];
        for (int32_t j = t->pre_off[a]; j < t->pre_off[a + 1]; j++)
            t->cof_off[t->pre_facts[j] + 1]++;
        n_entries += t->cls_len[c];
    }
    for (Py_ssize_t q = 0; q < np; q++)
        t->xcof_off[pair_fact[q] + 1]++;
    for (Py_ssize_t f = 0; f < F; f++) {
        t->xcof_off[f + 1] += t->cof_off[f + 1];
        t->cof_off[f + 1] += t->cof_off[f];
        t->xcof_off[f + 1] += t->xcof_off[f];
    }
    t->cof = xcalloc((size_t)n_entries, sizeof(int32_t));
    t->xcof_cls = xcalloc((size_t)(n_entries + np), sizeof(int32_t));
    t->xcof_pair = xcalloc((size_t)(n_entries + np), sizeof(int32_t));
    if (!t->cof || !t->xcof_cls || !t->xcof_pair)
        goto nomem;
    for (int32_t c = 0; c < n; c++)
        for (int32_t j = t->pre_off[rep[c]]; j < t->pre_off[rep[c] + 1]; j++) {
            int32_t f = t->pre_facts[j];
            int32_t at = t->xcof_off[f] + fill[f];
            t->cof[t->cof_off[f] + fill[f]++] = c;
            t->xcof_cls[at] = c;
            t->xcof_pair[at] = -1;
        }
    for (Py_ssize_t q = 0; q < np; q++) {
        int32_t f = pair_fact[q];
        int32_t at = t->xcof_off[f] + fill[f]++;
        t->xcof_cls[at] = t->cls_of[t->pair_action[q]];
        t->xcof_pair[at] = (int32_t)q;
    }
    free(slot);
    free(rep);
    free(fill);
    return 0;
nomem:
    free(slot);
    free(rep);
    free(fill);
    return -1;
}

/* Derived tables: reads masks, unit clauses and pairs, pre_of lists, no_pre. */
static int task_derive(TaskObject *t)
{
    Py_ssize_t A = t->n_actions, W = t->W;
    t->unit_off = xcalloc((size_t)A + 1, sizeof(int32_t));
    t->n_pairs_of = xcalloc((size_t)A, sizeof(int32_t));
    Py_ssize_t n_cl = t->cl_off[A];
    t->unit_fact = xcalloc((size_t)n_cl, sizeof(int32_t));
    t->unit_clause = xcalloc((size_t)n_cl, sizeof(int32_t));
    t->unit_pair = xcalloc((size_t)n_cl, sizeof(int32_t));
    t->pair_action = xcalloc((size_t)n_cl, sizeof(int32_t));
    int32_t *pair_fact = xcalloc((size_t)n_cl, sizeof(int32_t));
    if (!t->unit_off || !t->n_pairs_of || !t->unit_fact || !t->unit_clause ||
        !t->unit_pair || !t->pair_action || !pair_fact)
        goto nomem;
    Py_ssize_t nu = 0, np = 0;
    for (Py_ssize_t a = 0; a < A; a++) {
        t->unit_off[a] = (int32_t)nu;
        Py_ssize_t first_pair = np;
        for (int32_t k = t->cl_off[a]; k < t->cl_off[a + 1]; k++) {
            const word *pos = t->cl_pos + (Py_ssize_t)k * W, *neg = t->cl_neg + (Py_ssize_t)k * W;
            int32_t f = -1;
            if (popcount_words(pos, W, &f) != 1 || !any_word(neg, W))
                continue;
            int32_t pair = -1, in_base = 0;
            for (int32_t j = t->pre_off[a]; j < t->pre_off[a + 1]; j++)
                if (t->pre_facts[j] == f)
                    in_base = 1;
            if (!in_base) {
                for (Py_ssize_t q = first_pair; q < np; q++)
                    if (pair_fact[q] == f)
                        pair = (int32_t)q;
                if (pair < 0) {
                    pair = (int32_t)np;
                    pair_fact[np] = f;
                    t->pair_action[np++] = (int32_t)a;
                    t->n_pairs_of[a]++;
                }
            }
            t->unit_fact[nu] = f;
            t->unit_clause[nu] = k;
            t->unit_pair[nu++] = pair;
        }
    }
    t->unit_off[A] = (int32_t)nu;
    t->n_unit = nu;
    t->n_pairs = np;
    /* the negative facts of each unit clause, listed (usually one: a state is tested with
     * one bit per clause instead of a scan of its W-word mask; 160-place AVS problems have
     * 8,704 unit clauses of 40 words each) */
    t->unit_neg_off = xcalloc((size_t)nu + 1, sizeof(int32_t));
    if (!t->unit_neg_off)
        goto nomem;
    Py_ssize_t n_neg = 0;
    for (Py_ssize_t k = 0; k < nu; k++) {
        const word *neg = t->cl_neg + (Py_ssize_t)t->unit_clause[k] * W;
        for (Py_ssize_t i = 0; i < W; i++)
            n_neg += __builtin_popcountll(neg[i]);
        t->unit_neg_off[k + 1] = (int32_t)n_neg;
    }
    t->unit_neg = xcalloc((size_t)n_neg, sizeof(int32_t));
    if (!t->unit_neg)
        goto nomem;
    for (Py_ssize_t k = 0, j = 0; k < nu; k++) {
        const word *neg = t->cl_neg + (Py_ssize_t)t->unit_clause[k] * W;
        for (Py_ssize_t i = 0; i < W; i++)
            for (word x = neg[i]; x; x &= x - 1)
                t->unit_neg[j++] = (int32_t)(i * 64 + __builtin_ctzll(x));
    }

    if (derive_classes(t, pair_fact))
        goto nomem;
    Py_ssize_t R = t->n_rel;
    t->no_pre = xcalloc((size_t)R, sizeof(int32_t));
    if (!t->no_pre)
        goto nomem;
    t->pre_len = xcalloc((size_t)R, sizeof(int32_t));
    if (!t->pre_len)
        goto nomem;
    for (Py_ssize_t a = 0; a < R; a++)
        t->pre_len[a] = t->pre_off[a + 1] - t->pre_off[a];
    t->n_no_pre = 0;
    for (Py_ssize_t a = 0; a < R; a++)
        if (t->pre_off[a] == t->pre_off[a + 1] && t->kind[a] != K_AWAY)
            t->no_pre[t->n_no_pre++] = (int32_t)a;
    t->total_add = t->add_off[R];
    free(pair_fact);
    return 0;
nomem:
    free(pair_fact);
    PyErr_NoMemory();
    return -1;
}

#define NBUF 25

/* Append two int32 CSRs (a: n_a rows, b: n_b rows) into a new one. */
static int join_csr(int32_t **off, int32_t **val, Py_ssize_t n_a, const int32_t *b_off,
                    const int32_t *b_val, Py_ssize_t n_b)
{
    int32_t m_a = (*off)[n_a], m_b = b_off[n_b];
    int32_t *o = xcalloc((size_t)(n_a + n_b) + 1, sizeof(int32_t));
    int32_t *v = xcalloc((size_t)m_a + (size_t)m_b, sizeof(int32_t));
    if (!o || !v) {
        free(o);
        free(v);
        PyErr_NoMemory();
        return -1;
    }
    memcpy(o, *off, sizeof(int32_t) * ((size_t)n_a + 1));
    for (Py_ssize_t i = 1; i <= n_b; i++)
        o[n_a + i] = m_a + b_off[i];
    memcpy(v, *val, sizeof(int32_t) * (size_t)m_a);
    memcpy(v + m_a, b_val, sizeof(int32_t) * (size_t)m_b);
    free(*off);
    free(*val);
    *off = o;
    *val = v;
    return 0;
}

/* The relaxed merge (b[0..8]: extra pre CSR, extra add CSR, away, weight_of, link, member CSR;
 * int64 each): extends pre/add CSRs, weights and kinds to n_rel relaxed actions. */
static int task_merge(TaskObject *t, Py_ssize_t n_rfacts, Py_ssize_t n_merged, Py_buffer *b)
{
    Py_ssize_t A = t->n_actions, F = t->n_facts;
    if (n_rfacts < F || n_rfacts > INT32_MAX / 2 || n_merged < 0 || b[5].len % 8) {
        PyErr_SetString(PyExc_ValueError, "native task: bad relaxed merge sizes");
        return -1;
    }
    Py_ssize_t E = b[5].len / 8; /* extra actions */
    if (n_merged > E || E > INT32_MAX / 4 || (size_t)b[4].len != (size_t)A * 8 ||
        (size_t)b[6].len != (size_t)E * 8) {
        PyErr_SetString(PyExc_ValueError, "native task: relaxed merge arrays disagree");
        return -1;
    }
    int32_t *x_pre_off = NULL, *x_pre = NULL, *x_add_off = NULL, *x_add = NULL;
    int ok = -1;
    if (copy_csr(&b[0], &b[1], E, n_rfacts, &x_pre_off, &x_pre, "merged pre") ||
        copy_csr(&b[2], &b[3], E, n_rfacts, &x_add_off, &x_add, "merged add") ||
        copy_csr(&b[7], &b[8], n_merged, A, &t->member_off, &t->members, "merged members") ||
        join_csr(&t->pre_off, &t->pre_facts, A, x_pre_off, x_pre, E) ||
        join_csr(&t->add_off, &t->add_facts, A, x_add_off, x_add, E))
        goto done;
    Py_ssize_t R = A + E;
    const int64_t *away = b[4].buf, *weight_of = b[5].buf, *link = b[6].buf;
    double *cost = realloc(t->cost, sizeof(double) * (size_t)(R ? R : 1));
    if (cost)
        t->cost = cost;
    double *prob = realloc(t->prob, sizeof(double) * (size_t)(R ? R : 1));
    if (prob)
        t->prob = prob;
    double *neglog = realloc(t->neglog, sizeof(double) * (size_t)(R ? R : 1));
    if (neglog)
        t->neglog = neglog;
    t->kind = xcalloc((size_t)R, 1);
    t->link = xcalloc((size_t)R, sizeof(int32_t));
    if (!cost || !prob || !neglog || !t->kind || !t->link) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t a = 0; a < A; a++) {
        t->kind[a] = away[a] ? K_AWAY : K_REAL;
        t->link[a] = -1;
    }
    for (Py_ssize_t e = 0; e < E; e++) {
        int64_t w = weight_of[e];
        int merged = e < n_merged;
        if ((merged && (w < 0 || w >= A)) || (!merged && w != -1) || link[e] < 0 ||
            (merged ? link[e] < F || link[e] >= n_rfacts : link[e] > INT32_MAX / 2)) {
            PyErr_Format(PyExc_ValueError, "native task: relaxed action %zd is malformed", A + e);
            goto done;
        }
        t->kind[A + e] = merged ? K_MERGED : K_AUX;
        t->link[A + e] = (int32_t)link[e];
        t->cost[A + e] = merged ? t->cost[w] : 0.0;
        t->prob[A + e] = merged ? t->prob[w] : 1.0;
        t->neglog[A + e] = merged ? t->neglog[w] : 0.0;
    }
    t->n_rel = R;
    t->n_rfacts = n_rfacts;
    ok = 0;
done:
    free(x_pre_off);
    free(x_pre);
    free(x_add_off);
    free(x_add);
    return ok;
}

/* An action table's fact ids (`native.packed_rows`): one int64 buffer of n_actions + 1
 * offsets, from 0 and monotone, then the ids, each in [0, n_facts). */
typedef struct {
    const int64_t *off, *val;
} Rows;

static int get_rows(Py_buffer *b, Py_ssize_t A, Py_ssize_t F, const char *what, Rows *r)
{
    const int64_t *v = b->buf;
    Py_ssize_t items = b->len / 8;
    if (b->len % 8 || items < A + 1 || v[0] != 0)
        goto bad;
    for (Py_ssize_t a = 0; a < A; a++)
        if (v[a] > v[a + 1])
            goto bad;
    if (items != A + 1 + v[A])
        goto bad;
    r->off = v;
    r->val = v + A + 1;
    for (Py_ssize_t a = 0; a < A; a++)
        for (int64_t j = v[a]; j < v[a + 1]; j++)
            if (r->val[j] < 0 || r->val[j] >= F) {
                PyErr_Format(PyExc_ValueError, "native task: action %zd has a %s fact %lld "
                             "outside [0, %zd)", a, what, (long long)r->val[j], F);
                return -1;
            }
    return 0;
bad:
    PyErr_Format(PyExc_ValueError, "native task: %s is not a packed CSR over %zd actions",
                 what, A);
    return -1;
}

/* Scratch for turning fact lists into (word index, bits) lists: rows of W words kept zero
 * between actions, and the words an action touched (stamp[i] == the action's mark). */
typedef struct {
    word *row[2];
    uint32_t *stamp, mark;
    int32_t *touched, n;
    Py_ssize_t W;
} WordScratch;

static int scratch_alloc(WordScratch *x, Py_ssize_t W)
{
    memset(x, 0, sizeof(*x));
    x->W = W;
    x->row[0] = xcalloc((size_t)W, sizeof(word));
    x->row[1] = xcalloc((size_t)W, sizeof(word));
    x->stamp = xcalloc((size_t)W, sizeof(uint32_t));
    x->touched = xcalloc((size_t)W, sizeof(int32_t));
    return !x->row[0] || !x->row[1] || !x->stamp || !x->touched ? -1 : 0;
}

static void scratch_free(WordScratch *x)
{
    free(x->row[0]);
    free(x->row[1]);
    free(x->stamp);
    free(x->touched);
}

/* A new action (or list): nothing touched yet. */
static inline void scratch_begin(WordScratch *x)
{
    x->n = 0;
    if (++x->mark == 0) { /* wrapped: forget every stamp */
        memset(x->stamp, 0, (size_t)x->W * sizeof(uint32_t));
        x->mark = 1;
    }
}

static inline void scratch_word(WordScratch *x, int k, int32_t i, word bits)
{
    if (!bits)
        return;
    if (x->stamp[i] != x->mark) {
        x->stamp[i] = x->mark;
        x->touched[x->n++] = i;
    }
    x->row[k][i] |= bits;
}

static void scratch_facts(WordScratch *x, int k, const Rows *r, Py_ssize_t a)
{
    for (int64_t j = r->off[a]; j < r->off[a + 1]; j++)
        scratch_word(x, k, (int32_t)(r->val[j] >> 6), (word)1 << (r->val[j] & 63));
}

/* The touched words in ascending order (insertion sort: an action touches a few). */
static void scratch_sort(WordScratch *x)
{
    for (int32_t m = 1; m < x->n; m++) {
        int32_t v = x->touched[m], at = m;
        for (; at > 0 && x->touched[at - 1] > v; at--)
            x->touched[at] = x->touched[at - 1];
        x->touched[at] = v;
    }
}

static inline void scratch_clear(WordScratch *x)
{
    for (int32_t m = 0; m < x->n; m++)
        x->row[0][x->touched[m]] = x->row[1][x->touched[m]] = 0;
}

/* TaskObject.pw_* and ew_* from the actions' fact ids */
static int sparse_rows(TaskObject *t, const Rows *pre, const Rows *neg, const Rows *add,
                       const Rows *del)
{
    Py_ssize_t A = t->n_actions;
    int64_t n_pw = pre->off[A] + neg->off[A], n_ew = add->off[A] + del->off[A];
    if (n_pw > INT32_MAX / 2 || n_ew > INT32_MAX / 2)
        return -1;
    WordScratch x;
    t->pw_off = xcalloc((size_t)A + 1, sizeof(int32_t));
    t->pw_n_pre = xcalloc((size_t)A + 1, sizeof(int32_t));
    t->pw_idx = xcalloc((size_t)n_pw + 1, sizeof(int32_t));
    t->pw_mask = xcalloc((size_t)n_pw + 1, sizeof(word));
    t->ew_off = xcalloc((size_t)A + 1, sizeof(int32_t));
    t->ew_idx = xcalloc((size_t)n_ew + 1, sizeof(int32_t));
    t->ew_add = xcalloc((size_t)n_ew + 1, sizeof(word));
    t->ew_del = xcalloc((size_t)n_ew + 1, sizeof(word));
    if (scratch_alloc(&x, t->W) || !t->pw_off || !t->pw_n_pre || !t->pw_idx || !t->pw_mask ||
        !t->ew_off || !t->ew_idx || !t->ew_add || !t->ew_del) {
        scratch_free(&x);
        return -1;
    }
    int32_t k = 0, e = 0;
    for (Py_ssize_t a = 0; a < A; a++) {
        t->pw_off[a] = k;
        int32_t first = k;
        scratch_begin(&x);
        scratch_facts(&x, 0, pre, a);
        scratch_sort(&x);
        for (int32_t m = 0; m < x.n; m++) {
            int32_t i = x.touched[m];
            word bits = x.row[0][i];
            t->pw_idx[k] = i;
            t->pw_mask[k] = bits;
            if (__builtin_popcountll(bits) > __builtin_popcountll(t->pw_mask[first])) {
                t->pw_idx[k] = t->pw_idx[first]; /* the word with the most bits first */
                t->pw_mask[k] = t->pw_mask[first];
                t->pw_idx[first] = i;
                t->pw_mask[first] = bits;
            }
            k++;
        }
        scratch_clear(&x);
        t->pw_n_pre[a] = k - first;
        scratch_begin(&x);
        scratch_facts(&x, 0, neg, a);
        scratch_sort(&x);
        for (int32_t m = 0; m < x.n; m++) {
            t->pw_idx[k] = x.touched[m];
            t->pw_mask[k++] = x.row[0][x.touched[m]];
        }
        scratch_clear(&x);
        t->ew_off[a] = e;
        scratch_begin(&x);
        scratch_facts(&x, 0, add, a);
        scratch_facts(&x, 1, del, a);
        scratch_sort(&x);
        for (int32_t m = 0; m < x.n; m++) {
            int32_t i = x.touched[m];
            t->ew_idx[e] = i;
            t->ew_add[e] = x.row[0][i];
            t->ew_del[e++] = x.row[1][i];
        }
        scratch_clear(&x);
    }
    t->pw_off[A] = k;
    t->ew_off[A] = e;
    scratch_free(&x);
    return 0;
}

/* TaskObject.rw_*: per action the words of its pre and pre_neg facts, of its clauses, and of
 * `extra` (n_actions * W words, or NULL: what it reads through derived predicates) */
static int sparse_reads(TaskObject *t, const Rows *pre, const Rows *neg, const word *extra)
{
    Py_ssize_t A = t->n_actions, W = t->W;
    WordScratch x;
    int64_t cap = pre->off[A] + neg->off[A] + 16, n = 0;
    t->rw_off = xcalloc((size_t)A + 1, sizeof(int32_t));
    t->rw_idx = malloc((size_t)cap * sizeof(int32_t));
    t->rw_mask = malloc((size_t)cap * sizeof(word));
    if (scratch_alloc(&x, W) || !t->rw_off || !t->rw_idx || !t->rw_mask)
        goto nomem;
    for (Py_ssize_t a = 0; a < A; a++) {
        t->rw_off[a] = (int32_t)n;
        scratch_begin(&x);
        scratch_facts(&x, 0, pre, a);
        scratch_facts(&x, 0, neg, a);
        for (int32_t k = t->cl_off[a]; k < t->cl_off[a + 1]; k++) {
            const word *pos = t->cl_pos + (Py_ssize_t)k * W, *cn = t->cl_neg + (Py_ssize_t)k * W;
            for (Py_ssize_t i = 0; i < W; i++)
                scratch_word(&x, 0, (int32_t)i, pos[i] | cn[i]);
        }
        if (extra)
            for (Py_ssize_t i = 0; i < W; i++)
                scratch_word(&x, 0, (int32_t)i, extra[a * W + i]);
        scratch_sort(&x);
        if (n + x.n > cap) {
            int64_t more = 2 * (n + x.n);
            int32_t *idx = realloc(t->rw_idx, (size_t)more * sizeof(int32_t));
            if (idx)
                t->rw_idx = idx;
            word *mask = realloc(t->rw_mask, (size_t)more * sizeof(word));
            if (mask)
                t->rw_mask = mask;
            if (!idx || !mask)
                goto nomem;
            cap = more;
        }
        if (n + x.n > INT32_MAX / 2)
            goto nomem;
        for (int32_t m = 0; m < x.n; m++) {
            t->rw_idx[n] = x.touched[m];
            t->rw_mask[n++] = x.row[0][x.touched[m]];
        }
        scratch_clear(&x);
    }
    t->rw_off[A] = (int32_t)n;
    scratch_free(&x);
    return 0;
nomem:
    scratch_free(&x);
    PyErr_NoMemory();
    return -1;
}

/* The optional derived predicates' rules (b[0]: GroundAxioms.native_args) and what each
 * action reads through them (b[1]: n_actions * W words OR-ed into its reads, so that
 * commutes() sees the facts a derived precondition depends on); then the reads. */
static int task_axioms(TaskObject *t, Py_buffer *b, const Rows *pre, const Rows *neg)
{
    if (b[0].obj && b[0].len) {
        if (b[0].len % 8) {
            PyErr_SetString(PyExc_ValueError, "native task: the packed rules are not int64");
            return -1;
        }
        if (axioms_parse(&t->ax, b[0].buf, b[0].len / 8, t->n_facts, t->W))
            return -1;
    }
    if (b[1].obj && b[1].len) {
        Py_ssize_t AW = t->n_actions * t->W;
        if ((size_t)b[1].len != (size_t)AW * 8) {
            PyErr_SetString(PyExc_ValueError, "native task: extra reads have the wrong size");
            return -1;
        }
        return sparse_reads(t, pre, neg, b[1].buf);
    }
    return sparse_reads(t, pre, neg, NULL);
}

static PyObject *task_new(PyTypeObject *type, PyObject *args, PyObject *kwds)
{
    Py_ssize_t n_facts, n_actions, n_rfacts, n_merged;
    Py_buffer b[NBUF];
    memset(b, 0, sizeof(b));
    if (!PyArg_ParseTuple(args, "nny*y*y*y*y*y*y*y*y*y*y*y*y*y*nny*y*y*y*y*y*y*y*y*|y*y*:Task",
                          &n_facts, &n_actions, &b[0], &b[1], &b[2], &b[3], &b[4], &b[5],
                          &b[6], &b[7], &b[8], &b[9], &b[10], &b[11], &b[12], &b[13],
                          &n_rfacts, &n_merged, &b[14], &b[15], &b[16], &b[17], &b[18],
                          &b[19], &b[20], &b[21], &b[22], &b[23], &b[24]))
        return NULL;
    TaskObject *t = NULL;
    if (n_facts < 0 || n_actions < 0 || n_facts > INT32_MAX / 2 || n_actions > INT32_MAX / 2) {
        PyErr_SetString(PyExc_ValueError, "native task: bad fact or action count");
        goto fail;
    }
    t = (TaskObject *)type->tp_alloc(type, 0);
    if (!t)
        goto fail;
    t->n_facts = n_facts;
    t->n_actions = n_actions;
    t->W = n_facts / 64 + 1;
    Rows pre, neg, add, del;
    if (get_rows(&b[0], n_actions, n_facts, "pre", &pre) ||
        get_rows(&b[1], n_actions, n_facts, "pre_neg", &neg) ||
        get_rows(&b[2], n_actions, n_facts, "add", &add) ||
        get_rows(&b[3], n_actions, n_facts, "delete", &del))
        goto fail;
    if (!(t->cost = copy_buffer(&b[4], n_actions, 8, "cost")) ||
        !(t->prob = copy_buffer(&b[5], n_actions, 8, "probability")) ||
        !(t->neglog = copy_buffer(&b[6], n_actions, 8, "neglog")))
        goto fail;
    if (copy_csr(&b[7], &b[8], n_actions, n_facts, &t->pre_off, &t->pre_facts, "pre_facts") ||
        copy_csr(&b[9], &b[10], n_actions, n_facts, &t->add_off, &t->add_facts, "add_facts"))
        goto fail;
    if ((size_t)b[11].len != (size_t)(n_actions + 1) * 8) {
        PyErr_SetString(PyExc_ValueError, "native task: clause offsets have the wrong size");
        goto fail;
    }
    const int64_t *cl = b[11].buf;
    for (Py_ssize_t a = 0; a < n_actions; a++)
        if (cl[a + 1] < cl[a]) {
            PyErr_SetString(PyExc_ValueError, "native task: clause offsets decrease");
            goto fail;
        }
    if (cl[0] != 0 || cl[n_actions] > INT32_MAX / 2) {
        PyErr_SetString(PyExc_ValueError, "native task: bad clause offsets");
        goto fail;
    }
    Py_ssize_t n_cl = (Py_ssize_t)cl[n_actions];
    t->cl_off = xcalloc((size_t)n_actions + 1, sizeof(int32_t));
    if (!t->cl_off) {
        PyErr_NoMemory();
        goto fail;
    }
    for (Py_ssize_t a = 0; a <= n_actions; a++)
        t->cl_off[a] = (int32_t)cl[a];
    if (!(t->cl_pos = copy_buffer(&b[12], n_cl * t->W, 8, "clause pos")) ||
        !(t->cl_neg = copy_buffer(&b[13], n_cl * t->W, 8, "clause neg")))
        goto fail;
    if (sparse_rows(t, &pre, &neg, &add, &del)) {
        PyErr_NoMemory();
        goto fail;
    }
    if (task_merge(t, n_rfacts, n_merged, b + 14) || task_derive(t) ||
        task_axioms(t, b + 23, &pre, &neg))
        goto fail;
    for (int i = 0; i < NBUF; i++)
        PyBuffer_Release(&b[i]);
    return (PyObject *)t;
fail:
    for (int i = 0; i < NBUF; i++)
        if (b[i].obj)
            PyBuffer_Release(&b[i]);
    Py_XDECREF(t);
    return NULL;
}

static PyObject *task_get_n_actions(TaskObject *t, void *closure)
{
    return PyLong_FromSsize_t(t->n_actions);
}

static PyObject *task_get_n_facts(TaskObject *t, void *closure)
{
    return PyLong_FromSsize_t(t->n_facts);
}

static PyGetSetDef task_getset[] = {
    {"n_actions", (getter)task_get_n_actions, NULL, "number of actions", NULL},
    {"n_facts", (getter)task_get_n_facts, NULL, "number of facts", NULL},
    {NULL},
};

static PyTypeObject TaskType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "avs_planner.cp._native.Task",
    .tp_basicsize = sizeof(TaskObject),
    .tp_dealloc = (destructor)task_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Packed ground actions (see avs_planner.cp.native.pack_task).",
    .tp_new = task_new,
    .tp_getset = task_getset,
};

/* ------------------------------------------------------------------------------------------ */
/* Search data                                                                                  */

typedef struct {
    double c, p;
    int32_t node;
} Label;

typedef struct {
    Label *labels;
    int32_t n_labels, cap_labels;
    int8_t h_known;
    double hc, hl;
    int64_t help_off;
    int32_t help_n;
    uint64_t hash;
} StateRec;

typedef struct {
    double f, h;
    int32_t node;
} QEntry;

typedef struct {
    QEntry *v;
    size_t n, cap;
} Queue;

typedef struct {
    double d;
    int32_t f;
} DEntry;

typedef struct {
    double value;      /* h^max / h^add of the action's preconditions so far */
    int32_t remaining; /* preconditions not yet reached */
} Counter;

/* Scratch of one heuristic evaluation: one per evaluating thread (Search.ev) */
typedef struct {
    double *dist;
    Counter *counter;     /* per precondition class */
    uint32_t *set_in;     /* fact -> pop that last improved it (relax_fire) */
    uint32_t pop_id;
    int32_t *support, *rem_ext, *stack, *chosen;
    uint32_t *seen_stamp, *chosen_stamp, *emit_stamp;
    uint32_t stamp;
    int8_t *active, *pair_eff;
    DEntry *dheap;
    int32_t *hpos; /* fact -> index in dheap, -1 if absent */
    size_t dn;
    int32_t *help; /* helpful actions of the evaluations since the caller reset n_help */
    int64_t n_help, cap_help;
    int oom;
} Eval;

/* Search.lazy: every successor evaluated when generated (eager), every one when popped
 * (deferred evaluation), or only those reached by a helpful action when generated and the
 * others when popped (search.py's _lazy says when each is used) */
enum { LAZY_NONE = 0, LAZY_ALL = 1, LAZY_UNHELPFUL = 2 };
#ifndef STALL
#define STALL 64 /* search.py's STALL */
#endif

#define MAX_EVAL 2 /* evaluating threads: the search's own and at most one worker */

/* A batch of states to evaluate: each state k is claimed by one thread (owner[k]), whose
 * Eval's help list holds its helpful actions from help_at[k], help_n[k] of them */
typedef struct {
    const int32_t *sids;
    int32_t n;
    double *hc, *hl;
    int64_t *help_at, *help_n;
    int8_t *owner;
} Batch;

typedef struct {
    const TaskObject *t;
    Py_ssize_t W;
    /* options */
    int heuristic, lazy, preferred, threads;
    double reward, weight, min_success, timeout;
    int64_t node_limit, patience; /* patience < 0: unlimited */
    int stopped;                  /* STOP_*: why the best plan so far was returned */
    /* goal */
    word *goal, *goal_neg;
    int32_t *goal_facts;
    int8_t *is_goal;
    Py_ssize_t n_goal;
    /* symmetry (may be empty) */
    int has_sym;
    const int64_t *sym_act_off, *sym_pair_ids, *sym_pair_off, *sym_fg;
    /* state table */
    word *sdata;
    StateRec *recs;
    int32_t n_states, cap_states;
    int32_t *slots;
    size_t n_slots;
    /* nodes */
    int32_t *n_state, *n_parent, *n_via;
    double *n_c, *n_p, *n_h;
    int8_t *n_alive, *n_eval;
    int32_t n_nodes, cap_nodes;
    /* queues: the main one, helpful actions', and with goal_count the goal-count ones
     * (search.py's _Search.queues; Q_* index priority) */
    Queue heap, pref, gc_heap, gc_pref;
    int64_t priority[4];
    double best_h, best_gc;
    int goal_count, commute; /* QF_GOAL_COUNT set; QF_NO_COMMUTE not set */
    /* LAZY_UNHELPFUL defers only while h improves: expansions so far, the expansion count
     * when best_h last dropped, and whether the node being expanded defers (STALL) */
    int64_t n_expanded, progress_at;
    int defer_now;
    int32_t *waiting; /* nodes deferred since the last flush_deferred */
    int64_t n_waiting, cap_waiting;
    double popped_h;  /* h of the queue entry pop_node took */
    int from_queue, pruned_threshold; /* from_queue: Q_* of the queue pop_node took from */
    /* helpful pool: StateRec.help_off/help_n index it */
    int32_t *help;
    int64_t n_help, cap_help;
    /* heuristic */
    double *combined;
    Eval ev[MAX_EVAL];
    uint32_t *help_stamp, help_mark;
    /* successors of one expansion, evaluated as a batch (expand) */
    word *kids;
    int32_t *kid_act, *todo;
    double *kid_c, *kid_p, *todo_hc, *todo_hl;
    int64_t *todo_at, *todo_n;
    int8_t *kid_pref, *todo_owner;
    Batch batch;
    struct Worker *worker; /* NULL: evaluations run on the search's thread only */
    word *parent; /* the expanded state, copied: the state table may move */
    AxiomScratch ax; /* closing successors under the task's rules */
    int oom;
    PyThreadState *thread; /* saved while the GIL is released (NULL: not released) */
} Search;

enum { Q_MAIN = 0, Q_PREF = 1, Q_GC = 2, Q_GC_PREF = 3 };
/* native_search's queue flags: helpful actions first, goal-count queues, and no pruning of
 * the second order of two commuting actions (search.py's _preferred, _goal_count and
 * SearchOptions.commute) */
enum { QF_PREFERRED = 1, QF_GOAL_COUNT = 2, QF_NO_COMMUTE = 4 };
static const int POP_ORDER[4] = {Q_PREF, Q_MAIN, Q_GC_PREF, Q_GC}; /* ties broken in order */

static inline Queue *queue_of(Search *s, int q)
{
    return q == Q_MAIN ? &s->heap : q == Q_PREF ? &s->pref : q == Q_GC ? &s->gc_heap
                                                                        : &s->gc_pref;
}

static inline int qless(const QEntry *a, const QEntry *b)
{
    if (a->f != b->f)
        return a->f < b->f;
    if (a->h != b->h)
        return a->h < b->h;
    return a->node < b->node;
}

static int qpush(Search *s, Queue *q, double f, double h, int32_t node)
{
    if (q->n == q->cap) {
        size_t cap = q->cap ? q->cap * 2 : 1024;
        QEntry *v = realloc(q->v, cap * sizeof(QEntry));
        if (!v) {
            s->oom = 1;
            return -1;
        }
        q->v = v;
        q->cap = cap;
    }
    QEntry e = {f, h, node};
    size_t i = q->n++;
    while (i > 0) {
        size_t parent = (i - 1) / 2;
        if (!qless(&e, &q->v[parent]))
            break;
        q->v[i] = q->v[parent];
        i = parent;
    }
    q->v[i] = e;
    return 0;
}

static QEntry qpop(Queue *q)
{
    QEntry top = q->v[0];
    QEntry last = q->v[--q->n];
    size_t i = 0, n = q->n;
    while (1) {
        size_t l = 2 * i + 1;
        if (l >= n)
            break;
        size_t m = (l + 1 < n && qless(&q->v[l + 1], &q->v[l])) ? l + 1 : l;
        if (!qless(&q->v[m], &last))
            break;
        q->v[i] = q->v[m];
        i = m;
    }
    if (n)
        q->v[i] = last;
    return top;
}

static inline int dless(const DEntry *a, const DEntry *b)
{
    return a->d < b->d || (a->d == b->d && a->f < b->f);
}

/* ------------------------------------------------------------------------------------------ */
/* Relaxed heuristics (heuristics.py); each evaluation uses one Eval's scratch only            */

/* The relaxed Dijkstra's queue: an indexed heap, one entry per fact keyed (dist, fact). Python
 * pushes a new (d, f) on every improvement and skips stale entries when popped; keeping one
 * entry per fact and lowering its key pops the non-stale entries in the same order (keys are
 * unique), with a heap of at most n_facts entries. */
static inline void dsift_up(Eval *e, size_t i, DEntry d)
{
    DEntry *v = e->dheap;
    while (i > 0) {
        size_t parent = (i - 1) / 2;
        if (!dless(&d, &v[parent]))
            break;
        v[i] = v[parent];
        e->hpos[v[i].f] = (int32_t)i;
        i = parent;
    }
    v[i] = d;
    e->hpos[d.f] = (int32_t)i;
}

static inline void dpush(Eval *e, double d, int32_t f)
{
    DEntry x = {d, f};
    int32_t at = e->hpos[f];
    if (at >= 0) /* keys only decrease (an improvement), so sift up */
        dsift_up(e, (size_t)at, x);
    else
        dsift_up(e, e->dn++, x);
}

static inline DEntry dpop(Eval *e)
{
    DEntry *v = e->dheap;
    DEntry top = v[0];
    e->hpos[top.f] = -1;
    DEntry last = v[--e->dn];
    size_t i = 0, n = e->dn;
    if (!n)
        return top;
    while (1) {
        size_t l = 2 * i + 1;
        if (l >= n)
            break;
        size_t m = (l + 1 < n && dless(&v[l + 1], &v[l])) ? l + 1 : l;
        if (!dless(&v[m], &last))
            break;
        v[i] = v[m];
        e->hpos[v[i].f] = (int32_t)i;
        i = m;
    }
    v[i] = last;
    e->hpos[last.f] = (int32_t)i;
    return top;
}

static inline void dclear(Eval *e)
{
    for (size_t i = 0; i < e->dn; i++)
        e->hpos[e->dheap[i].f] = -1;
    e->dn = 0;
}

/* Which unit clauses hold their negative part in `state` (RelaxedTask.for_state), which
 * (action, fact) pairs that makes effective, and the variant's remaining counts. */
static void clause_variant(const Search *s, Eval *e, const word *state)
{
    const TaskObject *t = s->t;
    memset(e->pair_eff, 0, (size_t)t->n_pairs);
    for (Py_ssize_t k = 0; k < t->n_unit; k++) {
        int on = 1;
        for (int32_t j = t->unit_neg_off[k]; j < t->unit_neg_off[k + 1]; j++)
            if (!BIT(state, t->unit_neg[j])) {
                on = 0;
                break;
            }
        e->active[k] = (int8_t)on;
        if (on && t->unit_pair[k] >= 0)
            e->pair_eff[t->unit_pair[k]] = 1;
    }
    memcpy(e->rem_ext, t->cls_len, sizeof(int32_t) * (size_t)t->n_cls);
    for (Py_ssize_t q = 0; q < t->n_pairs; q++)
        if (e->pair_eff[q])
            e->rem_ext[t->cls_of[t->pair_action[q]]]++;
}

/* An action reached: improve its add effects. Python fires the actions one pop completes in
 * index order and keeps the first supporter of the best value (strict <); here they may come
 * in class order, so an equal value from a lower index set in the same pop wins instead. */
static inline void relax_fire(const TaskObject *t, Eval *e, int32_t a, double nd)
{
    for (int32_t j = t->add_off[a]; j < t->add_off[a + 1]; j++) {
        int32_t g = t->add_facts[j];
        if (nd < e->dist[g]) {
            e->dist[g] = nd;
            e->support[g] = a;
            e->set_in[g] = e->pop_id;
            dpush(e, nd, g);
        } else if (nd == e->dist[g] && e->set_in[g] == e->pop_id && a < e->support[g]) {
            e->support[g] = a;
        }
    }
}

static void next_pop(const TaskObject *t, Eval *e)
{
    if (++e->pop_id == 0) {
        memset(e->set_in, 0, sizeof(uint32_t) * (size_t)t->n_rfacts);
        e->pop_id = 1;
    }
}

/* relaxed_costs(): generalised Dijkstra, h^max (use_max) or h^add; ext = clause variant.
 * Counters are per precondition class; a class reaching zero fires its actions at once (see
 * relax_fire for why the order of firing does not change dist or support). */
static void relaxed_costs(const Search *s, Eval *e, const word *state, const double *w,
                          int use_max, int ext)
{
    const TaskObject *t = s->t;
    double *dist = e->dist;
    for (Py_ssize_t f = 0; f < t->n_rfacts; f++) {
        dist[f] = INFINITY;
        e->support[f] = -1;
    }
    dclear(e);
    for (Py_ssize_t f = 0; f < t->n_facts; f++)
        if (BIT(state, f)) {
            dist[f] = 0.0;
            dpush(e, 0.0, (int32_t)f);
        }
    /* value and remaining count side by side: one cache line per class touched */
    Counter *cnt = e->counter;
    const int32_t *rem = ext ? e->rem_ext : t->cls_len;
    for (int32_t c = 0; c < t->n_cls; c++) {
        cnt[c].value = 0.0;
        cnt[c].remaining = rem[c];
    }
    next_pop(t, e);
    for (Py_ssize_t i = 0; i < t->n_no_pre; i++) {
        int32_t a = t->no_pre[i];
        if (ext && cnt[t->cls_of[a]].remaining != 0)
            continue; /* an active clause gave it a precondition */
        relax_fire(t, e, a, w[a]);
    }
    Py_ssize_t goals_left = s->n_goal;
    const int32_t *off = ext ? t->xcof_off : t->cof_off;
    const int32_t *cls = ext ? t->xcof_cls : t->cof;
    while (e->dn && goals_left) {
        DEntry x = dpop(e);
        double d = x.d;
        int32_t f = x.f;
        if (d > dist[f])
            continue;
        if (s->is_goal[f])
            goals_left--;
        next_pop(t, e);
        for (int32_t j = off[f]; j < off[f + 1]; j++) {
            if (ext && t->xcof_pair[j] >= 0 && !e->pair_eff[t->xcof_pair[j]])
                continue;
            int32_t c = cls[j];
            Counter *cc = &cnt[c];
            if (use_max)
                cc->value = cc->value > d ? cc->value : d;
            else
                cc->value = cc->value + d;
            if (--cc->remaining == 0)
                for (int32_t k = t->cls_off[c]; k < t->cls_off[c + 1]; k++) {
                    int32_t a = t->cls_members[k];
                    relax_fire(t, e, a, cc->value + w[a]);
                }
        }
    }
}

static double goal_value(const Search *s, const Eval *e, int use_max)
{
    if (!s->n_goal)
        return 0.0;
    if (use_max) {
        double best = e->dist[s->goal_facts[0]];
        for (Py_ssize_t i = 1; i < s->n_goal; i++) {
            double v = e->dist[s->goal_facts[i]];
            if (v > best)
                best = v;
        }
        return best;
    }
    PySum sum = {0.0, 0.0};
    for (Py_ssize_t i = 0; i < s->n_goal; i++)
        pysum_add(&sum, e->dist[s->goal_facts[i]]);
    return pysum_value(&sum);
}

static void cost_and_risk(const Search *s, Eval *e, const word *state, int use_max, int ext,
                          double *hc, double *hl)
{
    relaxed_costs(s, e, state, s->t->cost, use_max, ext);
    *hc = goal_value(s, e, use_max);
    if (*hc == INFINITY) {
        *hl = INFINITY;
        return;
    }
    relaxed_costs(s, e, state, s->t->neglog, use_max, ext);
    *hl = goal_value(s, e, use_max);
}

static int applicable(const TaskObject *t, Py_ssize_t W, int32_t a, const word *state)
{
    int32_t j = t->pw_off[a], mid = j + t->pw_n_pre[a], end = t->pw_off[a + 1];
    for (; j < mid; j++)
        if ((state[t->pw_idx[j]] & t->pw_mask[j]) != t->pw_mask[j])
            return 0;
    for (; j < end; j++)
        if (state[t->pw_idx[j]] & t->pw_mask[j])
            return 0;
    for (int32_t k = t->cl_off[a]; k < t->cl_off[a + 1]; k++) {
        const word *cp = t->cl_pos + (Py_ssize_t)k * W, *cn = t->cl_neg + (Py_ssize_t)k * W;
        int ok = 0;
        for (Py_ssize_t i = 0; i < W && !ok; i++)
            if ((state[i] & cp[i]) || (cn[i] & ~state[i]))
                ok = 1;
        if (!ok)
            return 0;
    }
    return 1;
}

/* append to a growable int32 list (helpful actions); -1 and *oom set when out of memory */
static int list_push(int32_t **v, int64_t *n, int64_t *cap, int32_t x, int *oom)
{
    if (*n == *cap) {
        int64_t c = *cap ? *cap * 2 : 4096;
        int32_t *w = realloc(*v, (size_t)c * sizeof(int32_t));
        if (!w) {
            *oom = 1;
            return -1;
        }
        *v = w;
        *cap = c;
    }
    (*v)[(*n)++] = x;
    return 0;
}

static uint32_t next_stamp(const TaskObject *t, Eval *e)
{
    if (++e->stamp == 0) { /* wrapped: clear every stamp array */
        memset(e->seen_stamp, 0, sizeof(uint32_t) * (size_t)t->n_rfacts);
        memset(e->chosen_stamp, 0, sizeof(uint32_t) * (size_t)t->n_rel);
        memset(e->emit_stamp, 0, sizeof(uint32_t) * ((size_t)t->n_pairs + 1));
        e->stamp = 1;
    }
    return e->stamp;
}

/* _FF.__call__: h_add on the combined weights, relaxed plan by supporters, helpful actions
 * (appended to e->help) */
static void ff(const Search *s, Eval *e, const word *state, double *hc, double *hl)
{
    const TaskObject *t = s->t;
    relaxed_costs(s, e, state, s->combined, 0, 1);
    for (Py_ssize_t i = 0; i < s->n_goal; i++)
        if (e->dist[s->goal_facts[i]] == INFINITY) {
            *hc = *hl = INFINITY;
            return;
        }
    uint32_t st = next_stamp(t, e);
    Py_ssize_t top = 0, n_chosen = 0;
    for (Py_ssize_t i = 0; i < s->n_goal; i++) {
        int32_t g = s->goal_facts[i];
        if (!BIT(state, g)) {
            e->stack[top++] = g;
            e->seen_stamp[g] = st;
        }
    }
    while (top) {
        int32_t a = e->support[e->stack[--top]];
        if (a < 0 || e->chosen_stamp[a] == st)
            continue;
        e->chosen_stamp[a] = st;
        e->chosen[n_chosen++] = a;
        /* the variant's pre[a]: base pre_facts, then active clause facts not yet there */
        for (int32_t j = t->pre_off[a]; j < t->pre_off[a + 1]; j++) {
            int32_t f = t->pre_facts[j];
            if (e->seen_stamp[f] != st && !(f < t->n_facts && BIT(state, f))) {
                e->seen_stamp[f] = st;
                e->stack[top++] = f;
            }
        }
        if (a >= t->n_actions)
            continue; /* merged and auxiliary actions have no clauses */
        for (int32_t k = t->unit_off[a]; k < t->unit_off[a + 1]; k++) {
            int32_t q = t->unit_pair[k];
            if (!e->active[k] || q < 0 || e->emit_stamp[q] == st)
                continue;
            e->emit_stamp[q] = st;
            int32_t f = t->unit_fact[k];
            if (e->seen_stamp[f] != st && !BIT(state, f)) {
                e->seen_stamp[f] = st;
                e->stack[top++] = f;
            }
        }
    }
    PySum sc = {0.0, 0.0}, sl = {0.0, 0.0};
    for (Py_ssize_t i = 0; i < n_chosen; i++)
        if (t->kind[e->chosen[i]] != K_AUX)
            pysum_add(&sc, t->cost[e->chosen[i]] + 1.0);
    for (Py_ssize_t i = 0; i < n_chosen; i++)
        if (t->kind[e->chosen[i]] != K_AUX)
            pysum_add(&sl, t->neglog[e->chosen[i]]);
    *hc = pysum_value(&sc);
    *hl = pysum_value(&sl);
    for (Py_ssize_t i = 0; i < n_chosen; i++) {
        int32_t a = e->chosen[i];
        if (t->kind[a] == K_AUX)
            continue;
        if (t->kind[a] == K_MERGED) { /* the member whose alternative reached X */
            int32_t aux = e->support[t->link[a]];
            int32_t m = a - (int32_t)t->n_actions;
            a = t->members[t->member_off[m] + t->link[aux]];
        }
        if (applicable(t, s->W, a, state) &&
            list_push(&e->help, &e->n_help, &e->cap_help, a, &e->oom))
            return;
    }
}

/* The heuristic on one state, with e's scratch only: what worker threads run. Helpful
 * actions are appended to e->help. */
static void evaluate_state(const Search *s, Eval *e, const word *state, double *hc,
                           double *hl)
{
    *hc = *hl = 0.0;
    switch (s->heuristic) {
    case H_MAX:
        cost_and_risk(s, e, state, 1, 0, hc, hl);
        break;
    case H_ADD:
        clause_variant(s, e, state);
        cost_and_risk(s, e, state, 0, 1, hc, hl);
        break;
    case H_FF:
        clause_variant(s, e, state);
        ff(s, e, state, hc, hl);
        break;
    default:
        break;
    }
}

/* A state's estimate into its record; its helpful actions (n from `help`) to the pool. */
static int commit_estimate(Search *s, int32_t sid, double hc, double hl, const int32_t *help,
                           int64_t n)
{
    StateRec *rec = &s->recs[sid];
    rec->hc = hc;
    rec->hl = hl;
    rec->h_known = 1;
    rec->help_off = s->n_help;
    rec->help_n = (int32_t)n;
    for (int64_t i = 0; i < n; i++)
        if (list_push(&s->help, &s->n_help, &s->cap_help, help[i], &s->oom))
            return -1;
    return 0;
}

static void estimate(Search *s, int32_t sid)
{
    if (s->recs[sid].h_known)
        return;
    Eval *e = &s->ev[0];
    e->n_help = 0;
    double hc, hl;
    evaluate_state(s, e, s->sdata + (Py_ssize_t)sid * s->W, &hc, &hl);
    if (e->oom) {
        s->oom = 1;
        return;
    }
    commit_estimate(s, sid, hc, hl, e->help, e->n_help);
}

/* _Search.f: c + w*hc + R(1 - p exp(-hl)) */
static double f_value(Search *s, int32_t sid, double c, double p)
{
    estimate(s, sid);
    StateRec *rec = &s->recs[sid];
    if (rec->hc == INFINITY)
        return INFINITY;
    double w = s->weight;
    return c + w * rec->hc + s->reward * (1.0 - p * exp(-rec->hl));
}

static inline double objective(double c, double p, double reward)
{
    return c + reward * (1.0 - p);
}

/* ------------------------------------------------------------------------------------------ */
/* State table                                                                                  */

static inline uint64_t hash_state(const word *x, Py_ssize_t W)
{
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (Py_ssize_t i = 0; i < W; i++) {
        h ^= x[i] + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xFF51AFD7ED558CCDull;
        h ^= h >> 32;
    }
    return h;
}

static int grow_slots(Search *s)
{
    size_t n = s->n_slots ? s->n_slots * 2 : 1024;
    int32_t *slots = malloc(n * sizeof(int32_t));
    if (!slots) {
        s->oom = 1;
        return -1;
    }
    memset(slots, 0xff, n * sizeof(int32_t));
    for (int32_t id = 0; id < s->n_states; id++) {
        size_t i = (size_t)s->recs[id].hash & (n - 1);
        while (slots[i] >= 0)
            i = (i + 1) & (n - 1);
        slots[i] = id;
    }
    free(s->slots);
    s->slots = slots;
    s->n_slots = n;
    return 0;
}

/* id of `state`, or -1 if absent; *slot_out: where to insert it */
static int32_t find_state(Search *s, const word *state, uint64_t h, size_t *slot_out)
{
    size_t mask = s->n_slots - 1, i = (size_t)h & mask;
    Py_ssize_t W = s->W;
    while (s->slots[i] >= 0) {
        int32_t id = s->slots[i];
        if (s->recs[id].hash == h && !memcmp(s->sdata + (Py_ssize_t)id * W, state, 8 * (size_t)W))
            return id;
        i = (i + 1) & mask;
    }
    *slot_out = i;
    return -1;
}

static int32_t insert_state(Search *s, const word *state, uint64_t h, size_t slot)
{
    if (s->n_states == s->cap_states) {
        if (s->cap_states > INT32_MAX / 2) {
            s->oom = 1;
            return -1;
        }
        int32_t cap = s->cap_states ? s->cap_states * 2 : 1024;
        word *sd = realloc(s->sdata, (size_t)cap * (size_t)s->W * 8);
        if (!sd) {
            s->oom = 1;
            return -1;
        }
        s->sdata = sd;
        StateRec *r = realloc(s->recs, (size_t)cap * sizeof(StateRec));
        if (!r) {
            s->oom = 1;
            return -1;
        }
        s->recs = r;
        s->cap_states = cap;
    }
    int32_t id = s->n_states++;
    memcpy(s->sdata + (Py_ssize_t)id * s->W, state, 8 * (size_t)s->W);
    StateRec *rec = &s->recs[id];
    memset(rec, 0, sizeof(*rec));
    rec->hash = h;
    s->slots[slot] = id;
    if ((size_t)s->n_states * 2 > s->n_slots && grow_slots(s))
        return -1;
    return id;
}

/* _Labels.add: keep (c, p, node) unless dominated; drop (and kill) labels it dominates */
static int labels_add(Search *s, StateRec *rec, double c, double p, int32_t node)
{
    for (int32_t i = 0; i < rec->n_labels; i++)
        if (rec->labels[i].c <= c && rec->labels[i].p >= p)
            return 0;
    int32_t kept = 0;
    for (int32_t i = 0; i < rec->n_labels; i++) {
        Label l = rec->labels[i];
        if (c <= l.c && p >= l.p)
            s->n_alive[l.node] = 0;
        else
            rec->labels[kept++] = l;
    }
    rec->n_labels = kept;
    if (rec->n_labels == rec->cap_labels) {
        int32_t cap = rec->cap_labels ? rec->cap_labels * 2 : 1;
        Label *v = realloc(rec->labels, (size_t)cap * sizeof(Label));
        if (!v) {
            s->oom = 1;
            return -1;
        }
        rec->labels = v;
        rec->cap_labels = cap;
    }
    rec->labels[rec->n_labels++] = (Label){c, p, node};
    return 1;
}

/* realloc s->field to `count` elements of `size` bytes; on failure set s->oom, return -1 */
#define GROW_FIELD(s, field, count, size)                                                       \
    do {                                                                                        \
        void *grown_ = realloc((s)->field, (size_t)(count) * (size));                           \
        if (!grown_) {                                                                          \
            (s)->oom = 1;                                                                       \
            return -1;                                                                          \
        }                                                                                       \
        (s)->field = grown_;                                                                    \
    } while (0)

static int grow_nodes(Search *s)
{
    if (s->cap_nodes > INT32_MAX / 2) {
        s->oom = 1;
        return -1;
    }
    int32_t cap = s->cap_nodes ? s->cap_nodes * 2 : 4096;
    GROW_FIELD(s, n_state, cap, sizeof(int32_t));
    GROW_FIELD(s, n_parent, cap, sizeof(int32_t));
    GROW_FIELD(s, n_via, cap, sizeof(int32_t));
    GROW_FIELD(s, n_c, cap, sizeof(double));
    GROW_FIELD(s, n_p, cap, sizeof(double));
    GROW_FIELD(s, n_h, cap, sizeof(double));
    GROW_FIELD(s, n_alive, cap, sizeof(int8_t));
    GROW_FIELD(s, n_eval, cap, sizeof(int8_t));
    s->cap_nodes = cap;
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* The search (_Search)                                                                         */

/* progress: trust the helpful actions for a while (LAMA's boost of 1000) */
static inline void boost(Search *s)
{
    s->priority[Q_PREF] -= 1000;
    if (s->goal_count)
        s->priority[Q_GC_PREF] -= 1000;
}

static int queue_node(Search *s, double f, double h, int32_t node, int preferred)
{
    if (qpush(s, &s->heap, f, h, node))
        return -1;
    if (preferred && qpush(s, &s->pref, f, h, node))
        return -1;
    if (h < s->best_h && s->n_eval[node]) {
        s->best_h = h;
        s->progress_at = s->n_expanded;
        boost(s);
    }
    return 0;
}

/* _Search.queue_goal_count: the goal-count queues, by goal facts left (ties: h, then age) */
static int queue_goal_count(Search *s, const word *state, double h, int32_t node,
                            int preferred)
{
    int64_t left = 0;
    for (Py_ssize_t i = 0; i < s->W; i++)
        left += __builtin_popcountll(s->goal[i] & ~state[i]) +
                __builtin_popcountll(state[i] & s->goal_neg[i]);
    double count = (double)left;
    if (qpush(s, &s->gc_heap, count, h, node))
        return -1;
    if (preferred && qpush(s, &s->gc_pref, count, h, node))
        return -1;
    if (count < s->best_gc) {
        s->best_gc = count;
        boost(s);
    }
    return 0;
}

/* a successor with this probability is not pushed (p = 0, or below --min-success) */
static inline int below_threshold(const Search *s, double p)
{
    return p <= 0.0 || p < s->min_success;
}

static int push_node(Search *s, const word *state, double c, double p, int32_t parent,
                     int32_t action, int preferred)
{
    if (below_threshold(s, p)) {
        s->pruned_threshold |= p > 0.0;
        return 0;
    }
    int32_t node = s->n_nodes;
    uint64_t h = hash_state(state, s->W);
    size_t slot = 0;
    int32_t sid = find_state(s, state, h, &slot);
    if (sid < 0) {
        sid = insert_state(s, state, h, slot);
        if (sid < 0)
            return -1;
    }
    int added = labels_add(s, &s->recs[sid], c, p, node);
    if (added <= 0)
        return added;
    double g = objective(c, p, s->reward);
    double hv;
    int deferred = parent >= 0 && (s->lazy == LAZY_ALL || (s->defer_now && !preferred));
    if (deferred)
        hv = s->n_h[parent];
    else
        hv = f_value(s, sid, c, p) - g;
    if (s->oom)
        return -1;
    if (s->n_nodes == s->cap_nodes && grow_nodes(s))
        return -1;
    s->n_nodes++;
    s->n_state[node] = sid;
    s->n_c[node] = c;
    s->n_p[node] = p;
    s->n_parent[node] = parent;
    s->n_via[node] = action;
    s->n_alive[node] = hv != INFINITY;
    s->n_h[node] = hv;
    s->n_eval[node] = !deferred;
    if (deferred && s->lazy == LAZY_UNHELPFUL &&
        list_push(&s->waiting, &s->n_waiting, &s->cap_waiting, node, &s->oom))
        return -1;
    if (hv == INFINITY)
        return 0;
    if (queue_node(s, g + hv, hv, node, preferred))
        return -1;
    return s->goal_count ? queue_goal_count(s, state, hv, node, preferred) : 0;
}

static int32_t pop_node(Search *s)
{
    /* the non-empty queue that has had the fewest turns (ties: POP_ORDER) */
    int pick = -1;
    for (int i = 0; i < 4; i++) {
        int q = POP_ORDER[i];
        if (queue_of(s, q)->n && (pick < 0 || s->priority[q] < s->priority[pick]))
            pick = q;
    }
    s->from_queue = pick;
    s->priority[pick] += 1;
    QEntry e = qpop(queue_of(s, pick));
    s->popped_h = e.h;
    return e.node;
}

/* Evaluate `node` now (n_eval set to `mark`): its f and h (h stored in n_h). 1 if alive,
 * 0 if the heuristic proved it dead (dropped), -1 on an allocation error. */
static int evaluate_now(Search *s, int32_t node, int8_t mark, double *f, double *h)
{
    s->n_eval[node] = mark;
    double c = s->n_c[node], p = s->n_p[node];
    *f = f_value(s, s->n_state[node], c, p);
    if (s->oom)
        return -1;
    if (*f == INFINITY) {
        s->n_alive[node] = 0;
        return 0;
    }
    *h = *f - objective(c, p, s->reward);
    s->n_h[node] = *h;
    return 1;
}

/* LAZY_UNHELPFUL after STALL expansions without a lower h: every node still waiting for its
 * estimate gets it now and is queued again by it (n_eval 2: the entry it was queued with,
 * its parent's h, is stale), as if it had been evaluated when generated. */
static int flush_deferred(Search *s)
{
    for (int64_t i = 0; i < s->n_waiting; i++) {
        int32_t node = s->waiting[i];
        if (!s->n_alive[node] || s->n_eval[node])
            continue;
        double f, h;
        int ok = evaluate_now(s, node, 2, &f, &h);
        if (ok < 0)
            return -1;
        if (!ok)
            continue;
        if (queue_node(s, f, h, node, 0))
            return -1;
    }
    s->n_waiting = 0;
    return 0;
}

/* _Search.evaluate: 1 if the node may be expanded now, 0 if dropped or re-queued, -1 error */
static int evaluate_node(Search *s, int32_t node)
{
    if (s->n_eval[node])
        return 1;
    double f, h;
    int ok = evaluate_now(s, node, 1, &f, &h);
    if (ok <= 0)
        return ok;
    if (s->from_queue == Q_MAIN || s->from_queue == Q_PREF) {
        /* goal-count keys do not change with h: a node from those queues is expanded now */
        Queue *q = queue_of(s, s->from_queue);
        if (q->n && f > q->v[0].f) {
            if (queue_node(s, f, h, node, s->from_queue == Q_PREF))
                return -1;
            return 0;
        }
    }
    if (h < s->best_h) {
        s->best_h = h;
        s->progress_at = s->n_expanded;
        boost(s);
    }
    return 1;
}

static inline int is_goal_state(const Search *s, const word *state)
{
    for (Py_ssize_t i = 0; i < s->W; i++)
        if ((state[i] & s->goal[i]) != s->goal[i] || (state[i] & s->goal_neg[i]))
            return 0;
    return 1;
}

/* Some word of action a's reads meets a word b's effects change (both lists ascending). */
static inline int reads_changed(const TaskObject *t, int32_t a, int32_t b)
{
    int32_t i = t->rw_off[a], ie = t->rw_off[a + 1], j = t->ew_off[b], je = t->ew_off[b + 1];
    while (i < ie && j < je) {
        if (t->rw_idx[i] < t->ew_idx[j])
            i++;
        else if (t->rw_idx[i] > t->ew_idx[j])
            j++;
        else if (t->rw_mask[i++] & (t->ew_add[j] | t->ew_del[j]))
            return 1;
        else
            j++;
    }
    return 0;
}

static inline int commutes(const TaskObject *t, Py_ssize_t W, int32_t a, int32_t b)
{
    (void)W;
    if (reads_changed(t, a, b) || reads_changed(t, b, a))
        return 0;
    /* one adds what the other deletes */
    int32_t i = t->ew_off[a], ie = t->ew_off[a + 1], j = t->ew_off[b], je = t->ew_off[b + 1];
    while (i < ie && j < je) {
        if (t->ew_idx[i] < t->ew_idx[j])
            i++;
        else if (t->ew_idx[i] > t->ew_idx[j])
            j++;
        else if ((t->ew_add[i] & t->ew_del[j]) || (t->ew_del[i++] & t->ew_add[j++]))
            return 0;
    }
    return 1;
}

/* Symmetries.prunes */
static int sym_prunes(const Search *s, int32_t a, const word *state)
{
    for (int64_t k = s->sym_act_off[a]; k < s->sym_act_off[a + 1]; k++) {
        int64_t pair = s->sym_pair_ids[k];
        int all = 1;
        for (int64_t j = s->sym_pair_off[pair]; j < s->sym_pair_off[pair + 1]; j++) {
            int64_t f = s->sym_fg[2 * j], g = s->sym_fg[2 * j + 1];
            unsigned bf = (unsigned)BIT(state, f);
            unsigned bg = g >= 0 ? (unsigned)BIT(state, g) : 0u;
            if (bf != bg) {
                all = 0;
                break;
            }
        }
        if (all)
            return 1;
    }
    return 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A limit was hit: the best plan found so far (the incumbent) if any, else the limit's status. */
static int stop_at(Search *s, int32_t best, int32_t *goal_node, int why, int status)
{
    if (best < 0)
        return status;
    *goal_node = best;
    s->stopped = why;
    return ST_SOLVED;
}

/* returns status; *goal_node set when solved; -1 on allocation failure */
static int grow_kids(Search *s, int32_t n, int32_t *cap);
static int evaluate_batch(Search *s);

static int run_search(Search *s, const word *init, int32_t *goal_node, int64_t *expanded_out)
{
    const TaskObject *t = s->t;
    Py_ssize_t W = s->W, A = t->n_actions;
    double t0 = now_s();
    int64_t expanded = 0, best_at = 0;
    double best_obj = INFINITY;
    int32_t best = -1; /* incumbent: the best goal node popped so far, expanded at best_at */
    int32_t kid_cap = 0;
    *expanded_out = 0;
    if (push_node(s, init, 0.0, 1.0, -1, -1, 0) < 0)
        return -1;
    while (s->heap.n || s->pref.n || s->gc_heap.n || s->gc_pref.n) {
        int32_t node = pop_node(s);
        if (!s->n_alive[node])
            continue;
        if (s->n_eval[node] == 2 && s->popped_h != s->n_h[node])
            continue; /* queued by its parent's h before flush_deferred queued it by its own */
        int ev = evaluate_node(s, node);
        if (ev < 0)
            return -1;
        if (!ev)
            continue;
        s->n_alive[node] = 0;
        int32_t sid = s->n_state[node];
        double c = s->n_c[node], p = s->n_p[node];
        /* copy: the state table may move while successors are inserted */
        memcpy(s->parent, s->sdata + (Py_ssize_t)sid * W, 8 * (size_t)W);
        const word *state = s->parent;
        if (is_goal_state(s, state)) {
            double obj = objective(c, p, s->reward);
            if (obj < best_obj) {
                best_obj = obj;
                best = node;
                best_at = expanded;
            }
            if (s->from_queue != Q_MAIN && s->heap.n && s->heap.v[0].f < obj) {
                s->n_alive[node] = 1;
                if (qpush(s, &s->heap, obj, 0.0, node))
                    return -1;
                continue;
            }
            *goal_node = node;
            *expanded_out = expanded;
            return ST_SOLVED;
        }
        expanded += 1;
        *expanded_out = expanded;
        s->n_expanded = expanded;
        s->defer_now = s->lazy == LAZY_UNHELPFUL && expanded - s->progress_at <= STALL;
        if (s->lazy == LAZY_UNHELPFUL && !s->defer_now && s->n_waiting && flush_deferred(s))
            return -1;
        if (best >= 0 && s->patience >= 0 && expanded - best_at > s->patience)
            return stop_at(s, best, goal_node, STOP_PATIENCE, ST_SOLVED);
        if (s->node_limit >= 0 && expanded > s->node_limit)
            return stop_at(s, best, goal_node, STOP_NODE_LIMIT, ST_NODE_LIMIT);
        if (s->timeout >= 0 && now_s() - t0 > s->timeout)
            return stop_at(s, best, goal_node, STOP_TIMEOUT, ST_TIMEOUT);
        if (s->thread && (expanded & 1023) == 0) { /* let Ctrl-C through now and then */
            PyEval_RestoreThread(s->thread);
            int interrupted = PyErr_CheckSignals();
            s->thread = PyEval_SaveThread();
            if (interrupted)
                return ST_INTERRUPTED;
        }
        int32_t last = s->n_via[node];
        uint32_t mark = 0;
        if (s->preferred) {
            StateRec *rec = &s->recs[sid];
            if (++s->help_mark == 0) {
                memset(s->help_stamp, 0, sizeof(uint32_t) * (size_t)A);
                s->help_mark = 1;
            }
            mark = s->help_mark;
            for (int32_t i = 0; i < rec->help_n; i++)
                s->help_stamp[s->help[rec->help_off + i]] = mark;
        }
        /* the successors first, with the states they reach for the first time (push_node
         * would evaluate those one by one: here they are evaluated as a batch), then
         * push_node on each in order, as a search evaluating one at a time would */
        int32_t n_kids = 0, n_todo = 0;
        int batching = s->lazy != LAZY_ALL && s->heuristic != H_BLIND;
        for (Py_ssize_t a = 0; a < A; a++) {
            int32_t j = t->pw_off[a], mid = j + t->pw_n_pre[a], end = t->pw_off[a + 1];
            for (; j < mid; j++)
                if ((state[t->pw_idx[j]] & t->pw_mask[j]) != t->pw_mask[j])
                    break;
            if (j < mid)
                continue;
            for (; j < end; j++)
                if (state[t->pw_idx[j]] & t->pw_mask[j])
                    break;
            if (j < end)
                continue;
            if (t->cl_off[a] != t->cl_off[a + 1] && !applicable(t, W, (int32_t)a, state))
                continue;
            if (s->commute && last > a && commutes(t, W, (int32_t)a, last))
                continue; /* the order (a, last) is explored instead */
            if (s->has_sym && sym_prunes(s, (int32_t)a, state))
                continue; /* a mirror image with a lower object is explored */
            if (grow_kids(s, n_kids, &kid_cap))
                return -1;
            word *succ = s->kids + (Py_ssize_t)n_kids * W;
            memcpy(succ, state, 8 * (size_t)W);
            for (int32_t e = t->ew_off[a]; e < t->ew_off[a + 1]; e++) {
                int32_t i = t->ew_idx[e];
                succ[i] = (succ[i] & ~t->ew_del[e]) | t->ew_add[e];
            }
            if (t->ax.n_rules)
                axioms_close(&t->ax, W, &s->ax, succ);
            double kc = c + t->cost[a], kp = p * t->prob[a];
            s->kid_act[n_kids] = (int32_t)a;
            s->kid_c[n_kids] = kc;
            s->kid_p[n_kids] = kp;
            s->kid_pref[n_kids] = (int8_t)(s->preferred && s->help_stamp[a] == mark);
            n_kids++;
            if (s->defer_now && !s->kid_pref[n_kids - 1])
                continue; /* deferred: evaluated when popped */
            if (batching && !below_threshold(s, kp)) { /* else push_node drops it */
                uint64_t h = hash_state(succ, W);
                size_t slot = 0;
                if (find_state(s, succ, h, &slot) < 0) {
                    int32_t sid = insert_state(s, succ, h, slot);
                    if (sid < 0)
                        return -1;
                    s->todo[n_todo++] = sid;
                }
            }
        }
        if (n_todo) {
            s->batch = (Batch){s->todo, n_todo, s->todo_hc, s->todo_hl, s->todo_at, s->todo_n,
                               s->todo_owner};
            if (evaluate_batch(s))
                return -1;
        }
        for (int32_t k = 0; k < n_kids; k++)
            if (push_node(s, s->kids + (Py_ssize_t)k * W, s->kid_c[k], s->kid_p[k], node,
                          s->kid_act[k], s->kid_pref[k]) < 0)
                return -1;
    }
    *expanded_out = expanded;
    return s->pruned_threshold ? ST_THRESHOLD : ST_UNSOLVABLE;
}

static void eval_free(Eval *e)
{
    void *ptrs[] = {e->dist, e->counter, e->set_in, e->support, e->rem_ext, e->stack,
                    e->chosen, e->seen_stamp, e->chosen_stamp, e->emit_stamp, e->active,
                    e->pair_eff, e->dheap, e->hpos, e->help};
    for (size_t i = 0; i < sizeof(ptrs) / sizeof(ptrs[0]); i++)
        free(ptrs[i]);
    memset(e, 0, sizeof(*e));
}

static int eval_alloc(const TaskObject *t, Eval *e)
{
    /* relaxed sizes: auxiliary facts and extra actions of the merge included */
    size_t F = (size_t)t->n_rfacts, A = (size_t)t->n_rel;
    e->dist = xcalloc(F, sizeof(double));
    e->counter = xcalloc((size_t)t->n_cls, sizeof(Counter));
    e->set_in = xcalloc(F, sizeof(uint32_t));
    e->support = xcalloc(F, sizeof(int32_t));
    e->rem_ext = xcalloc((size_t)t->n_cls, sizeof(int32_t));
    e->stack = xcalloc(F, sizeof(int32_t));
    e->chosen = xcalloc(A, sizeof(int32_t));
    e->seen_stamp = xcalloc(F, sizeof(uint32_t));
    e->chosen_stamp = xcalloc(A, sizeof(uint32_t));
    e->emit_stamp = xcalloc((size_t)t->n_pairs + 1, sizeof(uint32_t));
    e->active = xcalloc((size_t)t->n_unit, 1);
    e->pair_eff = xcalloc((size_t)t->n_pairs, 1);
    e->dheap = xcalloc(F + 1, sizeof(DEntry));
    e->hpos = xcalloc(F, sizeof(int32_t));
    if (e->hpos)
        memset(e->hpos, 0xff, F * sizeof(int32_t));
    if (!e->dist || !e->counter || !e->set_in || !e->support || !e->rem_ext || !e->stack ||
        !e->chosen || !e->seen_stamp || !e->chosen_stamp || !e->emit_stamp || !e->active ||
        !e->pair_eff || !e->dheap || !e->hpos)
        return -1;
    return 0;
}

static void worker_stop(Search *s);

static void search_free(Search *s)
{
    worker_stop(s);
    for (int32_t i = 0; i < s->n_states; i++)
        free(s->recs[i].labels);
    void *ptrs[] = {s->goal, s->goal_neg, s->goal_facts, s->is_goal, s->sdata, s->recs,
                    s->slots, s->n_state, s->n_parent, s->n_via, s->n_c, s->n_p, s->n_h,
                    s->n_alive, s->n_eval, s->heap.v, s->pref.v, s->gc_heap.v,
                    s->gc_pref.v, s->help, s->combined,
                    s->help_stamp, s->parent, s->kids, s->kid_act, s->todo, s->kid_c,
                    s->kid_p, s->todo_hc, s->todo_hl, s->todo_at, s->todo_n, s->kid_pref,
                    s->todo_owner, s->waiting};
    for (size_t i = 0; i < sizeof(ptrs) / sizeof(ptrs[0]); i++)
        free(ptrs[i]);
    for (int i = 0; i < MAX_EVAL; i++)
        eval_free(&s->ev[i]);
    axiom_scratch_free(&s->ax);
}

static int search_alloc(Search *s)
{
    const TaskObject *t = s->t;
    size_t F = (size_t)t->n_rfacts, A = (size_t)t->n_rel, W = (size_t)s->W;
    s->goal = xcalloc(W, 8);
    s->goal_neg = xcalloc(W, 8);
    s->goal_facts = xcalloc(F, sizeof(int32_t));
    s->is_goal = xcalloc(F, 1);
    s->combined = xcalloc(A, sizeof(double));
    s->help_stamp = xcalloc(A, sizeof(uint32_t));
    s->parent = xcalloc(W, 8);
    if (!s->goal || !s->goal_neg || !s->goal_facts || !s->is_goal || !s->combined ||
        !s->help_stamp || !s->parent || eval_alloc(t, &s->ev[0]))
        return -1;
    if (t->ax.n_rules && axiom_scratch_alloc(&t->ax, &s->ax))
        return -1;
    return grow_slots(s);
}

/* Room for one more successor of the expansion in progress (capacity `cap` in kids) */
static int grow_kids(Search *s, int32_t n, int32_t *cap)
{
    if (n < *cap)
        return 0;
    int32_t c = *cap ? *cap * 2 : 64;
    GROW_FIELD(s, kids, c, 8 * (size_t)s->W);
    GROW_FIELD(s, kid_act, c, sizeof(int32_t));
    GROW_FIELD(s, todo, c, sizeof(int32_t));
    GROW_FIELD(s, kid_c, c, sizeof(double));
    GROW_FIELD(s, kid_p, c, sizeof(double));
    GROW_FIELD(s, todo_hc, c, sizeof(double));
    GROW_FIELD(s, todo_hl, c, sizeof(double));
    GROW_FIELD(s, todo_at, c, sizeof(int64_t));
    GROW_FIELD(s, todo_n, c, sizeof(int64_t));
    GROW_FIELD(s, kid_pref, c, 1);
    GROW_FIELD(s, todo_owner, c, 1);
    *cap = c;
    return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* Evaluating an expansion's new states on two threads                                         */

/* Evaluations are pure functions of the state (each thread has its own Eval scratch), and
 * their results are written to the states' records in the order the successors were
 * generated, so the search runs exactly as on one thread: same plan, same counts. */
static void eval_one(Search *s, int who, int32_t k)
{
    const Batch *b = &s->batch;
    Eval *e = &s->ev[who];
    b->owner[k] = (int8_t)who;
    b->help_at[k] = e->n_help;
    evaluate_state(s, e, s->sdata + (Py_ssize_t)b->sids[k] * s->W, &b->hc[k], &b->hl[k]);
    b->help_n[k] = e->n_help - b->help_at[k];
}

#if (defined(__unix__) || defined(__APPLE__)) && (defined(__GNUC__) || defined(__clang__))
#include <pthread.h>
#include <unistd.h>

/* Hand-over. The search publishes a batch as a ticket, (n << 32) | next index, and both
 * threads claim states from it with an atomic add until the index reaches n; `done` counts
 * the finished ones. A worker that wakes late finds fewer states left (or none), so the search
 * never waits on it, only on a state it is still evaluating. A claim from a finished batch's
 * ticket is past its n, so a late worker cannot take a state twice. The worker spins a little
 * before it sleeps on a condition variable: batches come every few tens of microseconds, and
 * a sleeping thread takes longer than that to wake. */
#define SPINS 2000 /* ~0.1 ms of pause instructions */

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

struct Worker {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t go, done_cv;
    Search *s;
    uint64_t posted; /* batches published (wakes the worker) */
    uint64_t ticket;
    int32_t done;
    int quit;
};

#define LOAD(x) __atomic_load_n(&(x), __ATOMIC_ACQUIRE)
#define STORE(x, v) __atomic_store_n(&(x), (v), __ATOMIC_RELEASE)

/* Claim and evaluate states of the current batch until none is left. */
static void claim_states(struct Worker *w, int who)
{
    for (;;) {
        uint64_t ticket = __atomic_fetch_add(&w->ticket, 1, __ATOMIC_ACQ_REL);
        int32_t n = (int32_t)(ticket >> 32), k = (int32_t)(ticket & 0xffffffffu);
        if (k >= n)
            return;
        eval_one(w->s, who, k);
        if (__atomic_add_fetch(&w->done, 1, __ATOMIC_ACQ_REL) == n && who == 1) {
            /* under the mutex: the search either saw done == n or already sleeps */
            pthread_mutex_lock(&w->mu);
            pthread_cond_signal(&w->done_cv);
            pthread_mutex_unlock(&w->mu);
        }
    }
}

static void *worker_main(void *arg)
{
    struct Worker *w = arg;
    uint64_t seen = 0;
    for (;;) {
        for (int i = 0; i < SPINS && LOAD(w->posted) == seen && !LOAD(w->quit); i++)
            cpu_relax();
        if (LOAD(w->posted) == seen && !LOAD(w->quit)) {
            pthread_mutex_lock(&w->mu);
            while (LOAD(w->posted) == seen && !LOAD(w->quit))
                pthread_cond_wait(&w->go, &w->mu);
            pthread_mutex_unlock(&w->mu);
        }
        if (LOAD(w->quit))
            break;
        seen = LOAD(w->posted);
        claim_states(w, 1);
    }
    return NULL;
}

static int online_cpus(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

/* A worker thread with its own Eval; on any failure the search stays on one thread. */
static void worker_start(Search *s)
{
    struct Worker *w = calloc(1, sizeof(*w));
    if (!w)
        return;
    if (eval_alloc(s->t, &s->ev[1])) {
        eval_free(&s->ev[1]);
        free(w);
        return;
    }
    w->s = s;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->go, NULL);
    pthread_cond_init(&w->done_cv, NULL);
    if (pthread_create(&w->thread, NULL, worker_main, w)) {
        pthread_mutex_destroy(&w->mu);
        pthread_cond_destroy(&w->go);
        pthread_cond_destroy(&w->done_cv);
        eval_free(&s->ev[1]);
        free(w);
        return;
    }
    s->worker = w;
}

static void worker_stop(Search *s)
{
    struct Worker *w = s->worker;
    if (!w)
        return;
    pthread_mutex_lock(&w->mu);
    STORE(w->quit, 1);
    pthread_cond_signal(&w->go);
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->thread, NULL);
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->go);
    pthread_cond_destroy(&w->done_cv);
    free(w);
    s->worker = NULL;
}

/* Both threads evaluate states of s->batch; returns when every state is done. No state of
 * the previous batch is in progress here (its done count reached n), so both Evals' help
 * lists can start over. */
static void run_batch(Search *s)
{
    struct Worker *w = s->worker;
    int32_t n = s->batch.n;
    s->ev[0].n_help = s->ev[1].n_help = 0;
    STORE(w->done, 0);
    STORE(w->ticket, (uint64_t)n << 32);
    pthread_mutex_lock(&w->mu);
    STORE(w->posted, LOAD(w->posted) + 1);
    pthread_cond_signal(&w->go);
    pthread_mutex_unlock(&w->mu);
    claim_states(w, 0);
    for (int i = 0; i < SPINS && LOAD(w->done) != n; i++)
        cpu_relax();
    if (LOAD(w->done) != n) {
        pthread_mutex_lock(&w->mu);
        while (LOAD(w->done) != n)
            pthread_cond_wait(&w->done_cv, &w->mu);
        pthread_mutex_unlock(&w->mu);
    }
}
#else /* no threads: every evaluation runs on the search's thread */
static int online_cpus(void) { return 1; }
static void worker_start(Search *s) { (void)s; }
static void worker_stop(Search *s) { (void)s; }
static void run_batch(Search *s) { (void)s; }
#endif

/* Relaxed tasks with fewer (class, precondition) entries than this evaluate in a few
 * microseconds, where starting a thread (~0.05-0.1 ms) and handing batches over gain little
 * or lose (0.10 -> 0.14 ms on table-known); threads = 0 (auto) leaves them on one thread, and
 * so do single-CPU machines. The 8- to 20-place AVS problems have 1,100-2,450 entries. */
#define AUTO_MIN_ENTRIES 1000

static int use_worker(const Search *s)
{
    if (s->heuristic == H_BLIND || s->lazy == LAZY_ALL)
        return 0; /* nothing evaluated in batches */
    if (s->threads == 1)
        return 0;
    if (s->threads == 2)
        return 1;
    return s->t->cof_off[s->t->n_rfacts] >= AUTO_MIN_ENTRIES && online_cpus() >= 2;
}

/* Evaluate the batch's states (on two threads when there is a worker and more than one
 * state), then record the estimates in batch order. */
static int evaluate_batch(Search *s)
{
    const Batch *b = &s->batch;
    if (s->worker && b->n > 1) {
        run_batch(s);
    } else {
        s->ev[0].n_help = 0;
        for (int32_t k = 0; k < b->n; k++)
            eval_one(s, 0, k);
    }
    for (int i = 0; i < MAX_EVAL; i++)
        if (s->ev[i].oom)
            s->oom = 1;
    if (s->oom)
        return -1;
    for (int32_t k = 0; k < b->n; k++) {
        const Eval *e = &s->ev[b->owner[k]];
        if (commit_estimate(s, b->sids[k], b->hc[k], b->hl[k], e->help + b->help_at[k],
                            b->help_n[k]))
            return -1;
    }
    return 0;
}

/* RelaxedTask.combined, same expression; auxiliary actions weigh nothing */
static void fill_combined(Search *s)
{
    const TaskObject *t = s->t;
    for (Py_ssize_t a = 0; a < t->n_rel; a++)
        s->combined[a] =
            t->kind[a] == K_AUX ? 0.0 : 1.0 + t->cost[a] + s->reward * (1.0 - t->prob[a]);
}

static int check_words(Py_buffer *b, Py_ssize_t W, Py_ssize_t n_facts, const char *what)
{
    if ((size_t)b->len != (size_t)W * 8) {
        PyErr_Format(PyExc_ValueError, "native search: %s has %zd bytes, expected %zd", what,
                     b->len, W * 8);
        return -1;
    }
    const word *x = b->buf;
    if (x[W - 1] & ~(((word)1 << (n_facts & 63)) - 1)) {
        PyErr_Format(PyExc_ValueError, "native search: %s has a fact >= %zd", what, n_facts);
        return -1;
    }
    return 0;
}

static int check_symmetry(Search *s, Py_buffer *b, Py_ssize_t A, Py_ssize_t F)
{
    /* b: act_off (A+1 or empty), pair_ids, pair_off, fg */
    if (b[0].len == 0) {
        s->has_sym = 0;
        return 0;
    }
    for (int i = 0; i < 4; i++)
        if (b[i].len % 8) {
            PyErr_SetString(PyExc_ValueError, "native search: symmetry arrays must be int64");
            return -1;
        }
    Py_ssize_t n_ids = b[1].len / 8, n_off = b[2].len / 8, n_fg = b[3].len / 16;
    const int64_t *act_off = b[0].buf, *ids = b[1].buf, *poff = b[2].buf, *fg = b[3].buf;
    if (b[0].len / 8 != A + 1 || act_off[0] != 0 || act_off[A] != n_ids || n_off < 1 ||
        poff[0] != 0 || poff[n_off - 1] != n_fg || b[3].len % 16) {
        PyErr_SetString(PyExc_ValueError, "native search: inconsistent symmetry arrays");
        return -1;
    }
    for (Py_ssize_t a = 0; a < A; a++)
        if (act_off[a + 1] < act_off[a])
            goto bad;
    for (Py_ssize_t i = 0; i < n_ids; i++)
        if (ids[i] < 0 || ids[i] >= n_off - 1)
            goto bad;
    for (Py_ssize_t i = 0; i + 1 < n_off; i++)
        if (poff[i + 1] < poff[i])
            goto bad;
    for (Py_ssize_t i = 0; i < n_fg; i++)
        if (fg[2 * i] < 0 || fg[2 * i] >= F || fg[2 * i + 1] < -1 || fg[2 * i + 1] >= F)
            goto bad;
    s->has_sym = 1;
    s->sym_act_off = act_off;
    s->sym_pair_ids = ids;
    s->sym_pair_off = poff;
    s->sym_fg = fg;
    return 0;
bad:
    PyErr_SetString(PyExc_ValueError, "native search: symmetry arrays out of range");
    return -1;
}

static PyObject *native_search(PyObject *self, PyObject *args)
{
    TaskObject *t;
    Py_buffer b[7];
    memset(b, 0, sizeof(b));
    Search s;
    memset(&s, 0, sizeof(s));
    long long node_limit, patience;
    int flags; /* QF_* */
    if (!PyArg_ParseTuple(args, "O!y*y*y*iddddLLiiy*y*y*y*i:search", &TaskType, &t, &b[0],
                          &b[1], &b[2], &s.heuristic, &s.reward, &s.weight, &s.min_success,
                          &s.timeout, &node_limit, &patience, &s.lazy, &flags, &b[3],
                          &b[4], &b[5], &b[6], &s.threads))
        return NULL;
    s.preferred = (flags & QF_PREFERRED) != 0;
    s.goal_count = (flags & QF_GOAL_COUNT) != 0;
    s.commute = (flags & QF_NO_COMMUTE) == 0;
    PyObject *result = NULL;
    s.t = t;
    s.W = t->W;
    s.node_limit = node_limit;
    s.patience = patience;
    s.best_h = s.best_gc = INFINITY;
    Py_ssize_t W = t->W, F = t->n_facts, A = t->n_actions;
    if (s.heuristic < H_BLIND || s.heuristic > H_FF) {
        PyErr_SetString(PyExc_ValueError, "native search: unknown heuristic code");
        goto done;
    }
    if (check_words(&b[0], W, F, "init") || check_words(&b[1], W, F, "goal") ||
        check_words(&b[2], W, F, "goal_neg") || check_symmetry(&s, &b[3], A, F))
        goto done;
    if (search_alloc(&s)) {
        PyErr_NoMemory();
        goto done;
    }
    s.preferred = s.preferred && s.heuristic == H_FF;
    if (s.lazy < LAZY_NONE || s.lazy > LAZY_UNHELPFUL) {
        PyErr_SetString(PyExc_ValueError, "native search: lazy must be 0, 1 or 2");
        goto done;
    }
    if (s.lazy == LAZY_UNHELPFUL && !s.preferred)
        s.lazy = LAZY_NONE; /* no helpful actions: every successor evaluated when generated */
    memcpy(s.goal, b[1].buf, 8 * (size_t)W);
    memcpy(s.goal_neg, b[2].buf, 8 * (size_t)W);
    for (Py_ssize_t f = 0; f < F; f++)
        if (BIT(s.goal, f)) {
            s.goal_facts[s.n_goal++] = (int32_t)f;
            s.is_goal[f] = 1;
        }
    fill_combined(&s);
    if (s.threads < 0 || s.threads > MAX_EVAL) {
        PyErr_Format(PyExc_ValueError, "native search: threads must be 0 (auto), 1 or %d",
                     MAX_EVAL);
        goto done;
    }
    if (use_worker(&s))
        worker_start(&s);
    int32_t goal_node = -1;
    int64_t expanded = 0;
    int status;
    s.thread = PyEval_SaveThread(); /* the GIL is released while searching */
    status = run_search(&s, b[0].buf, &goal_node, &expanded);
    PyEval_RestoreThread(s.thread);
    if (status == ST_INTERRUPTED)
        goto done; /* a signal handler raised (Ctrl-C: KeyboardInterrupt) */
    if (status < 0 || s.oom) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t length = 0;
    for (int32_t n = goal_node; n >= 0 && s.n_via[n] >= 0; n = s.n_parent[n])
        length++;
    PyObject *path = PyTuple_New(length);
    if (!path)
        goto done;
    Py_ssize_t i = length;
    for (int32_t n = goal_node; n >= 0 && s.n_via[n] >= 0; n = s.n_parent[n]) {
        PyObject *v = PyLong_FromLong(s.n_via[n]);
        if (!v) {
            Py_DECREF(path);
            goto done;
        }
        PyTuple_SET_ITEM(path, --i, v);
    }
    result = Py_BuildValue("(iNLii)", status, path, (long long)expanded, (int)s.n_nodes,
                           s.stopped);
done:
    search_free(&s);
    for (int i = 0; i < 7; i++)
        if (b[i].obj)
            PyBuffer_Release(&b[i]);
    return result;
}

/* estimates(task, goal, heuristic, reward, states) -> [(hc, hl, helpful actions)]: the
 * heuristic alone on each state (W words each), for tests against heuristics.py */
static PyObject *native_estimates(PyObject *self, PyObject *args)
{
    TaskObject *t;
    Py_buffer goal = {0}, states = {0};
    Search s;
    memset(&s, 0, sizeof(s));
    if (!PyArg_ParseTuple(args, "O!y*idy*:estimates", &TaskType, &t, &goal, &s.heuristic,
                          &s.reward, &states))
        return NULL;
    PyObject *out = NULL;
    s.t = t;
    s.W = t->W;
    Py_ssize_t W = t->W, F = t->n_facts;
    if (s.heuristic < H_BLIND || s.heuristic > H_FF) {
        PyErr_SetString(PyExc_ValueError, "native estimates: unknown heuristic code");
        goto done;
    }
    if (check_words(&goal, W, F, "goal"))
        goto done;
    if (states.len % (8 * W)) {
        PyErr_SetString(PyExc_ValueError, "native estimates: states are not whole bitsets");
        goto done;
    }
    if (search_alloc(&s)) {
        PyErr_NoMemory();
        goto done;
    }
    memcpy(s.goal, goal.buf, 8 * (size_t)W);
    for (Py_ssize_t f = 0; f < F; f++)
        if (BIT(s.goal, f)) {
            s.goal_facts[s.n_goal++] = (int32_t)f;
            s.is_goal[f] = 1;
        }
    fill_combined(&s);
    Py_ssize_t n = states.len / (8 * W);
    out = PyList_New(0);
    for (Py_ssize_t i = 0; out && i < n; i++) {
        const word *state = (const word *)states.buf + i * W;
        if (state[W - 1] & ~(((word)1 << (F & 63)) - 1)) {
            PyErr_SetString(PyExc_ValueError, "native estimates: a state has a fact too many");
            Py_CLEAR(out);
            break;
        }
        uint64_t h = hash_state(state, W);
        size_t slot = 0;
        int32_t sid = find_state(&s, state, h, &slot);
        if (sid < 0 && (sid = insert_state(&s, state, h, slot)) < 0)
            break;
        estimate(&s, sid);
        if (s.oom)
            break;
        StateRec *rec = &s.recs[sid];
        PyObject *helpful = PyTuple_New(rec->help_n);
        if (!helpful) {
            Py_CLEAR(out);
            break;
        }
        for (int32_t j = 0; j < rec->help_n; j++)
            PyTuple_SET_ITEM(helpful, j, PyLong_FromLong(s.help[rec->help_off + j]));
        PyObject *item = Py_BuildValue("(ddN)", rec->hc, rec->hl, helpful);
        if (!item || PyList_Append(out, item)) {
            Py_XDECREF(item);
            Py_CLEAR(out);
            break;
        }
        Py_DECREF(item);
    }
    if (s.oom) {
        Py_CLEAR(out);
        PyErr_NoMemory();
    }
done:
    search_free(&s);
    PyBuffer_Release(&goal);
    PyBuffer_Release(&states);
    return out;
}

/* close(task, states) -> bytes: each state (W words) closed under the task's rules, as the
 * search closes successors (for tests against ground_axioms.py) */
static PyObject *native_close(PyObject *self, PyObject *args)
{
    TaskObject *t;
    Py_buffer states = {0};
    if (!PyArg_ParseTuple(args, "O!y*:close", &TaskType, &t, &states))
        return NULL;
    PyObject *out = NULL;
    AxiomScratch x = {0};
    Py_ssize_t W = t->W;
    if (states.len % (8 * W)) {
        PyErr_SetString(PyExc_ValueError, "native close: states are not whole bitsets");
        goto done;
    }
    out = PyBytes_FromStringAndSize(states.buf, states.len);
    if (!out || !t->ax.n_rules)
        goto done;
    if (axiom_scratch_alloc(&t->ax, &x)) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    word *data = (word *)PyBytes_AS_STRING(out);
    for (Py_ssize_t i = 0; i < states.len / (8 * W); i++)
        axioms_close(&t->ax, W, &x, data + i * W);
done:
    axiom_scratch_free(&x);
    PyBuffer_Release(&states);
    return out;
}

static PyMethodDef native_methods[] = {
    {"search", native_search, METH_VARARGS,
     "search(task, init, goal, goal_neg, heuristic, reward, weight, min_success, timeout_s, "
     "node_limit, lazy, preferred, sym_act_off, sym_pair_ids, sym_pair_off, sym_fg) -> "
     "(status, path, expanded, generated). Use avs_planner.cp.native, not this directly."},
    {"estimates", native_estimates, METH_VARARGS,
     "estimates(task, goal, heuristic, reward, states) -> [(hc, hl, helpful)] (for tests)."},
    {"close", native_close, METH_VARARGS,
     "close(task, states) -> states closed under the task's rules (for tests)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef native_module = {
    PyModuleDef_HEAD_INIT, "_native",
    "Compiled search core of the continual planner (see avs_planner/cp/native.py).", -1,
    native_methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__native(void)
{
    if (PyType_Ready(&TaskType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&native_module);
    if (!m)
        return NULL;
    Py_INCREF(&TaskType);
    if (PyModule_AddObject(m, "Task", (PyObject *)&TaskType) < 0) {
        Py_DECREF(&TaskType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
