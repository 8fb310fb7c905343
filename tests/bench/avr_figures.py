"""The AVR benches' measured figures, in one file that docs/BENCHMARKS.md is checked against
(tests/test_avr_figures.py): each bench replaces its own section of docs/figures/avr.json."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

FIGURES = Path(__file__).resolve().parents[2] / "docs" / "figures" / "avr.json"


def load() -> dict[str, Any]:
    return json.loads(FIGURES.read_text()) if FIGURES.exists() else {}


def record(section: str, figures: dict[str, Any]) -> None:
    """Replace `section` of the figures file with `figures` (JSON values only)."""
    data = load()
    data[section] = figures
    FIGURES.parent.mkdir(parents=True, exist_ok=True)
    FIGURES.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
