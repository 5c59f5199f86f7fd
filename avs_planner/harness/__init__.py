"""The harness: the only code that knows both the simulator and the robot's mind.

`run_episode(spec, emit, should_stop)` is the entry point the HTTP jobs and `avs simulate`
call. Robot side: `sim_robot.py` (the adapter, the only module of the episode that talks to
`sim`); `runner.py` (one episode), `validate.py` and `worlds.py` (world files and generated
worlds), `scenarios.py` (the built-in scenarios in `scenarios/`), `scoring.py` (the robot's
map scored against the world's truth), `prebuilt.py` (pre-built maps).
"""

from avs_planner.harness.runner import Episode, EpisodeSpec, run_episode

__all__ = ["Episode", "EpisodeSpec", "run_episode"]
