"""One object per content, held weakly: the tables behind the expression and type managers.

The managers are shared by every read in a process (as UP's global environment is), so that
a node or type of some content is the same object wherever it is made: `is` compares nodes,
and two reads of one text give equal actions, which the grounding cache keys on. A table that
kept each object for good would grow with every text a long-running process (an API worker)
reads. This one keeps an object only while something else holds it (a problem, its success
expressions, a grounding cache entry); its entry goes when the object does. Whoever can still
compare an object holds it, so the one-object-per-content rule holds exactly as before.
"""

from __future__ import annotations

from _weakref import _remove_dead_weakref  # the atomic removal WeakValueDictionary uses
from collections.abc import Hashable
from typing import Generic, TypeVar
from weakref import KeyedRef, ref

_V = TypeVar("_V")


class WeakTable(Generic[_V]):
    """Content -> the live object made for it; the value class needs a `__weakref__` slot."""

    __slots__ = ("_refs", "_drop", "__weakref__")

    def __init__(self) -> None:
        self._refs: dict[Hashable, KeyedRef] = {}
        table = ref(self)  # the entries' callback does not keep the table alive

        def drop(entry: KeyedRef) -> None:
            live = table()
            if live is not None:  # removes the key only if it still holds a dead reference
                _remove_dead_weakref(live._refs, entry.key)

        self._drop = drop

    def get(self, key: Hashable) -> _V | None:
        entry = self._refs.get(key)
        return None if entry is None else entry()

    def setdefault(self, key: Hashable, value: _V) -> _V:
        """The live object of `key` if there is one (made meanwhile), else `value`, kept from
        now on while it lives."""
        entry = KeyedRef(value, self._drop, key)
        found = self._refs.setdefault(key, entry)()
        if found is None:  # a dead entry whose removal has not run yet
            self._refs[key] = entry
            return value
        return found

    def __len__(self) -> int:
        return len(self._refs)
