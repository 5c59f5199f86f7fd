"""The target entries of a campaign file (`targets:` lists, docs/experiments.md): a label or
`{label, expected}`, a task of several objects (`{targets: [a, b], mode: all|any}`, `{label:
a, count: all, stop_below: p}`), or, for generated worlds, `auto` (the generator's own
targets) and `{auto: present, all|any: N | count: all | labels: N, ...}` (tasks over the labels
a building holds; `subjects.py`'s module doc says how they are drawn). Each entry is checked
once (`target_entries`), with errors naming its key, and resolved per world into `Wanted`s."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Any

from avs_planner.errors import AvsError
from avs_planner.experiment.values import Where

if TYPE_CHECKING:
    from avs_planner.experiment.subjects import Building

AUTO = "auto"
AUTO_PRESENT = "present"  # tasks over the labels a generated building holds
MIN_COUNTED = 2  # `{auto: present, count: all}`: labels with at least this many instances
_TARGET_KEYS = {"label", "expected"}
_TASK_KEYS = {"targets", "label", "mode", "count", "stop_below", "expected", "singles"}
_AUTO_KEYS = {"auto", "all", "any", "count", "labels", "stop_below", "pick", "singles"}
FORM_KEYS = {"auto", "label", "targets"}  # a `targets` mapping with one of these is one form
EXPECTED = ("found", "gave_up")
_FORMS = ("a label or {label, expected}, or a task: {targets: [a, b], mode: all|any} or "
          "{label: a, count: all, stop_below: p}")


@dataclass(frozen=True)
class Wanted:
    """A target entry for one world: a label or a task, the outcome to expect, and whether it
    is a single search that `singles: true` added (left out when the world's list has it)."""

    name: str
    expected: str | None = None
    task: Mapping[str, Any] | None = None
    added: bool = False

    @property
    def labels(self) -> tuple[str, ...]:
        return (self.name,) if self.task is None else tuple(self.task["targets"])

    def expected_in(self, present: set[str]) -> str:
        """The expected outcome in a world holding the labels `present` (unless given)."""
        if self.expected is not None:
            return self.expected
        there = [label in present for label in self.labels]
        if self.task is not None and self.task["count"] == "one" and self.task["mode"] == "all":
            return EXPECTED[not all(there)]
        return EXPECTED[not any(there)]



class _Entry:
    """One entry of a `targets` list, checked once; `resolve` gives what it asks of a world
    (`building`: the generated world, None for a world file)."""

    def resolve(self, building: Building | None) -> list[Wanted]:
        raise NotImplementedError


@dataclass(frozen=True)
class _Fixed(_Entry):
    wanted: tuple[Wanted, ...]

    def resolve(self, building: Building | None) -> list[Wanted]:
        return list(self.wanted)


@dataclass(frozen=True)
class _AutoTargets(_Entry):
    """`auto`: the generator's own targets (two present, one absent)."""

    where: Where

    def resolve(self, building: Building | None) -> list[Wanted]:
        assert building is not None
        return building.targets(self.where)


@dataclass(frozen=True)
class _AutoTask(_Entry):
    """`{auto: present, all: N}`, `{auto: present, any: N}`, `{auto: present, count: all}`:
    tasks over the labels each generated building holds (see the module's doc);
    `{auto: present, labels: N}`: a single search for each of its first N labels."""

    where: Where
    kind: str  # all, any, count, or labels (single searches)
    size: int | None  # all / any: labels per task; count: `pick` (None: every eligible one);
    # labels: how many labels (a single search each)
    stop_below: float | None
    singles: bool

    def resolve(self, building: Building | None) -> list[Wanted]:
        assert building is not None
        labels = building.labels(self.where)
        about = f"world seed {building.seed} ({building.name()})"
        if self.kind == "count":
            eligible = [label for label, n in labels if n >= MIN_COUNTED]
            if self.size is not None and len(eligible) < self.size:
                raise self.where.at("pick").error(
                    f"{about}: pick {self.size} asks for {self.size} labels with "
                    f"{MIN_COUNTED} or more instances; the building has {len(eligible)}"
                    + (f" ({', '.join(eligible)})" if eligible else ""))
            groups = [[label] for label in eligible[:self.size]]
        elif self.kind == "labels":
            if len(labels) < (self.size or 0):
                raise self.where.at("labels").error(
                    f"{about}: labels: {self.size} asks for {self.size} labels the building "
                    f"holds; it holds {len(labels)} "
                    f"({', '.join(label for label, _ in labels)})")
            return [Wanted(known_label(label, self.where), "found")
                    for label, _ in labels[:self.size]]
        else:
            if len(labels) < (self.size or 0):
                raise self.where.at(self.kind).error(
                    f"{about}: {self.kind}: {self.size} asks for {self.size} labels the "
                    f"building holds; it holds {len(labels)} "
                    f"({', '.join(label for label, _ in labels)})")
            groups = [[label for label, _ in labels[:self.size]]]
        out: list[Wanted] = []
        for group in groups:
            for label in group:
                known_label(label, self.where)
            spec: dict[str, Any] = {"targets": group}
            spec.update({"count": "all"} if self.kind == "count" else {"mode": self.kind})
            if self.stop_below is not None:
                spec["stop_below"] = self.stop_below
            out.append(_task_wanted(_form(spec, self.where), "found",
                                    self.stop_below is not None))
            if self.singles:
                out += [Wanted(label, "found", added=True) for label in group]
        return out


def target_entries(value: Any, where: Where, generated: bool) -> list[_Entry]:
    """The entries of a `targets` value (a list, or one entry such as `auto`), each checked
    and named by where it sits."""
    if isinstance(value, str) or (isinstance(value, dict) and set(value) & FORM_KEYS):
        return [_entry(value, where, generated)]
    if not isinstance(value, list) or not value:
        raise where.error(f"a non-empty list of labels or tasks (or 'auto'), got {value!r}")
    return [_entry(item, where.at(i), generated) for i, item in enumerate(value)]


def _entry(item: Any, where: Where, generated: bool) -> _Entry:
    if item == AUTO or (isinstance(item, dict) and AUTO in item):
        if not generated:
            raise where.error("'auto' targets are for generated worlds; list labels instead")
        return _AutoTargets(where) if item == AUTO else _auto_task(item, where)
    if isinstance(item, str) and item:
        return _Fixed((Wanted(known_label(item, where)),))
    if not isinstance(item, dict):
        raise where.error(f"{_FORMS}; got {item!r}")
    if set(item) & (_TASK_KEYS - _TARGET_KEYS):
        return _Fixed(_task(item, where))
    if not isinstance(item.get("label"), str):
        raise where.error(f"{_FORMS}; got {item!r}")
    if set(item) - _TARGET_KEYS:
        raise where.error(f"unknown keys {sorted(set(item) - _TARGET_KEYS)}")
    return _Fixed((Wanted(known_label(item["label"], where.at("label")),
                          _expected(item, where)),))


def _expected(item: Mapping[str, Any], where: Where) -> str | None:
    expected = item.get("expected")
    if expected is not None and expected not in EXPECTED:
        raise where.at("expected").error(f"found or gave_up, got {expected!r}")
    return expected


def _task(item: dict[str, Any], where: Where) -> tuple[Wanted, ...]:
    """`{targets: [a, b], mode: all|any}` or `{label: a, count: all, stop_below: p}`, checked
    by the episode's own rules (`TaskForm.from_spec`); with `singles: true`, each label's
    single search too. A form of one label found once is a plain single search."""
    unknown = set(item) - _TASK_KEYS
    if unknown:
        raise where.error(f"unknown keys {sorted(unknown)}; a task takes "
                          f"{sorted(_TASK_KEYS)}")
    if "label" in item and "targets" in item:
        raise where.error("give 'label' (one label, e.g. with count: all) or 'targets' (a "
                          "list), not both")
    if "label" not in item and "targets" not in item:
        raise where.error(f"a task names its labels: 'targets: [a, b]' or 'label: a'; got "
                          f"{item!r}")
    spec = {k: item[k] for k in ("mode", "count", "stop_below") if k in item}
    if "targets" in item:
        spec["targets"] = item["targets"]
    else:
        spec["target"] = item["label"]
    form = _form(spec, where)
    for i, label in enumerate(form.targets):
        known_label(label, where.at("targets").at(i) if "targets" in item else where.at("label"))
    expected = _expected(item, where)
    singles = _flag(item, "singles", where)
    if not form.several:
        return (Wanted(form.targets[0], expected),)
    wanted = _task_wanted(form, expected, "stop_below" in item)
    added = tuple(Wanted(label, None, added=True) for label in form.targets) if singles else ()
    return (wanted, *added)


def _auto_task(item: dict[str, Any], where: Where) -> _AutoTask:
    unknown = set(item) - _AUTO_KEYS
    if unknown:
        raise where.error(f"unknown keys {sorted(unknown)}; a task over the building's labels "
                          f"takes {sorted(_AUTO_KEYS)}")
    if item[AUTO] != AUTO_PRESENT:
        raise where.at(AUTO).error(f"'{AUTO_PRESENT}' (tasks over labels the building "
                                   f"holds); got {item[AUTO]!r}")
    kinds = [k for k in ("all", "any", "count", "labels") if k in item]
    if len(kinds) != 1:
        raise where.error("give one of 'all: N' (one object of each of N labels), 'any: N' "
                          "(one of any of N labels), 'count: all' (every instance) or "
                          "'labels: N' (a single search for each of N labels)")
    kind = kinds[0]
    from avs_planner.harness.tasks import MAX_TARGETS

    if kind == "count":
        if item["count"] != "all":
            raise where.at("count").error(f"'all' (every instance of a label); got "
                                          f"{item['count']!r}")
        size = item.get("pick")
        if size is not None and (isinstance(size, bool) or not isinstance(size, int)
                                 or size < 1):
            raise where.at("pick").error(f"a positive number of labels, got {size!r}")
        stop = None
        if "stop_below" in item:
            stop = _form({"target": "x", "count": "all", "stop_below": item["stop_below"]},
                         where).stop_below
    elif kind == "labels":
        size = item["labels"]
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise where.at("labels").error(f"a positive number of labels, got {size!r}")
        for key in ("pick", "stop_below", "singles"):
            if key in item:
                raise where.at(key).error(f"'{key}' does not go with 'labels: N' (single "
                                          "searches already)")
        stop = None
    else:
        size = item[kind]
        if isinstance(size, bool) or not isinstance(size, int) \
                or not 2 <= size <= MAX_TARGETS:
            raise where.at(kind).error(f"a number of labels from 2 to {MAX_TARGETS}, got "
                                       f"{size!r}")
        for key in ("pick", "stop_below"):
            if key in item:
                raise where.at(key).error(f"'{key}' goes with 'count: all' only")
        stop = None
    return _AutoTask(where, kind, size, stop, _flag(item, "singles", where))


def _form(spec: Mapping[str, Any], where: Where):  # noqa: ANN202 - harness.tasks.TaskForm
    """The episode's own check of a task form; its message, named by where it sits."""
    from avs_planner.harness.tasks import TaskForm

    try:
        return TaskForm.from_spec(spec)
    except AvsError as exc:
        raise where.error(str(exc).removeprefix("episode spec: ")) from None


def _task_wanted(form: Any, expected: str | None, stop_given: bool) -> Wanted:
    """A task (`harness.tasks.TaskForm`) as a target: named as the episode names it ("cup and
    book", "every chair"), and with its stop level when the campaign gives one (two levels:
    two targets); its episode keys say `stop_below` only then."""
    task: dict[str, Any] = {"targets": list(form.targets), "mode": form.mode,
                            "count": form.count}
    if stop_given:
        task["stop_below"] = form.stop_below
    name = form.name + (f" (stop below {form.stop_below:g})" if stop_given else "")
    return Wanted(name, expected, task)


def _flag(item: Mapping[str, Any], key: str, where: Where) -> bool:
    value = item.get(key, False)
    if not isinstance(value, bool):
        raise where.at(key).error(f"true or false, got {value!r}")
    return value


def unique_wanted(wanted: list[Wanted]) -> list[Wanted]:
    """The world's targets, leaving out a single search `singles` added when the list holds
    it already (two tasks over the same labels, or the label listed on its own)."""
    listed = {w.name for w in wanted if not w.added}
    out: list[Wanted] = []
    for w in wanted:
        if w.added and (w.name in listed or any(o.name == w.name for o in out)):
            continue
        out.append(w)
    return out


def known_label(label: str, where: Where) -> str:
    """A label the robot's knowledge has priors for (else no strategy can search for it)."""
    labels = _knowledge_labels()
    if label not in labels:
        raise where.error(f"unknown target label {label!r}; the knowledge knows "
                          f"{', '.join(sorted(labels))}")
    return label


@cache
def _knowledge_labels() -> frozenset[str]:
    from conceptual_map.knowledge.loader import load_knowledge

    return frozenset(load_knowledge().labels)
