"""Command-line interface: a thin layer over the public API.

Every module in this package that defines ``COMMAND`` is a subcommand; it
provides ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``. Heavy
imports happen inside ``run`` so that ``synth --help`` and ``synth check``
start fast.

Exit codes: 0 met / designed, 1 not met / infeasible / failed, 2 bad input, 3 undetermined (design, simulate).
"""

from __future__ import annotations

import argparse
import gc
import importlib
import pkgutil
import sys
import warnings
from collections.abc import Sequence

from synth.errors import SynthError
from synth.forked import allow_fork
from synth.version import __version__

__all__ = ["EXIT_BAD_INPUT", "EXIT_NOT_MET", "EXIT_OK", "GC_YOUNG_THRESHOLD", "build_parser", "joined_values", "main",
           "unrecognized_message"]

EXIT_OK, EXIT_NOT_MET, EXIT_BAD_INPUT = 0, 1, 2

GC_YOUNG_THRESHOLD = 50_000
"""Net allocations between two collections of the garbage collector's youngest generation in the ``synth``
command (:func:`entry`; a library call keeps the interpreter's setting)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line plus usage, exit 2 (argparse's own convention)
        self.print_usage(sys.stderr)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def _commands() -> list:
    mods = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(mod, "COMMAND"):
            mods.append(mod)
    return sorted(mods, key=lambda m: (getattr(m, "ORDER", 50), m.COMMAND))


def build_parser() -> argparse.ArgumentParser:
    """The ``synth`` argument parser with every subcommand."""
    parser = _Parser(
        prog="synth",
        description="Design fixed-structure compensators from measured data and written specs.",
        epilog="Exit codes: 0 met/designed, 1 not met/infeasible/failed, 2 bad input, 3 undetermined (design, "
               "simulate); each command's --help says what its own mean.",
    )
    parser.add_argument("--version", action="version", version=f"synth {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for mod in _commands():
        p = sub.add_parser(mod.COMMAND, help=mod.HELP, description=getattr(mod, "DESCRIPTION", mod.HELP),
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def entry() -> None:
    """The ``synth`` console command and ``python -m synth``: :func:`main`, then exit.

    Before exiting, every object still alive is moved out of the garbage collector's reach
    (:func:`gc.freeze`): the interpreter's last collection would otherwise walk everything the command
    loaded (0.3-0.5 s after a design with its report); files are closed and ``atexit`` handlers still run.
    While it runs, the collector's youngest generation is collected every :data:`GC_YOUNG_THRESHOLD` net
    allocations instead of Python's 700: a design allocates millions of small arrays and result objects,
    few in reference cycles, and the frequent collections walked them for 3-4 % of a design command's time.
    """
    gc.set_threshold(GC_YOUNG_THRESHOLD, *gc.get_threshold()[1:])
    code = main()
    gc.freeze()
    sys.exit(code)


def _command_parser(parser: argparse.ArgumentParser, name: str) -> argparse.ArgumentParser | None:
    """The subcommand ``name``'s own parser, None if there is no such command."""
    sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
    return sub.choices.get(name) if sub is not None else None


def joined_values(parser: argparse.ArgumentParser, argv: list[str]) -> list[str]:
    """``argv`` with an option's value that starts with "-" but is no option of the command joined to it by "=".

    argparse takes ``--tf -2/(s+1)`` for two options and refuses; ``--tf=-2/(s+1)`` is what the user meant.

    Examples
    --------
    >>> joined_values(build_parser(), ["hq", "--tf", "-2/(s+1)", "--delay", "0.01"])
    ['hq', '--tf=-2/(s+1)', '--delay', '0.01']
    >>> joined_values(build_parser(), ["check", "a.yaml", "--controller", "-q"])  # -q is an option of check
    ['check', 'a.yaml', '--controller', '-q']
    """
    command = _command_parser(parser, argv[0]) if argv else None
    if command is None:
        return argv
    taking = {o for a in command._actions if a.option_strings and a.nargs is None for o in a.option_strings}  # one value
    known = {o for a in command._actions for o in a.option_strings}
    out: list[str] = []
    i = 0
    while i < len(argv):
        if (argv[i] in taking and i + 1 < len(argv) and argv[i + 1].startswith("-") and len(argv[i + 1]) > 1
                and not argv[i + 1].startswith("--") and argv[i + 1][:2] not in known):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
            continue
        out.append(argv[i])
        i += 1
    return out


def unrecognized_message(parser: argparse.ArgumentParser, args: argparse.Namespace, extra: list[str]) -> str:
    """argparse's "unrecognized arguments" message, with a hint where a command reads its record from ``--data``
    and was given a file name on its own (``synth identify log.csv``).

    Examples
    --------
    >>> p = build_parser()
    >>> unrecognized_message(p, *p.parse_known_args(["identify", "log.csv"]))
    'unrecognized arguments: log.csv (a record is given with --data: synth identify --data log.csv)'
    >>> unrecognized_message(p, *p.parse_known_args(["check", "a.yaml", "b.yaml", "--controller", "P(1)"]))
    'unrecognized arguments: b.yaml'
    """
    message = f"unrecognized arguments: {' '.join(extra)}"
    command = _command_parser(parser, getattr(args, "command", None) or "")
    bare = [a for a in extra if not a.startswith("-")]
    if command is not None and bare and "--data" in command._option_string_actions and args.data is None:
        message += f" (a record is given with --data: synth {args.command} --data {bare[0]})"
    return message


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``synth`` command.

    Examples
    --------
    >>> main(["check", "specs/x4_rotor.yaml", "--controller", "P(3)", "--quiet"])
    0
    """
    parser = build_parser()
    args, extra = parser.parse_known_args(joined_values(parser, list(sys.argv[1:] if argv is None else argv)))
    if extra:
        parser.error(unrecognized_message(parser, args, extra))
    allow_fork()  # reports and designs may use the second core (synth.forked; SYNTH_JOBS=1 turns it off)
    if not getattr(args, "_run", None):
        parser.print_help()
        return EXIT_BAD_INPUT
    try:
        with warnings.catch_warnings():
            if not sys.warnoptions:  # the libraries' numerical warnings (cvxpy's "may be inaccurate" on one
                # convex step, numpy's overflow while a trial design is simulated) are not the user's to act on:
                # every verdict says what it rests on; -W or PYTHONWARNINGS shows them
                warnings.simplefilter("ignore")
            return int(args._run(args))
    except SynthError as exc:
        print(f"synth {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("synth: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`, which stopped reading
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # the file system refused (disk full, a folder gone meanwhile): one line, not a traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"synth {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
