"""One object-search episode: the switching planner in the loop with a simulated robot.

`run_episode(spec, emit, should_stop)` is the entry point the HTTP jobs and `avs simulate`
call. Robot side: `robot.py` (the only module that talks to `sim`). Mind side: `mind.py`,
`state_builder.py`, `viewcones.py`, `executor.py`, `loop.py`.
"""

from avs_planner.episode.errors import EpisodeError
from avs_planner.episode.runner import Episode, EpisodeSpec, run_episode

__all__ = ["Episode", "EpisodeError", "EpisodeSpec", "run_episode"]
