"""/domains/check: the PDDL linter (`avs domain check`) over HTTP."""

from __future__ import annotations

from fastapi import APIRouter, Request

from api.deps import ManagerDep, WriteAccess
from api.limits import short
from api.manager import QuotaError
from api.routes.jobs import over_quota, run_job
from api.schemas import TOO_LARGE, Diagnostic, DomainCheckCreate, DomainCheckPublic, Message

router = APIRouter(prefix="/domains", tags=["domains"])


@router.post(
    "/check",
    responses={401: {"model": Message}, 403: {"model": Message}, 429: {"model": Message},
               503: {"model": Message}, **TOO_LARGE},
)
async def check_domain(
    body: DomainCheckCreate, caller: WriteAccess, manager: ManagerDep, request: Request
) -> DomainCheckPublic:
    """Lint a domain and problems: 200 with every diagnostic (`ok` is false if any error;
    messages are cut to 300 characters)."""
    payload = {"domain_text": body.domain, "problem_texts": body.problems}
    try:
        manager.take_plan_slot(caller)
    except QuotaError as exc:
        raise over_quota(exc) from exc
    try:
        found = await run_job(manager, "check", payload, request.is_disconnected)
    finally:
        manager.free_plan_slot(caller.owner)
    diagnostics = [Diagnostic.model_validate({**d, "message": short(str(d.get("message", "")))})
                   for d in found]
    errors = sum(d.severity == "error" for d in diagnostics)
    return DomainCheckPublic(
        ok=errors == 0, errors=errors, warnings=len(diagnostics) - errors, diagnostics=diagnostics
    )
