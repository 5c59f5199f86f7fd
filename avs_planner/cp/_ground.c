/* The cached grounding structure's construction, compiled (avs_planner/cp/bindings.py and
 * structure.py call it).
 *
 * Those modules build the same arrays with numpy when this one is not built; tests compare
 * the two. Atoms are integer codes (avs_planner/cp/encoding.py): a lifted atom's code under a
 * binding is base + sum(stride * local[object of parameter]), `local` being a table of each
 * object's position among the objects of one type (read from one flat `locals` buffer at an
 * offset).
 *
 * join: every binding of a schema's parameters consistent with its static atoms and
 *   (in)equalities. Nested loops over the parameters in a given join order; a check runs as
 *   soon as the parameters it reads are bound. The rows come out of the loops in
 *   lexicographic order of the join order and are then sorted (stable counting sorts) into
 *   lexicographic order of the parameters.
 * encode: the codes of lifted atoms under each row of bindings.
 * number: the atom codes used by a list of code arrays (sorted), and a table from code to
 *   fact id (the pads -1 and -2, read from the table's last two slots, map to n and n + 1).
 * renumber: code arrays of varying widths written through that table, one after the other,
 *   into one matrix, each row padded on the right.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { CHECK_IN = 0, CHECK_OUT = 1, CHECK_EQ = 2, CHECK_NE = 3 };
enum { JOIN_OK = 0, JOIN_TOO_MANY_PARTIAL = 1, JOIN_TOO_MANY_ROWS = 2 };

/* A C-contiguous buffer of int64 (or, with itemsize 1, bytes) of any length. */
static int get_items(PyObject *obj, Py_buffer *view, Py_ssize_t itemsize, const char *what,
                     int writable)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (view->len % itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes, not a multiple of %zd", what, view->len,
                     itemsize);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* The static atoms: a byte per code (dense) or sorted codes (binary search). */
typedef struct {
    const uint8_t *table;
    const int64_t *sorted;
    Py_ssize_t size;
} StaticSet;

static int is_static(const StaticSet *s, int64_t code)
{
    if (s->table)
        return code >= 0 && code < s->size && s->table[code];
    Py_ssize_t lo = 0, hi = s->size;
    while (lo < hi) {
        Py_ssize_t mid = lo + (hi - lo) / 2;
        if (s->sorted[mid] < code)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < s->size && s->sorted[lo] == code;
}

/* A check record: level, kind, n_terms, base, then n_terms (param, stride, local_off). */
typedef struct {
    const int64_t *checks;  /* the flat records */
    Py_ssize_t n_checks;    /* int64 items */
    const int64_t *locals;  /* flat local tables */
    Py_ssize_t n_locals;
    Py_ssize_t n_objects;
    Py_ssize_t n_params;
    const int64_t *order;   /* the parameter bound at each level (a permutation) */
} Checks;

/* The join level at which parameter p is bound. */
static Py_ssize_t level_of(const Checks *c, int64_t p)
{
    for (Py_ssize_t l = 0; l < c->n_params; l++)
        if (c->order[l] == p)
            return l;
    return c->n_params;
}

/* Records well formed: levels in [-1, n_params), terms name bound parameters (or, for the
 * (in)equalities, objects) and local tables inside `locals`. */
static int validate_checks(const Checks *c)
{
    Py_ssize_t i = 0;
    while (i < c->n_checks) {
        if (i + 4 > c->n_checks)
            goto bad;
        int64_t level = c->checks[i], kind = c->checks[i + 1], n_terms = c->checks[i + 2];
        if (level < -1 || level >= c->n_params || kind < 0 || kind > 3 || n_terms < 0 ||
            i + 4 + 3 * n_terms > c->n_checks || (kind >= CHECK_EQ && n_terms != 2))
            goto bad;
        const int64_t *t = c->checks + i + 4;
        for (int64_t k = 0; k < n_terms; k++, t += 3) {
            if (kind >= CHECK_EQ) {
                if (t[0] >= c->n_params || (t[0] < 0 && -(t[0] + 1) >= c->n_objects) ||
                    (t[0] >= 0 && level_of(c, t[0]) > level))
                    goto bad;
            } else if (t[0] < 0 || t[0] >= c->n_params || t[2] < 0 ||
                       t[2] + c->n_objects > c->n_locals || level_of(c, t[0]) > level) {
                goto bad;
            }
        }
        i += 4 + 3 * n_terms;
    }
    return 0;
bad:
    PyErr_Format(PyExc_ValueError, "join: malformed check record at item %zd", i);
    return -1;
}

static int64_t term_value(int64_t term, const int64_t *binding)
{
    return term >= 0 ? binding[term] : -(term + 1);
}

/* The checks of one level (their record offsets listed in `at`) hold under `binding`. */
static int checks_hold(const Checks *c, const StaticSet *s, const Py_ssize_t *at, Py_ssize_t n,
                       const int64_t *binding)
{
    for (Py_ssize_t k = 0; k < n; k++) {
        const int64_t *r = c->checks + at[k];
        int64_t kind = r[1], n_terms = r[2];
        const int64_t *t = r + 4;
        int ok;
        if (kind >= CHECK_EQ) {
            ok = (term_value(t[0], binding) == term_value(t[3], binding)) == (kind == CHECK_EQ);
        } else {
            int64_t code = r[3];
            for (int64_t j = 0; j < n_terms; j++, t += 3)
                code += t[1] * c->locals[t[2] + binding[t[0]]];
            ok = is_static(s, code) == (kind == CHECK_IN);
        }
        if (!ok)
            return 0;
    }
    return 1;
}

/* Rows (n_params ids each, in lexicographic order of the join order) into lexicographic
 * order of the parameters: nothing to do when the join order is the parameters' order, else
 * a stable counting sort of row indices per parameter, last to first (LSD radix sort), then
 * one gather of the rows. */
static int sort_rows(int64_t *rows, Py_ssize_t n, Py_ssize_t n_params, const int64_t *order,
                     Py_ssize_t n_objects)
{
    Py_ssize_t in_order = 0;
    while (in_order < n_params && order[in_order] == in_order)
        in_order++;
    if (in_order == n_params)
        return 0;
    int64_t *copy = malloc((size_t)n * n_params * sizeof(int64_t));
    Py_ssize_t *idx = malloc((size_t)n * sizeof(Py_ssize_t));
    Py_ssize_t *next = malloc((size_t)n * sizeof(Py_ssize_t));
    Py_ssize_t *count = malloc(((size_t)n_objects + 1) * sizeof(Py_ssize_t));
    if (!copy || !idx || !next || !count) {
        free(copy);
        free(idx);
        free(next);
        free(count);
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t r = 0; r < n; r++)
        idx[r] = r;
    for (Py_ssize_t p = n_params - 1; p >= 0; p--) {
        const int64_t *column = rows + p;
        memset(count, 0, ((size_t)n_objects + 1) * sizeof(Py_ssize_t));
        for (Py_ssize_t r = 0; r < n; r++)
            count[column[idx[r] * n_params] + 1]++;
        for (Py_ssize_t k = 0; k < n_objects; k++)
            count[k + 1] += count[k];
        for (Py_ssize_t r = 0; r < n; r++)
            next[count[column[idx[r] * n_params]]++] = idx[r];
        Py_ssize_t *swap = idx;
        idx = next;
        next = swap;
    }
    memcpy(copy, rows, (size_t)n * n_params * sizeof(int64_t));
    for (Py_ssize_t r = 0; r < n; r++)
        for (Py_ssize_t p = 0; p < n_params; p++)
            rows[r * n_params + p] = copy[idx[r] * n_params + p];
    free(copy);
    free(idx);
    free(next);
    free(count);
    return 0;
}

static PyObject *join(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *dom_off_o, *dom_o, *order_o, *checks_o, *locals_o, *static_o, *result = NULL;
    Py_ssize_t n_objects, max_partial, max_rows;
    int dense;
    if (!PyArg_ParseTuple(args, "nOOOOOOpnn", &n_objects, &dom_off_o, &dom_o, &order_o,
                          &checks_o, &locals_o, &static_o, &dense, &max_partial, &max_rows))
        return NULL;
    Py_buffer b[6];
    int got = 0;
    PyObject *objs[6] = {dom_off_o, dom_o, order_o, checks_o, locals_o, static_o};
    const char *names[6] = {"join: domain offsets", "join: domains", "join: order",
                            "join: checks", "join: locals", "join: static atoms"};
    int64_t *binding = NULL, *out = NULL;
    Py_ssize_t *at = NULL, *by_level = NULL, *level_start = NULL;
    for (; got < 6; got++)
        if (get_items(objs[got], &b[got], got == 5 && dense ? 1 : 8, names[got], 0) < 0)
            goto done;
    Py_ssize_t n_params = b[2].len / 8;
    const int64_t *dom_off = b[0].buf, *dom = b[1].buf, *order = b[2].buf;
    if (b[0].len / 8 != n_params + 1 || n_objects < 0 || max_partial < 0 || max_rows < 0) {
        PyErr_SetString(PyExc_ValueError, "join: bad sizes");
        goto done;
    }
    for (Py_ssize_t l = 0; l < n_params; l++) {
        if (order[l] < 0 || order[l] >= n_params || dom_off[l] < 0 || dom_off[l] > dom_off[l + 1]
            || dom_off[l + 1] > b[1].len / 8) {
            PyErr_SetString(PyExc_ValueError, "join: bad order or domain offsets");
            goto done;
        }
    }
    for (Py_ssize_t l = 0; l < n_params; l++)
        for (Py_ssize_t m = 0; m < l; m++)
            if (order[m] == order[l]) {
                PyErr_SetString(PyExc_ValueError, "join: order is not a permutation");
                goto done;
            }
    for (Py_ssize_t i = 0; i < b[1].len / 8; i++)
        if (dom[i] < 0 || dom[i] >= n_objects) {
            PyErr_SetString(PyExc_ValueError, "join: object id out of range");
            goto done;
        }
    Checks c = {b[3].buf, b[3].len / 8, b[4].buf, b[4].len / 8, n_objects, n_params, order};
    StaticSet s = {dense ? b[5].buf : NULL, dense ? NULL : b[5].buf, dense ? b[5].len
                                                                           : b[5].len / 8};
    if (validate_checks(&c) < 0)
        goto done;
    /* records grouped by level (-1 first), as offsets into the flat array */
    size_t np1 = (size_t)n_params + 2;
    binding = calloc((size_t)n_params + 1, sizeof(int64_t));
    at = calloc((size_t)n_params + 1, sizeof(Py_ssize_t));
    level_start = calloc(np1, sizeof(Py_ssize_t));
    by_level = calloc((size_t)c.n_checks / 4 + 1, sizeof(Py_ssize_t));
    if (!binding || !at || !level_start || !by_level) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t n_records = 0;
    for (Py_ssize_t i = 0; i < c.n_checks; i += 4 + 3 * c.checks[i + 2], n_records++)
        level_start[c.checks[i] + 2]++;
    for (size_t l = 1; l < np1; l++)
        level_start[l] += level_start[l - 1];
    {
        Py_ssize_t *fill = calloc(np1, sizeof(Py_ssize_t));
        if (!fill) {
            PyErr_NoMemory();
            goto done;
        }
        memcpy(fill, level_start, np1 * sizeof(Py_ssize_t));
        for (Py_ssize_t i = 0; i < c.n_checks; i += 4 + 3 * c.checks[i + 2])
            by_level[fill[c.checks[i] + 1]++] = i;
        free(fill);
    }
    /* level l's records: by_level[level_start[l + 1] .. level_start[l + 2]) (l = -1 first) */
    Py_ssize_t rows = 0, cap = 0, partial = 0;
    int status = JOIN_OK;
    if (checks_hold(&c, &s, by_level, level_start[1], binding)) {
        if (n_params == 0) {
            rows = 1;
        } else {
            Py_ssize_t l = 0;
            at[0] = dom_off[0];
            while (l >= 0) {
                if (at[l] == dom_off[l + 1]) {
                    if (--l >= 0)
                        at[l]++;
                    continue;
                }
                binding[order[l]] = dom[at[l]];
                if (++partial > max_partial) {
                    status = JOIN_TOO_MANY_PARTIAL;
                    break;
                }
                if (!checks_hold(&c, &s, by_level + level_start[l + 1],
                                 level_start[l + 2] - level_start[l + 1], binding)) {
                    at[l]++;
                    continue;
                }
                if (l < n_params - 1) {
                    l++;
                    at[l] = dom_off[l];
                    continue;
                }
                if (rows == max_rows) {
                    status = JOIN_TOO_MANY_ROWS;
                    break;
                }
                if (rows == cap) {
                    cap = cap ? 2 * cap : 256;
                    int64_t *grown = realloc(out, (size_t)cap * n_params * sizeof(int64_t));
                    if (!grown) {
                        PyErr_NoMemory();
                        goto done;
                    }
                    out = grown;
                }
                for (Py_ssize_t p = 0; p < n_params; p++)
                    out[rows * n_params + p] = binding[p];
                rows++;
                at[l]++;
            }
        }
    }
    if (status != JOIN_OK)
        rows = 0;
    if (rows > 1 && sort_rows(out, rows, n_params, order, n_objects) < 0)
        goto done;
    PyObject *bytes = PyByteArray_FromStringAndSize(out ? (const char *)out : "",
                                                    rows * n_params * 8);
    if (bytes) {
        result = Py_BuildValue("Nni", bytes, rows, status);
    }
done:
    free(binding);
    free(at);
    free(level_start);
    free(by_level);
    free(out);
    for (int j = 0; j < got; j++)
        PyBuffer_Release(&b[j]);
    return result;
}

/* out[r][k] = template k's code under row r: per template, a pass over the rows per term. */
static void encode_rows(const int64_t *restrict rows, Py_ssize_t n_rows, Py_ssize_t n_params,
                        const int64_t *restrict tpl, const Py_ssize_t *starts,
                        Py_ssize_t n_templates, const int64_t *restrict locals,
                        int64_t *restrict out)
{
    for (Py_ssize_t k = 0; k < n_templates; k++) {
        const int64_t *t = tpl + starts[k];
        const int64_t base = t[0];
        for (Py_ssize_t r = 0; r < n_rows; r++)
            out[r * n_templates + k] = base;
        for (int64_t j = 0; j < t[1]; j++) {
            const int64_t param = t[2 + 3 * j], stride = t[3 + 3 * j];
            const int64_t *restrict local = locals + t[4 + 3 * j];
            for (Py_ssize_t r = 0; r < n_rows; r++)
                out[r * n_templates + k] += stride * local[rows[r * n_params + param]];
        }
    }
}

/* Template records: base, n_terms, then n_terms (param, stride, local_off). */
static PyObject *encode(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *rows_o, *templates_o, *locals_o, *out_o, *result = NULL;
    Py_ssize_t n_rows, n_params, n_objects, n_templates;
    if (!PyArg_ParseTuple(args, "OnnOnOnO", &rows_o, &n_rows, &n_params, &templates_o,
                          &n_templates, &locals_o, &n_objects, &out_o))
        return NULL;
    Py_buffer b[4];
    int got = 0;
    PyObject *objs[4] = {rows_o, templates_o, locals_o, out_o};
    const char *names[4] = {"encode: rows", "encode: templates", "encode: locals", "encode: out"};
    Py_ssize_t *starts = NULL;
    for (; got < 4; got++)
        if (get_items(objs[got], &b[got], 8, names[got], got == 3) < 0)
            goto done;
    if (n_rows < 0 || n_params < 0 || n_templates < 0 || n_objects < 0 ||
        b[0].len / 8 != n_rows * n_params || b[3].len / 8 != n_rows * n_templates) {
        PyErr_SetString(PyExc_ValueError, "encode: bad sizes");
        goto done;
    }
    const int64_t *rows = b[0].buf, *tpl = b[1].buf, *locals = b[2].buf;
    Py_ssize_t n_items = b[1].len / 8, n_locals = b[2].len / 8;
    starts = calloc((size_t)n_templates + 1, sizeof(Py_ssize_t));
    if (!starts) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t i = 0;
    for (Py_ssize_t k = 0; k < n_templates; k++) {
        if (i + 2 > n_items || tpl[i + 1] < 0 || i + 2 + 3 * tpl[i + 1] > n_items)
            goto bad;
        starts[k] = i;
        for (int64_t j = 0; j < tpl[i + 1]; j++) {
            const int64_t *t = tpl + i + 2 + 3 * j;
            if (t[0] < 0 || t[0] >= n_params || t[2] < 0 || t[2] + n_objects > n_locals)
                goto bad;
        }
        i += 2 + 3 * tpl[i + 1];
    }
    if (i != n_items)
        goto bad;
    for (Py_ssize_t r = 0; r < n_rows * n_params; r++)
        if (rows[r] < 0 || rows[r] >= n_objects) {
            PyErr_SetString(PyExc_ValueError, "encode: object id out of range");
            goto done;
        }
    encode_rows(rows, n_rows, n_params, tpl, starts, n_templates, locals, b[3].buf);
    result = Py_None;
    Py_INCREF(result);
    goto done;
bad:
    PyErr_SetString(PyExc_ValueError, "encode: malformed template records");
done:
    free(starts);
    for (int j = 0; j < got; j++)
        PyBuffer_Release(&b[j]);
    return result;
}

/* Buffers of a sequence of int64 arrays; *held counts those acquired. */
static int get_list(PyObject *seq, Py_buffer *views, Py_ssize_t n, Py_ssize_t *held,
                    const char *what)
{
    for (*held = 0; *held < n; (*held)++)
        if (get_items(PySequence_Fast_GET_ITEM(seq, *held), &views[*held], 8, what, 0) < 0)
            return -1;
    return 0;
}

static PyObject *number(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *arrays_o, *result = NULL, *seq = NULL;
    Py_ssize_t space, held = 0;
    if (!PyArg_ParseTuple(args, "nO", &space, &arrays_o))
        return NULL;
    if (space < 0) {
        PyErr_SetString(PyExc_ValueError, "number: negative code space");
        return NULL;
    }
    seq = PySequence_Fast(arrays_o, "number: arrays must be a sequence");
    if (!seq)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Py_buffer *views = calloc((size_t)n + 1, sizeof(Py_buffer));
    uint8_t *used = calloc((size_t)space + 1, 1);
    PyObject *table = NULL, *codes = NULL;
    if (!views || !used) {
        PyErr_NoMemory();
        goto done;
    }
    if (get_list(seq, views, n, &held, "number: codes") < 0)
        goto done;
    for (Py_ssize_t a = 0; a < n; a++) {
        const int64_t *v = views[a].buf;
        for (Py_ssize_t i = 0; i < views[a].len / 8; i++) {
            if (v[i] >= 0 && v[i] < space)
                used[v[i]] = 1;
            else if (v[i] != -1 && v[i] != -2) {
                PyErr_Format(PyExc_ValueError, "number: code %lld outside [-2, %zd)",
                             (long long)v[i], space);
                goto done;
            }
        }
    }
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < space; i++)
        count += used[i];
    table = PyByteArray_FromStringAndSize(NULL, (space + 2) * 8);
    codes = PyByteArray_FromStringAndSize(NULL, count * 8);
    if (!table || !codes)
        goto done;
    int64_t *t = (int64_t *)PyByteArray_AS_STRING(table), *c = (int64_t *)PyByteArray_AS_STRING(codes);
    Py_ssize_t k = 0;
    for (Py_ssize_t i = 0; i < space; i++) {
        if (used[i]) {
            c[k] = i;
            t[i] = k++;
        } else {
            t[i] = -1;
        }
    }
    t[space] = count + 1; /* code -2 */
    t[space + 1] = count; /* code -1 */
    result = Py_BuildValue("OO", codes, table);
done:
    Py_XDECREF(table);
    Py_XDECREF(codes);
    for (Py_ssize_t j = 0; j < held; j++)
        PyBuffer_Release(&views[j]);
    free(views);
    free(used);
    Py_DECREF(seq);
    return result;
}

/* One array's rows through the table into out (rows x width, padded): INT64_MIN, or the
 * first code without a fact id. */
static int64_t renumber_rows(const int64_t *restrict v, Py_ssize_t rows, Py_ssize_t w,
                             const int64_t *restrict table, Py_ssize_t size,
                             int64_t *restrict out, Py_ssize_t width, int64_t pad)
{
    for (Py_ssize_t r = 0; r < rows; r++, out += width) {
        for (Py_ssize_t j = 0; j < w; j++) {
            int64_t code = v[r * w + j], at = code < 0 ? size + code : code;
            if (at < 0 || at >= size || table[at] < 0)
                return code;
            out[j] = table[at];
        }
        for (Py_ssize_t j = w; j < width; j++)
            out[j] = pad;
    }
    return INT64_MIN;
}

static PyObject *renumber(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *table_o, *arrays_o, *shapes_o, *out_o, *result = NULL, *seq = NULL;
    Py_ssize_t width, pad, held = 0;
    if (!PyArg_ParseTuple(args, "OOOOnn", &table_o, &arrays_o, &shapes_o, &out_o, &width,
                          &pad))
        return NULL;
    seq = PySequence_Fast(arrays_o, "renumber: arrays must be a sequence");
    if (!seq)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Py_buffer tb, wb, ob, *views = calloc((size_t)n + 1, sizeof(Py_buffer));
    int got = 0;
    if (!views) {
        PyErr_NoMemory();
        goto done;
    }
    if (get_items(table_o, &tb, 8, "renumber: table", 0) < 0)
        goto done;
    got++;
    if (get_items(shapes_o, &wb, 8, "renumber: shapes", 0) < 0)
        goto done;
    got++;
    if (get_items(out_o, &ob, 8, "renumber: out", 1) < 0)
        goto done;
    got++;
    if (get_list(seq, views, n, &held, "renumber: codes") < 0)
        goto done;
    const int64_t *table = tb.buf, *shapes = wb.buf;
    Py_ssize_t size = tb.len / 8, total = 0;
    if (wb.len / 8 != 2 * n || width < 0 || size < 2) {
        PyErr_SetString(PyExc_ValueError, "renumber: bad sizes");
        goto done;
    }
    for (Py_ssize_t a = 0; a < n; a++) {
        if (shapes[2 * a] < 0 || shapes[2 * a + 1] < 0 || shapes[2 * a + 1] > width ||
            views[a].len / 8 != shapes[2 * a] * shapes[2 * a + 1]) {
            PyErr_SetString(PyExc_ValueError, "renumber: an array does not match its shape");
            goto done;
        }
        total += shapes[2 * a];
    }
    if (ob.len / 8 != total * width) {
        PyErr_SetString(PyExc_ValueError, "renumber: out has the wrong size");
        goto done;
    }
    int64_t *out = ob.buf;
    for (Py_ssize_t a = 0; a < n; a++) {
        Py_ssize_t rows = shapes[2 * a], w = shapes[2 * a + 1];
        int64_t bad = renumber_rows(views[a].buf, rows, w, table, size, out, width, pad);
        if (bad != INT64_MIN) {
            PyErr_Format(PyExc_ValueError, "renumber: code %lld has no fact id", (long long)bad);
            goto done;
        }
        out += rows * width;
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (Py_ssize_t j = 0; j < held; j++)
        PyBuffer_Release(&views[j]);
    if (got > 0)
        PyBuffer_Release(&tb);
    if (got > 1)
        PyBuffer_Release(&wb);
    if (got > 2)
        PyBuffer_Release(&ob);
    free(views);
    Py_DECREF(seq);
    return result;
}

static PyMethodDef methods[] = {
    {"join", join, METH_VARARGS,
     "join(n_objects, domain_offsets, domains, order, checks, locals, static, dense, "
     "max_partial, max_rows) -> (bytearray, rows, status): int64 rows x len(order) bindings "
     "(column p = parameter p) in lexicographic order of the parameters; status 1 when more "
     "than max_partial partial bindings were tried, 2 when more than max_rows rows came out "
     "(no rows then)"},
    {"encode", encode, METH_VARARGS,
     "encode(rows, n_rows, n_params, templates, n_templates, locals, n_objects, out): the "
     "code of each template under each row into out (n_rows x n_templates)"},
    {"number", number, METH_VARARGS,
     "number(space, arrays) -> (codes, table): the codes in [0, space) the arrays use, "
     "ascending, and int64 table[code] = its index (-1 if unused; table[-1] = n, "
     "table[-2] = n + 1)"},
    {"renumber", renumber, METH_VARARGS,
     "renumber(table, arrays, shapes, out, width, pad): each array's codes (shapes: rows and "
     "width per array) through the table (negative codes from its end) into consecutive "
     "rows of out (rows x width), the rest of each row set to pad"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ground",
    "The grounding structure's join, atom encoding and fact numbering, compiled.", -1,
    methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__ground(void) { return PyModule_Create(&module); }
