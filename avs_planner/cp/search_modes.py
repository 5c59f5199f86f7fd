"""How a search call runs, decided once from its options and task: when successors are
evaluated (`_lazy`) and which open lists exist (`_preferred`, `_goal_count`).

Both engines take the same decisions: `python_search.py` reads them, and `search.py` hands
them to the C core (the core's LAZY_* and queue flags QF_*), so the two expand the same
nodes. Optimality counts with an admissible h, and then every mode falls back to the plain
eager A* with one open list.
"""

from __future__ import annotations

from avs_planner.cp.heuristics import get_heuristic
from avs_planner.cp.search_options import SearchOptions
from avs_planner.cp.task import GroundTask

EAGER, DEFERRED, DEFERRED_UNHELPFUL = 0, 1, 2  # _lazy's modes (the C core's LAZY_*)


def _lazy(task: GroundTask, options: SearchOptions) -> int:
    """When successors are evaluated: as asked, or by default deferred on deterministic tasks
    and, on probabilistic ones, deferred unless reached by a helpful action; never deferred
    with admissible h.

    Deferring all of them on probabilistic tasks hurts: a successor inherits its parent's
    estimate, so a move that brings the goal closer looks no better than a cheaper useless
    step (a view cone for a label nobody looks for), and the search exhausts the plateau of
    such steps first (a 20-place AVS problem: 200,000 expansions without a plan, 14 eager).
    Helpful actions are the relaxed plan's first steps: evaluating their successors at once
    puts the moves the estimate wants first in the queue with their own estimate, and the
    rest (most of a large task's successors: 341 of 346 at the start of a 160-place
    problem) wait to be popped. When h stalls, see STALL and `_Search.flush`."""
    if get_heuristic(options.heuristic).admissible:
        return EAGER
    if options.lazy is not None:
        return DEFERRED if options.lazy else EAGER
    if task.arrays is not None:
        deterministic = bool((task.arrays.probability == 1.0).all())
    else:
        deterministic = all(a.probability == 1.0 for a in task.actions)
    if deterministic:
        return DEFERRED
    return DEFERRED_UNHELPFUL if _preferred(options) and options.heuristic == "ff" else EAGER


def _goal_count(options: SearchOptions) -> bool:
    """The goal-count lists: asked for, and optimality does not count."""
    return options.goal_count and not get_heuristic(options.heuristic).admissible


def _preferred(options: SearchOptions) -> bool:
    """LAMA's dual queue: only where optimality does not count (and h records helpful
    actions: FF; the native core checks that itself)."""
    return options.preferred and not get_heuristic(options.heuristic).admissible
