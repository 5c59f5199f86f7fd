"""Load and validate a commonsense-knowledge YAML file into a `Knowledge` object.

Every problem raises `KnowledgeError` naming the file and the offending entry, never a traceback.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import yaml

from conceptual_map.errors import KnowledgeError
from conceptual_map.knowledge.model import (
    RELATIONS,
    Knowledge,
    MobilityModel,
    PlaceholderModel,
    PropertyModel,
    UnknownLabelModel,
)

DEFAULT_KNOWLEDGE_PATH = Path(__file__).with_name("default.yaml")
_ROW_TOLERANCE = 1e-6


class KnowledgeYamlLoader(yaml.SafeLoader):
    """SafeLoader where only true/false are booleans: YAML 1.1 would read `on` as True."""


KnowledgeYamlLoader.yaml_implicit_resolvers = {
    first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
KnowledgeYamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool",
    re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
    list("tTfF"),
)


class _Reader:
    """Validation helpers that know which file they read, so every error names it."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, entry: str, message: str) -> KnowledgeError:
        return KnowledgeError(f"{self.source}: {entry}: {message}")

    def mapping(self, value: Any, entry: str) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.fail(entry, f"expected a mapping, got {type(value).__name__}")
        return value

    def names(self, value: Any, entry: str) -> tuple[str, ...]:
        if not isinstance(value, list) or not value:
            raise self.fail(entry, "expected a non-empty list of names")
        if not all(isinstance(v, str) and v for v in value):
            raise self.fail(entry, "every name must be a non-empty string")
        if len(set(value)) != len(value):
            raise self.fail(entry, "names must be unique")
        return tuple(value)

    def number(self, value: Any, entry: str, low: float, high: float = math.inf) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(entry, f"expected a number, got {value!r}")
        if not (math.isfinite(value) and low <= value <= high):
            raise self.fail(entry, f"{value!r} is outside [{low}, {high}]")
        return float(value)

    def positive(self, value: Any, entry: str) -> float:
        number = self.number(value, entry, 0.0)
        if number <= 0.0:
            raise self.fail(entry, f"must be > 0, got {value!r}")
        return number

    def category_vector(
        self, value: Any, entry: str, categories: tuple[str, ...], default: float
    ) -> np.ndarray:
        """Per-category non-negative numbers; unlisted categories get `default`."""
        table = self.mapping(value, entry)
        vector = np.full(len(categories), default)
        for cat, number in table.items():
            if cat not in categories:
                raise self.fail(f"{entry}.{cat}", "unknown room category")
            vector[categories.index(cat)] = self.number(number, f"{entry}.{cat}", 0.0)
        return vector


def load_knowledge(path: str | Path | None = None) -> Knowledge:
    """Read knowledge from `path` (the built-in default file when None) and validate it."""
    file = Path(path) if path is not None else DEFAULT_KNOWLEDGE_PATH
    return parse_knowledge(read_yaml(file), _Reader(str(file)).source)


def read_yaml(file: Path) -> Any:
    """A knowledge YAML file's document; KnowledgeError naming the file if it cannot be
    read or parsed (shared by the knowledge and QSR loaders)."""
    try:
        text = file.read_text(encoding="utf-8")
    except OSError as exc:
        raise KnowledgeError(f"{file}: cannot read: {exc.strerror or exc}") from None
    try:
        return yaml.load(text, Loader=KnowledgeYamlLoader)  # a SafeLoader subclass
    except yaml.YAMLError as exc:
        raise KnowledgeError(f"{file}: not valid YAML: {exc}") from None


def parse_knowledge(data: Any, source: str = "<knowledge>") -> Knowledge:
    """Validate already-parsed YAML data (`source` names it in errors)."""
    reader = _Reader(source)
    root = reader.mapping(data, "top level")
    _check_keys(reader, root, "top level", required={"categories", "properties", "connectivity",
                                                    "objects", "relations", "placeholders"},
                optional={"version", "unknown_labels", "mobility"})
    categories, prior = _categories(reader, root["categories"])
    object_lambda, default_object, rate_shape = _objects(reader, root["objects"], categories)
    relation_lambda, default_relation = _relations(
        reader, root["relations"], categories, frozenset(object_lambda)
    )
    return Knowledge(
        source=source,
        categories=categories,
        prior=prior,
        properties=MappingProxyType(_properties(reader, root["properties"], categories)),
        connectivity=_connectivity(reader, root["connectivity"], categories),
        object_lambda=MappingProxyType(object_lambda),
        default_object_lambda=default_object,
        relation_lambda=MappingProxyType(relation_lambda),
        default_relation_lambda=default_relation,
        placeholder=_placeholder(reader, root["placeholders"]),
        unknown=_unknown_labels(reader, root.get("unknown_labels"), frozenset(object_lambda)),
        mobility=_mobility(reader, root.get("mobility"), frozenset(object_lambda)),
        rate_shape=rate_shape,
    )


def _check_keys(
    reader: _Reader, table: Mapping[str, Any], entry: str, required: set[str], optional: set[str]
) -> None:
    missing = sorted(required - set(table))
    if missing:
        raise reader.fail(entry, f"missing key(s) {', '.join(missing)}")
    unknown = sorted(set(table) - required - optional)
    if unknown:
        raise reader.fail(entry, f"unknown key(s) {', '.join(map(str, unknown))}")


def _categories(reader: _Reader, value: Any) -> tuple[tuple[str, ...], np.ndarray]:
    table = reader.mapping(value, "categories")
    if not table:
        raise reader.fail("categories", "at least one room category is required")
    names = tuple(str(name) for name in table)
    prior = np.empty(len(names))
    for i, name in enumerate(names):
        entry = reader.mapping(table[name], f"categories.{name}")
        _check_keys(reader, entry, f"categories.{name}", {"prior"}, set())
        prior[i] = reader.positive(entry["prior"], f"categories.{name}.prior")
    if abs(prior.sum() - 1.0) > _ROW_TOLERANCE:
        raise reader.fail("categories", f"priors sum to {prior.sum():.6f}, expected 1")
    return names, prior


def _properties(
    reader: _Reader, value: Any, categories: tuple[str, ...]
) -> dict[str, PropertyModel]:
    kinds = reader.mapping(value, "properties")
    models = {}
    for kind, spec in kinds.items():
        entry = f"properties.{kind}"
        spec = reader.mapping(spec, entry)
        _check_keys(reader, spec, entry, {"values", "likelihood"}, set())
        values = reader.names(spec["values"], f"{entry}.values")
        rows = reader.mapping(spec["likelihood"], f"{entry}.likelihood")
        table = np.empty((len(categories), len(values)))
        for k, cat in enumerate(categories):
            if cat not in rows:
                raise reader.fail(f"{entry}.likelihood", f"no row for category {cat!r}")
            table[k] = _probability_row(reader, rows[cat], f"{entry}.likelihood.{cat}", values)
        extra = sorted(set(rows) - set(categories))
        if extra:
            raise reader.fail(f"{entry}.likelihood.{extra[0]}", "unknown room category")
        models[str(kind)] = PropertyModel(str(kind), values, table)
    return models


def _probability_row(
    reader: _Reader, value: Any, entry: str, values: tuple[str, ...]
) -> np.ndarray:
    row_map = reader.mapping(value, entry)
    unknown = sorted(set(row_map) - set(values))
    if unknown:
        raise reader.fail(f"{entry}.{unknown[0]}", "unknown property value")
    missing = [v for v in values if v not in row_map]
    if missing:
        raise reader.fail(entry, f"missing value(s) {', '.join(missing)}")
    row = np.array([reader.number(row_map[v], f"{entry}.{v}", 0.0, 1.0) for v in values])
    if abs(row.sum() - 1.0) > _ROW_TOLERANCE:
        raise reader.fail(entry, f"probabilities sum to {row.sum():.6f}, expected 1")
    return row


def _connectivity(reader: _Reader, value: Any, categories: tuple[str, ...]) -> np.ndarray:
    spec = reader.mapping(value, "connectivity")
    _check_keys(reader, spec, "connectivity", {"default"}, {"pairs"})
    default = reader.positive(spec["default"], "connectivity.default")
    phi = np.full((len(categories), len(categories)), default)
    pairs = spec.get("pairs") or []
    if not isinstance(pairs, list):
        raise reader.fail("connectivity.pairs", "expected a list of [cat, cat, value]")
    for i, pair in enumerate(pairs):
        entry = f"connectivity.pairs[{i}]"
        if not (isinstance(pair, list) and len(pair) == 3):
            raise reader.fail(entry, f"expected [category, category, value], got {pair!r}")
        a, b, number = pair
        for cat in (a, b):
            if cat not in categories:
                raise reader.fail(entry, f"unknown room category {cat!r}")
        ia, ib = categories.index(a), categories.index(b)
        phi[ia, ib] = phi[ib, ia] = reader.positive(number, entry)
    return phi


def _objects(
    reader: _Reader, value: Any, categories: tuple[str, ...]
) -> tuple[dict[str, np.ndarray], float, float | None]:
    spec = reader.mapping(value, "objects")
    _check_keys(reader, spec, "objects", {"default_lambda", "lambda"}, {"rate_shape"})
    default = reader.number(spec["default_lambda"], "objects.default_lambda", 0.0)
    shape = spec.get("rate_shape")
    if shape is not None:
        shape = reader.positive(shape, "objects.rate_shape")
    table = reader.mapping(spec["lambda"], "objects.lambda")
    lambdas = {
        str(label): reader.category_vector(row, f"objects.lambda.{label}", categories, default)
        for label, row in table.items()
    }
    return lambdas, default, shape


def _relations(
    reader: _Reader, value: Any, categories: tuple[str, ...], labels: frozenset[str]
) -> tuple[dict[tuple[str, str, str], np.ndarray], float]:
    spec = reader.mapping(value, "relations")
    _check_keys(reader, spec, "relations", {"default_lambda", "entries"}, set())
    default = reader.number(spec["default_lambda"], "relations.default_lambda", 0.0)
    entries = spec["entries"] or []
    if not isinstance(entries, list):
        raise reader.fail("relations.entries", "expected a list")
    lambdas: dict[tuple[str, str, str], np.ndarray] = {}
    for i, item in enumerate(entries):
        entry = f"relations.entries[{i}]"
        item = reader.mapping(item, entry)
        _check_keys(reader, item, entry, {"label", "relation", "support", "lambda"}, set())
        key = (item["label"], item["relation"], item["support"])
        for part, name in zip(("label", "support"), (key[0], key[2]), strict=True):
            if name not in labels:
                raise reader.fail(f"{entry}.{part}", f"{name!r} has no entry under objects.lambda")
        if key[1] not in RELATIONS:
            raise reader.fail(f"{entry}.relation", f"{key[1]!r} is not one of {RELATIONS}")
        if key in lambdas:
            raise reader.fail(entry, f"duplicate entry for {key}")
        lambdas[key] = reader.category_vector(item["lambda"], f"{entry}.lambda", categories,
                                              default)
    return lambdas, default


def _placeholder(reader: _Reader, value: Any) -> PlaceholderModel:
    spec = reader.mapping(value, "placeholders")
    keys = {"space_scale_m2", "room_area_m2", "p_room_leads_on"}
    _check_keys(reader, spec, "placeholders", keys, set())
    return PlaceholderModel(
        space_scale_m2=reader.positive(spec["space_scale_m2"], "placeholders.space_scale_m2"),
        room_area_m2=reader.positive(spec["room_area_m2"], "placeholders.room_area_m2"),
        p_room_leads_on=reader.number(
            spec["p_room_leads_on"], "placeholders.p_room_leads_on", 0.0, 1.0
        ),
    )


def _mobility(reader: _Reader, value: Any, labels: frozenset[str]) -> MobilityModel:
    """How often each label is moved (per day); `MobilityModel`'s defaults where the section
    (or a key of it) is left out."""
    if value is None:
        return MobilityModel()
    spec = reader.mapping(value, "mobility")
    _check_keys(reader, spec, "mobility", set(), {"default", "fixed_below", "rate"})
    default = MobilityModel()
    rates: dict[str, float] = {}
    if "rate" in spec:
        table = reader.mapping(spec["rate"], "mobility.rate")
        for name, rate in table.items():
            where = f"mobility.rate.{name}"
            if name not in labels:
                raise reader.fail(where, f"{name!r} has no entry under objects.lambda")
            rates[str(name)] = reader.number(rate, where, 0.0, 1e6)
    return MobilityModel(
        default=reader.number(spec.get("default", default.default), "mobility.default",
                              0.0, 1e6),
        fixed_below=reader.number(spec.get("fixed_below", default.fixed_below),
                                  "mobility.fixed_below", 0.0, 1e6),
        rates=MappingProxyType(rates))


def _unknown_labels(reader: _Reader, value: Any, labels: frozenset[str]) -> UnknownLabelModel:
    """The uninformed prior of labels the file does not list; `UnknownLabelModel`'s defaults
    where the section (or a key of it) is left out."""
    if value is None:
        return UnknownLabelModel()
    spec = reader.mapping(value, "unknown_labels")
    _check_keys(reader, spec, "unknown_labels", set(), {"rate", "room_share", "supports"})
    default = UnknownLabelModel()
    supports = default.supports
    if "supports" in spec:
        supports = reader.names(spec["supports"], "unknown_labels.supports")
        for name in supports:
            if name not in labels:
                raise reader.fail("unknown_labels.supports",
                                  f"{name!r} has no entry under objects.lambda")
    return UnknownLabelModel(
        rate=reader.positive(spec.get("rate", default.rate), "unknown_labels.rate"),
        room_share=reader.number(spec.get("room_share", default.room_share),
                                 "unknown_labels.room_share", 0.0, 1.0),
        supports=supports,
    )
