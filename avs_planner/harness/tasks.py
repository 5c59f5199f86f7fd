"""Tasks of several objects: "find the cup and the book", "the cup or the book", "every chair".

A task names its targets and how they combine (`TaskForm`):

- `mode: all` (the default): one object of each target label;
- `mode: any`: the first object of any of them ends the task;
- `count: all` (one label only): every instance; the task stops when the conceptual map's
  P(another one in space not yet searched) falls below `stop_below` (the Poisson existence
  model: instances in disjoint parts of the building are independent, so the ones found do
  not make another more or less likely except through the building's learnt rate).

A task of one label and `count: one` is today's single search and runs as before (the
episode calls the strategy once). A task of several runs as turns over one robot, one mind
and one clock (`TaskRun`): each turn is the strategy's own search for one open label, while
the detector also watches for every other open label in every frame it takes
(`SearchTask.watch`, `Sensing.glimpse`): frames that do not show one lower its probability
where they looked, and one it confirms becomes a known object. A confirmed sighting of
another open label ends the turn at once, and the next turn is that label's: its object is
known, so its search is a short one (the robot faces it, looks again and reports it). The
robot keeps everything it mapped, classified and ruled out, so later turns do not drive the
same corridors again.

A DT search in a turn is one session over the turn's label and the other open labels the
searched cones may hold (`ViewConeSearch._run_several`, `avs_planner.dt.multi`).

Which open label a turn serves: one with a known object not reported yet (the nearest
first), else the one whose search is worth most going on from here (`TaskRun.worth`: the
stopping rule's bound, R x P(found within cost c) - c at best). The robot looks round once
before the first turn, watching for every label, so the first choice is made on a map.

Every strategy runs the same way: a turn is `Strategy.load()(context)` with the context's
target and state builder set to the turn's label, and the task's budgets and start clock.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from avs_planner.cp.search import DEFAULT_REWARD
from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import Outcome, SearchResult
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.strategies import SearchContext
from avs_planner.strategies.switching.stopping import Remaining, look_cost, remaining

MODES = ("all", "any")
COUNTS = ("one", "all")
MAX_TARGETS = 8
MAX_TURNS = 200
NOT_NEEDED = "not_needed"  # a target left open because the task ("any") was done
# P(another one unseen) below which a task counting every instance stops, unless the task
# says otherwise: a setting of the task's (how sure "that was all" must be), not tuned
STOP_BELOW = 0.1


class TaskFormError(EpisodeError):
    """A task form that cannot be: `key` names the spec key at fault (the service's 422
    names it as the field)."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"episode spec: {message}")
        self.key = key


@dataclass(frozen=True)
class TaskForm:
    """What the task asks for (see the module's doc)."""

    targets: tuple[str, ...]
    mode: str = "all"
    count: str = "one"
    stop_below: float = STOP_BELOW

    @property
    def several(self) -> bool:
        """More than one object may be reported: the task runs in turns (`TaskRun`)."""
        return len(self.targets) > 1 or self.count == "all"

    @property
    def name(self) -> str:
        """The task in a few words ("cup", "cup and book", "cup or glass", "every chair")."""
        if self.count == "all":
            return f"every {self.targets[0]}"
        if len(self.targets) == 1:
            return self.targets[0]
        joint = " and " if self.mode == "all" else " or "
        return ", ".join(self.targets[:-1]) + joint + self.targets[-1]

    @classmethod
    def from_spec(cls, spec: Mapping[str, Any]) -> TaskForm:
        """The task form of an episode spec: `target` (one label) or `targets` (a list), with
        `mode`, `count` and `stop_below`. EpisodeError names the key that is wrong."""
        target, targets = spec.get("target"), spec.get("targets")
        if target is not None and targets is not None:
            raise TaskFormError("targets", "give 'target' (one label) or 'targets' (a "
                                "list), not both")
        if targets is None:
            if not isinstance(target, str) or not target.strip():
                raise TaskFormError("target", "'target' (an object label) is required")
            labels = (target.strip(),)
        else:
            if isinstance(targets, str) or not isinstance(targets, list | tuple) or not targets:
                raise TaskFormError("targets", f"'targets' must be a non-empty list of "
                                    f"object labels, like [cup, book]; got {targets!r}")
            if not all(isinstance(t, str) and t.strip() for t in targets):
                raise TaskFormError("targets", f"'targets' must hold object labels "
                                    f"(non-empty strings); got {targets!r}")
            labels = tuple(t.strip() for t in targets)
            if len(labels) > MAX_TARGETS:
                raise TaskFormError("targets", f"'targets' holds {len(labels)} labels; at "
                                    f"most {MAX_TARGETS}")
            twice = sorted({t for t in labels if labels.count(t) > 1})
            if twice:
                raise TaskFormError("targets", f"'targets' names {', '.join(twice)} more "
                                    f"than once (to find every instance, use count: all)")
        mode = spec.get("mode", "all")
        if mode not in MODES:
            raise TaskFormError("mode", f"'mode' must be one of {', '.join(MODES)}; "
                                f"got {mode!r}")
        count = spec.get("count", "one")
        if count not in COUNTS:
            raise TaskFormError("count", f"'count' must be one of {', '.join(COUNTS)}; "
                                f"got {count!r}")
        if count == "all" and len(labels) != 1:
            raise TaskFormError("count", f"'count: all' finds every instance of one "
                                f"label; 'targets' names {len(labels)}")
        stop = spec.get("stop_below", STOP_BELOW)
        if isinstance(stop, bool) or not isinstance(stop, int | float) \
                or not 0.0 < float(stop) < 1.0:
            raise TaskFormError("stop_below", f"'stop_below' must be a probability between 0 "
                                f"and 1 (exclusive); got {stop!r}")
        if "stop_below" in spec and count != "all":
            raise TaskFormError("stop_below", "'stop_below' applies to 'count: all' only")
        return cls(labels, str(mode), str(count), float(stop))

    def spelled(self, spell: Callable[[str], str]) -> TaskForm:
        """The same task with every label as the knowledge spells it."""
        labels = tuple(spell(t) for t in self.targets)
        twice = sorted({t for t in labels if labels.count(t) > 1})
        if twice:
            raise TaskFormError("targets", f"'targets' names {', '.join(twice)} more than "
                                f"once (spelled differently)")
        return replace(self, targets=labels)


@dataclass
class TargetOutcome:
    """One target label's part of a task: open (`outcome` None) or how it ended, the
    objects reported for it, and the robot's clock when it ended."""

    label: str
    outcome: Outcome | None = None
    reason: str = ""
    found: list[KnownObject] = field(default_factory=list)
    ended_at: float | None = None
    turns: int = 0


@dataclass
class TaskResult:
    """How a task of several ended: the whole task's result (what the episode's summary
    reads, as for one search) and each target's part."""

    result: SearchResult
    targets: list[TargetOutcome]


class _Turn:
    """Ends a turn when the detector confirmed an object of another open label (its id not
    known when the turn began), or, counting every instance, when P(another) fell below the
    task's level."""

    def __init__(self, run: TaskRun, label: str, watch: tuple[str, ...]) -> None:
        self.run, self.label, self.watch = run, label, set(watch)
        mind = run.ctx.mind
        self.known = {oid for oid, obj in mind.objects.items() if obj.label in self.watch}
        self.seen: KnownObject | None = None
        self.enough: float | None = None

    def __call__(self) -> bool:
        if self.run.user_stop():
            return True
        for oid, obj in self.run.ctx.mind.objects.items():
            if obj.label in self.watch and oid not in self.known:
                self.seen = obj
                return True
        if self.run.form.count == "all" and self.run.outcomes[self.label].found:
            p = self.run.p_another(self.label)
            if p < self.run.form.stop_below:
                self.enough = p
                return True
        return False


class _TurnTrace:
    """The episode's trace as a turn's strategy sees it: its `done` is the turn's end (a
    `turn` event); the task's own `done` comes once, when the task ends."""

    def __init__(self, trace: Any, turn: _Turn) -> None:
        self._trace, self._turn = trace, turn

    def emit(self, type_: str, **fields: Any) -> dict[str, Any]:
        if type_ != "done":
            return self._trace.emit(type_, **fields)
        turn = self._turn
        if turn.seen is not None:  # the turn was ended for another label, not by the user
            fields |= {"outcome": "switched", "reason": f"{turn.seen.label} seen "
                                                        f"({turn.seen.id}): its turn next"}
        elif turn.enough is not None:
            fields |= {"outcome": "enough",
                       "reason": f"P(another {turn.label} unseen) = {turn.enough:.3g}"}
        return self._trace.emit("turn", target=turn.label, status="end", **fields)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._trace, name)


class TaskRun:
    """Runs a task of several objects as turns of `search` (a strategy's run) over the
    episode's context (see the module's doc)."""

    def __init__(self, form: TaskForm, ctx: SearchContext,
                 search: Callable[[SearchContext], SearchResult]) -> None:
        self.form, self.ctx, self.search = form, ctx, search
        self.user_stop = ctx.should_stop
        self.outcomes = {label: TargetOutcome(label) for label in form.targets}
        self.builders: dict[str, StateBuilder] = {ctx.builder.task.target: ctx.builder}
        self.result = SearchResult(Outcome.GAVE_UP, "")
        self.turns = 0
        self.looked_first = False  # the task looked round before its first turn

    # ---- the turns ---------------------------------------------------------------------

    def run(self) -> TaskResult:
        ctx = self.ctx
        ctx.trace.emit("task", targets=list(self.form.targets), mode=self.form.mode,
                       count=self.form.count, stop_below=self.form.stop_below
                       if self.form.count == "all" else None)
        if not ctx.mind.place_map.rooms:
            # the first look around, watching for every label, so that the first turn's
            # label is chosen on a map; the first turn's strategy does not repeat it
            ctx.executor.context.builder = self._builder(self.form.targets[0],
                                                         self.form.targets[1:])
            ctx.executor.look_around()
            self.looked_first = True
        while not self._over():
            stop = ctx.budget_spent()
            if stop:
                self._close_open(Outcome.TIMEOUT, stop)
                break
            if self.turns >= MAX_TURNS:  # a safety net: every turn reports, closes or times out
                self._close_open(Outcome.GAVE_UP, f"{MAX_TURNS} turns taken")
                break
            label = self.next_label()
            if self._enough(label):
                continue
            self._turn(label)
        return self._end()

    def _over(self) -> bool:
        found = [t for t in self.outcomes.values() if t.found]
        if self.form.mode == "any" and found:
            for t in self.outcomes.values():
                if t.outcome is None:  # left open: the summary says "not_needed"
                    t.reason = f"not needed: {found[0].label} was found first"
            return True
        return all(t.outcome is not None for t in self.outcomes.values())

    def _open(self) -> list[str]:
        return [label for label, t in self.outcomes.items() if t.outcome is None]

    def _turn(self, label: str) -> None:
        ctx = self.ctx
        watch = tuple(other for other in self._open() if other != label)
        builder = self._builder(label, watch)
        ctx.executor.context.builder = builder
        ctx.executor.sensing.take_seen()  # atoms of another label's problem: known objects now
        turn = _Turn(self, label, watch)
        target = self.outcomes[label]
        target.turns += 1
        # a turn after the first goes on from where the robot stands: the strategy's first
        # look around is skipped (`Sensing.resumed`)
        ctx.executor.sensing.resumed = tuple(ctx.robot.pose[:2]) \
            if self.turns or self.looked_first else None
        self.turns += 1
        ctx.trace.emit("turn", target=label, status="start", watch=list(watch),
                       found=len(target.found))
        sub = replace(ctx, target=label, builder=builder, should_stop=turn,
                      trace=_TurnTrace(ctx.trace, turn),
                      stop_below=self.form.stop_below if self.form.count == "all" else None)
        result = self.search(sub)
        self.result.plans += result.plans
        self.result.replans += result.replans
        self.result.cp_times.extend(result.cp_times)
        if result.outcome is Outcome.FOUND and result.found is not None:
            target.found.append(result.found)
            if self.form.count == "one":
                self._close(label, Outcome.FOUND, result.reason)
            return
        if turn.seen is not None or turn.enough is not None:
            if turn.enough is not None:
                self._close(label, Outcome.FOUND, self._enough_reason(label, turn.enough))
            return  # the next turn serves the label seen (`next_label`)
        if result.outcome is Outcome.TIMEOUT:
            self._close_open(Outcome.TIMEOUT, result.reason)
        elif target.found:  # counting: the search found no way to another one
            self._close(label, Outcome.FOUND, f"{len(target.found)} found; no other one: "
                        f"{result.reason}; P(another {label} in space not yet searched) = "
                        f"{self.p_another(label):.3g}")
        else:
            self._close(label, Outcome.GAVE_UP, result.reason)

    def _builder(self, label: str, watch: tuple[str, ...]) -> StateBuilder:
        """The turn's state builder (`_builder_of`), told what else to watch for and which of
        its label's objects were reported."""
        builder = self._builder_of(label)
        builder.task = replace(builder.task, watch=watch, mode=self.form.mode,
                               exclude=frozenset(obj.id for obj in self.outcomes[label].found))
        return builder

    def _builder_of(self, label: str) -> StateBuilder:
        """The label's state builder: one per label, kept across its turns (the searches it
        saw fail, the search times it measured)."""
        builder = self.builders.get(label)
        if builder is None:
            first = self.ctx.builder
            builder = StateBuilder(self.ctx.mind, SearchTask(label, first.task.category),
                                   first.config)
            builder.search_times = first.search_times  # the robot's own, shared
            self.builders[label] = builder
        return builder

    def _reported(self) -> set[str]:
        return {obj.id for t in self.outcomes.values() for obj in t.found}

    def next_label(self) -> str:
        """The open label a known, unreported object has (the nearest), else the one whose
        search is worth most going on from here (see the module's doc)."""
        open_ = self._open()
        ctx = self.ctx
        here = ctx.robot.pose[:2]
        reported = self._reported()
        known = [(math.dist(obj.position[:2], here), i, obj.label)
                 for i, obj in enumerate(ctx.mind.objects.values())
                 if obj.label in open_ and obj.id not in reported]
        if known:
            return min(known)[2]
        if len(open_) == 1 or not ctx.mind.place_map.rooms:
            return open_[0]
        return max(open_, key=lambda label: (self.worth(label), -open_.index(label)))

    def worth(self, label: str) -> float:
        """What searching on for `label` from here is worth at most: over the cost bounds c
        of the conceptual map's options (rooms not searched through, what placeholders may
        lead to: `stopping.remaining`), the largest R x P(found within c) - c, R the reward
        the strategy plans with (the switching planner's objective; the stopping rule's
        bound on any continuation)."""
        reward = float(self.ctx.options.get("reward", DEFAULT_REWARD))
        return max((reward * p - cost for cost, p in self._remaining(label).within),
                   default=-math.inf)

    def p_another(self, label: str) -> float:
        """P(another `label` in space not yet searched, mapped or beyond the frontiers)."""
        return self._remaining(label).p

    def _remaining(self, label: str) -> Remaining:
        """The conceptual map's building-level belief for `label` from where the robot is."""
        ctx = self.ctx
        return remaining(ctx.mind, self._builder_of(label), ctx.robot.pose[:2],
                         look_cost(ctx.mind.body, ctx.executor.config.look_headings))

    def _enough(self, label: str) -> bool:
        """Counting every instance: P(another) is below the task's level already."""
        target = self.outcomes[label]
        if self.form.count != "all" or not target.found or label not in self.builders:
            return False
        p = self.p_another(label)
        if p >= self.form.stop_below:
            return False
        self._close(label, Outcome.FOUND, self._enough_reason(label, p))
        return True

    def _enough_reason(self, label: str, p: float) -> str:
        return (f"{len(self.outcomes[label].found)} found; P(another {label} in space not "
                f"yet searched) = {p:.3g} < {self.form.stop_below:g}")

    def _close(self, label: str, outcome: Outcome, reason: str) -> None:
        target = self.outcomes[label]
        target.outcome, target.reason = outcome, reason
        target.ended_at = self.ctx.robot.clock
        self.ctx.trace.emit("target", target=label, outcome=outcome.value, reason=reason,
                            found=[obj.id for obj in target.found])

    def _close_open(self, outcome: Outcome, reason: str) -> None:
        for label in self._open():
            self._close(label, outcome, reason)

    def _end(self) -> TaskResult:
        """The whole task's outcome: found when it got what it asked for (every label, any
        one, or the instances counted), a timeout when the budget ended it, else gave up."""
        targets = list(self.outcomes.values())
        found = [t for t in targets if t.outcome is Outcome.FOUND]
        if self.form.mode == "any":
            done = bool(found)
        else:
            done = len(found) == len(targets)
        if done:
            outcome = Outcome.FOUND
        elif any(t.outcome is Outcome.TIMEOUT for t in targets):
            outcome = Outcome.TIMEOUT
        else:
            outcome = Outcome.GAVE_UP
        parts = [f"{t.label}: {t.outcome.value if t.outcome else NOT_NEEDED}"
                 + (f" ({len(t.found)})" if self.form.count == "all" else "")
                 for t in targets]
        reason = f"{self.form.name}: " + "; ".join(parts)
        self.result.outcome, self.result.reason = outcome, reason
        self.result.found = next((obj for t in targets for obj in t.found), None)
        self.ctx.trace.emit("done", outcome=outcome.value, reason=reason)
        return TaskResult(self.result, targets)
