"""The environment reads share (as UP's global environment is shared): its managers."""

from __future__ import annotations

from avs_planner.pddl.lite.declarations import TypeManager
from avs_planner.pddl.lite.expression_manager import ExpressionManager
from avs_planner.pddl.lite.nodes import FreeVarsExtractor
from avs_planner.pddl.lite.simplifier import Simplifier


class Environment:
    """The managers a read uses (shared by all reads, as UP's global environment is) and
    whether kinds may share names (UP's `error_used_name`, per read here)."""

    def __init__(self, error_used_name: bool = True,
                 shared_from: Environment | None = None):
        self.error_used_name = error_used_name
        if shared_from is None:
            self.expression_manager = ExpressionManager()
            self.type_manager = TypeManager()
            self.simplifier = Simplifier(self.expression_manager)
            self.free_vars_extractor = FreeVarsExtractor()
        else:
            self.expression_manager = shared_from.expression_manager
            self.type_manager = shared_from.type_manager
            self.simplifier = shared_from.simplifier
            self.free_vars_extractor = shared_from.free_vars_extractor


ENVIRONMENT = Environment()
SIMPLIFIER = ENVIRONMENT.simplifier


def environment(names_shared: bool) -> Environment:
    """The shared environment, with names shared across kinds or not."""
    if not names_shared:
        return ENVIRONMENT
    return Environment(error_used_name=False, shared_from=ENVIRONMENT)
