"""What the grounder refuses, named: the construct, the action, derived predicate's rule or
goal it is in, and (for a task read from PDDL) where that is written, as
`FILE:LINE:COL: message`."""

from __future__ import annotations

from avs_planner.errors import PlanningError, SourcePosition
from avs_planner.pddl.model import SourceMap


class UnsupportedError(PlanningError):
    """A construct the grounder cannot take, in `action` or in conjunct `goal_part` (index,
    count) of the goal; `located` adds the position the reader recorded for it."""

    def __init__(self, message: str, *, action: str | None = None,
                 goal_part: tuple[int, int] | None = None,
                 position: SourcePosition | None = None, rule: str | None = None):
        self.message = message
        self.action = action
        self.goal_part = goal_part
        self.position = position
        self.rule = rule  # a derived predicate whose rules it is in
        super().__init__(f"{position}: {message}" if position is not None else message)

    def located(self, sources: SourceMap) -> UnsupportedError:
        """The same error at the action's (or the goal conjunct's) position, if known."""
        if self.position is not None:
            return self
        if self.action is not None:
            position = sources.action(self.action)
        elif self.rule is not None:
            position = sources.rule(self.rule)
        elif self.goal_part is not None:
            position = sources.goal_part(*self.goal_part)
        else:
            position = None
        if position is None:
            return self
        return UnsupportedError(self.message, action=self.action, goal_part=self.goal_part,
                                position=position, rule=self.rule)


def in_action(name: str, exc: PlanningError) -> UnsupportedError:
    """`exc`, raised while compiling or grounding action `name`, as an error about it."""
    if isinstance(exc, UnsupportedError) and exc.action == name:
        return exc
    message = getattr(exc, "message", None) or str(exc)
    if not message.startswith((f"action {name}:", f"action {name},")):
        message = f"action {name}: {message}"
    return UnsupportedError(message, action=name)


def in_rule(predicate: str, exc: PlanningError) -> UnsupportedError:
    """`exc`, raised while compiling or grounding the rules of derived predicate
    `predicate`, as an error about them."""
    if isinstance(exc, UnsupportedError) and exc.rule == predicate:
        return exc
    message = getattr(exc, "message", None) or str(exc)
    prefix = f"derived predicate {predicate}: "
    return UnsupportedError(message if message.startswith(prefix) else prefix + message,
                            rule=predicate)
