"""Reading the user's text files (configurations, jobs): failures become one clear line naming the file; and
replacing a file whole, so that a crash leaves the old one or the new one, never half of either."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

MAX_BYTES = 256 * 1024 * 1024  # a job or configuration larger than this is refused before it is read


def read_text(path: Path, error: type[Exception]) -> str:
    """The file's UTF-8 text; raises `error` saying why when it cannot be read, is too large or is not text."""
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise error(f"{path}: {size / 1e6:.0f} MB, larger than the {MAX_BYTES // 2**20} MB a file may be")
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a text file ({exc.reason} at byte {exc.start})") from None


def parse_nested(parse: Callable[[str], Any], text: str, path: Path, error: type[Exception]) -> Any:
    """`parse(text)` (JSON, YAML, TOML), with input nested too deep for the parser, or expanding to more values
    than the file has characters (YAML aliases of aliases), as one clear error."""
    try:
        data = parse(text)
        if _values(data, {}) > len(text) + 1:
            raise error(f"{path}: its aliases expand to more values than the file has characters")
        return data
    except RecursionError:
        raise error(f"{path}: nested too deep (lists or tables inside one another hundreds of levels down)") from None


def _values(data: Any, counted: dict[int, int]) -> int:
    """How many values `data` holds once every shared list or table is written out; each counted once."""
    if not isinstance(data, (list, dict)):
        return 1
    if id(data) not in counted:
        items = data.values() if isinstance(data, dict) else data
        counted[id(data)] = 1 + sum(_values(item, counted) for item in items)
    return counted[id(data)]


def replace_text(path: Path, text: str) -> None:
    """Replace `path` with `text` atomically: written beside it, flushed to disk, renamed over it (its mode kept)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        if path.exists():
            shutil.copymode(path, temporary)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)  # the rename itself reaches the disk
    finally:
        os.close(directory)
