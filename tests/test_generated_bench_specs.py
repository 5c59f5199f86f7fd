"""The generated-world benchmark's episode specs: targets from the generator, options and the
simulated budget passed through, bad arguments a clear error."""

from __future__ import annotations

import pytest

from bench.generated_bench import episodes, main


def test_specs_carry_the_budget_and_the_switching_options_only_to_switching() -> None:
    specs = episodes(1, "office", ["switching", "exhaustive"], first=3,
                     options={"reward": 1000}, budget=2400.0)
    assert len(specs) == 6  # 3 targets x 2 strategies
    assert {s["time_budget_s"] for s in specs} == {2400.0}
    assert sum(s["present"] for s in specs) == 4
    assert all(("strategy_options" in s) == (s["strategy"] == "switching") for s in specs)
    assert all("time_budget_s" not in s for s in episodes(1, "office", ["switching"]))


def test_a_bad_budget_is_a_clear_error(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["--budget", "0"])
    assert "--budget must be a positive number of seconds" in capsys.readouterr().err
