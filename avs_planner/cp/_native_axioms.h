/* Derived predicates' rules in the compiled search core: the closure of a state under them.
 *
 * The port of avs_planner/cp/ground_axioms.py's GroundAxioms.close, included by _native.c
 * (one translation unit; setup.py lists this header as a dependency). The rules arrive as
 * one int64 array (GroundAxioms.native_args): n_strata, n_rules, n_clauses, n_derived, the
 * strata's rule offsets, the heads, the derived facts (cleared before a state is closed),
 * then the CSRs of each rule's positive and negative facts, of each rule's clauses and of
 * each clause's positive and negative facts.
 *
 * A stratum's rules are monotone in its own facts (negative literals name basic facts or
 * facts of lower strata: checked here), so the closure is the least fixpoint found by
 * counting: each rule starts with the number of its unit literals and clauses that do not
 * hold yet (or is disabled by a negative literal that holds), and each fact the stratum
 * derives decrements the rules reading it positively (a clause once). The least fixpoint is
 * unique, so this gives the Python engine's states exactly.
 */
#ifndef AVS_NATIVE_AXIOMS_H
#define AVS_NATIVE_AXIOMS_H

typedef struct {
    int32_t n_strata, n_rules, n_clauses;
    int32_t *strata;                         /* rule offsets per stratum, n_strata + 1 */
    int32_t *head;                           /* per rule */
    int32_t *pos_off, *pos, *neg_off, *neg;  /* per rule, its unit literals */
    int32_t *cl_off;                         /* per rule, its clauses */
    int32_t *clp_off, *clp, *cln_off, *cln;  /* per clause, its literals */
    int32_t *occ_off, *occ_rule, *occ_clause; /* per fact: the rules of its own stratum
                                               * reading it positively (clause -1: a unit
                                               * literal) */
    uint64_t *mask; /* W words: the derived facts and heads (cleared, then derived) */
} Axioms;

typedef struct {
    int32_t *count, *queue;
    uint8_t *sat;
} AxiomScratch;

static void axioms_free(Axioms *ax)
{
    void *ptrs[] = {ax->strata, ax->head, ax->pos_off, ax->pos, ax->neg_off, ax->neg,
                    ax->cl_off, ax->clp_off, ax->clp, ax->cln_off, ax->cln, ax->occ_off,
                    ax->occ_rule, ax->occ_clause, ax->mask};
    for (size_t i = 0; i < sizeof(ptrs) / sizeof(ptrs[0]); i++)
        free(ptrs[i]);
    memset(ax, 0, sizeof(*ax));
}

static void axiom_scratch_free(AxiomScratch *x)
{
    free(x->count);
    free(x->queue);
    free(x->sat);
    memset(x, 0, sizeof(*x));
}

static int axiom_scratch_alloc(const Axioms *ax, AxiomScratch *x)
{
    x->count = calloc((size_t)ax->n_rules + 1, sizeof(int32_t));
    x->queue = calloc((size_t)ax->n_rules + 1, sizeof(int32_t));
    x->sat = calloc((size_t)ax->n_clauses + 1, 1);
    return x->count && x->queue && x->sat ? 0 : -1;
}

/* Read a CSR of `rows` rows at blob[*at]: offsets (rows + 1, from 0, not decreasing) then
 * values, each in [0, limit); -1 with a ValueError naming `what` if malformed. */
static int axioms_csr(const int64_t *blob, Py_ssize_t len, Py_ssize_t *at, Py_ssize_t rows,
                      Py_ssize_t limit, int32_t **off, int32_t **val, const char *what)
{
    if (rows < 0 || *at + rows + 1 > len || blob[*at] != 0)
        goto bad;
    *off = calloc((size_t)rows + 1, sizeof(int32_t));
    if (!*off) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i <= rows; i++) {
        int64_t o = blob[*at + i];
        if ((i && o < blob[*at + i - 1]) || o > INT32_MAX / 2)
            goto bad;
        (*off)[i] = (int32_t)o;
    }
    Py_ssize_t n = (*off)[rows];
    *at += rows + 1;
    if (*at + n > len)
        goto bad;
    *val = calloc((size_t)n + 1, sizeof(int32_t));
    if (!*val) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t v = blob[*at + i];
        if (v < 0 || v >= limit)
            goto bad;
        (*val)[i] = (int32_t)v;
    }
    *at += n;
    return 0;
bad:
    PyErr_Format(PyExc_ValueError, "native task: the rules' %s are malformed", what);
    return -1;
}

/* Fill `ax` from the packed rules (see the top of this file) over n_facts facts and W words;
 * -1 with an exception set if they are malformed or not stratified. */
/* One occurrence of fact f in rule r (clause q, -1 for its positive literals): the first pass
   counts it in occ_off[f + 1], the second stores it at f's next free slot. */
static inline void axioms_occurrence(Axioms *ax, int pass, int32_t f, int32_t r, int32_t q)
{
    if (!pass) {
        ax->occ_off[f + 1]++;
        return;
    }
    int32_t at = ax->occ_off[f]++;
    ax->occ_rule[at] = r;
    ax->occ_clause[at] = q;
}

static int axioms_parse(Axioms *ax, const int64_t *blob, Py_ssize_t len, Py_ssize_t n_facts,
                        Py_ssize_t W)
{
    int32_t *stratum_of = NULL; /* per fact: the stratum deriving it, -1: basic */
    if (len < 4 || blob[0] < 1 || blob[1] < 0 || blob[2] < 0 || blob[3] < 0 ||
        blob[0] > INT32_MAX / 4 || blob[1] > INT32_MAX / 4 || blob[2] > INT32_MAX / 4 ||
        blob[3] > n_facts)
        goto bad;
    ax->n_strata = (int32_t)blob[0];
    ax->n_rules = (int32_t)blob[1];
    ax->n_clauses = (int32_t)blob[2];
    Py_ssize_t n_derived = blob[3];
    Py_ssize_t at = 4, S = ax->n_strata, R = ax->n_rules, C = ax->n_clauses;
    if (at + S + 1 + R + n_derived > len)
        goto bad;
    ax->strata = calloc((size_t)S + 1, sizeof(int32_t));
    ax->head = calloc((size_t)R + 1, sizeof(int32_t));
    ax->mask = calloc((size_t)W, sizeof(uint64_t));
    stratum_of = malloc(sizeof(int32_t) * ((size_t)n_facts + 1));
    if (!ax->strata || !ax->head || !ax->mask || !stratum_of) {
        PyErr_NoMemory();
        goto fail;
    }
    for (Py_ssize_t k = 0; k <= S; k++) {
        int64_t o = blob[at + k];
        if ((k == 0 && o != 0) || (k && o <= blob[at + k - 1] && R) || (k == S && o != R) ||
            o < 0 || o > R)
            goto bad;
        ax->strata[k] = (int32_t)o;
    }
    at += S + 1;
    for (Py_ssize_t f = 0; f < n_facts; f++)
        stratum_of[f] = -1;
    for (Py_ssize_t k = 0; k < S; k++)
        for (int32_t r = ax->strata[k]; r < ax->strata[k + 1]; r++) {
            int64_t h = blob[at + r];
            if (h < 0 || h >= n_facts || (stratum_of[h] >= 0 && stratum_of[h] != k))
                goto bad;
            ax->head[r] = (int32_t)h;
            stratum_of[h] = (int32_t)k;
            ax->mask[h >> 6] |= (uint64_t)1 << (h & 63);
        }
    at += R;
    for (Py_ssize_t i = 0; i < n_derived; i++) {
        int64_t f = blob[at + i];
        if (f < 0 || f >= n_facts)
            goto bad;
        ax->mask[f >> 6] |= (uint64_t)1 << (f & 63);
    }
    at += n_derived;
    if (axioms_csr(blob, len, &at, R, n_facts, &ax->pos_off, &ax->pos, "positive literals") ||
        axioms_csr(blob, len, &at, R, n_facts, &ax->neg_off, &ax->neg, "negative literals"))
        goto fail;
    if (at + R + 1 > len || blob[at] != 0 || blob[at + R] != C)
        goto bad;
    ax->cl_off = calloc((size_t)R + 1, sizeof(int32_t));
    if (!ax->cl_off) {
        PyErr_NoMemory();
        goto fail;
    }
    for (Py_ssize_t r = 0; r <= R; r++) {
        if (r && blob[at + r] < blob[at + r - 1])
            goto bad;
        ax->cl_off[r] = (int32_t)blob[at + r];
    }
    at += R + 1;
    if (axioms_csr(blob, len, &at, C, n_facts, &ax->clp_off, &ax->clp, "clauses") ||
        axioms_csr(blob, len, &at, C, n_facts, &ax->cln_off, &ax->cln, "clauses"))
        goto fail;
    if (at != len)
        goto bad;
    /* stratified: what a rule negates is basic or of a lower stratum; what it reads
     * positively is not of a higher one */
    for (Py_ssize_t k = 0; k < S; k++)
        for (int32_t r = ax->strata[k]; r < ax->strata[k + 1]; r++) {
            for (int32_t j = ax->neg_off[r]; j < ax->neg_off[r + 1]; j++)
                if (stratum_of[ax->neg[j]] >= k)
                    goto unstratified;
            for (int32_t j = ax->pos_off[r]; j < ax->pos_off[r + 1]; j++)
                if (stratum_of[ax->pos[j]] > k)
                    goto unstratified;
            for (int32_t q = ax->cl_off[r]; q < ax->cl_off[r + 1]; q++) {
                for (int32_t j = ax->cln_off[q]; j < ax->cln_off[q + 1]; j++)
                    if (stratum_of[ax->cln[j]] >= k)
                        goto unstratified;
                for (int32_t j = ax->clp_off[q]; j < ax->clp_off[q + 1]; j++)
                    if (stratum_of[ax->clp[j]] > k)
                        goto unstratified;
            }
        }
    /* occurrences: per fact, the same-stratum rules reading it positively */
    ax->occ_off = calloc((size_t)n_facts + 1, sizeof(int32_t));
    if (!ax->occ_off) {
        PyErr_NoMemory();
        goto fail;
    }
    for (int pass = 0; pass < 2; pass++) {
        if (pass) {
            for (Py_ssize_t f = 0; f < n_facts; f++)
                ax->occ_off[f + 1] += ax->occ_off[f];
            int32_t n = ax->occ_off[n_facts];
            ax->occ_rule = calloc((size_t)n + 1, sizeof(int32_t));
            ax->occ_clause = calloc((size_t)n + 1, sizeof(int32_t));
            if (!ax->occ_rule || !ax->occ_clause) {
                PyErr_NoMemory();
                goto fail;
            }
        }
        for (Py_ssize_t k = 0; k < S; k++)
            for (int32_t r = ax->strata[k]; r < ax->strata[k + 1]; r++) {
                for (int32_t j = ax->pos_off[r]; j < ax->pos_off[r + 1]; j++)
                    if (stratum_of[ax->pos[j]] == k)
                        axioms_occurrence(ax, pass, ax->pos[j], r, -1);
                for (int32_t q = ax->cl_off[r]; q < ax->cl_off[r + 1]; q++)
                    for (int32_t j = ax->clp_off[q]; j < ax->clp_off[q + 1]; j++)
                        if (stratum_of[ax->clp[j]] == k)
                            axioms_occurrence(ax, pass, ax->clp[j], r, q);
            }
    }
    /* the fill advanced each fact's offset to its end: shift back */
    for (Py_ssize_t f = n_facts; f > 0; f--)
        ax->occ_off[f] = ax->occ_off[f - 1];
    ax->occ_off[0] = 0;
    free(stratum_of);
    return 0;
unstratified:
    PyErr_SetString(PyExc_ValueError, "native task: the rules are not stratified");
    goto fail;
bad:
    PyErr_SetString(PyExc_ValueError, "native task: the packed rules are malformed");
fail:
    free(stratum_of);
    axioms_free(ax);
    return -1;
}

#define AX_BIT(s, f) (((s)[(f) >> 6] >> ((f) & 63)) & 1u)
#define AX_SET(s, f) ((s)[(f) >> 6] |= (uint64_t)1 << ((f) & 63))

/* GroundAxioms.close: `state`'s basic facts and every derived fact they imply */
static void axioms_close(const Axioms *ax, Py_ssize_t W, const AxiomScratch *x,
                         uint64_t *state)
{
    for (Py_ssize_t i = 0; i < W; i++)
        state[i] &= ~ax->mask[i];
    int32_t *count = x->count, *queue = x->queue;
    uint8_t *sat = x->sat;
    for (int32_t k = 0; k < ax->n_strata; k++) {
        int32_t top = 0;
        for (int32_t r = ax->strata[k]; r < ax->strata[k + 1]; r++) {
            count[r] = -1; /* disabled: a negative literal holds */
            int32_t j = ax->neg_off[r];
            for (; j < ax->neg_off[r + 1]; j++)
                if (AX_BIT(state, ax->neg[j]))
                    break;
            if (j < ax->neg_off[r + 1])
                continue;
            int32_t c = 0;
            for (j = ax->pos_off[r]; j < ax->pos_off[r + 1]; j++)
                c += !AX_BIT(state, ax->pos[j]);
            for (int32_t q = ax->cl_off[r]; q < ax->cl_off[r + 1]; q++) {
                uint8_t holds = 0;
                for (j = ax->clp_off[q]; j < ax->clp_off[q + 1] && !holds; j++)
                    holds = (uint8_t)AX_BIT(state, ax->clp[j]);
                for (j = ax->cln_off[q]; j < ax->cln_off[q + 1] && !holds; j++)
                    holds = (uint8_t)!AX_BIT(state, ax->cln[j]);
                sat[q] = holds;
                c += !holds;
            }
            count[r] = c;
            if (c == 0)
                queue[top++] = ax->head[r]; /* set below: every count is against the same
                                             * state, so each later fact counts once */
        }
        int32_t ready = top;
        top = 0;
        for (int32_t i = 0; i < ready; i++)
            if (!AX_BIT(state, queue[i])) {
                AX_SET(state, queue[i]);
                queue[top++] = queue[i];
            }
        while (top) {
            int32_t f = queue[--top];
            for (int32_t o = ax->occ_off[f]; o < ax->occ_off[f + 1]; o++) {
                int32_t r = ax->occ_rule[o], q = ax->occ_clause[o];
                if (count[r] <= 0)
                    continue; /* disabled, or its head is derived already */
                if (q >= 0) {
                    if (sat[q])
                        continue;
                    sat[q] = 1;
                }
                if (--count[r] == 0 && !AX_BIT(state, ax->head[r])) {
                    AX_SET(state, ax->head[r]);
                    queue[top++] = ax->head[r];
                }
            }
        }
    }
}

#endif
