/* The grounder's two per-call fixpoints (avs_planner/cp/grounding.py), compiled.
 *
 * Both run over the cached grounding structure's rows (one row per statically possible ground
 * action, entries are fact ids in int64 matrices, padded) and return one flag per row. They
 * compute the same least fixpoints as the numpy versions in avs_planner/cp/derived.py, which
 * stay as the fallback when this module is not built; tests compare the two.
 *
 * gather_rows: the fact ids of a list of structure rows sorted and unique, and (if asked)
 *   their bitset words, written to fresh k-row arrays, optionally keeping only the facts a
 *   `read` mask marks (a call's kept rows: sorting them afresh is cheaper than keeping a structure-wide
 *   cache of sorted rows, which only the numpy fallback in derived.py does).
 * index: rows by fact (CSR) of a matrix, built once per structure and passed to the others
 *   (one int64 buffer: n_facts + 1 offsets, then the row ids; every occurrence once).
 * reachable: relaxed reachability. A row is active when every fact of its `pre` row is
 *   reached; its `add` facts are then reached. Counter-based: each fact, once reached, lowers
 *   the counters of the allowed rows reading it (every occurrence counts).
 * relevant: backward relevance. An allowed row is kept when it adds a fact needed true or
 *   deletes one needed false; a kept row's positive conditions (pre and clause positives)
 *   become needed true, its negative ones (pre_neg and clause negatives) needed false.
 * relaxed_merge: not a fixpoint, but per call on a task's action rows too: the relaxed merge
 *   of avs_planner/cp/relaxed_merge.py (numpy there, the fallback and the tests' reference).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* A C-contiguous (and, if asked, writable) buffer of `count` items of `itemsize` bytes, or
 * an error naming `what`. */
static int get_buffer(PyObject *obj, Py_buffer *view, Py_ssize_t count, Py_ssize_t itemsize,
                      const char *what, int writable)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (view->len != count * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes, expected %zd", what, view->len,
                     count * itemsize);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Every entry of an int64 array lies in [0, limit). */
static int check_range(const int64_t *v, Py_ssize_t count, int64_t limit, const char *what)
{
    for (Py_ssize_t i = 0; i < count; i++) {
        if (v[i] < 0 || v[i] >= limit) {
            PyErr_Format(PyExc_ValueError, "%s: id %lld outside [0, %lld)", what,
                         (long long)v[i], (long long)limit);
            return -1;
        }
    }
    return 0;
}

/* An index buffer (offsets then row ids) over n_facts facts and `rows` rows: its offsets are
 * monotone and its row ids in range. Sets *off and *val. */
static int get_index(PyObject *obj, Py_buffer *view, Py_ssize_t n_facts, Py_ssize_t rows,
                     const char *what, const int64_t **off, const int64_t **val)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS) < 0)
        return -1;
    Py_ssize_t items = view->len / 8;
    const int64_t *v = view->buf;
    if (view->len % 8 || items < n_facts + 1 || v[0] != 0 || items != n_facts + 1 + v[n_facts])
        goto bad;
    for (Py_ssize_t f = 0; f < n_facts; f++)
        if (v[f] > v[f + 1])
            goto bad;
    if (check_range(v + n_facts + 1, v[n_facts], rows, what) < 0) {
        PyBuffer_Release(view);
        return -1;
    }
    *off = v;
    *val = v + n_facts + 1;
    return 0;
bad:
    PyErr_Format(PyExc_ValueError, "%s: not an index over %zd facts", what, n_facts);
    PyBuffer_Release(view);
    return -1;
}

/* Buffers acquired in order; *got counts those held (release them whatever happens). */
typedef struct {
    PyObject *obj;
    Py_ssize_t count, itemsize;
    int writable;
    const char *what;
} Spec;

static int get_all(const Spec *specs, int n, Py_buffer *b, int *got)
{
    for (; *got < n; (*got)++) {
        const Spec *sp = &specs[*got];
        if (get_buffer(sp->obj, &b[*got], sp->count, sp->itemsize, sp->what, sp->writable) < 0)
            return -1;
    }
    return 0;
}

/* Sort row r's valid ids (0 <= id < n_facts, and read[id] if read is given) into row, unique
 * and -1 padded to width, and set their bits in words. tmp holds width + 1 ids. */
static void sorted_row(const int64_t *src, Py_ssize_t width, Py_ssize_t n_facts,
                       const uint8_t *read, int64_t *tmp, int64_t *row, uint64_t *words,
                       Py_ssize_t n_words)
{
    Py_ssize_t m = 0;
    for (Py_ssize_t j = 0; j < width; j++) {
        int64_t f = src[j];
        if (f < 0 || f >= n_facts || (read && !read[f]))
            continue;
        Py_ssize_t at = m++;
        while (at > 0 && tmp[at - 1] > f) { /* insertion sort: rows are short */
            tmp[at] = tmp[at - 1];
            at--;
        }
        tmp[at] = f;
    }
    if (words)
        memset(words, 0, (size_t)n_words * sizeof(uint64_t));
    Py_ssize_t u = 0;
    for (Py_ssize_t j = 0; j < m; j++) {
        if (u && row[u - 1] == tmp[j])
            continue;
        row[u++] = tmp[j];
        if (words)
            words[tmp[j] >> 6] |= (uint64_t)1 << (tmp[j] & 63);
    }
    for (; u < width; u++)
        row[u] = -1;
}

static PyObject *gather_rows(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *src_o, *idx_o, *read_o, *out_o, *bits_o;
    Py_ssize_t rows, width, n_facts, n_words, k;
    if (!PyArg_ParseTuple(args, "nOnnnOnOOO", &rows, &src_o, &width, &n_facts, &n_words,
                          &idx_o, &k, &read_o, &out_o, &bits_o))
        return NULL;
    if (rows < 0 || width < 0 || n_facts < 0 || n_words < n_facts / 64 + 1 || k < 0) {
        PyErr_SetString(PyExc_ValueError, "gather_rows: bad sizes");
        return NULL;
    }
    Py_buffer b[5];
    int got = 0, n_specs = 3, at_bits = -1, at_read = -1;
    PyObject *result = NULL;
    int64_t *tmp = NULL;
    Spec specs[5] = {
        {src_o, rows * width, 8, 0, "gather_rows: matrix"},
        {idx_o, k, 8, 0, "gather_rows: rows"},
        {out_o, k * width, 8, 1, "gather_rows: out"},
    };
    if (bits_o != Py_None) { /* None: no bitset words */
        at_bits = n_specs;
        specs[n_specs++] = (Spec){bits_o, k * n_words, 8, 1, "gather_rows: bits"};
    }
    if (read_o != Py_None) {
        at_read = n_specs;
        specs[n_specs++] = (Spec){read_o, n_facts, 1, 0, "gather_rows: read"};
    }
    if (get_all(specs, n_specs, b, &got) < 0)
        goto done;
    const int64_t *src = b[0].buf, *idx = b[1].buf;
    const uint8_t *read = at_read >= 0 ? b[at_read].buf : NULL;
    uint64_t *bits = at_bits >= 0 ? b[at_bits].buf : NULL;
    if (check_range(idx, k, rows, "gather_rows: rows") < 0)
        goto done;
    tmp = malloc(((size_t)width + 1) * sizeof(int64_t));
    if (!tmp) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < k; i++)
        sorted_row(src + idx[i] * width, width, n_facts, read, tmp,
                   (int64_t *)b[2].buf + i * width, bits ? bits + i * n_words : NULL, n_words);
    result = Py_None;
    Py_INCREF(result);
done:
    free(tmp);
    for (int j = 0; j < got; j++)
        PyBuffer_Release(&b[j]);
    return result;
}

static PyObject *build_index(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *m_o;
    Py_ssize_t rows, width, n_facts;
    if (!PyArg_ParseTuple(args, "nOnn", &rows, &m_o, &width, &n_facts))
        return NULL;
    if (rows < 0 || width < 0 || n_facts < 0) {
        PyErr_SetString(PyExc_ValueError, "index: bad sizes");
        return NULL;
    }
    Py_buffer b;
    if (get_buffer(m_o, &b, rows * width, 8, "index: matrix", 0) < 0)
        return NULL;
    const int64_t *m = b.buf;
    PyObject *out = NULL;
    int64_t *fill = calloc((size_t)n_facts + 1, sizeof(int64_t));
    if (!fill) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t nnz = 0;
    for (Py_ssize_t i = 0; i < rows * width; i++)
        if (m[i] >= 0 && m[i] < n_facts) {
            fill[m[i] + 1]++;
            nnz++;
        }
    out = PyBytes_FromStringAndSize(NULL, (n_facts + 1 + nnz) * 8);
    if (!out)
        goto done;
    int64_t *off = (int64_t *)PyBytes_AS_STRING(out), *val = off + n_facts + 1;
    off[0] = 0;
    for (Py_ssize_t f = 0; f < n_facts; f++) {
        off[f + 1] = off[f] + fill[f + 1];
        fill[f] = off[f];
    }
    for (Py_ssize_t r = 0; r < rows; r++)
        for (Py_ssize_t j = 0; j < width; j++) {
            int64_t f = m[r * width + j];
            if (f >= 0 && f < n_facts)
                val[fill[f]++] = r;
        }
done:
    free(fill);
    PyBuffer_Release(&b);
    return out;
}

/* Row r applies: mark it and queue the facts it adds that were not reached yet. */
static inline Py_ssize_t fire(int64_t r, const int64_t *add, Py_ssize_t aw, Py_ssize_t never,
                              uint8_t *active, uint8_t *reached, int64_t *queue, Py_ssize_t tail)
{
    active[r] = 1;
    for (Py_ssize_t j = 0; j < aw; j++) {
        int64_t g = add[r * aw + j];
        if (g != never && !reached[g]) {
            reached[g] = 1;
            queue[tail++] = g;
        }
    }
    return tail;
}

static PyObject *reachable(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *pre_o, *add_o, *init_o, *allowed_o, *index_o;
    Py_ssize_t rows, pw, aw, n_slots, never;
    if (!PyArg_ParseTuple(args, "nOnOnnnOOO", &rows, &pre_o, &pw, &add_o, &aw, &n_slots,
                          &never, &init_o, &allowed_o, &index_o))
        return NULL;
    if (rows < 0 || pw < 0 || aw < 0 || n_slots < 1 || never < 0 || never >= n_slots) {
        PyErr_SetString(PyExc_ValueError, "reachable: bad sizes");
        return NULL;
    }
    Py_buffer b[5];
    int got = 0;
    PyObject *out = NULL;
    int64_t *count = NULL, *queue = NULL;
    uint8_t *reached = NULL;
    const int64_t *off, *val;
    const Spec specs[4] = {
        {pre_o, rows * pw, 8, 0, "reachable: pre"},
        {add_o, rows * aw, 8, 0, "reachable: add"},
        {init_o, n_slots, 1, 0, "reachable: init"},
        {allowed_o, rows, 1, 0, "reachable: allowed"},
    };
    if (get_all(specs, 4, b, &got) < 0)
        goto done;
    if (get_index(index_o, &b[got], n_slots, rows, "reachable: index", &off, &val) < 0)
        goto done;
    got++;
    const int64_t *pre = b[0].buf, *add = b[1].buf;
    const uint8_t *init = b[2].buf, *allowed = b[3].buf;
    if (check_range(pre, rows * pw, n_slots, "reachable: pre") < 0 ||
        check_range(add, rows * aw, n_slots, "reachable: add") < 0)
        goto done;
    out = PyByteArray_FromStringAndSize(NULL, rows);
    count = malloc(((size_t)rows + 1) * sizeof(int64_t));
    queue = malloc(((size_t)n_slots + 1) * sizeof(int64_t));
    reached = calloc((size_t)n_slots, 1);
    if (!out || !count || !queue || !reached) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    uint8_t *active = (uint8_t *)PyByteArray_AS_STRING(out);
    memset(active, 0, (size_t)rows);
    Py_ssize_t head = 0, tail = 0;
    for (Py_ssize_t r = 0; r < rows; r++)
        count[r] = pw;
    for (Py_ssize_t f = 0; f < n_slots; f++) {
        if (init[f] && f != never) {
            reached[f] = 1;
            queue[tail++] = f;
        }
    }
    for (Py_ssize_t r = 0; pw == 0 && r < rows; r++) /* no preconditions: fire at once */
        if (allowed[r])
            tail = fire(r, add, aw, never, active, reached, queue, tail);
    while (head < tail) {
        int64_t f = queue[head++];
        for (int64_t k = off[f]; k < off[f + 1]; k++) {
            int64_t r = val[k];
            if (allowed[r] && --count[r] == 0)
                tail = fire(r, add, aw, never, active, reached, queue, tail);
        }
    }
done:
    free(count);
    free(queue);
    free(reached);
    for (int k = 0; k < got; k++)
        PyBuffer_Release(&b[k]);
    return out;
}

typedef struct {
    uint8_t *need_true, *need_false;
    int64_t *queue; /* fact * 2 + (1 if needed false) */
    Py_ssize_t tail;
    int64_t n;
} Needs;

static inline void need(Needs *s, int64_t f, int negative)
{
    if (f < 0 || f >= s->n)
        return;
    uint8_t *flag = negative ? s->need_false : s->need_true;
    if (!flag[f]) {
        flag[f] = 1;
        s->queue[s->tail++] = f * 2 + negative;
    }
}

static PyObject *relevant(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *pre_o, *neg_o, *coff_o, *cpos_o, *cneg_o, *allowed_o, *gt_o, *gf_o, *ai_o, *di_o;
    Py_ssize_t rows, pw, nw, n, n_slots, cpos_n, cneg_n, gt_n, gf_n;
    if (!PyArg_ParseTuple(args, "nnnOnOnOOnOnOOnOnOO", &rows, &n, &n_slots, &pre_o, &pw,
                          &neg_o, &nw, &coff_o, &cpos_o, &cpos_n, &cneg_o, &cneg_n,
                          &allowed_o, &gt_o, &gt_n, &gf_o, &gf_n, &ai_o, &di_o))
        return NULL;
    if (rows < 0 || n < 0 || n_slots < n || pw < 0 || nw < 0 || cpos_n < 0 || cneg_n < 0 ||
        gt_n < 0 || gf_n < 0) {
        PyErr_SetString(PyExc_ValueError, "relevant: bad sizes");
        return NULL;
    }
    Py_buffer b[10];
    int got = 0;
    PyObject *out = NULL;
    Needs s = {0};
    s.n = n;
    /* clause facts per row, interleaved offsets (2 * (rows + 1) entries): row r's positives
     * are cpos[coff[2r] .. coff[2r + 2]), its negatives cneg[coff[2r + 1] .. coff[2r + 3]) */
    const Spec specs[8] = {
        {pre_o, rows * pw, 8, 0, "relevant: pre"},
        {neg_o, rows * nw, 8, 0, "relevant: pre_neg"},
        {coff_o, 2 * (rows + 1), 8, 0, "relevant: clause offsets"},
        {cpos_o, cpos_n, 8, 0, "relevant: clause positives"},
        {cneg_o, cneg_n, 8, 0, "relevant: clause negatives"},
        {allowed_o, rows, 1, 0, "relevant: allowed"},
        {gt_o, gt_n, 8, 0, "relevant: goal"},
        {gf_o, gf_n, 8, 0, "relevant: goal_neg"},
    };
    if (get_all(specs, 8, b, &got) < 0)
        goto done;
    const int64_t *aoff, *aval, *doff, *dval;
    if (get_index(ai_o, &b[got], n, rows, "relevant: add index", &aoff, &aval) < 0)
        goto done;
    got++;
    if (get_index(di_o, &b[got], n, rows, "relevant: delete index", &doff, &dval) < 0)
        goto done;
    got++;
    const int64_t *pre = b[0].buf, *neg = b[1].buf;
    const int64_t *coff = b[2].buf, *cpos = b[3].buf, *cneg = b[4].buf;
    const uint8_t *allowed = b[5].buf;
    const int64_t *gt = b[6].buf, *gf = b[7].buf;
    if (check_range(pre, rows * pw, n_slots, "relevant: pre") < 0 ||
        check_range(neg, rows * nw, n_slots, "relevant: pre_neg") < 0)
        goto done;
    for (Py_ssize_t r = 0; r < rows; r++) {
        if (coff[2 * r] > coff[2 * r + 2] || coff[2 * r + 1] > coff[2 * r + 3] ||
            coff[2 * r + 2] > cpos_n || coff[2 * r + 3] > cneg_n || coff[2 * r] < 0 ||
            coff[2 * r + 1] < 0) {
            PyErr_SetString(PyExc_ValueError, "relevant: clause offsets out of order");
            goto done;
        }
    }
    out = PyByteArray_FromStringAndSize(NULL, rows);
    s.need_true = calloc((size_t)n + 1, 1);
    s.need_false = calloc((size_t)n + 1, 1);
    s.queue = malloc(((size_t)n * 2 + 1) * sizeof(int64_t));
    if (!out || !s.need_true || !s.need_false || !s.queue) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    uint8_t *kept = (uint8_t *)PyByteArray_AS_STRING(out);
    memset(kept, 0, (size_t)rows);
    for (Py_ssize_t k = 0; k < gt_n; k++)
        need(&s, gt[k], 0);
    for (Py_ssize_t k = 0; k < gf_n; k++)
        need(&s, gf[k], 1);
    for (Py_ssize_t head = 0; head < s.tail; head++) {
        int64_t item = s.queue[head];
        int64_t f = item / 2;
        int negative = (int)(item % 2);
        const int64_t *off = negative ? doff : aoff, *val = negative ? dval : aval;
        for (int64_t k = off[f]; k < off[f + 1]; k++) {
            int64_t r = val[k];
            if (kept[r] || !allowed[r])
                continue;
            kept[r] = 1;
            for (Py_ssize_t j = 0; j < pw; j++)
                need(&s, pre[r * pw + j], 0);
            for (Py_ssize_t j = 0; j < nw; j++)
                need(&s, neg[r * nw + j], 1);
            for (int64_t j = coff[2 * r]; j < coff[2 * r + 2]; j++)
                need(&s, cpos[j], 0);
            for (int64_t j = coff[2 * r + 1]; j < coff[2 * r + 3]; j++)
                need(&s, cneg[j], 1);
        }
    }
done:
    free(s.need_true);
    free(s.need_false);
    free(s.queue);
    for (int k = 0; k < got; k++)
        PyBuffer_Release(&b[k]);
    return out;
}

/* ------------------------------------------------------------------------------------------ */
/* relaxed_merge.py's grouping and merge construction (one_argument_groups + build_merge), the
 * same arrays in the same order: hashes are the same wrapping sums of value * weight[c % 256]
 * with the weights passed in, and every order the numpy code takes from a sort is reproduced
 * by sorting on the same keys (ties by index). */

#define MERGE_BIG ((int64_t)1 << 62)

typedef struct {
    uint64_t k1, k2;
    int64_t i;
} Key3;

static int key3_cmp(const void *pa, const void *pb)
{
    const Key3 *a = pa, *b = pb;
    if (a->k1 != b->k1)
        return a->k1 < b->k1 ? -1 : 1;
    if (a->k2 != b->k2)
        return a->k2 < b->k2 ? -1 : 1;
    return (a->i > b->i) - (a->i < b->i);
}

static int bit_length(int64_t v)
{
    int n = 0;
    while (v > 0) {
        n++;
        v >>= 1;
    }
    return n;
}

/* Growable int64 list. */
typedef struct {
    int64_t *v;
    Py_ssize_t n, cap;
} I64List;

static int i64_push(I64List *l, int64_t x)
{
    if (l->n == l->cap) {
        Py_ssize_t cap = l->cap ? l->cap * 2 : 256;
        int64_t *v = realloc(l->v, (size_t)cap * sizeof(int64_t));
        if (!v)
            return -1;
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n++] = x;
    return 0;
}

static PyObject *i64_bytes(const int64_t *v, Py_ssize_t n)
{
    return PyBytes_FromStringAndSize((const char *)v, n * (Py_ssize_t)sizeof(int64_t));
}

static PyObject *relaxed_merge(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *args_o, *pre_o, *add_o, *cost_o, *prob_o, *elig_o, *w_o;
    Py_ssize_t n, arity, wp, wa, n_facts;
    if (!PyArg_ParseTuple(args, "nnnnnOOOOOOO", &n, &arity, &wp, &wa, &n_facts, &args_o, &pre_o,
                          &add_o, &cost_o, &prob_o, &elig_o, &w_o))
        return NULL;
    if (n < 0 || arity < 0 || wp < 0 || wa < 0 || n_facts < 0 || n_facts > INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "relaxed_merge: bad sizes");
        return NULL;
    }
    Py_buffer b[7];
    int got = 0;
    const Spec specs[7] = {
        {args_o, n * arity, 8, 0, "relaxed_merge: args"},
        {pre_o, n * wp, 8, 0, "relaxed_merge: pre"},
        {add_o, n * wa, 8, 0, "relaxed_merge: add"},
        {cost_o, n, 8, 0, "relaxed_merge: cost"},
        {prob_o, n, 8, 0, "relaxed_merge: probability"},
        {elig_o, n, 1, 0, "relaxed_merge: eligible"},
        {w_o, 256, 8, 0, "relaxed_merge: weights"},
    };
    PyObject *result = NULL;
    Py_ssize_t K = arity + wa + 2;
    uint64_t *key = NULL, *full = NULL;
    int64_t *gid = NULL, *first = NULL, *rank = NULL, *members = NULL, *g = NULL, *alt = NULL;
    int64_t *cnt = NULL, *start = NULL, *sizes = NULL, *x_of = NULL, *common_n = NULL;
    uint8_t *free_ = NULL, *away = NULL, *okg = NULL;
    Key3 *ks = NULL, *gs = NULL;
    int64_t *slot = NULL, *slot_g = NULL, *gains = NULL, *korder = NULL, *goff = NULL;
    int64_t *common = NULL, *kept = NULL, *reps = NULL, *run_of = NULL, *run_x = NULL;
    int64_t *is_rep = NULL, *orig = NULL;
    I64List pre_off = {0}, pre_v = {0}, add_off = {0}, add_v = {0}, weight_of = {0},
            link = {0}, member_off = {0}, mem_out = {0};
    Py_ssize_t n_x = 0, n_m = 0;
    if (get_all(specs, 7, b, &got) < 0)
        goto done;
    const int64_t *A = b[0].buf, *P = b[1].buf, *D = b[2].buf;
    const uint64_t *C = b[3].buf, *Q = b[4].buf, *W = b[6].buf;
    const uint8_t *E = b[5].buf;
    gid = malloc(sizeof(int64_t) * (size_t)(n + 1));
    away = calloc((size_t)n + 1, 1);
    if (!gid || !away)
        goto nomem;
    for (Py_ssize_t i = 0; i < n; i++)
        gid[i] = -1;
    /* one_argument_groups */
    if (n >= 2 && arity) {
        key = malloc(sizeof(uint64_t) * (size_t)(n * K));
        full = malloc(sizeof(uint64_t) * (size_t)n);
        free_ = malloc((size_t)n);
        ks = malloc(sizeof(Key3) * (size_t)n);
        gains = calloc((size_t)arity, sizeof(int64_t));
        korder = malloc(sizeof(int64_t) * (size_t)arity);
        if (!key || !full || !free_ || !ks || !gains || !korder)
            goto nomem;
        for (Py_ssize_t i = 0; i < n; i++) {
            uint64_t *row = key + i * K, h = 0;
            for (Py_ssize_t c = 0; c < arity; c++)
                row[c] = (uint64_t)A[i * arity + c];
            for (Py_ssize_t c = 0; c < wa; c++)
                row[arity + c] = (uint64_t)D[i * wa + c];
            row[arity + wa] = C[i];
            row[arity + wa + 1] = Q[i];
            for (Py_ssize_t c = 0; c < K; c++)
                h += row[c] * W[c % 256];
            full[i] = h;
            free_[i] = E[i];
        }
        size_t cap = 16;
        while (cap < 2 * (size_t)n)
            cap <<= 1;
        slot = malloc(sizeof(int64_t) * cap);
        slot_g = malloc(sizeof(int64_t) * (size_t)n);
        if (!slot || !slot_g)
            goto nomem;
        for (Py_ssize_t k = 0; k < arity; k++) { /* gains: rows whose hash an earlier has */
            memset(slot, 0xff, sizeof(int64_t) * cap);
            uint64_t wk = W[k % 256];
            for (Py_ssize_t i = 0; i < n; i++) {
                if (!free_[i] || A[i * arity + k] < 0)
                    continue;
                uint64_t h = full[i] - key[i * K + k] * wk;
                size_t s = (size_t)(h ^ (h >> 31)) & (cap - 1);
                while (slot[s] >= 0 && full[slot[s]] - key[slot[s] * K + k] * wk != h)
                    s = (s + 1) & (cap - 1);
                if (slot[s] >= 0)
                    gains[k]++;
                else
                    slot[s] = i;
            }
            korder[k] = k;
        }
        for (Py_ssize_t x = 1; x < arity; x++) { /* by (-gain, k): insertion sort */
            int64_t k = korder[x];
            Py_ssize_t y = x;
            while (y > 0 && gains[korder[y - 1]] < gains[k]) {
                korder[y] = korder[y - 1];
                y--;
            }
            korder[y] = k;
        }
        int64_t n_groups = 0;
        for (Py_ssize_t x = 0; x < arity; x++) {
            int64_t k = korder[x];
            if (!gains[k])
                break;
            /* rows with the same hash and the same key columns (k aside) form a group; a
             * slot holds the first such row, slot_g its group (-1 while alone) */
            memset(slot, 0xff, sizeof(int64_t) * cap);
            uint64_t wk = W[k % 256];
            for (Py_ssize_t i = 0; i < n; i++) {
                if (!free_[i] || A[i * arity + k] < 0)
                    continue;
                uint64_t h = full[i] - key[i * K + k] * wk;
                size_t s = (size_t)(h ^ (h >> 31)) & (cap - 1);
                while (slot[s] >= 0) {
                    int64_t r = slot[s];
                    if (full[r] - key[r * K + k] * wk == h) {
                        const uint64_t *r0 = key + r * K, *r1 = key + i * K;
                        int same = 1;
                        for (Py_ssize_t c = 0; c < K && same; c++)
                            if (c != k && r0[c] != r1[c])
                                same = 0;
                        if (same)
                            break;
                    }
                    s = (s + 1) & (cap - 1);
                }
                if (slot[s] < 0) {
                    slot[s] = i;
                    slot_g[i] = -1;
                    continue;
                }
                int64_t r = slot[s];
                if (slot_g[r] < 0)
                    slot_g[r] = n_groups++;
                gid[r] = gid[i] = slot_g[r];
            }
            for (Py_ssize_t i = 0; i < n; i++) /* grouped rows leave the pool after this k */
                if (gid[i] >= 0)
                    free_[i] = 0;
        }
        if (n_groups) { /* renumber by first member */
            first = malloc(sizeof(int64_t) * (size_t)n_groups);
            rank = malloc(sizeof(int64_t) * (size_t)n_groups);
            if (!first || !rank)
                goto nomem;
            for (int64_t q = 0; q < n_groups; q++)
                first[q] = -1;
            int64_t next = 0;
            for (Py_ssize_t i = 0; i < n; i++)
                if (gid[i] >= 0 && first[gid[i]] < 0) {
                    first[gid[i]] = i;
                    rank[gid[i]] = next++;
                }
            for (Py_ssize_t i = 0; i < n; i++)
                if (gid[i] >= 0)
                    gid[i] = rank[gid[i]];
        }
    }
    /* build_merge */
    Py_ssize_t n_mem = 0;
    for (Py_ssize_t i = 0; i < n; i++)
        n_mem += gid[i] >= 0;
    if (n_mem && wp) {
        /* members by (group, index); a group's members are contiguous */
        members = malloc(sizeof(int64_t) * (size_t)n_mem);
        int64_t n_groups = 0;
        for (Py_ssize_t i = 0; i < n; i++)
            if (gid[i] + 1 > n_groups)
                n_groups = gid[i] + 1;
        goff = calloc((size_t)n_groups + 1, sizeof(int64_t));
        if (!members || !goff)
            goto nomem;
        for (Py_ssize_t i = 0; i < n; i++)
            if (gid[i] >= 0)
                goff[gid[i] + 1]++;
        for (int64_t q = 0; q < n_groups; q++)
            goff[q + 1] += goff[q];
        {
            int64_t *fill = calloc((size_t)n_groups, sizeof(int64_t));
            if (!fill)
                goto nomem;
            for (Py_ssize_t i = 0; i < n; i++)
                if (gid[i] >= 0)
                    members[goff[gid[i]] + fill[gid[i]]++] = i;
            free(fill);
        }
        /* per member: which preconditions all of its group have (common); the rest */
        cnt = calloc((size_t)n_facts + 2, sizeof(int64_t));
        okg = malloc((size_t)n_groups);
        alt = malloc(sizeof(int64_t) * (size_t)(n_mem * wp));
        common_n = calloc((size_t)n_groups, sizeof(int64_t));
        common = malloc(sizeof(int64_t) * (size_t)(n_groups * wp) + 8);
        if (!cnt || !okg || !alt || !common_n || !common)
            goto nomem;
        for (int64_t q = 0; q < n_groups; q++) {
            int64_t size = goff[q + 1] - goff[q];
            for (int64_t t = goff[q]; t < goff[q + 1]; t++)
                for (Py_ssize_t c = 0; c < wp; c++) {
                    int64_t f = P[members[t] * wp + c];
                    if (f >= 0 && f < n_facts + 2)
                        cnt[f]++;
                }
            okg[q] = 1;
            for (int64_t t = goff[q]; t < goff[q + 1]; t++) {
                Py_ssize_t na = 0;
                int64_t *row = alt + t * wp;
                for (Py_ssize_t c = 0; c < wp; c++) {
                    int64_t f = P[members[t] * wp + c];
                    if (f < 0)
                        continue;
                    if (f < n_facts + 2 && cnt[f] == size) {
                        if (t == goff[q])
                            common[q * wp + common_n[q]++] = f;
                    } else
                        row[na++] = f;
                }
                if (!na)
                    okg[q] = 0;
                for (Py_ssize_t c = na; c < wp; c++)
                    row[c] = MERGE_BIG;
                /* pre rows are sorted, so the remainder is too */
            }
            for (int64_t t = goff[q]; t < goff[q + 1]; t++)
                for (Py_ssize_t c = 0; c < wp; c++) {
                    int64_t f = P[members[t] * wp + c];
                    if (f >= 0 && f < n_facts + 2)
                        cnt[f] = 0;
                }
        }
        /* dense ids over the kept groups */
        g = malloc(sizeof(int64_t) * (size_t)n_groups);
        if (!g)
            goto nomem;
        for (int64_t q = 0; q < n_groups; q++)
            g[q] = okg[q] ? n_m++ : -1;
        if (n_m) {
            /* members of kept groups ordered by (group, hash bits of remainder, index) */
            ks = ks ? ks : malloc(sizeof(Key3) * (size_t)n_mem);
            if (!ks)
                goto nomem;
            int gb = bit_length(n_m) > 1 ? bit_length(n_m) : 1;
            int mb = bit_length(n) > 1 ? bit_length(n) : 1;
            int hb = 64 - gb - mb;
            Py_ssize_t m = 0;
            for (int64_t q = 0; q < n_groups; q++) {
                if (!okg[q])
                    continue;
                for (int64_t t = goff[q]; t < goff[q + 1]; t++) {
                    uint64_t h = 0;
                    for (Py_ssize_t c = 0; c < wp; c++)
                        h += (uint64_t)alt[t * wp + c] * W[c % 256];
                    away[members[t]] = 1;
                    ks[m].k1 = (uint64_t)g[q];
                    ks[m].k2 = hb >= 16 ? h >> (64 - hb) : h;
                    ks[m++].i = t; /* position in members/alt; same order as the index */
                }
            }
            /* ks is in group order already: sort each group's run (small: insertion) */
            for (Py_ssize_t j0 = 0; j0 < m;) {
                Py_ssize_t j1 = j0 + 1;
                while (j1 < m && ks[j1].k1 == ks[j0].k1)
                    j1++;
                if (j1 - j0 > 32)
                    qsort(ks + j0, (size_t)(j1 - j0), sizeof(Key3), key3_cmp);
                else
                    for (Py_ssize_t x = j0 + 1; x < j1; x++) {
                        Key3 v = ks[x];
                        Py_ssize_t y = x;
                        while (y > j0 && key3_cmp(&ks[y - 1], &v) > 0) {
                            ks[y] = ks[y - 1];
                            y--;
                        }
                        ks[y] = v;
                    }
                j0 = j1;
            }
            /* drop a remainder repeated within a group (the lowest index stays) */
            sizes = calloc((size_t)n_m, sizeof(int64_t));
            start = calloc((size_t)n_m + 1, sizeof(int64_t));
            kept = malloc(sizeof(int64_t) * (size_t)m + 8);
            if (!sizes || !start || !kept)
                goto nomem;
            Py_ssize_t nk = 0;
            for (Py_ssize_t j = 0; j < m; j++) {
                if (j && ks[j].k1 == ks[j - 1].k1 &&
                    !memcmp(alt + ks[j].i * wp, alt + ks[j - 1].i * wp,
                            sizeof(int64_t) * (size_t)wp))
                    continue;
                kept[nk++] = ks[j].i;
                sizes[ks[j].k1]++;
            }
            int64_t maxsize = 0;
            for (Py_ssize_t q = 0; q < n_m; q++) {
                start[q + 1] = start[q] + sizes[q];
                if (sizes[q] > maxsize)
                    maxsize = sizes[q];
            }
            /* X per distinct list of alternatives, numbered by first group */
            Py_ssize_t tw = (Py_ssize_t)maxsize * wp;
            gs = malloc(sizeof(Key3) * (size_t)n_m);
            x_of = malloc(sizeof(int64_t) * (size_t)n_m);
            reps = malloc(sizeof(int64_t) * (size_t)n_m);
            if (!gs || !x_of || !reps)
                goto nomem;
            /* a group's row is its members' remainders, padded with MERGE_BIG to tw
             * entries; the padding's share of the hash comes from prefix sums of the weights
             * (a row by row sum would be quadratic with one large group among many) */
            uint64_t wsum[257];
            wsum[0] = 0;
            for (int c = 0; c < 256; c++)
                wsum[c + 1] = wsum[c] + W[c];
            for (Py_ssize_t q = 0; q < n_m; q++) {
                uint64_t h = 0;
                Py_ssize_t len = sizes[q] * wp;
                for (Py_ssize_t c = 0; c < len; c++)
                    h += (uint64_t)alt[kept[start[q] + c / wp] * wp + c % wp] * W[c % 256];
                uint64_t upto_tw = (uint64_t)(tw / 256) * wsum[256] + wsum[tw % 256];
                uint64_t upto_len = (uint64_t)(len / 256) * wsum[256] + wsum[len % 256];
                h += (uint64_t)MERGE_BIG * (upto_tw - upto_len);
                gs[q].k1 = h;
                gs[q].k2 = 0;
                gs[q].i = q;
            }
            qsort(gs, (size_t)n_m, sizeof(Key3), key3_cmp);
            Py_ssize_t n_runs = 0;
            run_of = malloc(sizeof(int64_t) * (size_t)n_m);
            if (!run_of)
                goto nomem;
            for (Py_ssize_t j = 0; j < n_m; j++) {
                int same = 0;
                if (j && gs[j].k1 == gs[j - 1].k1) {
                    int64_t q0 = gs[j - 1].i, q1 = gs[j].i;
                    same = sizes[q0] == sizes[q1];
                    for (int64_t p = 0; same && p < sizes[q0]; p++)
                        same = !memcmp(alt + kept[start[q0] + p] * wp,
                                       alt + kept[start[q1] + p] * wp,
                                       sizeof(int64_t) * (size_t)wp);
                }
                if (!same)
                    reps[n_runs++] = gs[j].i; /* the run's first = lowest group */
                run_of[gs[j].i] = n_runs - 1;
            }
            /* X ids: runs by their first group */
            run_x = malloc(sizeof(int64_t) * (size_t)n_runs + 8);
            is_rep = calloc((size_t)n_m, sizeof(int64_t));
            if (!run_x || !is_rep)
                goto nomem;
            for (Py_ssize_t r = 0; r < n_runs; r++)
                is_rep[reps[r]] = r + 1;
            n_x = 0;
            for (Py_ssize_t q = 0; q < n_m; q++)
                if (is_rep[q])
                    run_x[is_rep[q] - 1] = n_x++;
            for (Py_ssize_t q = 0; q < n_m; q++)
                x_of[q] = run_x[run_of[q]];
            /* the extra actions: merged (one per kept group), then auxiliary per X */
            int ok = !i64_push(&pre_off, 0) && !i64_push(&add_off, 0) &&
                     !i64_push(&member_off, 0);
            orig = malloc(sizeof(int64_t) * (size_t)n_m); /* kept group -> group */
            if (!orig)
                ok = 0;
            for (int64_t q = 0; ok && q < n_groups; q++)
                if (okg[q])
                    orig[g[q]] = q;
            for (Py_ssize_t q = 0; ok && q < n_m; q++) {
                int64_t q0 = orig[q], lead = members[kept[start[q]]];
                for (int64_t c = 0; ok && c < common_n[q0]; c++)
                    ok = !i64_push(&pre_v, common[q0 * wp + c]);
                ok = ok && !i64_push(&pre_v, n_facts + x_of[q]) &&
                     !i64_push(&pre_off, pre_v.n);
                for (Py_ssize_t c = 0; ok && c < wa; c++)
                    if (D[lead * wa + c] >= 0)
                        ok = !i64_push(&add_v, D[lead * wa + c]);
                ok = ok && !i64_push(&add_off, add_v.n) && !i64_push(&weight_of, lead) &&
                     !i64_push(&link, n_facts + x_of[q]) &&
                     !i64_push(&member_off, start[q + 1]);
            }
            for (Py_ssize_t j = 0; ok && j < nk; j++)
                ok = !i64_push(&mem_out, members[kept[j]]);
            for (Py_ssize_t q = 0; ok && q < n_m; q++) { /* X order = ascending first group */
                if (!is_rep[q])
                    continue;
                int64_t x = run_x[is_rep[q] - 1];
                for (int64_t p = 0; ok && p < sizes[q]; p++) {
                    const int64_t *row = alt + kept[start[q] + p] * wp;
                    for (Py_ssize_t c = 0; ok && c < wp && row[c] != MERGE_BIG; c++)
                        ok = !i64_push(&pre_v, row[c]);
                    ok = ok && !i64_push(&pre_off, pre_v.n) &&
                         !i64_push(&add_v, n_facts + x) && !i64_push(&add_off, add_v.n) &&
                         !i64_push(&weight_of, -1) && !i64_push(&link, p);
                }
            }
            if (!ok)
                goto nomem;
            goto build;
        }
        /* no kept group: nothing merged */
        memset(away, 0, (size_t)n);
    }
    n_m = 0;
    n_x = 0;
    if (i64_push(&pre_off, 0) || i64_push(&add_off, 0) || i64_push(&member_off, 0))
        goto nomem;
build:
    {
        PyObject *away_b = PyBytes_FromStringAndSize((const char *)away, n);
        result = Py_BuildValue("(nnNNNNNNNNN)", n_facts + n_x, n_m, away_b,
                               i64_bytes(pre_off.v, pre_off.n), i64_bytes(pre_v.v, pre_v.n),
                               i64_bytes(add_off.v, add_off.n), i64_bytes(add_v.v, add_v.n),
                               i64_bytes(weight_of.v, weight_of.n), i64_bytes(link.v, link.n),
                               i64_bytes(member_off.v, member_off.n),
                               i64_bytes(mem_out.v, mem_out.n));
    }
    goto done;
nomem:
    PyErr_NoMemory();
done:
    free(key);
    free(full);
    free(gid);
    free(first);
    free(rank);
    free(members);
    free(g);
    free(alt);
    free(cnt);
    free(start);
    free(sizes);
    free(x_of);
    free(common_n);
    free(free_);
    free(away);
    free(okg);
    free(ks);
    free(gs);
    free(gains);
    free(korder);
    free(goff);
    free(common);
    free(kept);
    free(reps);
    free(run_of);
    free(run_x);
    free(is_rep);
    free(orig);
    free(slot);
    free(slot_g);
    free(pre_off.v);
    free(pre_v.v);
    free(add_off.v);
    free(add_v.v);
    free(weight_of.v);
    free(link.v);
    free(member_off.v);
    free(mem_out.v);
    for (int j = 0; j < got; j++)
        PyBuffer_Release(&b[j]);
    return result;
}

static PyMethodDef methods[] = {
    {"gather_rows", gather_rows, METH_VARARGS,
     "gather_rows(rows, matrix, width, n_facts, n_words, row_ids, k, read, out, out_bits): "
     "for each listed row, its valid fact ids (those read marks, unless read is None) sorted "
     "and unique (-1 padded) into the next row of out (k x width) and as little-endian uint64 "
     "bitset words into out_bits (k x n_words)"},
    {"index", build_index, METH_VARARGS,
     "index(rows, matrix, width, n_facts) -> bytes: int64 offsets (n_facts + 1) then the "
     "row ids, per fact the rows whose matrix row names it (entries outside [0, n_facts) "
     "skipped)"},
    {"reachable", reachable, METH_VARARGS,
     "reachable(rows, pre, pre_width, add, add_width, n_slots, never, init, allowed, "
     "pre_index) -> bytearray: 1 for each allowed row relaxed-reachable from init (fact id "
     "`never` is never reached; pre_index = index(rows, pre, pre_width, n_slots))"},
    {"relevant", relevant, METH_VARARGS,
     "relevant(rows, n, n_slots, pre, pw, pre_neg, nw, clause_offsets, clause_pos, n_pos, "
     "clause_neg, n_neg, allowed, goal, n_goal, goal_neg, n_goal_neg, add_index, "
     "delete_index) -> bytearray: 1 for each allowed row that can contribute to the goal "
     "(the indexes over n facts)"},
    {"relaxed_merge", relaxed_merge, METH_VARARGS,
     "relaxed_merge(n, arity, pre_width, add_width, n_facts, arg_ids, pre, add, cost_bits, "
     "probability_bits, eligible, weights) -> (n_rfacts, n_merged, away, pre_off, pre, "
     "add_off, add, weight_of, link, member_off, members): relaxed_merge.py's merge of "
     "actions differing in one argument (int64 matrices, -1 padded; bytes out)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_fixpoint",
    "The grounder's relaxed reachability and relevance fixpoints and the relaxed merge, "
    "compiled.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__fixpoint(void) { return PyModule_Create(&module); }
