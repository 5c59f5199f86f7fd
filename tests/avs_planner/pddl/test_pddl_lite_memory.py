"""Reading text after text in one process (an API worker) does not grow `lite`'s tables.

The expression and type managers are shared by every read, as UP's global environment is:
a node of some content is one object wherever it is made, so two reads of one text give
equal actions and the grounding cache finds the first read's structure for the second. The
tables hold an object only while something else does, so a dropped problem leaves nothing.
"""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

from avs_planner.cp.grounding import GroundingCache, ground
from avs_planner.pddl import lite, read_text

ROOT = Path(__file__).resolve().parents[3]
AVS = ROOT / "domains" / "avs"

# every name carries `i`: nodes of names other tests in the process also use (a `room`
# type, objects `r1`, `r2`) may be held by them, and would not be counted as this read's
DOMAIN = """(define (domain d{i})
  (:requirements :strips :typing)
  (:types box{i} - thing{i} room{i})
  (:predicates (at{i} ?b - box{i} ?r - room{i}) (moved{i}))
  (:action move{i} :parameters (?b - box{i} ?from ?to - room{i})
    :precondition (at{i} ?b ?from)
    :effect (and (not (at{i} ?b ?from)) (at{i} ?b ?to) (moved{i}))))
"""
PROBLEM = """(define (problem p{i}) (:domain d{i})
  (:objects b{i} - box{i} ra{i} rb{i} - room{i})
  (:init (at{i} b{i} ra{i}))
  (:goal (and (at{i} b{i} rb{i}) (moved{i}))))
"""


def read(i: int) -> lite.Problem:
    """A problem whose type, predicate, action and object names carry `i`."""
    model = read_text(DOMAIN.format(i=i), PROBLEM.format(i=i)).model
    assert lite.is_lite(model)
    return model  # type: ignore[return-value]


def sizes() -> tuple[int, int]:
    """(nodes, user types) the shared tables hold, once garbage is collected."""
    gc.collect()
    environment = lite.ENVIRONMENT
    return environment.expression_manager.table_size, environment.type_manager.table_size


def test_reading_200_problems_does_not_grow_the_tables() -> None:
    """Half of the reads are one text again, half a text with new names; whatever else in
    the process holds nodes, the tables end as they began."""
    before = sizes()
    one = read(0)
    nodes_one = sizes()[0] - before[0]
    assert nodes_one > 0  # a problem's nodes are in the table while it is held
    del one
    for k in range(200):
        model = read(0 if k % 2 else k + 1)
        assert model.goals  # used, then dropped by the next read
    del model
    assert sizes() == before


def test_a_problem_s_nodes_and_types_go_with_it() -> None:
    model = read(1)
    goal = weakref.ref(model.goals[0])
    box = weakref.ref(model.user_type("box1"))
    del model
    gc.collect()
    assert goal() is None and box() is None


def test_reads_of_one_text_share_nodes_and_the_grounding_cache() -> None:
    """While the first read is held, a second read of the same text makes the very same
    nodes, so its actions are equal and grounding it finds the first one's schemas and
    structure in the cache."""
    domain = (AVS / "domain.pddl").read_text()
    problem = (AVS / "problems" / "corridor.pddl").read_text()
    cache = GroundingCache()
    first, second = read_text(domain, problem), read_text(domain, problem)
    assert first.model is not second.model
    assert second.model.goals[0] is first.model.goals[0]
    assert second.model.actions == first.model.actions
    ground(first, cache=cache)
    ground(second, cache=cache)
    assert (cache.hits, cache.misses) == (2, 2)
