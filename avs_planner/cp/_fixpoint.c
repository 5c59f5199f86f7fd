/* The grounder's two per-call fixpoints (avs_planner/cp/grounding.py), compiled.
 *
 * Both run over the cached grounding structure's rows (one row per statically possible ground
 * action, entries are fact ids in int64 matrices, padded) and return one flag per row. They
 * compute the same least fixpoints as the numpy versions in avs_planner/cp/derived.py, which
 * stay as the fallback when this module is not built; tests compare the two.
 *
 * gather_rows: the fact ids of a list of structure rows sorted and unique, and their bitset
 *   words, written to fresh k-row arrays, optionally keeping only the facts a `read` mask
 *   marks (a call's kept rows: sorting them afresh is cheaper than keeping a structure-wide
 *   cache of sorted rows, which only the numpy fallback in derived.py does).
 * index: rows by fact (CSR) of a matrix, built once per structure and passed to the others
 *   (one int64 buffer: n_facts + 1 offsets, then the row ids; every occurrence once).
 * reachable: relaxed reachability. A row is active when every fact of its `pre` row is
 *   reached; its `add` facts are then reached. Counter-based: each fact, once reached, lowers
 *   the counters of the allowed rows reading it (every occurrence counts).
 * relevant: backward relevance. An allowed row is kept when it adds a fact needed true or
 *   deletes one needed false; a kept row's positive conditions (pre and clause positives)
 *   become needed true, its negative ones (pre_neg and clause negatives) needed false.
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
    memset(words, 0, (size_t)n_words * sizeof(uint64_t));
    Py_ssize_t u = 0;
    for (Py_ssize_t j = 0; j < m; j++) {
        if (u && row[u - 1] == tmp[j])
            continue;
        row[u++] = tmp[j];
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
    int got = 0, n_specs = read_o == Py_None ? 4 : 5;
    PyObject *result = NULL;
    int64_t *tmp = NULL;
    const Spec specs[5] = {
        {src_o, rows * width, 8, 0, "gather_rows: matrix"},
        {idx_o, k, 8, 0, "gather_rows: rows"},
        {out_o, k * width, 8, 1, "gather_rows: out"},
        {bits_o, k * n_words, 8, 1, "gather_rows: bits"},
        {read_o, n_facts, 1, 0, "gather_rows: read"},
    };
    if (get_all(specs, n_specs, b, &got) < 0)
        goto done;
    const int64_t *src = b[0].buf, *idx = b[1].buf;
    const uint8_t *read = n_specs == 5 ? b[4].buf : NULL;
    if (check_range(idx, k, rows, "gather_rows: rows") < 0)
        goto done;
    tmp = malloc(((size_t)width + 1) * sizeof(int64_t));
    if (!tmp) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t i = 0; i < k; i++)
        sorted_row(src + idx[i] * width, width, n_facts, read, tmp,
                   (int64_t *)b[2].buf + i * width, (uint64_t *)b[3].buf + i * n_words, n_words);
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
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_fixpoint",
    "The grounder's relaxed reachability and relevance fixpoints, compiled.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__fixpoint(void) { return PyModule_Create(&module); }
