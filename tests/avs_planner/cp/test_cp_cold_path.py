"""The faster pieces of a cold planning call agree with the plain definitions they replace:
the compiled gather of a call's kept rows (`derived.task_rows`) with the numpy path, and
numeric values looked up by atom code (`encoding.NumericValues`) with dict lookups."""

from __future__ import annotations

import numpy as np
import pytest

from avs_planner.cp import derived
from avs_planner.cp.encoding import NumericValues
from avs_planner.cp.grounding import GroundingCache, world_state


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
        for got, expected in zip(compiled[0] + compiled[1], plain[0] + plain[1], strict=True):
            assert got.dtype == expected.dtype and np.array_equal(got, expected)
    empty = derived.task_rows(st, np.zeros(0, dtype=np.int64), np.ones(n + 2, bool))
    assert all(m.shape[0] == 0 for m in empty[0] + empty[1])


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
