"""Request and response bodies, in families per resource (`TaskCreate`, `TaskPublic`, ...)."""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StringConstraints,
    ValidationError,
    field_validator,
    model_validator,
)
from pydantic_core import InitErrorDetails, PydanticCustomError

from api.limits import (
    flatten_strings,
    json_problem,
    load_yaml,
    looks_like_path,
    pddl_problem,
    yaml_problem,
)

NAME_PATTERN = r"^[A-Za-z][A-Za-z0-9_-]{0,63}$"
# a building's id: a directory name under DATA_DIR/buildings/ and the experience store's scope
# (conceptual_map/knowledge/experience.py: BUILDING_ID); no `/`, and never `.` or `..`
BUILDING_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$"
MAX_SINCE_S = 30 * 86_400.0  # the default since_s is capped here (a month: sightings fade
# below the memory's 1% in a few weeks; furniture rates are per year)
MAX_TEXT = 500_000
OptionValue = bool | int | float | Annotated[str, Field(max_length=200)] | None
OptionName = Annotated[str, StringConstraints(pattern=NAME_PATTERN)]
Label = Annotated[str, StringConstraints(pattern=NAME_PATTERN)]
# a task's form, as the episode runner reads it (avs_planner/harness/tasks.py: MAX_TARGETS,
# STOP_BELOW; tests/api/test_api_task_forms.py checks that they agree)
MAX_TARGETS = 8
STOP_BELOW = 0.1


def _exactly_one(*names: str) -> dict[str, Any]:
    """`oneOf` branches saying exactly one of `names` is given (a present null counts as
    absent, as the service reads it), for clients reading the schema."""
    return {"oneOf": [{"required": [name], "properties": {name: {"not": {"type": "null"}}}}
                      for name in names]}


# exactly one of world / world_file / generate, and one of target / targets
_ONE_WORLD = _exactly_one("world", "world_file", "generate")
_TASK_SCHEMA = {**_ONE_WORLD, "allOf": [_exactly_one("target", "targets")]}


def world_file_problem(text: str) -> str | None:
    """Why an inline world file cannot be a world (too costly to read, not YAML, not a
    mapping), or None. Read with bounded alias expansion, size and depth."""
    problem = yaml_problem(text, "world_file")
    if problem:
        return problem
    if not isinstance(load_yaml(text), dict):
        return "world_file must be a YAML mapping (name, size, rooms, ...)"
    return None



def _checked_pddl(text: str) -> str:
    """PDDL text within the nesting and name limits (`limits.pddl_problem`), else a short
    validation error."""
    problem = pddl_problem(text, "the text")
    if problem:
        raise ValueError(problem)
    return text

class TaskState(StrEnum):
    """Where a task is in its life; the last five are terminal."""

    QUEUED = "queued"
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    GAVE_UP = "gave_up"
    TIMEOUT = "timeout"
    CANCELLED = "cancelled"

    @property
    def terminal(self) -> bool:
        return self not in (TaskState.QUEUED, TaskState.RUNNING)


class GeneratedWorld(BaseModel):
    """A building made by the floor-plan generator (`avs world generate`): the same arguments
    give the same building. The room count's range depends on the style (422 naming it)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    seed: int = Field(ge=0, le=2**31 - 1, examples=[3])
    style: Literal["office", "apartment", "lab"] = "office"
    rooms: int | None = Field(None, ge=1, le=64, description="rooms off the spine; default: "
                              "drawn from the seed")
    surprise: float = Field(0.25, ge=0.0, le=1.0, description="share of small objects placed "
                            "where the knowledge base rates them unlikely")
    day: int | None = Field(None, ge=0, le=100_000, description="the building this many days "
                            "on (0: as generated): small objects moved and doors toggled day "
                            "by day, the same for the same arguments", examples=[1])
    move: float | None = Field(None, ge=0.0, le=1.0, description="with `day`: per day, the "
                               "probability each small object is moved (default 0.2)")
    doors: float | None = Field(None, ge=0.0, le=1.0, description="with `day`: per day, the "
                                "probability each door toggles open or closed (default 0)")


class TaskCreate(BaseModel):
    """Find `target` (a label), or the `targets` (several labels, `mode` all or any), or
    every instance of one label (`count: all`) [in a room of `category`] in a world, with a
    robot.

    Give exactly one of `target` and `targets`, exactly one of `world`, `world_file` and
    `generate`, and at most one of `start` and `start_room`. Checked at submission against the
    knowledge base (category; every target label when `strict_labels`), the world (start room,
    start pose free and inside a room) and the strategy registry: 422 naming the field."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False,
                              json_schema_extra=_TASK_SCHEMA)

    target: str | None = Field(
        None, pattern=NAME_PATTERN, description="one object label (or give `targets`)",
        examples=["cerealbox"])
    targets: list[Label] | None = Field(
        None, min_length=1, max_length=MAX_TARGETS,
        description=f"several object labels, each once, at most {MAX_TARGETS} (or give "
        "`target`): the task ends when one object of each is reported (`mode: all`) or the "
        "first of any (`mode: any`)", examples=[["cup", "stapler"]])
    mode: Literal["all", "any"] = Field(
        "all", description="how `targets` combine: `all` finds one object of each label, "
        "`any` ends at the first object of any of them")
    count: Literal["one", "all"] = Field(
        "one", description="`one`: report one object per label; `all`: every instance of "
        "the one label given (the task stops when P(another one in space not yet searched) "
        "falls below `stop_below`)")
    stop_below: float | None = Field(
        None, gt=0, lt=1, description=f"with `count: all` only: the probability of another "
        f"instance below which the count stops; default {STOP_BELOW}", examples=[0.1])
    category: str | None = Field(None, pattern=NAME_PATTERN, examples=["kitchen"])
    world: str | None = Field(None, pattern=NAME_PATTERN, description="a built-in world name")
    world_file: str | None = Field(
        None, max_length=MAX_TEXT, description="an inline world file (YAML text; at most 64 "
        "aliases, 50,000 nodes with aliases expanded, 20 levels deep)"
    )
    generate: GeneratedWorld | None = Field(
        None, description="a generated building (see `avs world generate`)",
        examples=[{"seed": 3, "style": "office"}])
    robot: Literal["pioneer", "pr2"] | None = Field(
        None, description="robot model; default: the one the world file names")
    start_room: str | None = Field(None, pattern=NAME_PATTERN)
    start: tuple[float, float, float] | None = Field(
        None, description="start pose x, y, yaw (m, m, rad), finite, inside a room and clear of "
        "furniture; default: the world's"
    )
    seed: int = Field(0, ge=0, le=2**31 - 1)
    time_budget_s: float = Field(600.0, gt=0, le=86_400, description="simulated seconds")
    strategy: str = Field("switching", pattern=NAME_PATTERN,
                          description="search strategy (GET /v1/strategies lists them)")
    strategy_options: dict[OptionName, OptionValue] = Field(
        default_factory=dict, max_length=50, description="the strategy's options by name; "
        "options naming files (any `*_file`, `*_path`, `*_dir`) and values that look like "
        "file paths are refused (422): the service reads and writes no file a request names")
    qsr: list[dict[str, Any]] | dict[str, Any] | None = Field(
        None, description="QSR descriptions of where the target is (strategies qsr, "
        "supporting-planes, random and the switching planner's cones): a list in the format of "
        "the QSR knowledge file's `descriptions` (or {descriptions: [...]}), e.g. [{target: "
        "cup, relations: [right, close], of: keyboard, count: 1}]; see "
        "conceptual_map/qsr/README.md. Default: the built-in QSR knowledge",
        examples=[[{"target": "cup", "relations": ["right", "close"], "of": "keyboard",
                    "count": 1}]])
    strict_labels: bool = Field(
        False, description="refuse a target label the knowledge base does not know (422 at "
        "submission); default: such a label is searched for with an uninformed prior")
    building: str | None = Field(
        None, pattern=BUILDING_PATTERN, description="the building's id (1-64 letters, digits, "
        "`_`, `.`, `-`, starting with a letter or digit): the task starts from what the robot "
        "remembers of it and keeps what it learns (its map, furniture, sightings; "
        "docs/memory.md) and plans with the priors learned there (docs/learning.md). Tasks of "
        "one building run one at a time, in order; a building is always the same world",
        examples=["office-3"])
    since_s: float | None = Field(
        None, ge=0, le=10 * 365 * 86_400.0, description="with `building`: simulated seconds "
        "since the building's previous task (objects are moved at the knowledge's rates in "
        "that time); default: the real seconds since its memory was last written, at most "
        f"{MAX_SINCE_S:.0f} (30 days)", examples=[86400])

    @field_validator("world_file")
    @classmethod
    def _bounded_world_file(cls, text: str | None) -> str | None:
        problem = world_file_problem(text) if text is not None else None
        if problem:
            raise ValueError(problem)
        return text

    @field_validator("qsr")
    @classmethod
    def _bounded_qsr(cls, value: Any) -> Any:
        if value is None:
            return value
        problem = json_problem(value, "qsr")
        if problem:
            raise ValueError(problem)
        if any(looks_like_path(text) for text in flatten_strings(value)):
            raise ValueError("qsr holds a value that looks like a file path; descriptions are "
                             "given inline, the service reads no file a request names")
        return value

    @model_validator(mode="after")
    def _one_world(self) -> TaskCreate:
        given = [self.world, self.world_file, self.generate]
        if sum(v is not None for v in given) != 1:
            raise ValueError("give exactly one of 'world' (a name), 'world_file' (YAML text) "
                             "or 'generate' ({seed, style, rooms, surprise})")
        if self.start is not None and self.start_room is not None:
            raise ValueError("give at most one of 'start' and 'start_room'")
        return self

    @model_validator(mode="after")
    def _since_needs_building(self) -> TaskCreate:
        if self.since_s is not None and self.building is None:
            raise ValidationError.from_exception_data(type(self).__name__, [InitErrorDetails(
                type=PydanticCustomError("value_error", "'since_s' applies to a task in a "
                                         "'building' only"), loc=("since_s",),
                input=self.since_s)])
        return self

    @model_validator(mode="after")
    def _task_form(self) -> TaskCreate:
        """The task form's rules (those of the episode runner's `TaskForm.from_spec`), each
        error located at the field it is about."""
        errors = task_form_problems(self.target, self.targets, self.count, self.stop_below)
        if errors:
            raise ValidationError.from_exception_data(type(self).__name__, [
                InitErrorDetails(type=PydanticCustomError(kind, message), loc=(name,),
                                 input=getattr(self, name))
                for name, kind, message in errors])
        return self

    def as_request(self) -> dict[str, Any]:
        """The task as stored and given to the episode runner: the body with defaults filled
        in, less the task-form keys it does not use. A task of one label found once reads as
        it did before `targets` existed (`target`, no `mode` or `count` at their defaults);
        `targets` tasks keep `mode` and `count`; `stop_below`, `building`, `since_s` and
        `generate`'s `day`, `move`, `doors` only when given."""
        request = self.model_dump(mode="json")
        for key in ("target", "targets", "stop_below", "building", "since_s"):
            if request[key] is None:
                del request[key]
        if request.get("generate") is not None:  # a generated day only when asked for
            for key in ("day", "move", "doors"):
                if request["generate"][key] is None:
                    del request["generate"][key]
        if self.targets is None and self.count == "one":
            for key, default in (("mode", "all"), ("count", "one")):
                if request[key] == default:
                    del request[key]
        return request


def task_form_problems(target: str | None, targets: list[str] | None, count: str,
                       stop_below: float | None) -> list[tuple[str, str, str]]:
    """(field, error type, message) for each rule of a task's form the values break: one of
    `target` and `targets`, each label once, `count: all` with one label, `stop_below` with
    `count: all` only (types and ranges are the fields' own)."""
    errors = []
    if target is not None and targets is not None:
        errors.append(("targets", "value_error", "give 'target' (one label) or 'targets' (a "
                       "list), not both"))
    elif target is None and targets is None:
        errors.append(("target", "missing", "Field required: give 'target' (one object "
                       "label) or 'targets' (a list of labels)"))
    if targets is not None:
        twice = sorted({t for t in targets if targets.count(t) > 1})
        if twice:
            errors.append(("targets", "value_error", f"'targets' names {', '.join(twice)} "
                           f"more than once (to find every instance, use count: all)"))
        if count == "all" and len(targets) != 1:
            errors.append(("count", "value_error", f"'count: all' finds every instance of "
                           f"one label; 'targets' names {len(targets)}"))
    if stop_below is not None and count != "all":
        errors.append(("stop_below", "value_error", "'stop_below' applies to 'count: all' "
                       "only"))
    return errors


def task_name(targets: list[str], mode: str = "all", count: str = "one") -> str:
    """The task in a few words, as the episode's summary names it (`TaskForm.name`): "cup",
    "cup and book", "cup or glass", "every chair"."""
    if count == "all":
        return f"every {targets[0]}"
    if len(targets) == 1:
        return targets[0]
    joint = " and " if mode == "all" else " or "
    return ", ".join(targets[:-1]) + joint + targets[-1]


class TaskFormPublic(BaseModel):
    """What a task asks for: its target labels, how they combine, and its name."""

    targets: list[str] = Field(description="the target labels (one for a `target` task)")
    mode: Literal["all", "any"] = Field(description="`all`: one object of each label; `any`: "
                                        "the first object of any of them")
    count: Literal["one", "all"] = Field(description="`all`: every instance of the label")
    stop_below: float | None = Field(None, description="with `count: all`: the level P(another "
                                     "one) must fall below (the default when not given)")
    name: str = Field(description="the task in a few words, as the summary's `target` names "
                      "it", examples=["cup and stapler"])
    several: bool = Field(description="more than one object may be reported (several labels "
                          "or `count: all`): the summary has `targets`")

    @classmethod
    def of_request(cls, request: dict[str, Any]) -> TaskFormPublic | None:
        """The form of a stored request (any version: older ones have `target` only); None
        when it names no target."""
        targets = request.get("targets")
        if not isinstance(targets, list) or not targets:
            target = request.get("target")
            targets = [target] if isinstance(target, str) and target else None
        if targets is None or not all(isinstance(t, str) for t in targets):
            return None
        mode = request.get("mode") if request.get("mode") in ("all", "any") else "all"
        count = request.get("count") if request.get("count") in ("one", "all") else "one"
        stop = request.get("stop_below")
        stop_below = (float(stop) if isinstance(stop, int | float) else STOP_BELOW) \
            if count == "all" else None
        return cls(targets=list(targets), mode=mode, count=count, stop_below=stop_below,
                   name=task_name(targets, mode, count),
                   several=len(targets) > 1 or count == "all")


class ReportedObject(BaseModel):
    """An object the robot reported, with the world entry it names (scoring only)."""

    id: str
    label: str
    position: list[float] = Field(description="x, y, z (m)")
    room: str | None = None
    truth: str | None = Field(None, description="the world's object the report names (the "
                              "robot never sees this)")
    correct: bool = Field(description="the report names a true instance of its label")


class TargetPublic(BaseModel):
    """One target label's part of a finished task of several (the summary's `targets`)."""

    label: str
    outcome: str = Field(description="`found`, `gave_up`, `timeout` or `not_needed` (a task of "
                         "`mode: any` ended before this label's turn)", examples=["found"])
    reason: str = ""
    objects: list[ReportedObject] = Field(default_factory=list,
                                          description="the objects reported for it")
    sim_time_s: float | None = Field(None, description="simulated seconds from the start "
                                     "when its part ended (null: never)")
    turns: int = Field(0, description="turns the robot spent searching for it")
    instances: int | None = Field(None, description="true instances in the world (scoring "
                                  "only)")
    distinct: int | None = Field(None, description="distinct true instances the reports name")
    correct: bool | None = Field(None, description="every report names a true instance")

    @classmethod
    def of_summary(cls, summary: dict[str, Any] | None) -> list[TargetPublic] | None:
        """The summary's `targets`, or None when it has none (a task of one label found
        once) or they are not in the expected shape."""
        parts = (summary or {}).get("targets")
        if not isinstance(parts, list):
            return None
        try:
            return [cls.model_validate(part) for part in parts]
        except ValidationError:
            return None


class TaskPublic(BaseModel):
    """A task as clients see it."""

    id: str
    state: TaskState
    request: dict[str, Any]
    task: TaskFormPublic | None = Field(None, description="what the task asks for (from `request`)")
    targets: list[TargetPublic] | None = Field(
        None, description="once a task of several (several labels or `count: all`) ended: "
        "each label's part, from the summary's `targets`; null otherwise (a task of one label "
        "has the summary's `outcome` and `object`)")
    created_at: float
    started_at: float | None = None
    finished_at: float | None = None
    summary: dict[str, Any] | None = None
    error: str | None = None
    events: int = 0
    attempts: int = Field(0, description="times it started running (2 after a requeue)")


class TasksPublic(BaseModel):
    data: list[TaskPublic]
    count: int


class PlanCreate(BaseModel):
    """A domain and a problem in (probabilistic) PDDL, with planner options."""

    model_config = ConfigDict(extra="forbid")

    domain: str = Field(min_length=1, max_length=MAX_TEXT)
    problem: str = Field(min_length=1, max_length=MAX_TEXT)

    @field_validator("domain", "problem")
    @classmethod
    def _bounded_pddl(cls, text: str) -> str:
        return _checked_pddl(text)
    reward: float | None = Field(None, gt=0, description="R in c(pi) + R(1 - p(pi))")
    weight: float | None = Field(None, ge=1, le=100)
    timeout_s: float | None = Field(None, gt=0, le=3600)
    patience: int | None = Field(
        None, ge=0, le=10_000_000,
        description="once a plan is found, expansions without a better one before the best "
        "is returned (default 2500 with the default heuristic)")
    anytime: bool | None = Field(
        None, description="anytime satisficing: greedy best-first first, then weighted A* "
        "restarts; the best plan by objective at timeout_s")


class Diagnostic(BaseModel):
    """One linter finding; `file` is `domain` or `problem[i]`."""

    file: str
    line: int
    column: int
    severity: Literal["error", "warning"]
    message: str
    code: str


class PlanPublic(BaseModel):
    """The planner's answer: status, plan and its cost, success probability and objective."""

    status: str
    plan: list[str] = []
    cost: float | None = None
    probability: float | None = None
    objective: float | None = None
    reward: float | None = None
    planning_time_s: float | None = None
    expanded: int | None = None
    stopped_by: str | None = Field(
        None, description="patience, timeout or node_limit: the search was stopped with a "
        "plan in hand, which is the best found so far")
    warnings: list[Diagnostic] = Field(
        default_factory=list, description="what the reader accepted or repaired, e.g. a "
        "requirement used but not declared (`avs domain check --strict` makes these errors)")


class PlanJobState(StrEnum):
    QUEUED = "queued"
    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"
    CANCELLED = "cancelled"


class JobError(BaseModel):
    """What the synchronous call would have answered instead of 200: its status and detail."""

    status: int
    detail: Any


class PlanJobPublic(BaseModel):
    """An asynchronous plan job (`POST /v1/plans?wait=false`); poll `GET /v1/plans/{id}`."""

    id: str
    state: PlanJobState
    created_at: float
    finished_at: float | None = None
    result: PlanPublic | None = None
    error: JobError | None = None


class DomainCheckCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    domain: str = Field(min_length=1, max_length=MAX_TEXT)
    problems: list[str] = Field(default_factory=list, max_length=50)

    @field_validator("domain")
    @classmethod
    def _bounded_domain(cls, text: str) -> str:
        return _checked_pddl(text)

    @field_validator("problems")
    @classmethod
    def _bounded_problems(cls, texts: list[str]) -> list[str]:
        for i, text in enumerate(texts):
            problem = pddl_problem(text, f"problems[{i}]")
            if problem:
                raise ValueError(problem)
        return texts


class DomainCheckPublic(BaseModel):
    ok: bool
    errors: int
    warnings: int
    diagnostics: list[Diagnostic]


class WorldPublic(BaseModel):
    name: str
    rooms: list[str] = []


class WorldsPublic(BaseModel):
    data: list[WorldPublic]
    count: int


class StrategyPublic(BaseModel):
    name: str
    summary: str
    options: dict[str, Any]


class StrategiesPublic(BaseModel):
    data: list[StrategyPublic]
    count: int


class Health(BaseModel):
    """`degraded` (still 200): the store refuses writes (e.g. the disk is full); `reason` says
    why. Reads work; submissions get 503 until writes succeed again, then it is `ok`."""

    status: Literal["ok", "degraded"]
    reason: str | None = None
    version: str
    workers: int
    queued: int
    running: int
    open_access: bool


class Message(BaseModel):
    detail: Any


TOO_LARGE: dict[int | str, dict[str, Any]] = {
    413: {"model": Message, "description": "body larger than AVS_MAX_BODY_BYTES"},
}
