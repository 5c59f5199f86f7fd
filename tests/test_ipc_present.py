"""The IPC benchmark set is where the tests and benches look for it (a failure under CI)."""

from tests.ipc import NOT_READ_YET, NOT_SOLVED_YET, ipc_domains, require_ipc


def test_ipc_set_present_and_known_gaps_exist() -> None:
    ipc = require_ipc()
    names = {d.parent.name for d in ipc.glob("*/domain.pddl")}
    assert names, f"no */domain.pddl under {ipc}"
    # the gaps listed as not read / not solved yet are domains of the set, not stale names
    assert set(NOT_READ_YET) | set(NOT_SOLVED_YET) <= names
    assert set(ipc_domains(solvable=True)) == names - set(NOT_READ_YET) - set(NOT_SOLVED_YET)
