"""Load and validate QSR knowledge (YAML) into `QsrKnowledge`; every error names its entry.

The format is documented in `conceptual_map/qsr/README.md`; the built-in file is
`conceptual_map/knowledge/qsr.yaml`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

from conceptual_map.errors import KnowledgeError
from conceptual_map.knowledge.loader import read_yaml
from conceptual_map.qsr.model import (
    DIRECTIONS,
    DISTANCES,
    RELATION_NAMES,
    QsrDescription,
    QsrKnowledge,
    QsrParameters,
    QsrStep,
    RelationModel,
)

DEFAULT_QSR_PATH = Path(__file__).parent.parent / "knowledge" / "qsr.yaml"
_TOP = {"model", "relations", "landmarks", "descriptions"}


class _Reader:
    """Checks that know their source, so each error reads `SOURCE: ENTRY: message`."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, entry: str, message: str) -> KnowledgeError:
        return KnowledgeError(f"{self.source}: {entry}: {message}")

    def mapping(
        self, value: Any, entry: str, required: set[str], optional: frozenset[str] = frozenset()
    ) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.fail(entry, f"expected a mapping, got {type(value).__name__}")
        missing = sorted(required - set(value))
        if missing:
            raise self.fail(entry, f"missing key(s) {', '.join(missing)}")
        unknown = sorted(map(str, set(value) - required - optional))
        if unknown:
            raise self.fail(entry, f"unknown key(s) {', '.join(unknown)}")
        return value

    def number(self, value: Any, entry: str, positive: bool = False) -> float:
        """A finite number (bools are not numbers here), > 0 when `positive`."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(entry, f"expected a finite number, got {value!r}")
        if not math.isfinite(value):
            raise self.fail(entry, f"expected a finite number, got {value!r}")
        if positive and value <= 0:
            raise self.fail(entry, f"must be > 0, got {value!r}")
        return float(value)

    def name(self, value: Any, entry: str) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(entry, f"expected a non-empty label, got {value!r}")
        return value


def load_qsr(path: str | Path | None = None) -> QsrKnowledge:
    """Read QSR knowledge from `path` (the built-in file when None) and validate it."""
    file = Path(path) if path is not None else DEFAULT_QSR_PATH
    return parse_qsr(read_yaml(file), str(file))


def parse_qsr(data: Any, source: str = "<qsr>") -> QsrKnowledge:
    """Validate already-parsed YAML data (`source` names it in errors)."""
    reader = _Reader(source)
    root = reader.mapping(data, "top level", _TOP, frozenset({"version"}))
    relations = _relations(reader, root["relations"])
    parameters = _parameters(reader, root["model"])
    fronts = _landmarks(reader, root["landmarks"])
    knowledge = QsrKnowledge(source, parameters, MappingProxyType(relations),
                             MappingProxyType(fronts), ())
    return parse_descriptions(root["descriptions"], knowledge, source)


def parse_descriptions(data: Any, knowledge: QsrKnowledge, source: str = "<descriptions>"
                       ) -> QsrKnowledge:  # fmt: skip
    """`knowledge` with the descriptions in `data` (a list, e.g. carried by a task) instead."""
    reader = _Reader(source)
    if not isinstance(data, list):
        raise reader.fail("descriptions", "expected a list of descriptions")
    out: list[QsrDescription] = []
    seen: set = set()
    for i, item in enumerate(data):
        entry = f"descriptions[{i}]"
        description = _description(reader, item, entry, knowledge)
        if description.key in seen:
            raise reader.fail(entry, f"duplicate description {description.text()}")
        seen.add(description.key)
        out.append(description)
    return knowledge.with_descriptions(tuple(out))


def _relations(reader: _Reader, value: Any) -> dict[str, RelationModel]:
    table = reader.mapping(value, "relations", set(RELATION_NAMES))
    out = {}
    for name in RELATION_NAMES:
        entry = f"relations.{name}"
        if name in DIRECTIONS:
            spec = reader.mapping(table[name], entry, {"mean_deg", "std_deg"})
            mean = math.radians(reader.number(spec["mean_deg"], f"{entry}.mean_deg"))
            std = math.radians(reader.number(spec["std_deg"], f"{entry}.std_deg", positive=True))
        else:
            spec = reader.mapping(table[name], entry, {"mean", "std"})
            mean = reader.number(spec["mean"], f"{entry}.mean", positive=True)
            std = reader.number(spec["std"], f"{entry}.std", positive=True)
        out[name] = RelationModel(name, mean, std)
    return out


def _parameters(reader: _Reader, value: Any) -> QsrParameters:
    lengths = ("origin_distance", "close_ratio", "learn_radius")
    keys = frozenset({*lengths, "default_distance", "samples"})
    spec = reader.mapping(value, "model", set(), keys)
    given: dict[str, Any] = {
        key: reader.number(spec[key], f"model.{key}", positive=True) for key in lengths
        if key in spec
    }  # fmt: skip
    if "samples" in spec:
        samples = spec["samples"]
        if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
            raise reader.fail("model.samples", f"expected an integer >= 2, got {samples!r}")
        given["samples"] = samples
    if "default_distance" in spec:
        distance = spec["default_distance"]
        if distance not in DISTANCES:
            raise reader.fail("model.default_distance", f"{distance!r} is not one of {DISTANCES}")
        given["default_distance"] = distance
    return QsrParameters(**given)


def _landmarks(reader: _Reader, value: Any) -> dict[str, float]:
    if not isinstance(value, Mapping) or not value:
        raise reader.fail("landmarks", "expected a non-empty mapping of label: {front_deg: ...}")
    fronts = {}
    for label, spec in value.items():
        entry = f"landmarks.{label}"
        spec = reader.mapping(spec, entry, {"front_deg"})
        fronts[reader.name(label, entry)] = math.radians(
            reader.number(spec["front_deg"], f"{entry}.front_deg")
        )
    return fronts


def _description(
    reader: _Reader, item: Any, entry: str, knowledge: QsrKnowledge
) -> QsrDescription:
    spec = reader.mapping(item, entry, {"target", "relations", "of", "count"}, frozenset({"via"}))
    target = reader.name(spec["target"], f"{entry}.target")
    count = reader.number(spec["count"], f"{entry}.count", positive=True)
    steps = [_step(reader, spec, entry)]
    via = spec.get("via", [])
    if not isinstance(via, list):
        raise reader.fail(f"{entry}.via", "expected a list of {relations, of} steps")
    for k, hop in enumerate(via):
        hop_entry = f"{entry}.via[{k}]"
        steps.append(_step(reader, reader.mapping(hop, hop_entry, {"relations", "of"}), hop_entry))
    last = steps[-1].of
    if last not in knowledge.fronts:
        where = f"{entry}.via[{len(via) - 1}].of" if via else f"{entry}.of"
        raise reader.fail(where, f"unknown landmark label {last!r} (known: "
                                 f"{', '.join(sorted(knowledge.fronts))})")
    labels = [target] + [s.of for s in steps]
    if len(set(labels)) != len(labels):
        raise reader.fail(entry, f"the chain {' -> '.join(labels)} repeats a label")
    return QsrDescription(target, tuple(steps), count)


def _step(reader: _Reader, spec: Mapping[str, Any], entry: str) -> QsrStep:
    of = reader.name(spec["of"], f"{entry}.of")
    relations = spec["relations"]
    if isinstance(relations, str):
        relations = [relations]
    if not isinstance(relations, list) or not relations:
        raise reader.fail(f"{entry}.relations", "expected a non-empty list of relations")
    for name in relations:
        if name not in RELATION_NAMES:
            known = ", ".join(RELATION_NAMES)
            raise reader.fail(f"{entry}.relations",
                              f"unknown relation {name!r} (expected one of {known})")
    for kind, what in ((DIRECTIONS, "directional"), (DISTANCES, "distance")):
        if sum(name in kind for name in relations) > 1:
            raise reader.fail(f"{entry}.relations", f"more than one {what} relation in "
                                                    f"{relations} (use separate descriptions)")
    return QsrStep(tuple(sorted(relations, key=RELATION_NAMES.index)), of)


def dump_qsr(knowledge: QsrKnowledge) -> dict[str, Any]:
    """`knowledge` as the YAML document `parse_qsr` reads (e.g. after learning)."""
    p = knowledge.parameters
    relations: dict[str, Any] = {}
    for name in RELATION_NAMES:
        model = knowledge.relations[name]
        if name in DIRECTIONS:
            relations[name] = {"mean_deg": round(math.degrees(model.mean), 6),
                               "std_deg": round(math.degrees(model.std), 6)}
        else:
            relations[name] = {"mean": model.mean, "std": model.std}
    descriptions = []
    for d in knowledge.descriptions:
        first, *via = d.chain
        entry: dict[str, Any] = {"target": d.target, "relations": list(first.relations),
                                 "of": first.of}
        if via:
            entry["via"] = [{"relations": list(s.relations), "of": s.of} for s in via]
        entry["count"] = d.count
        descriptions.append(entry)
    return {
        "version": 1,
        "model": {"origin_distance": p.origin_distance, "close_ratio": p.close_ratio,
                  "default_distance": p.default_distance, "samples": p.samples,
                  "learn_radius": p.learn_radius},
        "relations": relations,
        "landmarks": {label: {"front_deg": round(math.degrees(front), 6)}
                      for label, front in knowledge.fronts.items()},
        "descriptions": descriptions,
    }  # fmt: skip
