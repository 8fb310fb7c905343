"""A command run, the interpreter set for the link's threads first; its expected failures each
turned into one line on stderr and exit code 1."""

from __future__ import annotations

import argparse
import sys

from pydantic import ValidationError

from ..emulator import EmulatorError
from ..link import LinkError
from ..link.transport import favour_the_link
from ..machine import MachineError, StateError
from ..validation import describe_validation_error
from .options import CliError


def run_command(args: argparse.Namespace) -> int:
    favour_the_link()
    try:
        return int(args.handler(args))
    except CliError as exc:
        print(f"quadstep {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except ValidationError as exc:
        print(
            f"quadstep {args.command}: error: {'; '.join(describe_validation_error(exc))}",
            file=sys.stderr,
        )
        return 1
    except (LinkError, MachineError, StateError, EmulatorError) as exc:
        print(f"quadstep {args.command}: error: {exc}", file=sys.stderr)
        return 1
