"""/plans: plan a probabilistic PDDL problem (the same planner `avs plan` runs), waiting for the
answer or (`?wait=false`) as an asynchronous job to poll."""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, Any

from fastapi import APIRouter, HTTPException, Path, Query, Request, Response, status

from api.deps import ManagerDep, ReadAccess, SettingsDep, WriteAccess
from api.limits import MAX_ERRORS, short
from api.manager import QueueFullError, QuotaError, TaskManager
from api.plan_jobs import NotCancellable, PlanJobs
from api.routes.jobs import over_quota, pddl_422, queue_full, run_job
from api.schemas import TOO_LARGE, Message, PlanCreate, PlanJobPublic, PlanPublic

router = APIRouter(prefix="/plans", tags=["plans"])

PLANNER_SHARE = 0.8  # of the job's wall-clock limit; the rest is reading and grounding
JobId = Annotated[str, Path(max_length=64, description="a plan job id")]
_ERRORS: dict[int | str, dict[str, Any]] = {
    401: {"model": Message}, 403: {"model": Message}, 429: {"model": Message},
    503: {"model": Message},
}


def _payload(body: PlanCreate, settings: SettingsDep) -> dict[str, Any]:
    options = body.model_dump(include={"reward", "weight", "timeout_s", "patience", "anytime"},
                              exclude_none=True)
    cap = settings.plan_time_limit_s * PLANNER_SHARE
    options["timeout_s"] = min(options.get("timeout_s", cap), cap)
    return {"domain_text": body.domain, "problem_text": body.problem, "options": options}


async def _plan(manager: TaskManager, payload: dict[str, Any], request: Request | None = None,
                on_start: Callable[[], bool] = lambda: True) -> PlanPublic:
    disconnected = request.is_disconnected if request is not None else None
    value = await run_job(manager, "plan", payload, disconnected, on_start)
    if value.get("status") == "invalid":
        raise pddl_422(value.get("errors", []))
    if value.get("status") == "unsupported":
        detail = f"the planner cannot handle this problem: {value.get('message')}"
        raise HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)
    warnings = [{**w, "message": short(str(w.get("message", "")))}
                for w in value.get("warnings") or []][:MAX_ERRORS]
    return PlanPublic.model_validate({**value, "warnings": warnings})


@router.post(
    "",
    responses={
        **_ERRORS, **TOO_LARGE,
        202: {"model": PlanJobPublic, "description": "wait=false: the job, queued"},
        422: {"model": Message, "description": "bad input or PDDL"}, 504: {"model": Message},
    },
)
async def create_plan(
    body: PlanCreate, caller: WriteAccess, manager: ManagerDep, settings: SettingsDep,
    request: Request, response: Response,
    wait: Annotated[bool, Query(description="false: answer 202 at once with a job to poll "
                                            "at /v1/plans/{id}")] = True,
) -> PlanPublic | PlanJobPublic:
    """Plan: 200 with status (solved, unsolvable, timeout, ...) and the plan; 422 for bad PDDL.

    The planner's own timeout is capped below the job's wall-clock limit, so a long search
    ends as status `timeout` rather than a killed job (504). A client that disconnects has its
    job cancelled. With `wait=false` the answer is 202 and a job id: the job's `result` (or
    `error`, with the status the waiting call would have had) appears at `GET /v1/plans/{id}`."""
    payload = _payload(body, settings)
    if wait:
        try:
            manager.take_plan_slot(caller)
        except QuotaError as exc:
            raise over_quota(exc) from exc
        try:
            return await _plan(manager, payload, request)
        finally:
            manager.free_plan_slot(caller.owner)
    jobs: PlanJobs = request.app.state.plan_jobs
    try:
        job = jobs.start(caller, lambda started: _plan(manager, payload, on_start=started))
    except QueueFullError as exc:
        raise queue_full(exc) from exc
    except QuotaError as exc:
        raise over_quota(exc) from exc
    response.status_code = status.HTTP_202_ACCEPTED
    response.headers["Location"] = f"/v1/plans/{job.id}"
    return job


@router.get("/{job_id}", responses={401: {"model": Message}, 404: {"model": Message}})
async def read_plan_job(job_id: JobId, caller: ReadAccess, request: Request) -> PlanJobPublic:
    """An asynchronous plan job: its state, then its `result` or `error` (a key reads its own
    jobs; an admin key any)."""
    job = request.app.state.plan_jobs.get(job_id, caller)
    if job is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no plan job with id {job_id}")
    return job


@router.delete("/{job_id}",
               responses={**_ERRORS, 404: {"model": Message}, 409: {"model": Message}})
async def cancel_plan_job(job_id: JobId, caller: WriteAccess, request: Request
                          ) -> PlanJobPublic:
    """Cancel an asynchronous plan job (its worker is freed at once); 409 when it already
    ended (as for tasks): its result stays readable until newer jobs push it out."""
    try:
        job = request.app.state.plan_jobs.cancel(job_id, caller)
    except NotCancellable as exc:
        raise HTTPException(status.HTTP_409_CONFLICT, detail=str(exc)) from exc
    if job is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, detail=f"no plan job with id {job_id}")
    return job
