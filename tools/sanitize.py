"""`make sanitize`: the three C extensions built with AddressSanitizer and UndefinedBehavior-
Sanitizer, out of tree, and the differential tests (C against Python, float for float) run
against them.

The in-place extensions in avs_planner/cp/ are never touched: the sanitized .so files are built
into build/sanitize/ext/, beside a copy of the avs_planner package (Python and data files, no
.so) in build/sanitize/tree/, and pytest runs from the checkout with that copy first on sys.path.
A check at the start of the run (this module is also the pytest plugin doing it) fails loudly
unless every extension the tests use is the sanitized build. CPython itself is not built with
ASan, so gcc's libasan is preloaded; leak detection is off (CPython keeps memory on purpose) and
PYTHONMALLOC=malloc puts Python's own buffers under ASan too. A sanitizer report stops the run;
it is kept in build/sanitize/stderr.log and printed with the test that was running.

    python tools/sanitize.py                       # build, then run the differential tests
    python tools/sanitize.py -- -k native          # extra pytest arguments after --
    python tools/sanitize.py --source _fixpoint=/tmp/x.c --build-dir /tmp/b   # a modified copy
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import runpy
import shutil
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "avs_planner"
SANITIZE_FLAGS = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer",
                  "-fno-sanitize-recover=undefined", "-g", "-O1"]
# The differential tests: each compares a compiled extension with the Python/numpy code.
TEST_FILES = [
    f"tests/avs_planner/cp/test_cp_{name}.py"
    for name in ("native", "structure_compiled", "cold_path", "grounding", "relaxed_merge",
                 "settled", "derived", "search", "preferred", "goals", "axioms")
]
# The extension modules and the module attributes through which the planner uses them: each
# must be the sanitized build, not None (the silent fallback to Python/numpy).
USES = {
    "_native": ["avs_planner.cp.native:_native"],
    "_ground": ["avs_planner.cp.structure:_ground", "avs_planner.cp.bindings:_ground"],
    "_fixpoint": ["avs_planner.cp.derived:_fixpoint", "avs_planner.cp.relaxed_merge:_fixpoint"],
}
# a stack frame in CPython's own sources (Objects/call.c:214, Python/ceval.c:4769, ...)
INTERPRETER_FRAME = re.compile(r"\s+#\d+ 0x[0-9a-f]+ in \S+ (Objects|Python|Include|Modules|"
                               r"Parser|Programs)/\S+:\d+")
REPORT = re.compile(r"ERROR: AddressSanitizer: \S+|runtime error: [^\n]*")
ENV_TREE = "AVS_SANITIZE_TREE"  # set for the pytest run: the copy whose modules must be used
ENV_CURRENT = "AVS_SANITIZE_CURRENT"  # file naming the test that is running


def say(message: str, stream=None) -> None:
    """One line (or block) to stdout, or to `stream`, flushed before any child writes."""
    stream = stream or sys.stdout
    stream.write(message + "\n")
    stream.flush()


def fail(message: str) -> int:
    say(f"sanitize: {message}", sys.stderr)
    return 2


def extensions() -> list[tuple[str, list[str], list[str], list[str]]]:
    """(module name, sources, compile args, link args) of each extension in setup.py, read by
    running setup.py with setuptools.setup replaced, so the flags cannot drift from the build."""
    import setuptools

    captured: dict = {}
    real_setup = setuptools.setup
    setuptools.setup = lambda **kwargs: captured.update(kwargs)
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)
        runpy.run_path(str(ROOT / "setup.py"), run_name="__main__")
    finally:
        os.chdir(cwd)
        setuptools.setup = real_setup
    return [(ext.name, list(ext.sources), list(ext.extra_compile_args or []),
             list(ext.extra_link_args or [])) for ext in captured.get("ext_modules", [])]


def toolchain(cc: str) -> tuple[str, str] | str:
    """(path of cc, path of its libasan) or the reason they cannot be used."""
    compiler = shutil.which(cc)
    if compiler is None:
        return (f"no C compiler '{cc}' on PATH: the sanitized build needs gcc "
                "(Debian: apt-get install gcc)")
    found = subprocess.run([compiler, "-print-file-name=libasan.so"], capture_output=True,
                           text=True).stdout.strip()
    if not os.path.isabs(found) or not os.path.exists(found):
        return (f"{cc} has no AddressSanitizer runtime (`{cc} -print-file-name=libasan.so` "
                f"gives {found!r}); Debian's gcc package brings it (libasan via libgcc-*-dev)")
    return compiler, os.path.realpath(found)


def build(compiler: str, out: Path, sources: dict[str, Path]) -> dict[str, Path] | str:
    """Compile each extension with the sanitizers into `out`; {module name: .so} or the error."""
    include = sysconfig.get_paths()["include"]
    if not (Path(include) / "Python.h").exists():
        return f"Python.h not found in {include} (install the Python development headers)"
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    out.mkdir(parents=True, exist_ok=True)
    built = {}
    for name, srcs, compile_args, link_args in extensions():
        short = name.rsplit(".", 1)[1]
        files = [sources[short]] if short in sources else [ROOT / src for src in srcs]
        flags = [a for a in compile_args if not a.startswith("-O")]  # -std, -ffp-contract, ...
        target = out / f"{short}{suffix}"
        command = [compiler, "-shared", "-fPIC", *SANITIZE_FLAGS, *flags, f"-I{include}",
                   *map(str, files), "-o", str(target), *link_args]
        say("sanitize: " + " ".join(command))
        done = subprocess.run(command)
        if done.returncode != 0:
            return f"compiling {name} failed (exit {done.returncode})"
        built[short] = target
    missing = set(USES) - set(built)
    if missing:
        return f"setup.py no longer builds {sorted(missing)}: update tools/sanitize.py"
    return built


def make_tree(tree: Path, built: dict[str, Path]) -> None:
    """A copy of the package without compiled files, with the sanitized .so in its cp/."""
    if tree.exists():
        shutil.rmtree(tree)
    shutil.copytree(ROOT / PACKAGE, tree / PACKAGE,
                    ignore=shutil.ignore_patterns("*.so", "*.c", "__pycache__", "*.pyc"))
    for so in built.values():
        shutil.copy2(so, tree / PACKAGE / "cp" / so.name)
    # data found relative to the package (avs_planner/episode/domain.py: <root>/domains)
    (tree / "domains").symlink_to(ROOT / "domains", target_is_directory=True)


def fold_interpreter_frames(report: str) -> str:
    """The report with each run of CPython's own stack frames (ceval, call, ...) as one line."""
    lines: list[str] = []
    folded = 0
    for line in report.splitlines():
        if INTERPRETER_FRAME.match(line):
            folded += 1
            continue
        if folded:
            lines.append(f"    ... {folded} CPython frames")
            folded = 0
        lines.append(line)
    if folded:
        lines.append(f"    ... {folded} CPython frames")
    return "\n".join(lines)


def run(args: argparse.Namespace, pytest_args: list[str]) -> int:
    tools = toolchain(args.cc)
    if isinstance(tools, str):
        return fail(tools)
    compiler, libasan = tools
    out = Path(args.build_dir).resolve()
    sources = {}
    for item in args.source:
        name, _, path = item.partition("=")
        if name not in USES or not path:
            return fail(f"--source takes NAME=PATH with NAME one of {sorted(USES)}: {item!r}")
        sources[name] = Path(path).resolve()
    started = time.monotonic()
    built = build(compiler, out / "ext", sources)
    if isinstance(built, str):
        return fail(built)
    tree = out / "tree"
    make_tree(tree, built)
    stderr = out / "stderr.log"
    current = out / "current-test"
    current.unlink(missing_ok=True)

    env = dict(os.environ)
    env.pop("AVS_ALLOW_NO_NATIVE", None)  # the "is built" tests must not skip
    env.update({
        "LD_PRELOAD": " ".join(filter(None, [libasan, env.get("LD_PRELOAD", "")])),
        "ASAN_OPTIONS": "detect_leaks=0",
        "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1",
        "PYTHONMALLOC": "malloc",
        # the plugin (this file) must import before pytest reads its pythonpath setting
        "PYTHONPATH": os.pathsep.join(filter(None, [str(tree), str(ROOT / "tools"),
                                                    env.get("PYTHONPATH", "")])),
        ENV_TREE: str(tree),
        ENV_CURRENT: str(current),
    })
    command = [sys.executable, "-m", "pytest", "-p", "sanitize", "-p", "no:cacheprovider",
               # the copy before the checkout (pyproject.toml's pythonpath = ["."])
               "-o", f"pythonpath={tree} .", "-q", "-m", "not slow",
               # capture at the Python level only: what the sanitizers write to file
               # descriptor 2 (then the process ends) goes to stderr.log, not into a capture
               "--capture=sys", *(pytest_args or TEST_FILES)]
    say("sanitize: " + " ".join(command))
    with open(stderr, "w") as err:
        rc = subprocess.run(command, cwd=ROOT, env=env, stderr=err).returncode
    text = stderr.read_text(errors="replace")
    if text.strip():
        say(f"\n===== stderr of the test process ({stderr}; CPython frames folded) =====",
            sys.stderr)
        say(fold_interpreter_frames(text), sys.stderr)
    reports = REPORT.findall(text)
    if reports:
        where = current.read_text().strip() if current.exists() else "(unknown)"
        say(f"sanitize: FAILED: sanitizer report ({reports[0].strip()}) while running {where}",
            sys.stderr)
        rc = rc or 1
    elif rc != 0:
        say(f"sanitize: FAILED: pytest exit {rc}", sys.stderr)
    else:
        say(f"sanitize: OK, no sanitizer reports ({time.monotonic() - started:.0f} s)")
    return rc


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    pytest_args: list[str] = []
    if "--" in argv:
        at = argv.index("--")
        argv, pytest_args = argv[:at], argv[at + 1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cc", default="gcc", help="the compiler (gcc; default %(default)s)")
    parser.add_argument("--build-dir", default=str(ROOT / "build" / "sanitize"),
                        help="where the .so files, the package copy and stderr.log go")
    parser.add_argument("--source", action="append", default=[], metavar="NAME=PATH",
                        help="compile extension NAME (_native, _ground, _fixpoint) from PATH "
                             "instead of avs_planner/cp/NAME.c (e.g. a copy with a planted bug)")
    return run(parser.parse_args(argv), pytest_args)


# --- the pytest plugin (`-p sanitize`): fail the run unless the sanitized build is in use ---

def _problems(tree: Path) -> list[str]:
    import importlib

    problems = []
    with open("/proc/self/maps") as maps:
        if "libasan" not in maps.read():
            problems.append("libasan is not loaded in this process (LD_PRELOAD)")
    package = importlib.import_module(PACKAGE)
    if not Path(package.__file__).resolve().is_relative_to(tree.resolve()):
        problems.append(f"{PACKAGE} imported from {package.__file__}, not from {tree}")
    for name, uses in USES.items():
        full = f"{PACKAGE}.cp.{name}"
        try:
            module = importlib.import_module(full)
        except ImportError as error:
            problems.append(f"{full} does not import: {error}")
            continue
        path = Path(module.__file__).resolve()
        if path.parent != (tree / PACKAGE / "cp").resolve():
            problems.append(f"{full} imported from {path}, not from the sanitized copy")
        elif b"__asan_init" not in path.read_bytes() or b"__ubsan_handle" not in \
                path.read_bytes():
            problems.append(f"{path} is not built with -fsanitize=address,undefined")
        for use in uses:
            owner, attribute = use.split(":")
            if getattr(importlib.import_module(owner), attribute, None) is not module:
                problems.append(f"{owner}.{attribute} is not the sanitized {full}")
    return problems


def pytest_sessionstart(session) -> None:
    tree = os.environ.get(ENV_TREE)
    if not tree:
        return
    import pytest

    problems = _problems(Path(tree))
    if problems:
        pytest.exit("sanitize: NOT running against the sanitized extensions:\n  "
                    + "\n  ".join(problems), returncode=3)
    cp = Path(tree) / PACKAGE / "cp"
    digests = [f"{so.name.split('.')[0]} {hashlib.sha256(so.read_bytes()).hexdigest()[:12]}"
               for so in sorted(cp.glob("*.so"))]
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line(f"sanitize: checked: the planner uses the ASan+UBSan builds in {cp} "
                            f"({', '.join(digests)}); libasan is loaded")


def pytest_runtest_logstart(nodeid, location) -> None:
    current = os.environ.get(ENV_CURRENT)
    if current:
        with open(current, "w") as handle:
            handle.write(nodeid + "\n")


if __name__ == "__main__":
    sys.exit(main())
