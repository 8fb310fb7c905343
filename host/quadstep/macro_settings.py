"""User commands of a machine configuration (`[[macros]]`): a key, a name and a few G-code lines,
run through the machine as the console runs a line (macro_check.py checks the G-code at load)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, field_validator

MACRO_LINES = 20  # a macro is a few lines; a job is a file


class Macro(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    key: str = Field(min_length=1, max_length=3, description="F2 … F12, a letter or a digit")
    name: str = Field(min_length=1, max_length=40)
    gcode: tuple[str, ...] = Field(min_length=1, max_length=MACRO_LINES)

    @field_validator("key")
    @classmethod
    def _a_key(cls, key: str) -> str:
        if len(key) == 1 and key.isascii() and key.isalnum():
            return key
        if key[0] in "Ff" and key[1:].isdigit() and 2 <= int(key[1:]) <= 12:
            return key.lower()
        raise ValueError(f"key = {key!r}: must be a letter, a digit or F2 … F12")
