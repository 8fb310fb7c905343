"""Writing a measured value back into the machine configuration file, comments and layout kept
(tomlkit).

The file is checked whole before it is replaced (the new text must load as a configuration), the old
one is kept beside it as FILE.bak, and the new one replaces it atomically.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import tomlkit
from tomlkit.items import AoT, Table

from .config import ConfigError, MachineConfig, parse_config
from .textfile import SETTINGS_MAX_BYTES, read_text, replace_text


def _axis_table(document: tomlkit.TOMLDocument, name: str, path: Path) -> Table:
    axes = document.get("axes")
    if not isinstance(axes, AoT | list):
        raise ConfigError(f"{path}: no [[axes]] to write to")
    for table in axes:
        if str(table.get("name", "")).upper() == name.upper():
            return table
    raise ConfigError(f"{path}: no [[axes]] with name = {name!r}")


def new_table_ends_file(document: tomlkit.TOMLDocument, table: Table) -> bool:
    axes = document.get("axes")
    return axes is not None and bool(axes) and axes[-1] is table


def set_backlash(path: Path, axis: str, **values: float) -> tuple[MachineConfig, Path]:
    """Set keys of axis `axis`'s [axes.backlash] (mm, switch_hysteresis, ...) in the file at `path`;
    returns the configuration as now written and where the old file was kept."""
    text = read_text(path, ConfigError, SETTINGS_MAX_BYTES)
    try:
        document = tomlkit.parse(text)
    except tomlkit.exceptions.ParseError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    table = _axis_table(document, axis, path)
    backlash = table.get("backlash")
    if backlash is None:
        backlash = tomlkit.table()
        backlash.comment("measured by quadstep backlash")
        table["backlash"] = backlash
    for key, value in values.items():
        backlash[key] = round(float(value), 6)
    if "backlash" not in text and not new_table_ends_file(document, table):
        backlash.add(tomlkit.nl())
    new_text = tomlkit.dumps(document)
    # refused whole if anything is wrong
    config = parse_config(tomlkit.parse(new_text).unwrap(), str(path))
    backup = path.with_name(path.name + ".bak")
    shutil.copy2(path, backup)
    replace_text(path, new_text)
    return config, backup


Key = tuple[str, ...]  # ("axes", "X", "homing", "seek"), ("spindle", "s_max"), ("arc_tolerance",)


def _place(document: tomlkit.TOMLDocument, key: Key, path: Path) -> Table | tomlkit.TOMLDocument:
    """The table that holds `key`'s last part, made where it is missing."""
    table: Table | tomlkit.TOMLDocument = document
    parts = key[:-1]
    if parts and parts[0] == "axes":
        table, parts = _axis_table(document, parts[1], path), parts[2:]
    for part in parts:
        inner = table.get(part)
        if inner is None:
            inner = tomlkit.table()
            table[part] = inner
        table = inner
    return table


def _value(value: float | bool | str) -> float | bool | str | int:
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e9:
        return int(value)
    return round(value, 6) if isinstance(value, float) else value


def set_values(
    path: Path,
    values: dict[Key, float | bool | str],
    check: Callable[[MachineConfig], None] | None = None,
) -> MachineConfig:
    """Set `values` in the file at `path` (comments and layout kept): the new configuration is
    loaded whole, then `check`ed, before the file is replaced (ConfigError, or what `check` raises,
    and nothing is written); the old file is kept as FILE.bak. Returns the new configuration."""
    text = read_text(path, ConfigError, SETTINGS_MAX_BYTES)
    try:
        document = tomlkit.parse(text)
    except tomlkit.exceptions.ParseError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    for key, value in values.items():
        _place(document, key, path)[key[-1]] = _value(value)
    new_text = tomlkit.dumps(document)
    config = parse_config(tomlkit.parse(new_text).unwrap(), str(path))
    if check is not None:
        check(config)
    shutil.copy2(path, path.with_name(path.name + ".bak"))
    replace_text(path, new_text)
    return config


__all__ = ["set_backlash", "set_values"]
