"""/plans: plan a probabilistic PDDL problem (the same planner `avs plan` runs)."""

from __future__ import annotations

from fastapi import APIRouter, HTTPException, status

from api.deps import ManagerDep, SettingsDep, WriteAccess
from api.routes.jobs import pddl_422, run_job
from api.schemas import Message, PlanCreate, PlanPublic

router = APIRouter(prefix="/plans", tags=["plans"])

PLANNER_SHARE = 0.8  # of the job's wall-clock limit; the rest is reading and grounding


@router.post(
    "",
    responses={
        401: {"model": Message}, 422: {"model": Message, "description": "bad input or PDDL"},
        429: {"model": Message}, 503: {"model": Message}, 504: {"model": Message},
    },
)
async def create_plan(
    body: PlanCreate, owner: WriteAccess, manager: ManagerDep, settings: SettingsDep
) -> PlanPublic:
    """Plan: 200 with status (solved, unsolvable, timeout, ...) and the plan; 422 for bad PDDL.

    The planner's own timeout is capped below the job's wall-clock limit, so a long search
    ends as status `timeout` rather than a killed job (504)."""
    options = body.model_dump(include={"reward", "weight", "timeout_s", "patience", "anytime"},
                              exclude_none=True)
    cap = settings.plan_time_limit_s * PLANNER_SHARE
    options["timeout_s"] = min(options.get("timeout_s", cap), cap)
    payload = {"domain_text": body.domain, "problem_text": body.problem, "options": options}
    value = await run_job(manager, "plan", payload)
    if value.get("status") == "invalid":
        raise pddl_422(value.get("errors", []))
    if value.get("status") == "unsupported":
        detail = f"the planner cannot handle this problem: {value.get('message')}"
        raise HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, detail=detail)
    return PlanPublic.model_validate(value)
