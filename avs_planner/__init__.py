"""avs-planner: active visual search with a switching planner (CP + DT) over PDDL."""

__version__ = "0.1.0"
