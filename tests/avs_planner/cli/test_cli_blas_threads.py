"""`avs` runs numpy with one OpenBLAS thread unless the user chose a number."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from avs_planner.cli import main

DOMAIN = Path(__file__).resolve().parents[3] / "domains" / "avs" / "domain.pddl"


def test_one_blas_thread_by_default(monkeypatch, capsys):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "unset")  # recorded: restored after the test
    monkeypatch.delenv("OPENBLAS_NUM_THREADS")
    assert main(["domain", "check", str(DOMAIN)]) == 0
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"


@pytest.mark.parametrize("chosen", ["1", "4"])
def test_the_users_choice_is_kept(monkeypatch, capsys, chosen):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", chosen)
    assert main(["domain", "check", str(DOMAIN)]) == 0
    assert os.environ["OPENBLAS_NUM_THREADS"] == chosen
