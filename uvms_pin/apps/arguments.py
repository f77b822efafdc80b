"""Argument types of the command line: a bad count or number is refused by the parser.

``argparse`` turns the ``ArgumentTypeError`` into ``uvms-pin CMD: error: argument
--workers: must be an integer >= 0, got -2`` and exit status 2, before any work.

Also what several commands share: the ``--set KEY=VALUE`` option (`add_set_option`) and
comma-separated name lists (`comma_names`, checked by the command: a `ParameterError`).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Callable

from uvms_pin.errors import ParameterError


def count(minimum: int, maximum: int | None = None, why: str = "") -> Callable[[str], int]:
    """An integer in ``minimum..maximum`` (process, job and start counts); ``why``: what the
    maximum is, for the message."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be an integer >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(
                f"must be an integer <= {maximum}{f' ({why})' if why else ''}, got {value}"
            )
        return value

    return parse


def process_count(minimum: int) -> Callable[[str], int]:
    """A count of worker processes on this machine: at most 4 per CPU (more only wait for
    the CPUs, each with its own copy of the model and its memory)."""
    cpus = os.cpu_count() or 1
    return count(minimum, 4 * cpus, f"4 per CPU, {cpus} CPUs here")


def finite(text: str) -> float:
    """A finite float (no nan, no inf)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def positive(text: str) -> float:
    """A finite float > 0 (durations, rates, densities, speeds)."""
    value = finite(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return value


def nonempty(what: str) -> Callable[[str], str]:
    """Text that is not empty nor blank, ``what`` naming it for the message (``--out ""`` is
    not the current directory: it is a missing value, most often an unset shell variable)."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
        return text

    return parse


#: a file or directory given on the command line
path_text = nonempty("a path")


def progress_printer(quiet: bool) -> Callable[[str], None] | None:
    """What a command reports its progress with: None when ``quiet``, else a function that
    prints each line to stderr at once (the results go to stdout)."""
    if quiet:
        return None
    return lambda line: print(line, file=sys.stderr, flush=True)


def say_user_traceback(traceback: str, what: str = "your code raised") -> None:
    """The frames of your code that failed (a controller, a metric), shown as such on
    stderr, before the command's own message; nothing for an empty ``traceback``."""
    if traceback:
        print(f"uvms-pin: {what}; its traceback:\n" + traceback.rstrip("\n"), file=sys.stderr)


def add_set_option(parser: argparse.ArgumentParser, help_text: str) -> None:
    """``--set KEY=VALUE``, repeatable: scenario entries to override (the command parses
    each with `uvms_pin.scenario.overrides.parse_assignment`); [] if not given."""
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help=help_text)


def comma_names(option: str, text: str, what: str = "names") -> list[str]:
    """The comma-separated names ``text`` of ``option`` (e.g. ``--arms``), stripped: at
    least one, none empty, none twice.

    Raises:
        ParameterError: naming the option and ``what`` it lists: an empty name, or the
            names given twice.
    """
    names = [n.strip() for n in text.split(",")]
    if "" in names:
        raise ParameterError(f"{option} {text!r}: give comma-separated {what}, none empty")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ParameterError(f"{option} {text!r}: {', '.join(twice)} given twice")
    return names


def add_comparison_command(
    subparsers,
    name: str,
    summary: str,
    description: str,
    *,
    scenario_required: bool = True,
    out_default: str | None = None,
) -> argparse.ArgumentParser:
    """A command that runs one scenario's task several ways and writes a comparison into an
    output directory: its parser with the ``scenario`` argument, ``--out`` (required unless
    ``out_default``) and ``--overwrite``."""
    from uvms_pin.results.outdir import OVERWRITE_HELP

    parser = subparsers.add_parser(name, help=summary, description=description)
    parser.add_argument(
        "scenario",
        nargs=None if scenario_required else "?",
        type=path_text,
        help="scenario TOML file",
    )
    parser.add_argument(
        "--out",
        required=out_default is None,
        default=out_default,
        type=path_text,
        help="output directory",
    )
    parser.add_argument("--overwrite", action="store_true", help=OVERWRITE_HELP)
    return parser
