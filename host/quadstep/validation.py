"""Files the user writes (configurations, move files, the state file) read into pydantic models:
every problem one line naming the key, the value given and the rule, e.g. `axes[0].max_speed =
900.0: must be at most 468.75 mm/s`."""

from __future__ import annotations

import json
import math
import re
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

Model = TypeVar("Model", bound=BaseModel)

_LIMIT_WORDS = {
    "greater_than": "must be greater than {gt}",
    "greater_than_equal": "must be at least {ge}",
    "less_than": "must be less than {lt}",
    "less_than_equal": "must be at most {le}",
    "too_short": "needs at least {min_length} {entries}",
    "too_long": "allows at most {max_length} entries",
}


_KEYED = re.compile(r"^\w+ = ")


def error_location(loc: tuple[int | str, ...]) -> str:
    """A pydantic error's location as written in the file: `axes[0].max_speed`."""
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


def describe_validation_error(error: ValidationError) -> list[str]:
    """pydantic errors as `key = value: rule` lines."""
    lines = []
    for e in error.errors():
        # a bad dict key: name it once
        key = error_location(tuple(part for part in e["loc"] if part != "[key]"))
        kind = e["type"]
        if kind == "too_short" and len(e["input"]) >= e["ctx"]["min_length"]:
            continue  # its entries were refused (named on their own lines), not too few given
        if kind in _LIMIT_WORDS:
            ctx = {k: f"{v:g}" if isinstance(v, float) else v for k, v in e.get("ctx", {}).items()}
            ctx["entries"] = "entry" if ctx.get("min_length") == 1 else "entries"
            lines.append(f"{key} = {e['input']!r}: {_LIMIT_WORDS[kind].format(**ctx)}")
        elif kind == "missing":
            lines.append(f"{key}: missing")
        elif kind == "extra_forbidden":
            lines.append(f"{key}: unknown key")
        elif kind == "literal_error":
            lines.append(f"{key} = {e['input']!r}: must be one of {e['ctx']['expected']}")
        elif kind == "value_error":
            # a validator's message may start with the key it is about ("travel_max = 5: ..."), a
            # line a problem
            for message in str(e["ctx"]["error"]).split("\n"):
                lines.append(
                    message
                    if not key
                    else f"{key}.{message}"
                    if _KEYED.match(message)
                    else f"{key}: {message}"
                )
        else:
            lines.append(f"{key} = {e['input']!r}: {e['msg'].lower()}")
    return lines


def validate(
    model: type[Model], data: Any, source: str, error: type[Exception], strict: bool = True
) -> Model:
    """`data` (as a JSON, YAML or TOML parser gives it) as a `model`, strictly: a string or a
    boolean is never taken for a number, nor a number for a string or a boolean. Raises `error` with
    one `source: key = value: rule` line per problem, or one line for what no such file can hold (a
    date, nesting hundreds of levels deep)."""
    try:
        # JSON's own types, in which strict validation takes lists as tuples
        text = json.dumps(data, allow_nan=False)
    except (TypeError, ValueError) as exc:
        bad = _non_finite(data)
        if bad is not None:
            raise error(f"{source}: {bad}: must be a finite number") from None
        raise error(
            f"{source}: {exc} (only numbers, strings, booleans, lists and tables)"
        ) from None
    except RecursionError:
        raise error(f"{source}: nested too deep") from None
    try:
        return model.model_validate_json(text, strict=strict)
    except ValidationError as exc:
        raise error(
            "\n".join(f"{source}: {line}" for line in describe_validation_error(exc))
        ) from None


def _non_finite(data: Any, key: str = "") -> str | None:
    """`key = value` for the first NaN or infinity in `data`, its key written as validation errors
    write it."""
    if isinstance(data, float) and not math.isfinite(data):
        return f"{key} = {data}"
    items = (
        data.items()
        if isinstance(data, dict)
        else enumerate(data)
        if isinstance(data, list)
        else ()
    )
    for name, value in items:
        found = _non_finite(
            value,
            f"{key}[{name}]" if isinstance(name, int) else f"{key}.{name}" if key else str(name),
        )
        if found is not None:
            return found
    return None
