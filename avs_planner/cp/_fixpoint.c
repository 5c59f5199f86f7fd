/* The grounder's two per-call fixpoints (avs_planner/cp/grounding.py), compiled.
 *
 * Both run over the cached grounding structure's rows (one row per statically possible ground
 * action, entries are fact ids in int64 matrices, padded) and return one flag per row. They
 * compute the same least fixpoints as the numpy versions in grounding.py, which stay as the
 * fallback when this module is not built; tests compare the two.
 *
 * reachable: relaxed reachability. A row is active when every fact of its `pre` row is
 *   reached; its `add` facts are then reached. Counter-based: each fact, once reached, lowers
 *   the counters of the rows reading it (every occurrence counts, so duplicates are fine).
 * relevant: backward relevance. A row is kept when it adds a fact needed true or deletes one
 *   needed false; a kept row's positive conditions (pre and clause positives) become needed
 *   true, its negative ones (pre_neg and clause negatives) needed false.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* A read-only C-contiguous buffer of `count` items of `itemsize` bytes, or an error naming
 * `what`. */
static int get_buffer(PyObject *obj, Py_buffer *view, Py_ssize_t count, Py_ssize_t itemsize,
                      const char *what)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS) < 0)
        return -1;
    if (view->len != count * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes, expected %zd", what, view->len,
                     count * itemsize);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Every entry of an int64 matrix lies in [0, limit). */
static int check_range(const int64_t *v, Py_ssize_t count, int64_t limit, const char *what)
{
    for (Py_ssize_t i = 0; i < count; i++) {
        if (v[i] < 0 || v[i] >= limit) {
            PyErr_Format(PyExc_ValueError, "%s: fact id %lld outside [0, %lld)", what,
                         (long long)v[i], (long long)limit);
            return -1;
        }
    }
    return 0;
}

/* CSR of rows by fact: for each fact f < n_facts, the allowed rows with f in their row of
 * `m` (rows x width), each occurrence once. Entries >= n_facts are skipped. */
static int by_fact(const int64_t *m, Py_ssize_t rows, Py_ssize_t width, int64_t n_facts,
                   const uint8_t *allowed, Py_ssize_t **off_out, Py_ssize_t **val_out)
{
    Py_ssize_t *off = calloc((size_t)n_facts + 1, sizeof(Py_ssize_t));
    if (!off)
        return -1;
    for (Py_ssize_t r = 0; r < rows; r++) {
        if (!allowed[r])
            continue;
        for (Py_ssize_t j = 0; j < width; j++) {
            int64_t f = m[r * width + j];
            if (f < n_facts)
                off[f + 1]++;
        }
    }
    for (int64_t f = 0; f < n_facts; f++)
        off[f + 1] += off[f];
    Py_ssize_t *val = malloc(((size_t)off[n_facts] + 1) * sizeof(Py_ssize_t));
    Py_ssize_t *fill = malloc(((size_t)n_facts + 1) * sizeof(Py_ssize_t));
    if (!val || !fill) {
        free(off);
        free(val);
        free(fill);
        return -1;
    }
    memcpy(fill, off, (size_t)n_facts * sizeof(Py_ssize_t));
    for (Py_ssize_t r = 0; r < rows; r++) {
        if (!allowed[r])
            continue;
        for (Py_ssize_t j = 0; j < width; j++) {
            int64_t f = m[r * width + j];
            if (f < n_facts)
                val[fill[f]++] = r;
        }
    }
    free(fill);
    *off_out = off;
    *val_out = val;
    return 0;
}

static PyObject *reachable(PyObject *self, PyObject *args)
{
    PyObject *pre_o, *add_o, *init_o, *allowed_o;
    Py_ssize_t rows, pw, aw, n_slots, never;
    if (!PyArg_ParseTuple(args, "nOnOnnnOO", &rows, &pre_o, &pw, &add_o, &aw, &n_slots,
                          &never, &init_o, &allowed_o))
        return NULL;
    if (rows < 0 || pw < 0 || aw < 0 || n_slots < 1 || never < 0 || never >= n_slots) {
        PyErr_SetString(PyExc_ValueError, "reachable: bad sizes");
        return NULL;
    }
    Py_buffer pre_b, add_b, init_b, allowed_b;
    if (get_buffer(pre_o, &pre_b, rows * pw, 8, "reachable: pre") < 0)
        return NULL;
    if (get_buffer(add_o, &add_b, rows * aw, 8, "reachable: add") < 0)
        goto fail_pre;
    if (get_buffer(init_o, &init_b, n_slots, 1, "reachable: init") < 0)
        goto fail_add;
    if (get_buffer(allowed_o, &allowed_b, rows, 1, "reachable: allowed") < 0)
        goto fail_init;
    const int64_t *pre = pre_b.buf, *add = add_b.buf;
    const uint8_t *init = init_b.buf, *allowed = allowed_b.buf;
    PyObject *out = NULL;
    Py_ssize_t *off = NULL, *val = NULL, *count = NULL, *queue = NULL;
    uint8_t *reached = NULL;
    if (check_range(pre, rows * pw, n_slots, "reachable: pre") < 0 ||
        check_range(add, rows * aw, n_slots, "reachable: add") < 0)
        goto done;
    out = PyByteArray_FromStringAndSize(NULL, rows);
    if (!out)
        goto done;
    uint8_t *active = (uint8_t *)PyByteArray_AS_STRING(out);
    memset(active, 0, (size_t)rows);
    count = malloc(((size_t)rows + 1) * sizeof(Py_ssize_t));
    queue = malloc(((size_t)n_slots + 1) * sizeof(Py_ssize_t));
    reached = calloc((size_t)n_slots, 1);
    if (!count || !queue || !reached || by_fact(pre, rows, pw, n_slots, allowed, &off, &val) < 0) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t head = 0, tail = 0;
    for (Py_ssize_t r = 0; r < rows; r++)
        count[r] = pw;
    for (Py_ssize_t f = 0; f < n_slots; f++) {
        if (init[f] && f != never) {
            reached[f] = 1;
            queue[tail++] = f;
        }
    }
    for (Py_ssize_t r = 0; pw == 0 && r < rows; r++) { /* no preconditions: fire at once */
        if (!allowed[r])
            continue;
        active[r] = 1;
        for (Py_ssize_t j = 0; j < aw; j++) {
            int64_t g = add[r * aw + j];
            if (g != never && !reached[g]) {
                reached[g] = 1;
                queue[tail++] = g;
            }
        }
    }
    while (head < tail) {
        Py_ssize_t f = queue[head++];
        for (Py_ssize_t k = off[f]; k < off[f + 1]; k++) {
            Py_ssize_t r = val[k];
            if (--count[r] != 0)
                continue;
            active[r] = 1;
            for (Py_ssize_t j = 0; j < aw; j++) {
                int64_t g = add[r * aw + j];
                if (g != never && !reached[g]) {
                    reached[g] = 1;
                    queue[tail++] = g;
                }
            }
        }
    }
done:
    free(off);
    free(val);
    free(count);
    free(queue);
    free(reached);
    PyBuffer_Release(&allowed_b);
    PyBuffer_Release(&init_b);
    PyBuffer_Release(&add_b);
    PyBuffer_Release(&pre_b);
    return out;
fail_init:
    PyBuffer_Release(&init_b);
fail_add:
    PyBuffer_Release(&add_b);
fail_pre:
    PyBuffer_Release(&pre_b);
    return NULL;
}

typedef struct {
    uint8_t *need_true, *need_false;
    Py_ssize_t *queue; /* fact * 2 + (1 if needed false) */
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
        s->queue[s->tail++] = (Py_ssize_t)f * 2 + negative;
    }
}

static PyObject *relevant(PyObject *self, PyObject *args)
{
    PyObject *add_o, *del_o, *pre_o, *neg_o, *coff_o, *cpos_o, *cneg_o, *allowed_o, *gt_o,
        *gf_o;
    Py_ssize_t rows, aw, dw, pw, nw, n, n_slots, cpos_n, cneg_n, gt_n, gf_n;
    if (!PyArg_ParseTuple(args, "nnnOnOnOnOnOOnOnOOnOn", &rows, &n, &n_slots, &add_o, &aw,
                          &del_o, &dw, &pre_o, &pw, &neg_o, &nw, &coff_o, &cpos_o, &cpos_n,
                          &cneg_o, &cneg_n, &allowed_o, &gt_o, &gt_n, &gf_o, &gf_n))
        return NULL;
    if (rows < 0 || n < 0 || n_slots < n || aw < 0 || dw < 0 || pw < 0 || nw < 0 ||
        cpos_n < 0 || cneg_n < 0 || gt_n < 0 || gf_n < 0) {
        PyErr_SetString(PyExc_ValueError, "relevant: bad sizes");
        return NULL;
    }
    Py_buffer b[10];
    int got = 0;
    PyObject *out = NULL;
    Py_ssize_t *aoff = NULL, *aval = NULL, *doff = NULL, *dval = NULL;
    Needs s = {0};
    s.n = n;
    /* clause facts per row, interleaved offsets (2 * (rows + 1) entries): row r's positives
     * are cpos[coff[2r] .. coff[2r + 2]), its negatives cneg[coff[2r + 1] .. coff[2r + 3]) */
    const Py_ssize_t sizes[10] = {rows * aw, rows * dw, rows * pw, rows * nw, 2 * (rows + 1),
                                  cpos_n, cneg_n, rows, gt_n, gf_n};
    const Py_ssize_t items[10] = {8, 8, 8, 8, 8, 8, 8, 1, 8, 8};
    PyObject *objs[10] = {add_o, del_o, pre_o, neg_o, coff_o, cpos_o, cneg_o, allowed_o, gt_o,
                          gf_o};
    static const char *names[10] = {"relevant: add", "relevant: delete", "relevant: pre",
                                    "relevant: pre_neg", "relevant: clause offsets",
                                    "relevant: clause positives", "relevant: clause negatives",
                                    "relevant: allowed", "relevant: goal", "relevant: goal_neg"};
    for (; got < 10; got++)
        if (get_buffer(objs[got], &b[got], sizes[got], items[got], names[got]) < 0)
            goto done;
    const int64_t *add = b[0].buf, *del = b[1].buf, *pre = b[2].buf, *neg = b[3].buf;
    const int64_t *coff = b[4].buf, *cpos = b[5].buf, *cneg = b[6].buf;
    const uint8_t *allowed = b[7].buf;
    const int64_t *gt = b[8].buf, *gf = b[9].buf;
    for (int k = 0; k < 4; k++)
        if (check_range(b[k].buf, sizes[k], n_slots, names[k]) < 0)
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
    if (!out)
        goto done;
    uint8_t *kept = (uint8_t *)PyByteArray_AS_STRING(out);
    memset(kept, 0, (size_t)rows);
    s.need_true = calloc((size_t)n + 1, 1);
    s.need_false = calloc((size_t)n + 1, 1);
    s.queue = malloc(((size_t)n * 2 + 1) * sizeof(Py_ssize_t));
    if (!s.need_true || !s.need_false || !s.queue ||
        by_fact(add, rows, aw, n, allowed, &aoff, &aval) < 0 ||
        by_fact(del, rows, dw, n, allowed, &doff, &dval) < 0) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t k = 0; k < gt_n; k++)
        need(&s, gt[k], 0);
    for (Py_ssize_t k = 0; k < gf_n; k++)
        need(&s, gf[k], 1);
    for (Py_ssize_t head = 0; head < s.tail; head++) {
        Py_ssize_t item = s.queue[head];
        Py_ssize_t f = item / 2;
        int negative = (int)(item % 2);
        const Py_ssize_t *off = negative ? doff : aoff, *val = negative ? dval : aval;
        for (Py_ssize_t k = off[f]; k < off[f + 1]; k++) {
            Py_ssize_t r = val[k];
            if (kept[r])
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
    free(aoff);
    free(aval);
    free(doff);
    free(dval);
    free(s.need_true);
    free(s.need_false);
    free(s.queue);
    for (int k = 0; k < got; k++)
        PyBuffer_Release(&b[k]);
    return out;
}

static PyMethodDef methods[] = {
    {"reachable", reachable, METH_VARARGS,
     "reachable(rows, pre, pre_width, add, add_width, n_slots, never, init, allowed) -> "
     "bytearray: 1 for each row relaxed-reachable from init (a fact id `never` is never "
     "reached)"},
    {"relevant", relevant, METH_VARARGS,
     "relevant(rows, n, n_slots, add, aw, delete, dw, pre, pw, pre_neg, nw, clause_offsets, "
     "clause_pos, n_pos, clause_neg, n_neg, allowed, goal, n_goal, goal_neg, n_goal_neg) -> "
     "bytearray: 1 for each allowed row that can contribute to the goal"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_fixpoint",
    "The grounder's relaxed reachability and relevance fixpoints, compiled.", -1, methods,
};

PyMODINIT_FUNC PyInit__fixpoint(void) { return PyModule_Create(&module); }
