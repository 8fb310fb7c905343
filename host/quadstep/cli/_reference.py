"""docs/CLI.md, written from the argument parser itself so that the reference cannot drift from the
commands: `python -m quadstep.cli._reference > docs/CLI.md` (a test checks the file is current).

Built from the parser's actions rather than argparse's help text, whose layout changes between
Python versions."""

from __future__ import annotations

import argparse

from . import build_parser

HEADER = """# Command-line reference

Generated from the argument parser (`python -m quadstep.cli._reference > docs/CLI.md`); a test
keeps it current. What each command does in depth: [JOBS.md](JOBS.md) (`check`, `run`, `plot`),
[TUI.md](TUI.md), [BACKLASH.md](BACKLASH.md), [INPUTS.md](INPUTS.md) (`home`, `probe`),
[SENDERS.md](SENDERS.md) (`grbl`), [HOST.md](HOST.md) (`info`, `send`, `ports`, `flash`).
"""


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _summaries(parser: argparse.ArgumentParser) -> dict[str, str]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return {choice.dest: choice.help or "" for choice in action._choices_actions}
    return {}


def _usage(action: argparse.Action) -> str:
    if not action.option_strings:
        if action.metavar is None and action.choices is not None:
            return "{" + ",".join(str(c) for c in action.choices) + "}"
        return str(action.metavar) if action.metavar is not None else action.dest.upper()
    names = ", ".join(action.option_strings)
    if action.nargs == 0:
        return names
    if action.metavar is not None:
        metavar = action.metavar if isinstance(action.metavar, str) else " ".join(action.metavar)
    elif action.choices is not None:
        metavar = "{" + ",".join(str(c) for c in action.choices) + "}"
    else:
        metavar = action.dest.upper()
    return f"{names} {metavar}"


def _help(action: argparse.Action) -> str:
    text = " ".join((action.help or "").split())
    if "%(default)" in text:
        text = text % {"default": action.default}
    if action.required and action.option_strings:
        text = f"(required) {text}".strip()
    return text.replace("|", "\\|")


def _options(parser: argparse.ArgumentParser) -> list[str]:
    rows = []
    for action in parser._actions:
        hidden = action.help == argparse.SUPPRESS
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction) or hidden:
            continue
        usage = _usage(action).replace("|", "\\|")  # a table cell ends at a bare |
        rows.append(f"| `{usage}` | {_help(action)} |")
    return rows


def _command(name: str, parser: argparse.ArgumentParser, summary: str, depth: int) -> list[str]:
    lines = ["", f"{'#' * depth} {name}"]
    about = " ".join((parser.description or summary).split())
    if about:
        lines += ["", about]
    options = _options(parser)
    if options:
        lines += ["", "| option | meaning |", "|---|---|", *options]
    summaries = _summaries(parser)
    for sub, subparser in _subcommands(parser).items():
        lines += _command(f"{name} {sub}", subparser, summaries.get(sub, ""), depth + 1)
    return lines


def reference() -> str:
    parser = build_parser()
    lines = [HEADER, "| command | what it does |", "|---|---|"]
    summaries = _summaries(parser)
    commands = _subcommands(parser)
    lines += [f"| [`{name}`](#quadstep-{name}) | {summaries.get(name, '')} |" for name in commands]
    for name, command in commands.items():
        lines += _command(f"quadstep {name}", command, summaries.get(name, ""), 2)
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(reference(), end="")
