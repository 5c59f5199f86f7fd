"""The IPC benchmark set is where the tests and benches look for it (a failure under CI)."""

from tests.ipc import (
    NOT_READ_YET,
    NOT_SOLVED_YET,
    domain_for,
    instances,
    ipc_domains,
    ipc_folders,
    require_ipc,
)


def test_ipc_set_present_and_known_gaps_exist() -> None:
    ipc = require_ipc()
    names = {f.name for f in ipc_folders(ipc)}
    assert names, f"no domain folder (domain.pddl or domain-N.pddl) under {ipc}"
    # every folder of the set is a domain the tests take, none is left out unnoticed
    assert names == {f.name for f in ipc.iterdir() if f.is_dir()}
    # the gaps listed as not read / not solved yet are domains of the set, not stale names
    assert set(NOT_READ_YET) | set(NOT_SOLVED_YET) <= names
    assert set(ipc_domains(solvable=True)) == names - set(NOT_READ_YET) - set(NOT_SOLVED_YET)


def test_every_instance_has_its_domain_file() -> None:
    """One domain.pddl per folder, or (airport, openstacks, trucks) domain-N per instance-N."""
    for folder in ipc_folders(require_ipc()):
        found = instances(folder)
        assert found, f"no instance-N.pddl in {folder}"
        for instance in found:
            assert domain_for(instance).is_file()
    own = require_ipc() / "trucks" / "instance-2.pddl"
    assert domain_for(own).name == "domain-2.pddl"
    assert domain_for(require_ipc() / "blocks" / "instance-10.pddl").name == "domain.pddl"
    assert [p.name for p in instances(require_ipc() / "blocks")][:3] == [
        "instance-1.pddl", "instance-2.pddl", "instance-3.pddl"]


def test_an_instance_without_a_domain_file_is_named(tmp_path) -> None:
    import pytest

    (tmp_path / "instance-3.pddl").write_text("")
    with pytest.raises(FileNotFoundError, match="neither domain.pddl nor domain-3.pddl"):
        domain_for(tmp_path / "instance-3.pddl")
