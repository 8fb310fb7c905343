"""Reading the user's text files (configurations, jobs, the state file): failures become one
clear line naming the file; and replacing a file whole, so that a crash leaves the old one or the
new one, never half of either."""

from __future__ import annotations

import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

# What a file may hold, checked before it is read and while it is (it may grow meanwhile). A job
# (G-code, a move file, raw segments) may be large; a configuration or a state file is kilobytes.
JOB_MAX_BYTES = 256 * 1024 * 1024
SETTINGS_MAX_BYTES = 4 * 1024 * 1024
_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a pipe"),
    (stat.S_ISSOCK, "a socket"),
)


def read_text(path: Path, error: type[Exception], max_bytes: int = JOB_MAX_BYTES) -> str:
    """The file's UTF-8 text; raises `error` saying why when it cannot be read, is not a regular
    file (a device such as /dev/zero, a pipe, a directory, or a link to one), is larger than
    `max_bytes` or is not text."""
    try:
        raw = _read_regular(path, error, max_bytes)
        return raw.decode("utf-8")
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a text file ({exc.reason} at byte {exc.start})") from None


def open_regular(path: Path, error: type[Exception], max_bytes: int) -> BinaryIO:
    """A regular file of at most `max_bytes`, open for reading in binary: opened without blocking
    (a pipe would wait for a writer), its kind checked on what was opened; raises `error` (OSError
    when it cannot be opened)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = next((name for test, name in _KINDS if test(mode)), "not a file")
        raise error(
            f"{path}: {kind}, not a regular file: quadstep reads configurations and jobs from files"
        )
    size = os.fstat(fd).st_size
    if size > max_bytes:
        os.close(fd)
        raise error(f"{path}: {size / 2**20:.0f} MB, {_too_large(max_bytes)}")
    return os.fdopen(fd, "rb")


def _too_large(max_bytes: int) -> str:
    return f"larger than the {max_bytes / 2**20:g} MB such a file may be"


def _read_regular(path: Path, error: type[Exception], max_bytes: int) -> bytes:
    """At most `max_bytes` of a regular file, read no further than a byte past the limit."""
    with open_regular(path, error, max_bytes) as file:
        limit = _too_large(max_bytes)
        raw = file.read(max_bytes + 1)
        if len(raw) > max_bytes:
            raise error(f"{path}: grew past {max_bytes / 2**20:g} MB while read, {limit}")
        return raw


def strict_json(text: str) -> Any:
    """`json.loads`, except that a key given twice in one object is refused (json keeps the
    last)."""
    return json.loads(text, object_pairs_hook=_unique_keys)


class DuplicateKeyError(ValueError):
    """A JSON object or YAML mapping names a key twice."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    data: dict[str, Any] = {}
    for key, value in pairs:
        if key in data:
            raise DuplicateKeyError(
                f"key {key!r} is given twice in one object (which one is meant?)"
            )
        data[key] = value
    return data


def parse_nested(parse: Callable[[str], Any], text: str, path: Path, error: type[Exception]) -> Any:
    """`parse(text)` (JSON, YAML, TOML), with input nested too deep for the parser, expanding to
    more values than the file has characters (YAML aliases of aliases) or a key given twice, as one
    clear error."""
    try:
        data = parse(text)
        if _values(data, {}) > len(text) + 1:
            raise error(f"{path}: its aliases expand to more values than the file has characters")
        return data
    except DuplicateKeyError as exc:
        raise error(f"{path}: {exc}") from None
    except RecursionError:
        raise error(
            f"{path}: nested too deep (lists or tables inside one another hundreds of levels down)"
        ) from None


def _values(data: Any, counted: dict[int, int]) -> int:
    """How many values `data` holds once every shared list or table is written out; each counted
    once."""
    if not isinstance(data, (list, dict)):
        return 1
    if id(data) not in counted:
        items = data.values() if isinstance(data, dict) else data
        counted[id(data)] = 1 + sum(_values(item, counted) for item in items)
    return counted[id(data)]


def replace_text(path: Path, text: str) -> None:
    """Replace `path` with `text` atomically: written beside it, flushed to disk, renamed over it
    (its mode kept)."""
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
