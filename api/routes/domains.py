"""/domains/check: the PDDL linter (`avs domain check`) over HTTP."""

from __future__ import annotations

from fastapi import APIRouter, Request

from api.deps import ManagerDep, WriteAccess
from api.routes.jobs import run_job
from api.schemas import TOO_LARGE, Diagnostic, DomainCheckCreate, DomainCheckPublic, Message

router = APIRouter(prefix="/domains", tags=["domains"])


@router.post(
    "/check",
    responses={401: {"model": Message}, 429: {"model": Message}, 503: {"model": Message},
               **TOO_LARGE},
)
async def check_domain(
    body: DomainCheckCreate, owner: WriteAccess, manager: ManagerDep, request: Request
) -> DomainCheckPublic:
    """Lint a domain and problems: 200 with every diagnostic (`ok` is false if any error)."""
    payload = {"domain_text": body.domain, "problem_texts": body.problems}
    found = await run_job(manager, "check", payload, request.is_disconnected)
    diagnostics = [Diagnostic.model_validate(d) for d in found]
    errors = sum(d.severity == "error" for d in diagnostics)
    return DomainCheckPublic(
        ok=errors == 0, errors=errors, warnings=len(diagnostics) - errors, diagnostics=diagnostics
    )
