"""The package's names load on first use: `avs_planner.dt` imports no solver until asked."""

from __future__ import annotations

import subprocess
import sys

import pytest

import avs_planner.dt as dt


def test_every_listed_name_has_a_home_and_loads() -> None:
    assert sorted(dt.__all__) == sorted(dt._HOME)
    for name in dt.__all__:
        value = getattr(dt, name)
        module = __import__(f"avs_planner.dt.{dt._HOME[name]}", fromlist=[name])
        assert value is getattr(module, name)
    assert dt.ViewCone.__module__ == "avs_planner.dt.inputs"


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        dt.Nope  # noqa: B018


def test_the_view_cone_and_detector_model_need_no_pomdp_py() -> None:
    code = ("import sys; from avs_planner.dt import DetectorModel, ViewCone; "
            "ViewCone('c', (0.0, 0.0, 0.0), 0.5).check('c'); DetectorModel(); "
            "print('pomdp_py' in sys.modules); from avs_planner.dt import DTSession; "
            "print('pomdp_py' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.split() == ["False", "True"], out.stderr
