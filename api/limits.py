"""Bounded work per request: YAML read without unbounded alias expansion, nesting limits, short
error messages, and no file names from a request.

Every message the service answers with goes through `bounded()`: a string longer than
`MAX_MESSAGE` is cut to an excerpt that says how long it was, so an error can never echo a huge
value back (an inline world whose aliases expand to gigabytes, a PDDL name of 100,000
characters). World YAML is first read as a stream of events, counting aliases, nodes (with
aliases expanded) and depth, before anything builds the document.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Any

import yaml

MAX_MESSAGE = 300  # characters of one message (or one `loc` item) in an error body
MAX_ERRORS = 50  # items of a `detail` list
MAX_YAML_ALIASES = 64  # alias uses (`*name`) in an inline world file
MAX_YAML_NODES = 50_000  # scalars and collections, aliases expanded (office.yaml: 408)
MAX_YAML_DEPTH = 20  # nested collections (office.yaml: 4)
MAX_PDDL_DEPTH = 200  # nested parentheses of a PDDL body (the avs domain: 9)
MAX_PDDL_NAME = 256  # characters of one name (the avs domain's longest: 25)
MAX_JSON_DEPTH = 12  # nesting of free-form JSON fields (`qsr`)
MAX_JSON_NODES = 20_000  # values in a free-form JSON field

# option names that name files; options naming files are refused from requests (the CLI may
# still use them). A name counts when it is one of these or ends with `_` and one of them.
FILE_WORDS = ("file", "files", "path", "paths", "dir", "dirs", "directory", "filename",
              "folder")
_PATH_LIKE = re.compile(r"[/\\]|^~|^\.{1,2}$|\.(ya?ml|json|pddl|sqlite3?|db|txt|rrd|png|py)$",
                        re.IGNORECASE)

_PARENS = re.compile(r"[()]")
_LONG_NAME = re.compile(rf"[^\s()]{{{MAX_PDDL_NAME + 1},}}")
_COMMENT = re.compile(r";[^\n]*")
_Loader: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def short(text: str, limit: int = MAX_MESSAGE) -> str:
    """`text`, or its first part and how long it was when longer than `limit`."""
    if len(text) <= limit:
        return text
    return f"{text[: max(0, limit - 40)]}... [{len(text)} characters, cut]"


def bounded(value: Any, depth: int = 0) -> Any:
    """An error body's `detail` with every string shortened and every list capped."""
    if isinstance(value, str):
        return short(value)
    if depth > 6:
        return "..."
    if isinstance(value, Mapping):
        return {short(str(k), 64): bounded(v, depth + 1) for k, v in list(value.items())[:50]}
    if isinstance(value, list | tuple):
        items = [bounded(v, depth + 1) for v in value[:MAX_ERRORS]]
        if len(value) > MAX_ERRORS:
            items.append({"type": "truncated", "loc": [], "msg": f"{len(value) - MAX_ERRORS} "
                          f"more not shown"} if depth == 0 else "...")
        return items
    return value


# -- YAML -----------------------------------------------------------------------------------

def yaml_problem(text: str, field: str) -> str | None:
    """Why `text` is too costly (or not valid) YAML to read, or None.

    Counts over the event stream, which needs no recursion and builds nothing: alias uses,
    nodes with every alias expanded (an alias counts as big as what it names, so nested
    aliases multiply), and nesting depth."""
    sizes: dict[str, int] = {}
    stack: list[list[Any]] = []  # [nodes so far, anchor] per open collection
    total = aliases = 0
    try:
        for event in yaml.parse(text, Loader=_Loader):
            if isinstance(event, yaml.CollectionStartEvent):
                stack.append([1, event.anchor])
                if len(stack) > MAX_YAML_DEPTH:
                    return f"{field} nests collections deeper than {MAX_YAML_DEPTH} levels"
                continue
            if isinstance(event, yaml.CollectionEndEvent):
                count, anchor = stack.pop()
            elif isinstance(event, yaml.ScalarEvent):
                count, anchor = 1, event.anchor
            elif isinstance(event, yaml.AliasEvent):
                aliases += 1
                if aliases > MAX_YAML_ALIASES:
                    return f"{field} uses more than {MAX_YAML_ALIASES} YAML aliases (*name)"
                count, anchor = sizes.get(event.anchor, 1), None
            else:
                continue
            if anchor is not None:
                sizes[anchor] = count
            if stack:
                stack[-1][0] += count
            else:
                total += count
            if total + sum(frame[0] for frame in stack) > MAX_YAML_NODES:
                return (f"{field} has more than {MAX_YAML_NODES} YAML nodes once its aliases "
                        f"are expanded")
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        return short(f"{field} is not valid YAML{where}: {getattr(exc, 'problem', None) or exc}")
    except RecursionError:
        return f"{field} nests too deeply"
    return None


def load_yaml(text: str) -> Any:
    """The YAML document in `text` (check it with `yaml_problem` first)."""
    return yaml.load(text, Loader=_Loader)


# -- PDDL and JSON ----------------------------------------------------------------------------

def pddl_problem(text: str, field: str) -> str | None:
    """Why a PDDL body is too costly to read (nesting deeper than `MAX_PDDL_DEPTH`, a name
    longer than `MAX_PDDL_NAME`), or None; comments are skipped."""
    code = _COMMENT.sub("", text)
    depth = deepest = 0
    for paren in _PARENS.findall(code):
        depth += 1 if paren == "(" else -1
        deepest = max(deepest, depth)
    if deepest > MAX_PDDL_DEPTH:
        return f"{field} nests parentheses deeper than {MAX_PDDL_DEPTH} levels"
    long = _LONG_NAME.search(code)
    if long:
        line = code.count("\n", 0, long.start()) + 1
        return (f"{field} has a name of more than {MAX_PDDL_NAME} characters at line {line}: "
                f"{short(long.group(), 60)!r}")
    return None


def json_problem(value: Any, field: str) -> str | None:
    """Why a free-form JSON value is too big or too deep, or None (iterative: no recursion)."""
    todo: list[tuple[Any, int]] = [(value, 1)]
    nodes = 0
    while todo:
        item, depth = todo.pop()
        nodes += 1
        if nodes > MAX_JSON_NODES:
            return f"{field} has more than {MAX_JSON_NODES} values"
        if depth > MAX_JSON_DEPTH:
            return f"{field} nests deeper than {MAX_JSON_DEPTH} levels"
        if isinstance(item, Mapping):
            todo.extend((v, depth + 1) for v in item.values())
        elif isinstance(item, list | tuple):
            todo.extend((v, depth + 1) for v in item)
    return None


# -- file names -------------------------------------------------------------------------------

def names_a_file(option: str) -> bool:
    """Whether a strategy option's name says it names a file (e.g. `learn_file`)."""
    name = option.lower()
    return any(name == word or name.endswith("_" + word) for word in FILE_WORDS)


def looks_like_path(value: Any) -> bool:
    """Whether an option's value reads like a file system path (a separator, `~`, `.`, `..`
    or a file extension); no option of any strategy takes such a value from a request."""
    return isinstance(value, str) and bool(_PATH_LIKE.search(value))


def file_option_problems(options: Mapping[str, Any]) -> list[tuple[str, str]]:
    """(field, message) for every strategy option a request may not give: one that names a
    file (whatever its value, unless empty), or any value that looks like a path."""
    problems = []
    for key, value in options.items():
        field = f"strategy_options.{short(str(key), 64)}"
        if names_a_file(str(key)) and value not in (None, ""):
            problems.append((field, f"option {short(str(key), 64)!r} names a file, which the "
                             "service does not read or write for a request; use it with the "
                             "CLI (avs simulate) instead"))
        elif looks_like_path(value):
            problems.append((field, f"option {short(str(key), 64)!r}: {short(value, 60)!r} "
                             "looks like a file path; the service takes no file paths from "
                             "a request"))
    return problems


def without_file_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """`options` less those naming files (for tasks stored before the service refused them)."""
    return {k: v for k, v in options.items() if not names_a_file(str(k))}


def flatten_strings(value: Any) -> Iterable[str]:
    """Every string in a JSON value (keys included)."""
    todo = [value]
    while todo:
        item = todo.pop()
        if isinstance(item, str):
            yield item
        elif isinstance(item, Mapping):
            todo.extend(item.keys())
            todo.extend(item.values())
        elif isinstance(item, list | tuple):
            todo.extend(item)
