"""One object-search episode as the robot's mind lives it: what it knows and how it acts.

Mind side only: `mind.py`, `state_builder.py` (with `probabilities.py` and `pricing.py`),
`viewcones.py`, `executor.py` and its skills (`context.py`, what each skill receives;
`driving.py`, `sensing.py`, `verifying.py`, `cone_sets.py`, `dt_search.py`), `robot_api.py`
(the robot as the mind sees it); nothing here imports the simulator. The wiring to `sim` and
the entry point `run_episode(spec, emit, should_stop)` are in `avs_planner.harness`; the
switching loop is the switching strategy's (`avs_planner.strategies.switching`).
"""

from avs_planner.episode.errors import EpisodeError

__all__ = ["EpisodeError"]
