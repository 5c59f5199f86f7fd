"""The project's own small task model: what `avs plan` grounds without unified-planning.

Importing unified-planning (UP) costs most of a short `avs plan` (its `Environment` imports
`unified_planning.engines`, which imports ConfigSpace and scipy.stats: ~0.8 s). The fast
reader (`up_builder`) builds a UP `Problem` through a few of UP's model calls; this package
offers those very calls (same names and arguments) on classes of its own, so the same builder
code fills either model, and the planner (`avs_planner.cp`) grounds either through the methods
they share (`FNode.is_and()`, `Effect.fluent`, `Problem.explicit_initial_values`, ...).

What is mirrored is what a PDDL read makes, as UP 1.3 does it: expressions shared per
content (so `is` compares them, as the builder relies on), `>`/`>=` as `<`/`<=` swapped, a
double `not` dropped, `and`/`or` of one argument being it; the type of every expression,
checked on creation as UP's type checker does; preconditions without duplicates, a `true` one
dropped; effects with only the `forall` variables they use, conflicting numeric effects
refused; names used twice refused (or allowed across kinds when the reader shares them); the
simplification of `when` conditions and of probability products; and how UP prints all of
it (error messages and cache keys print nodes, effects and metrics).

What it would have to mirror further (a simplification of quantifiers or numeric comparisons,
a division UP's type checker evaluates, a name clash UP would only warn about) raises
`ModelError` instead: the reader then reads the text with UP, as before, so a text this
model does not take reads exactly as it did. `tests/avs_planner/pddl/test_pddl_lite.py`
compares both models, printed and ground, on every file the project reads.

The modules, each one concept: `kinds` (node and effect kinds, `ModelError`), `declarations`
(types and their manager, parameters, variables, objects, fluents), `nodes` (the expression
node and the walks finding its fluents and free variables), `expression_manager` (one node per
content, typed and checked, with UP's shortcuts), `axioms` (derived predicates' rules,
which UP's model lacks), `interning` (the weak-valued tables behind
the managers: a node or type is kept while something holds it, so a process reading many
texts does not accumulate them), `simplifier`, `shared_environment` (the managers reads
share), `actions` (actions and effects), `metrics` and `problem` (with its UP
counterpart, `to_up`). The builder takes this package as its kit of model classes, so what it
names is imported here.
"""

from avs_planner.pddl.lite.actions import Effect, InstantaneousAction
from avs_planner.pddl.lite.axioms import Axiom
from avs_planner.pddl.lite.declarations import (
    BOOL,
    INT,
    REAL,
    Fluent,
    Object,
    Parameter,
    Type,
    TypeManager,
    UserType,
    Variable,
)
from avs_planner.pddl.lite.expression_manager import ExpressionManager
from avs_planner.pddl.lite.kinds import EffectKind, ModelError, OperatorKind
from avs_planner.pddl.lite.metrics import (
    MaximizeExpressionOnFinalState,
    MinimizeActionCosts,
    MinimizeExpressionOnFinalState,
    MinimizeMakespan,
)
from avs_planner.pddl.lite.nodes import FNode, FreeVarsExtractor, free_fluents, free_variables
from avs_planner.pddl.lite.problem import Problem, is_lite
from avs_planner.pddl.lite.shared_environment import (
    ENVIRONMENT,
    SIMPLIFIER,
    Environment,
    environment,
)
from avs_planner.pddl.lite.simplifier import Simplifier

__all__ = [
    "BOOL", "ENVIRONMENT", "INT", "REAL", "SIMPLIFIER", "Axiom", "Effect", "EffectKind",
    "Environment", "ExpressionManager", "FNode", "Fluent", "FreeVarsExtractor",
    "InstantaneousAction", "MaximizeExpressionOnFinalState", "MinimizeActionCosts",
    "MinimizeExpressionOnFinalState", "MinimizeMakespan", "ModelError", "Object",
    "OperatorKind", "Parameter", "Problem", "Simplifier", "Type", "TypeManager", "UserType",
    "Variable", "environment", "free_fluents", "free_variables", "is_lite",
]
