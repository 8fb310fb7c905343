"""docs/CLI.md is the argument parser's own reference: regenerated, it is the same file."""

from __future__ import annotations

from pathlib import Path

from quadstep.cli import build_parser
from quadstep.cli._reference import reference

REPO = Path(__file__).resolve().parents[1]


def test_the_cli_reference_is_current() -> None:
    written = (REPO / "docs" / "CLI.md").read_text()
    assert written == reference(), "regenerate: python -m quadstep.cli._reference > docs/CLI.md"


def test_every_command_and_option_is_in_it_with_its_help() -> None:
    text = reference()
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    assert commands is not None
    for name in commands:
        assert f"## quadstep {name}\n" in text
    assert "| `--from-line N` | start the job at line N" in text
    assert "| `--method {probe,switch}` | probe: touch a face" in text
    assert "|  |" not in text  # every option says what it is for
