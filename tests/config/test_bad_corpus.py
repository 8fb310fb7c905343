"""A corpus of bad configurations and job files (tests/helpers/bad_files.py: every value of the example
configuration, of a move file and of a raw-segment file made the wrong kind or out of range, keys missing, unknown
or twice, files cut short, nested too deep, aliases that expand without end, not text, G-code no controller runs):
every one refused with one error line naming the file, before any port is opened; none accepted, no traceback."""

from __future__ import annotations

from pathlib import Path

import pytest
from bad_files import corpus, judge


@pytest.mark.slow
def test_every_bad_file_is_refused_with_one_clear_error(tmp_path: Path) -> None:
    files = corpus()
    assert len(files) > 500
    wrong = []
    for bad in files:
        verdict, text = judge(bad, tmp_path)
        command = bad.command(tmp_path / bad.name)[0]
        if verdict != "refused" or not text.startswith(f"quadstep {command}: error: {tmp_path / bad.name}"):
            wrong.append(f"{bad.name}: {verdict}: {text[:300]}")
    assert not wrong, "\n".join(wrong)
