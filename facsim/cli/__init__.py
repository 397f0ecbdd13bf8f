"""``facsim`` command line: FACS strings to pictures and videos.

One module per command group; each has ``add_commands(sub)`` and sets a
``handler`` on its subparsers. Adding a group is one module and one name in
:data:`COMMAND_GROUPS`. Every user error ends in one line on stderr and exit
status 2; an unexpected internal error ends in one "please report" line and
exit status 1; nothing is written unless the whole output could be made (files
are written atomically). ``--debug`` (or ``FACSIM_DEBUG=1``) shows tracebacks.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
from importlib import import_module

EXIT_USAGE = 2
EXIT_INTERNAL = 1

#: Command groups, in the order ``facsim --help`` lists them (modules in facsim/cli/).
COMMAND_GROUPS = ("render", "dynamics", "exchange", "info", "speech", "batch", "studio", "analysis")


class CliError(Exception):
    """A user error the CLI reports in one line."""


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line (the usage is in --help)."""

    def error(self, message):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    from facsim import __version__

    parser = _Parser(prog="facsim", description="FACS notation to faces: stills, videos and exports.")
    parser.add_argument("--version", action="version", version=f"facsim {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error (or set FACSIM_DEBUG=1)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)
    for group in COMMAND_GROUPS:
        import_module(f"facsim.cli.{group}").add_commands(sub)
    from facsim.cli.options import add_overwrite_option

    add_overwrite_option(parser)
    return parser


def main(argv=None) -> int:
    from facsim.atomic import overwriting

    parser = build_parser()
    args = parser.parse_args(argv)
    stopped = _stop_on_signals()
    try:
        with overwriting(getattr(args, "overwrite", False)):
            args.handler(args)
    except KeyboardInterrupt:  # Ctrl-C, SIGTERM or SIGHUP: temporaries were removed on the way out
        return _interrupted(stopped)
    except Exception as exc:  # one clear line, never a traceback (unless asked for)
        if stopped:
            # The signal's KeyboardInterrupt was raised inside C code that swallowed it and raised
            # its own error instead (numpy's structured-array comparison turns it into a TypeError).
            return _interrupted(stopped)
        if getattr(args, "debug", False) or os.environ.get("FACSIM_DEBUG"):
            raise
        if _is_user_error(exc):
            print(f"facsim: error: {_message(exc)}", file=sys.stderr)
            return EXIT_USAGE
        print(f"facsim: internal error ({type(exc).__name__}: {_message(exc, 160)}); please report "
              "this bug with the output of the same command run as `facsim --debug ...`", file=sys.stderr)
        return EXIT_INTERNAL
    return 0


def _interrupted(stopped: list) -> int:
    """Say which signal stopped the command; the exit status is 128 + its number, as a shell's."""
    # CPython remembers a KeyboardInterrupt raised inside exec() of a string (dataclasses and
    # namedtuple build their methods so, on a lazy import) even once it is caught, and at exit
    # kills the process by SIGINT instead of returning this status; a string exec clears it.
    exec("None")
    signum = stopped[-1] if stopped else signal.SIGINT
    print(f"facsim: interrupted ({signal.Signals(signum).name}); nothing was left half-written", file=sys.stderr)
    return 128 + signum


def _stop_on_signals() -> list:
    """SIGTERM and SIGHUP stop a command like Ctrl-C (KeyboardInterrupt), so every ``with``
    block and ``finally`` runs and no temporary file or folder stays behind. Returns the
    list the signals received are appended to."""
    received = []

    def stop(signum, frame):
        received.append(signum)
        raise KeyboardInterrupt

    for signum in (signal.SIGTERM, signal.SIGHUP):
        try:
            signal.signal(signum, stop)
        except ValueError:  # not the main thread (main() called from a worker thread)
            break
    return received


def _message(exc: BaseException, width: int = 400) -> str:
    from facsim.limits import clip

    text = str(exc).strip() or type(exc).__name__
    if isinstance(exc, KeyError) and text.startswith(("'", '"')):
        text = text[1:-1]
    return clip(text, width)


def _is_user_error(exc: BaseException) -> bool:
    """Errors in what the user gave (values, files, permissions), as opposed to bugs in facsim.

    ``MemoryError`` and ``RecursionError`` are facsim's fault: the input limits
    (:mod:`facsim.limits`) should have refused the input first.
    """
    return isinstance(exc, (CliError, ValueError, KeyError, OSError))
