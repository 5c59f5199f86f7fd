"""`run_episode`: one object-search episode from a plain-data spec, as the API and CLI call it.

This is the wiring: it opens the simulated world (robot side), builds the mind, state builder,
executor and switching loop (mind side), and writes trace.jsonl, summary.json, trajectory.png,
explanation.json (`reporting.explain`) and, when asked (`record`), recording.rrd (`viewer`).
"""

from __future__ import annotations

import math
import reprlib
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.executor import Executor, ExecutorConfig
from avs_planner.episode.mind import Mind
from avs_planner.episode.outcome import SearchResult
from avs_planner.episode.robot_api import fence
from avs_planner.episode.state_builder import SearchTask, StateBuilder
from avs_planner.episode.trace import Trace, write_summary
from avs_planner.episode.viewcones import CameraModel
from avs_planner.harness.building_memory import EpisodeMemory, memory_keys
from avs_planner.harness.sim_robot import (
    SimRobot,
    check_categories,
    generated_spec,
    load_spec,
    open_world,
)
from avs_planner.harness.tasks import NOT_NEEDED, TargetOutcome, TaskForm, TaskRun
from avs_planner.reporting.snapshots import MapSnapshots
from avs_planner.strategies import SearchContext, Strategy, get_strategy
from conceptual_map.knowledge import Knowledge, load_knowledge

Emit = Callable[[dict[str, Any]], None]

# m: a report scores as correct when it names a spot this near a true instance of the target
# (several times the detector's position noise, 0.02 m per metre of range on each axis; half
# the 1 m within which two detections of a label are taken for one object)
REPORT_TOLERANCE = 0.5

_KEYS = {"target", "targets", "mode", "count", "stop_below", "category", "world", "world_file",
         "robot", "start_room", "start", "seed", "time_budget_s", "wall_budget_s", "task_id",
         "output_dir", "pre_explore", "dt_policy",
         "strategy", "strategy_options", "generate", "qsr", "record", "view", "strict_labels",
         "memory", "since_s", "experience", "building", "learn"}


@dataclass(frozen=True)
class EpisodeSpec:
    """What to search for, where, with which robot; see `avs_planner.jobs.run_episode`.
    `target` is the task's first label; `task` the whole task (several labels, how they
    combine: `harness/tasks.py`), None for one label."""

    target: str
    world: str = "office"
    category: str | None = None
    robot: str | None = None
    start_room: str | None = None
    start: tuple[float, float, float] | None = None
    seed: int = 0
    time_budget_s: float = 1200.0
    wall_budget_s: float = 600.0
    output_dir: str | None = None
    pre_explore: bool = False
    dt_policy: str = "pouct"
    strategy: str = "switching"
    strategy_options: Mapping[str, Any] = field(default_factory=dict)
    generate: Mapping[str, Any] | None = None  # {seed, style, rooms}: a generated world
    world_text: str | None = field(default=None, repr=False)
    qsr: Any = field(default=None, repr=False)  # QsrKnowledge with the task's descriptions
    record: bool = False  # write recording.rrd in output_dir (needs the viewer extra)
    view: bool = False  # stream the recording to a Rerun viewer spawned for it
    # a target the knowledge does not list is refused (else it is searched for with the
    # knowledge's uninformed prior, `Knowledge.with_label`, and a `warning` event)
    strict_labels: bool = False
    task: TaskForm | None = None
    # the building's memory (a directory: `episode/memory.py`); None: start from nothing
    memory: str | None = None
    since_s: float = 3600.0  # simulated seconds since the building's previous task
    experience: str | None = None  # path of the experience store (learned priors), if any
    building: str | None = None  # the building's id: its scope in the experience store
    learn: bool = True  # add the episode's evidence to the store (false: only read it)

    @property
    def form(self) -> TaskForm:
        """The task form (one label: `target`, found once)."""
        return self.task or TaskForm((self.target,))

    @classmethod
    def from_dict(cls, spec: Mapping[str, Any]) -> EpisodeSpec:
        unknown = set(spec) - _KEYS
        if unknown:
            raise EpisodeError(f"episode spec: unknown keys {sorted(unknown)}")
        form = TaskForm.from_spec(spec)
        options = spec.get("strategy_options") or {}
        if not isinstance(options, Mapping):
            raise EpisodeError(f"episode spec: 'strategy_options' must be a mapping, got "
                               f"{options!r}")
        strategy = get_strategy(str(spec.get("strategy") or "switching"))
        options = strategy.check_options(options)
        generate = spec.get("generate")
        if generate is not None and not isinstance(generate, Mapping):
            raise EpisodeError(f"episode spec: 'generate' must be a mapping like "
                               f"{{seed: 3, style: office}}, got {generate!r}")
        start = spec.get("start")
        if start is not None:
            if not isinstance(start, list | tuple) or len(start) != 3:
                raise EpisodeError(f"episode spec: 'start' must be [x, y, yaw], got {start!r}")
            start = tuple(_number(v, "start") for v in start)
        return cls(
            target=form.targets[0], task=form if form.several else None,
            world=str(spec.get("world") or "office"),
            category=spec.get("category"), robot=spec.get("robot"),
            start_room=spec.get("start_room"), start=start, seed=int(spec.get("seed") or 0),
            time_budget_s=_number(spec.get("time_budget_s", 1200.0), "time_budget_s"),
            wall_budget_s=_number(spec.get("wall_budget_s", 600.0), "wall_budget_s"),
            output_dir=spec.get("output_dir"), pre_explore=bool(spec.get("pre_explore")),
            dt_policy=str(spec.get("dt_policy") or "pouct"), strategy=strategy.name,
            strategy_options=options, generate=generate, world_text=spec.get("world_file"),
            qsr=qsr_descriptions(spec.get("qsr")), strict_labels=_flag(spec, "strict_labels"),
            **_recording(spec), **memory_keys(spec), **_experience(spec),
        )


def _flag(spec: Mapping[str, Any], key: str) -> bool:
    value = spec.get(key, False)
    if not isinstance(value, bool):
        raise EpisodeError(f"episode spec: {key!r} must be true or false, got {value!r}")
    return value


def _experience(spec: Mapping[str, Any]) -> dict[str, Any]:
    """`experience`: the store's path (a non-empty string); `building`: an id of at most 64
    letters, digits, `_`, `.`, `-`, starting with a letter or digit; `learn` (default true):
    false reads the store without adding to it (opened read-only)."""
    from conceptual_map.knowledge.experience import BUILDING_ID

    path, building = spec.get("experience"), spec.get("building")
    if path is not None and (not isinstance(path, str) or not path):
        raise EpisodeError(f"episode spec: 'experience' must be the path of an experience "
                           f"store file, got {reprlib.repr(path)}")
    if building is not None and (not isinstance(building, str)
                                 or not BUILDING_ID.match(building)):
        raise EpisodeError(f"episode spec: 'building' must be an id of 1-64 letters, digits, "
                           f"'_', '.' or '-' starting with a letter or digit, got "
                           f"{reprlib.repr(building)}")
    learn = _flag({"learn": spec.get("learn", True)}, "learn")
    if "learn" in spec and path is None:
        raise EpisodeError("episode spec: 'learn' says whether the episode adds to an "
                           "experience store: give 'experience' too")
    return {"experience": path, "building": building, "learn": learn}


def _recording(spec: Mapping[str, Any]) -> dict[str, bool]:
    """`record` / `view`: booleans; recording needs an output_dir and the viewer extra."""
    out = {}
    for key in ("record", "view"):
        value = spec.get(key, False)
        if not isinstance(value, bool):
            raise EpisodeError(f"episode spec: {key!r} must be true or false, got {value!r}")
        out[key] = value
    if out["record"] and not spec.get("output_dir"):
        raise EpisodeError("episode spec: 'record' writes recording.rrd into 'output_dir', "
                           "which is not given")
    if out["record"] or out["view"]:
        from avs_planner.viewer import ViewerError, require_rerun

        try:
            require_rerun("'record' / 'view'")
        except ViewerError as exc:
            raise EpisodeError(f"episode spec: {exc}") from None
    if out["view"]:
        from avs_planner.viewer.errors import display_missing

        missing = display_missing()
        if missing:
            raise EpisodeError(f"episode spec: 'view' opens a live Rerun viewer, but there is "
                               f"{missing}; record with 'record' (--record) and replay with "
                               f"`avs view RUN_DIR --web` instead")
    return out


def qsr_descriptions(data: Any, source: str = "episode spec: qsr") -> Any:
    """The task's QSR descriptions (a list in the format of conceptual_map/qsr/README.md, or
    {descriptions: [...]}) validated against the default knowledge's relations and landmarks,
    as a QsrKnowledge; None when not given. EpisodeError names the bad entry."""
    if data is None:
        return None
    from conceptual_map.errors import KnowledgeError
    from conceptual_map.qsr import load_qsr, parse_descriptions

    if isinstance(data, Mapping) and set(data) == {"descriptions"}:
        data = data["descriptions"]
    if not isinstance(data, list) or not data:
        raise EpisodeError(f"episode spec: 'qsr' must be a non-empty list of QSR descriptions "
                           f"like [{{target: cup, relations: [right, close], of: keyboard, "
                           f"count: 1}}], got {reprlib.repr(data)}")
    try:
        return parse_descriptions(data, load_qsr(), source=source)
    except KnowledgeError as exc:
        raise EpisodeError(str(exc)) from None


def _number(value: Any, key: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise EpisodeError(f"episode spec: {key!r} must be a number, got {value!r}") from None
    if not math.isfinite(number) or (key.endswith("budget_s") and number <= 0):
        raise EpisodeError(f"episode spec: {key!r} must be a finite positive number")
    return number


def target_knowledge(knowledge: Knowledge, target: str, strict: bool = False
                     ) -> tuple[Knowledge, list[dict[str, Any]]]:
    """The knowledge an episode searching for `target` plans with, and the warnings to trace:
    a label it does not list gets its uninformed prior (`Knowledge.with_label`) and a warning
    naming it; with `strict`, EpisodeError instead."""
    if target in knowledge.labels:
        return knowledge, []
    if strict:
        raise EpisodeError(f"unknown target label {target!r}; the knowledge knows "
                           f"{', '.join(sorted(knowledge.labels))}")
    model = knowledge.unknown
    return knowledge.with_label(target), [{
        "source": "knowledge", "label": target,
        "detail": f"the knowledge ({knowledge.source}) has no priors for label {target!r}: "
                  f"searching with its uninformed prior ({model.rate:g} expected per room of "
                  f"any category, {model.room_share:g} of it in the room, the rest on "
                  f"{', '.join(model.supports)})"}]


def run_episode(spec: Mapping[str, Any], emit: Emit | None = None,
                should_stop: Callable[[], bool] | None = None) -> dict[str, Any]:
    """Run one episode; returns the summary dict (also written to `output_dir`)."""
    episode = EpisodeSpec.from_dict(spec)
    return Episode(episode, emit, should_stop).run()


class Episode:
    """One episode's objects, built from a spec; `run` returns the summary."""

    def __init__(self, spec: EpisodeSpec, emit: Emit | None = None,
                 should_stop: Callable[[], bool] | None = None):
        self.spec = spec
        self.out = Path(spec.output_dir) if spec.output_dir else None
        self.world_spec = self._world_spec()
        knowledge = self._knowledge()
        # labels and categories as the knowledge spells them: "CerealBox" is the cerealbox
        task = spec.task.spelled(knowledge.spelled) if spec.task is not None else None
        spec = self.spec = replace(spec, target=knowledge.spelled(spec.target), task=task,
                                   category=knowledge.spelled(spec.category)
                                   if isinstance(spec.category, str) else spec.category)
        self.warnings = []
        for label in spec.form.targets:
            knowledge, warnings = target_knowledge(knowledge, label, spec.strict_labels)
            self.warnings += warnings
        check_categories(self.world_spec, knowledge.categories)
        self.robot: SimRobot = open_world(self.world_spec, spec.seed, knowledge.categories)
        self.mind = Mind.for_body(self.robot.body(), knowledge)  # its own body, not the world
        self.memory = self._recall_memory()
        if self.out is not None:
            self.out.mkdir(parents=True, exist_ok=True)
        self.trace = Trace(lambda: self.robot.clock, self.out / "trace.jsonl" if self.out
                           else None, emit)
        # the strategy's settings, built once: what its executor and state builder run with
        executor_config, builder_config = self._strategy().configs(spec.strategy_options)
        self.builder = StateBuilder(self.mind, SearchTask(
            spec.target, spec.category, watch=spec.form.targets[1:]), builder_config)
        body = self.robot.body()
        self.camera = CameraModel(self.robot.camera_height, body.hfov, body.detect_range,
                                  vfov=body.vfov)
        # the mind's side gets the robot through the fence: its sensors and motions, never
        # the world behind them (`robot_api.fence`); the harness keeps `self.robot`
        sensed = fence(self.robot)
        self.executor = Executor(sensed, self.mind, self.builder, self.camera, self._emit,
                                 replace(executor_config or ExecutorConfig(),
                                         dt_policy=spec.dt_policy), seed=spec.seed)
        self.trace.subscribe(MapSnapshots(self.executor, self._emit).observe)
        self.context = SearchContext(
            robot=sensed, body=body, mind=self.mind, builder=self.builder,
            executor=self.executor, trace=self.trace, target=spec.target,
            category=spec.category, time_budget_s=spec.time_budget_s,
            wall_budget_s=spec.wall_budget_s, options=spec.strategy_options,
            should_stop=should_stop or (lambda: False), dump_dir=spec.output_dir,
            qsr=spec.qsr, experience=self.experience)
        self.recorder = self._recorder()

    def _knowledge(self) -> Knowledge:
        """The file's knowledge; with an experience store, its posterior for the spec's
        building (`ExperienceStore.knowledge_for`), the store kept open for the update."""
        from conceptual_map.errors import ExperienceError
        from conceptual_map.knowledge.experience import ExperienceSession, ExperienceStore

        self.experience: ExperienceSession | None = None
        if self.spec.experience is None:
            return load_knowledge()
        try:
            store = ExperienceStore(self.spec.experience, readonly=not self.spec.learn)
            knowledge = store.knowledge_for(load_knowledge(), self.spec.building)
        except ExperienceError as exc:
            raise EpisodeError(f"episode spec: 'experience': {exc}") from None
        self.experience = ExperienceSession(store, self.spec.building)
        return knowledge

    def _learn(self, result: SearchResult) -> dict[str, Any]:
        """{"experience": ...}: the episode's evidence (`episode_evidence`, from the mind
        alone) added to the store, unless the search was stopped on request; nothing
        without a store."""
        if self.experience is None:
            return {}
        from avs_planner.episode.experience import episode_evidence
        from conceptual_map.errors import ExperienceError

        part: dict[str, Any] = {"store": self.experience.store.path.name,
                                "building": self.spec.building,
                                "updated": (self.spec.learn
                                            and result.reason != "stopped on request")}
        if not self.spec.learn:
            part["learn"] = False  # read only: the store was not opened for writing
        if part["updated"]:
            evidence = self.experience.with_learned(episode_evidence(self.mind))
            try:
                self.experience.store.update(self.spec.building, evidence)
            except ExperienceError as exc:  # the search's result stands; say why not kept
                part.update(updated=False, error=str(exc))
        return {"experience": part}

    def _recorder(self):  # noqa: ANN202 - a viewer.Recorder, or None
        """The Rerun recorder, subscribed to the trace, when the spec asks for one."""
        spec = self.spec
        if not (spec.record or spec.view):
            return None
        from avs_planner.viewer import RECORDING, ViewerError
        from avs_planner.viewer.recorder import Recorder

        path = self.out / RECORDING if spec.record and self.out is not None else None
        try:
            recorder = Recorder(self.mind, self.executor, self.robot, self.camera, spec.target,
                                path=path, spawn=spec.view,
                                name=spec.output_dir or f"{spec.world}-{spec.target}")
        except ViewerError as exc:
            self.robot.world.close()
            raise EpisodeError(str(exc)) from None
        self.trace.subscribe(recorder)
        return recorder

    def _world_spec(self):  # noqa: ANN202 - sim.WorldSpec
        spec = self.spec
        if spec.generate is not None:
            return generated_spec(spec.generate, spec.robot, spec.start, spec.start_room)
        if spec.world_text is None:
            return load_spec(spec.world, spec.robot, spec.start, spec.start_room)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "world_file.yaml"
            path.write_text(spec.world_text, encoding="utf-8")
            try:
                return load_spec(path, spec.robot, spec.start, spec.start_room)
            except EpisodeError as exc:  # name the spec key, not the temporary file
                raise EpisodeError(str(exc).replace(str(path), "world_file")) from None

    def _strategy(self) -> Strategy:
        return get_strategy(self.spec.strategy)

    def _emit(self, type_: str, **fields: Any) -> None:
        self.trace.emit(type_, **fields)

    def run(self) -> dict[str, Any]:
        try:
            self.trace.emit("start", target=self.spec.target, world=self.world_spec.name,
                            **self._task_fields(),
                            robot=self.robot.model, pose=list(self.robot.pose),
                            seed=self.spec.seed, strategy=self.spec.strategy)
            for warning in self.warnings:
                self.trace.emit("warning", **warning)
            if self.memory is not None and self.memory.recalled is not None:
                self.trace.emit("memory", recalled=True, **self.memory.recalled)
            start_clock, start_distance = self._pre_explore()
            if self.memory is not None:  # every strategy's task starts so
                self.memory.check(self.executor, self.spec.form.targets, self._emit,
                                  lambda: not self.context.budget_spent())
            search = self._strategy().load()
            targets = None
            if self.spec.task is not None:
                task = TaskRun(self.spec.task, self.context, search).run()
                result, targets = task.result, task.targets
            else:
                result = search(self.context)
            summary = self.summary(result, start_clock, start_distance, targets)
            if self.memory is not None:
                summary["memory"] = self.memory.keep(self.mind,
                                                     self.executor.config.same_object)
            summary.update(self._learn(result))
            if self.out is not None:
                write_summary(self.out / "summary.json", summary)
                self._explanation()
                self._picture()
            return summary
        finally:
            if self.experience is not None:
                self.experience.store.close()
            if self.recorder is not None:
                self.recorder.close()
            self.trace.close()
            self.robot.world.close()

    def _recall_memory(self) -> EpisodeMemory | None:
        """The building's memory, put into the fresh mind (`harness/building_memory.py`)."""
        if self.spec.memory is None:
            return None
        try:
            return EpisodeMemory.recall(self.spec.memory, self.spec.since_s, self.mind)
        except EpisodeError:
            self.robot.world.close()
            raise

    def _pre_explore(self) -> tuple[float, float]:
        """Fig. 3f: build the maps first (frontier exploration), then start the clock."""
        if self.spec.pre_explore:
            from avs_planner.harness.prebuilt import explore

            prepare = self._strategy().load_prepare()
            if prepare is not None:
                # the strategy's own survey (e.g. with depth frames); the robot is not searching
                # yet, so its detector does not watch for the target (as in `explore`)
                self.executor.watching = False
                try:
                    prepare(self.context)
                finally:
                    self.executor.watching = True
            else:
                explore(self.executor)
            self.trace.emit("belief", pre_explored=True, places=len(self.mind.place_map.places),
                            rooms=len(self.mind.place_map.rooms))
        self.context.start_clock = self.robot.clock
        return self.robot.clock, self.executor.stats.distance

    def summary(self, result: SearchResult, start_clock: float, start_distance: float,
                targets: list[TargetOutcome] | None = None) -> dict[str, Any]:
        stats = self.executor.stats
        obj = None if result.found is None else self._report(result.found)
        task: dict[str, Any] = {}
        correct = bool(obj and obj["correct"])
        if targets is not None:
            parts = [self._target_part(t, start_clock) for t in targets]
            reports = [o for part in parts for o in part["objects"]]
            correct = bool(reports) and all(o["correct"] for o in reports)
            task = {**self._task_fields(), "targets": parts}
        map_score = self._map_score()
        return {
            "outcome": result.outcome.value, "reason": result.reason,
            "target": self.spec.form.name, "category": self.spec.category, "object": obj,
            "correct": correct, **task,
            "sim_time_s": round(self.robot.clock - start_clock, 2),
            "distance_m": round(stats.distance - start_distance, 2),
            "plans": result.plans, "replans": result.replans,
            "cp_time_s": [round(t, 4) for t in result.cp_times],
            "dt_calls": stats.dt_calls,
            **self._dt_results(),
            "dt_decision_time_s": [round(t, 4) for t in stats.dt_decisions],
            "views_processed": stats.views, "seed": self.spec.seed,
            "world": self.world_spec.name, "robot": self.robot.model,
            "strategy": self.spec.strategy, "details": result.details,
            "wall_time_s": round(self.trace.wall, 2),
            **map_score,
            "target_evidence": self._target_evidence(
                [obj] if obj else [o for part in task.get("targets", []) for o in part["objects"]],
                map_score.get("map_score")),
            # what the robot's placeholders led to, against what the model predicted
            # (`conceptual_map/conceptual/calibration.py`; the mind's own record)
            "placeholders": self.mind.cmap.calibration.summary(),
        }

    def _task_fields(self) -> dict[str, Any]:
        """A task of several: its form (`harness/tasks.py`); nothing for one label."""
        form = self.spec.task
        if form is None:
            return {}
        return {"task": {"targets": list(form.targets), "mode": form.mode, "count": form.count,
                         **({"stop_below": form.stop_below} if form.count == "all" else {})}}

    def _report(self, found: Any) -> dict[str, Any]:
        """A reported object, with the world entry it names (scoring only) and whether that
        is an instance of the reported label."""
        sid = self.executor.found_sids.get(found.id)
        truth = self._truth_of(sid, found.position, found.label)
        return {"id": found.id, "label": found.label,
                "position": [round(v, 3) for v in found.position], "room": found.room,
                "truth": truth,
                "correct": bool(truth and self._truth_label(truth) == found.label)}

    def _target_part(self, target: TargetOutcome, start_clock: float) -> dict[str, Any]:
        """One target's part of a task's summary: its outcome, the reports (checked against
        the world: scoring only), the true instances in the world and how many distinct ones
        the reports name."""
        objects = [self._report(obj) for obj in target.found]
        instances = sum(1 for thing in self.robot.world.detectables
                        if thing.label == target.label)
        return {"label": target.label,
                "outcome": target.outcome.value if target.outcome else NOT_NEEDED,
                "reason": target.reason, "objects": objects,
                "sim_time_s": None if target.ended_at is None
                else round(target.ended_at - start_clock, 2),
                "turns": target.turns, "instances": instances,
                "distinct": len({o["truth"] for o in objects if o["correct"]}),
                "correct": all(o["correct"] for o in objects)}

    def _map_score(self) -> dict[str, Any]:
        """{"map_score": ...}: the mind's rooms scored against the world file's (the harness
        holds both; `scoring.py`); empty when the mind has no rooms."""
        from avs_planner.harness.scoring import map_score

        score = map_score(self.world_spec, self.mind, self.executor.stats.path)
        return {} if score is None else {"map_score": score}

    def _target_evidence(self, reports: list[dict[str, Any]],
                         score: dict[str, Any] | None) -> list[dict[str, Any]]:
        """The looks' claims about where the target's true instances stand, against what the
        camera saw of them and what `reports` named (`scoring.evidence_score`; the
        harness's referee), each instance in the robot room `score` (the map score) matched
        to its true room. For a task of several labels, its first."""
        from avs_planner.harness.scoring import evidence_score

        label = self.spec.target
        robot_room = {r["name"]: r["robot_room"] for r in (score or {}).get("rooms", [])}
        instances = []
        for thing in self.robot.world.detectables:
            if thing.label == label:
                true_room = self.world_spec.room_at(float(thing.center[0]),
                                                    float(thing.center[1]))
                instances.append((thing.name, thing.center,
                                  robot_room.get(true_room.name) if true_room else None))
        detected = {name for name in self.robot.truth_of.values() if name}
        reported = {o["truth"] for o in reports if o.get("truth")}
        return evidence_score(instances, self.mind, label, detected, reported)

    def _dt_results(self) -> dict[str, int]:
        """`dt_confirmed` / `dt_rejected`: the DT sessions of the episode by their result
        (the trace's `dt` events)."""
        results = [e.get("result") for e in self.trace.events if e["type"] == "dt"]
        return {f"dt_{status}": results.count(status) for status in ("confirmed", "rejected")}

    def _truth_of(self, sid: int | None, position: tuple[float, float, float],
                  label: str | None = None) -> str | None:
        """The world entry a report names (scoring only: the robot never sees this). The
        detection it was made from says, when that was of the target; otherwise the nearest
        target instance within `REPORT_TOLERANCE` m of the reported spot does: the first frame
        of a confirmed detection may be a phantom beside the real object that the frames
        confirming and verifying it saw, and the report then still names the object."""
        label = label or self.spec.target
        named = self.robot.truth_of.get(sid) if sid is not None else None
        if named is not None and self._truth_label(named) == label:
            return named
        near = [(math.dist(thing.center, position), thing.name)
                for thing in self.robot.world.detectables if thing.label == label]
        near = [entry for entry in near if entry[0] <= REPORT_TOLERANCE]
        return min(near)[1] if near else named

    def _truth_label(self, name: str) -> str | None:
        for item in (*self.world_spec.objects, *self.world_spec.furniture):
            if item.name == name:
                return item.label
        return None

    def _explanation(self) -> None:
        """explanation.json: the assumption ledger of the trace, with the final beliefs."""
        from avs_planner.reporting import explain

        assert self.out is not None
        final = explain.final_beliefs(self.mind, self.spec.target)
        explain.write(self.out / explain.FILE_NAME, explain.build(self.trace.events, final))

    def _picture(self) -> None:
        from avs_planner.reporting.picture import draw_trajectory

        assert self.out is not None
        draw_trajectory(self.mind, self.executor.stats, self.out / "trajectory.png",
                        title=f"{self.spec.form.name} in {self.world_spec.name}")
