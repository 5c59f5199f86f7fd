"""The ground actions of a grounded task, built only when somebody reads them.

The native search core reads a task's arrays (`GroundTask.arrays`), not its `GroundAction`
objects, and a plan names a dozen of the task's thousands of actions. Building every action
as a Python object cost about a third of a cold planning call on office-scale AVS problems,
so `ActionTable` builds an action on first access (all of them when iterated) and finds one
by name and arguments through the grounding structure without building the others.
"""

from __future__ import annotations

import operator
from collections.abc import Iterator, Sequence
from typing import overload

import numpy as np

from avs_planner.cp.structure import GroundStructure
from avs_planner.cp.task import GroundAction


class ActionTable(Sequence[GroundAction]):
    """Action i of the task is row `rows[i]` of the structure, with its effects on facts
    nothing reads dropped (`read_mask`) and the cost and probability of this call."""

    __slots__ = ("_st", "_rows", "_cost", "_probability", "_read", "_built", "_all",
                 "_blocks", "_objects", "memo")

    def __init__(self, structure: GroundStructure, rows: np.ndarray, cost: np.ndarray,
                 probability: np.ndarray, read_mask: int):
        self._st = structure
        self._rows = rows
        self._cost = cost
        self._probability = probability
        self._read = read_mask
        self._built: dict[int, GroundAction] = {}
        self._all: tuple[GroundAction, ...] | None = None
        self._blocks: dict[str, int] | None = None
        self._objects: dict[str, int] | None = None
        self.memo: dict[str, object] = {}
        """What consumers derive from these actions (the native packer's task), kept with
        them so it goes when the task goes."""

    def __len__(self) -> int:
        return len(self._rows)

    @overload
    def __getitem__(self, i: int) -> GroundAction: ...

    @overload
    def __getitem__(self, i: slice) -> tuple[GroundAction, ...]: ...

    def __getitem__(self, i):
        if self._all is not None:
            return self._all[i]
        if isinstance(i, slice):
            return tuple(self)[i]
        i, n = operator.index(i), len(self._rows)
        if not -n <= i < n:
            raise IndexError("action index out of range")
        i %= n
        hit = self._built.get(i)
        return hit if hit is not None else self.take([i])[0]

    def __iter__(self) -> Iterator[GroundAction]:
        if self._all is None:
            self._all = tuple(self.take(range(len(self._rows))))
        return iter(self._all)

    def __eq__(self, other: object) -> bool:
        if other is self:
            return True
        if isinstance(other, (ActionTable, tuple)):
            return tuple(self) == tuple(other)
        return NotImplemented

    def __hash__(self) -> int:
        return hash(tuple(self))

    def __repr__(self) -> str:
        return f"ActionTable({len(self)} actions)"

    def take(self, indices) -> list[GroundAction]:
        """The actions at these indices (0 <= i < len), building (and keeping) the missing
        ones together."""
        indices = [operator.index(i) for i in indices]
        if indices and not 0 <= min(indices) <= max(indices) < len(self._rows):
            raise IndexError("action index out of range")
        built = self._built
        missing = [i for i in indices if i not in built]
        if missing:
            rows = self._rows[missing].tolist()
            read = self._read
            unread = ~read
            costs = self._cost[missing].tolist()
            probabilities = self._probability[missing].tolist()
            for k, (i, info) in enumerate(zip(missing, self._st.rows(rows), strict=True)):
                (name, args, pre, neg, add, delete, pre_facts, add_facts, clauses, assume,
                 _) = info
                if add & unread:
                    add &= read
                    add_facts = tuple(f for f in add_facts if read >> f & 1)
                built[i] = GroundAction(
                    i, name, args, pre, neg, add, delete & read, costs[k], probabilities[k],
                    assume, pre_facts, add_facts, clauses,
                )
        return [built[i] for i in indices]

    def find(self, name: str, args: Sequence[str]) -> GroundAction | None:
        """The action with this name and arguments (case-insensitive), if the task has it.

        The structure's rows of one schema are sorted by their argument ids, parameter by
        parameter, so the row is found by narrowing a range per argument."""
        st = self._st
        if self._blocks is None:  # objects first: `_blocks` set means both are
            self._objects = {n.lower(): i for i, n in enumerate(st.space.names)}
            self._blocks = {b.schema.name.lower(): k for k, b in enumerate(st.blocks)}
        k = self._blocks.get(name.lower())
        if k is None:
            return None
        block = st.blocks[k]
        params = block.schema.params
        if len(args) != len(params):
            return None
        lo, hi = 0, block.stop - block.start
        for param, arg in zip(params, args, strict=True):
            obj = self._objects.get(arg.lower())
            if obj is None:
                return None
            first, last = np.searchsorted(block.columns[param][lo:hi], (obj, obj + 1))
            lo, hi = lo + int(first), lo + int(last)
            if lo >= hi:
                return None
        row = block.start + lo
        at = int(np.searchsorted(self._rows, row))
        if at < len(self._rows) and int(self._rows[at]) == row:
            return self[at]
        return None
