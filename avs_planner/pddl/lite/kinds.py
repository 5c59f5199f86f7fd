"""The kinds of node and effect, and the error for what the model refuses or does not mirror."""

from __future__ import annotations

import enum


class ModelError(Exception):
    """What UP's model refuses, or what this model does not mirror: read it with UP."""


class OperatorKind(enum.Enum):
    """The kinds of node this model makes, named as UP's `OperatorKind` members are."""

    AND = enum.auto()
    OR = enum.auto()
    NOT = enum.auto()
    IMPLIES = enum.auto()
    EXISTS = enum.auto()
    FORALL = enum.auto()
    FLUENT_EXP = enum.auto()
    PARAM_EXP = enum.auto()
    VARIABLE_EXP = enum.auto()
    OBJECT_EXP = enum.auto()
    BOOL_CONSTANT = enum.auto()
    INT_CONSTANT = enum.auto()
    REAL_CONSTANT = enum.auto()
    PLUS = enum.auto()
    MINUS = enum.auto()
    TIMES = enum.auto()
    DIV = enum.auto()
    LE = enum.auto()
    LT = enum.auto()
    EQUALS = enum.auto()


class EffectKind(enum.Enum):
    ASSIGN = enum.auto()
    INCREASE = enum.auto()
    DECREASE = enum.auto()


_K = OperatorKind
_BOOLEAN = frozenset((_K.AND, _K.OR, _K.NOT, _K.IMPLIES, _K.EXISTS, _K.FORALL))
_ARITHMETIC = frozenset((_K.PLUS, _K.MINUS, _K.TIMES, _K.DIV))
_CONSTANTS = frozenset((_K.BOOL_CONSTANT, _K.INT_CONSTANT, _K.REAL_CONSTANT, _K.OBJECT_EXP))
_INFIX = {_K.AND: " and ", _K.OR: " or ", _K.IMPLIES: " implies ", _K.PLUS: " + ",
          _K.MINUS: " - ", _K.TIMES: " * ", _K.DIV: " / ", _K.LE: " <= ", _K.LT: " < ",
          _K.EQUALS: " == "}
