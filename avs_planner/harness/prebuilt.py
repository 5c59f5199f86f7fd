"""Pre-built maps (Fig. 3f of the active visual search paper by Göbelbecker et al.): explore to
the nearest placeholder until none is left, with the executor's own sensing, so the maps and the
conceptual map are the robot's."""

from __future__ import annotations

from avs_planner.episode.executor import Executor
from avs_planner.episode.outcome import StepStatus


def explore(executor: Executor, max_moves: int = 60) -> int:
    """Visit placeholders nearest-first; returns how many drives were made. The robot is not
    searching yet (in the active visual search paper it was driven by joystick), so its detector
    does not watch."""
    mind = executor.mind
    executor.watching = False
    executor.look_around()
    moves = 0
    while moves < max_moves:
        target = executor.nearest_placeholder()
        if target is None:
            break
        moves += 1
        mind.tried_placeholders[target] = mind.tried_placeholders.get(target, 0) + 1
        goal = mind.place_map.placeholders[target].position
        outcome = executor.drive_to(goal, stop=lambda t=target: t not in
                                    mind.place_map.placeholders)
        if outcome.status is StepStatus.DONE:
            executor.look_around()
    mind.tried_placeholders.clear()
    executor.watching = True
    return moves
