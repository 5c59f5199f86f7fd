"""The faster pieces of a cold planning call agree with the plain definitions they replace:
the compiled gather of a call's kept rows (`derived.task_rows`) with the numpy path, and
numeric values looked up by atom code (`encoding.NumericValues`) with dict lookups."""

from __future__ import annotations

import numpy as np
import pytest

from avs_planner.cp import derived
from avs_planner.cp.encoding import NumericValues
from avs_planner.cp.grounding import GroundingCache, world_state
from avs_planner.cp.task import WorldState


@pytest.fixture(scope="module")
def corridor_structure(corridor):
    state = world_state(corridor.problem)
    return GroundingCache().structure(corridor, state), state


@pytest.mark.skipif(derived._fixpoint is None, reason="compiled fixpoints not built")
def test_compiled_task_rows_equal_the_numpy_path(corridor_structure, monkeypatch):
    st, _ = corridor_structure
    n = len(st.facts)
    rng = np.random.default_rng(7)
    for _ in range(4):
        rows = np.sort(rng.choice(st.size, size=st.size // 2, replace=False))
        read = rng.random(n + 2) < 0.6
        compiled = derived.task_rows(st, rows, read)
        with monkeypatch.context() as m:
            m.setattr(derived, "_fixpoint", None)
            plain = derived.task_rows(st, rows, read)
            st.memo.pop("derived")  # made without the compiled indexes: not for later tests
        assert len(compiled) == len(plain) == 4  # pre, pre_neg, add, delete
        for got, expected in zip(compiled, plain, strict=True):
            assert got.dtype == expected.dtype and np.array_equal(got, expected)
    empty = derived.task_rows(st, np.zeros(0, dtype=np.int64), np.ones(n + 2, bool))
    assert all(m.shape[0] == 0 for m in empty)


def test_numeric_values_by_code_match_dict_lookups(corridor_structure):
    st, state = corridor_structure
    space = st.space
    extra = {("p-obj-in", "nowhere", "x", "y"): 0.5,  # unknown objects: never matched
             ("p-obj-in", "a"): 0.25}  # wrong arity: never matched
    values = NumericValues(space, {**state.values, **extra})
    by_fluent: dict[str, list] = {}
    for atom in state.values:
        by_fluent.setdefault(atom[0], []).append(atom)
    assert by_fluent
    for fluent, atoms in by_fluent.items():
        codes = np.array([space.encode(a) for a in atoms], dtype=np.int64)
        found_values, found = values.lookup(fluent, codes)
        assert found.all()
        assert found_values.tolist() == [state.values[a] for a in atoms]
        # every other code of the fluent has no value
        base, count = space.base[fluent], len(atoms)
        others = np.setdiff1d(np.arange(base, min(base + 4 * count + 8, space.size)), codes)
        others = others[[space.decode(int(c))[0] == fluent for c in others]]
        assert not values.lookup(fluent, others)[1].any()
    assert not values.lookup("at", np.array([space.base["at"]]))[1].any()


def _swap(atom, a, b):
    return (atom[0], *(b if x == a else a if x == b else x for x in atom[1:]))


def _pairwise_classes(names, state):
    """The definition: a joins the first class whose first member it can swap with, the
    swap mapping every true atom to a true atom and every value to an equal value."""
    def interchangeable(a, b):
        atoms = [x for x in (*state.true_atoms, *state.values) if a in x[1:] or b in x[1:]]
        for atom in atoms:
            other = _swap(atom, a, b)
            if atom in state.true_atoms:
                if other not in state.true_atoms:
                    return False
            elif state.values.get(atom) != state.values.get(other):
                return False
        return True

    classes: list[list[str]] = []
    for name in names:
        for cls in classes:
            if interchangeable(cls[0], name):
                cls.append(name)
                break
        else:
            classes.append([name])
    return [tuple(c) for c in classes]


def _random_state(rng, names):
    """Atoms over a few objects, some of them made symmetric on purpose (copies of o0)."""
    atoms, values = set(), {}
    for _ in range(rng.integers(0, 12)):
        args = tuple(rng.choice(names, size=rng.integers(1, 4)))
        if rng.random() < 0.5:
            atoms.add(("p", *args))
        else:
            values[("v", *args)] = float(rng.integers(0, 3))
    for twin in names[1:3]:  # o1, o2 mirror o0 in unary atoms
        atoms |= {(a[0], twin) for a in atoms if a[1:] == (names[0],)}
        values |= {(a[0], twin): v for a, v in values.items() if a[1:] == (names[0],)}
    return WorldState(frozenset(atoms), values)


def test_symmetry_classes_match_the_pairwise_definition(corridor):
    from avs_planner.cp.symmetry import _mentions, _partition

    rng = np.random.default_rng(11)
    names = [f"o{i}" for i in range(6)]
    shapes = set()
    for _ in range(300):
        state = _random_state(rng, names)
        order = list(rng.permutation(names))
        got = _partition(order, state, _mentions(state, set(order)))
        assert got == _pairwise_classes(order, state)
        shapes.add(tuple(sorted(map(len, got))))
    assert len(shapes) >= 5  # the states gave many different partitions
    state = world_state(corridor.problem)
    by_type: dict[str, list[str]] = {}
    for obj in corridor.problem.all_objects:
        by_type.setdefault(str(obj.type), []).append(obj.name)
    for group in by_type.values():
        got = _partition(group, state, _mentions(state, set(group)))
        assert got == _pairwise_classes(group, state)


def test_fact_numbering_writes_into_out_as_it_returns():
    from avs_planner.cp.structure import _PAD_NONE, _PAD_TRUE, _fact_numbering

    rng = np.random.default_rng(5)
    array = rng.integers(0, 300, size=(30, 4))
    array[::3, 1], array[::5, 3] = _PAD_TRUE, _PAD_NONE
    for space_size in (300, 10**15):  # the dense table and the sorted path
        _, renumber = _fact_numbering(space_size, [array], np.zeros(0, dtype=np.int64))
        out = np.full((30, 4), -7, dtype=np.int64)
        assert renumber(array, out) is out
        assert out.tolist() == renumber(array).tolist()


def test_reachability_over_its_own_result_is_that_result(corridor_structure):
    """The grounder skips its second reachability pass when no row was dropped (p = 0):
    reachable(init, allowed=reachable(init, all rows)) must then be the first result."""
    st, state = corridor_structure
    n = len(st.facts)
    rng = np.random.default_rng(2)
    for _ in range(5):
        init = np.zeros(n + 2, dtype=bool)
        init[rng.choice(n, size=n // 4, replace=False)] = True
        init[n] = True
        allowed = rng.random(st.size) < 0.8
        first = derived.reachable(st, init, allowed)
        assert first.any()
        assert np.array_equal(derived.reachable(st, init, first), first)
