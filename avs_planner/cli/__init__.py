"""The `avs` command line.

Subcommands live in sibling modules of this package; each module defines
`register(subparsers) -> None`, which adds its parser(s) and sets `func=run` (a callable
taking the parsed args and returning an exit code). Modules are discovered, so adding a
subcommand never edits this file.

Exit codes: 0 ok, 1 bad input, 2 no plan / unsolvable, 3 timeout, 4 internal error,
5 `avs serve`: the data dir is in use by another live instance, 141 the reader of the output
went away (e.g. `avs plan --json | head`), silently, as a SIGPIPE'd Unix tool does.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
from collections.abc import Sequence

from avs_planner import __version__
from avs_planner.errors import AvsError

EXIT_OK = 0
EXIT_BAD_INPUT = 1
EXIT_NO_PLAN = 2
EXIT_TIMEOUT = 3
EXIT_INTERNAL = 4
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error exits with 1 (bad input), as every other input error does."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="avs",
        description="Active visual search: plan, check domains, simulate, serve.",
    )
    parser.add_argument("--version", action="version", version=f"avs {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    _single_threaded_blas()
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help()
        return EXIT_BAD_INPUT
    try:
        return int(func(args))
    except AvsError as exc:
        print(f"avs: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        print("avs: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - last line of defence: never a traceback
        print(f"avs: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
        print("avs: this is a bug; please report it with the command you ran.", file=sys.stderr)
        return EXIT_INTERNAL


def _single_threaded_blas() -> None:
    """One BLAS thread for this process and its children, unless the user chose otherwise.
    The planner's, the maps' and the simulator's numpy work is elementwise or on small
    matrices, where BLAS threads never help; but OpenBLAS starts one per core when numpy is
    imported, which took 0.11 s of every `avs plan` against 0.05 s with one (2 cores), and a
    campaign's worker processes would each start a pool competing for the same cores."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush does not fail again."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    finally:
        os.close(devnull)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
