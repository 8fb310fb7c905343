"""The firmware's protocol header and the host's declarations say the same thing.

firmware/core/qs_protocol.h and qs_messages.h are parsed (nothing is copied
by hand): every type code, capability bit, error, alarm, field, state, event
kind, board and ACK reason, every protocol number, every payload length and
the width of every field the C structs share with a message must be equal on
both sides, with nothing on one side missing from the other.
"""

from __future__ import annotations

import json
import re
from enum import IntEnum
from pathlib import Path

import pytest

from quadstep.protocol import constants as py
from quadstep.protocol.messages import EventKind, MessageType
from quadstep.protocol.wire import Int, PerAxis, WireMessage, declared_event_kinds, declared_messages

REPO = Path(__file__).resolve().parents[2]
HEADER = REPO / "firmware" / "core" / "qs_protocol.h"
MESSAGES_H = REPO / "firmware" / "core" / "qs_messages.h"
VECTORS = json.loads((REPO / "protocol" / "vectors.json").read_text())

_DEFINE = re.compile(r"^#define[ \t]+(QS_\w+)[ \t]+(.+?)[ \t]*(?:/\*.*)?$", re.MULTILINE)
_SAFE = re.compile(r"^[\w\s()+\-*<>|]+$")


def c_defines(path: Path) -> dict[str, int]:
    """Every object-like `#define QS_X value` whose value is an integer expression, evaluated."""
    raw = {name: value for name, value in _DEFINE.findall(path.read_text()) if "(" not in name}
    values: dict[str, int] = {}

    def evaluate(name: str) -> int | None:
        if name in values:
            return values[name]
        text = re.sub(r"\b(\d+)[uUlL]+\b", r"\1", raw[name])
        if not _SAFE.match(text):
            return None
        for ref in set(re.findall(r"\bQS_\w+\b", text)):
            if ref not in raw or evaluate(ref) is None:
                return None
            text = re.sub(rf"\b{ref}\b", str(values[ref]), text)
        try:
            values[name] = int(eval(text, {"__builtins__": {}}))  # digits and operators only, checked above
        except SyntaxError:
            return None
        return values[name]

    for name in raw:
        evaluate(name)
    return values


C = c_defines(HEADER)


def c_table(prefix: str, *, without: tuple[str, ...] = ()) -> dict[str, int]:
    """QS_<prefix>_<NAME> defines as {NAME: value}."""
    head = f"QS_{prefix}_"
    return {k[len(head):]: v for k, v in C.items() if k.startswith(head) and k[len(head):] not in without}


def py_table(enum: type[IntEnum]) -> dict[str, int]:
    return {member.name: int(member) for member in enum}  # type: ignore[misc]


@pytest.mark.parametrize(
    ("prefix", "enum", "without"),
    [
        ("TYPE", MessageType, ()),
        ("ACK", py.AckReason, ()),
        ("ERR", py.ErrorCode, ("NONE",)),
        ("FIELD", py.FieldId, ("NONE",)),
        ("ALARM", py.AlarmCode, ("NONE",)),
        ("STATE", py.State, ()),
        ("EVENT", EventKind, ()),
        ("BOARD", py.Board, ()),
        ("CAP", py.Capability, ()),
        ("INPUT", py.Input, ()),
        ("CAUSE", py.InputCause, ()),
    ],
)
def test_every_code_table_is_the_same_on_both_sides(prefix: str, enum: type[IntEnum], without: tuple[str, ...]) -> None:
    assert c_table(prefix, without=without) == py_table(enum)


def test_the_none_values_and_protocol_numbers_agree() -> None:
    assert (C["QS_ERR_NONE"], C["QS_ALARM_NONE"]) == (0, 0)
    assert C["QS_FIELD_NONE"] == py.NO_FIELD
    assert C["QS_AXIS_NONE"] == py.NO_AXIS
    assert C["QS_SEQ_UNSOLICITED"] == py.BROADCAST_SEQ
    for name in ("PROTOCOL_VERSION", "SPEED_SHIFT", "D", "N_MAX", "V_MAX", "R_MAX", "DECEL_SHIFT", "DECEL_MAX",
                 "MAX_FRAME", "MIN_FRAME", "CUBIC_SHIFT", "CUBIC_ACCEL_LIMIT", "CUBIC_N_MAX"):
        assert C[f"QS_{name}"] == getattr(py, name), name
    assert c_defines(MESSAGES_H)["QS_PROTOCOL_AXES"] == py.MAX_AXES


def declared_lengths() -> dict[str, int]:
    """The payload lengths the host's declarations give, named as the header names them."""
    lengths: dict[str, int] = {}
    classes: list[tuple[str, type[WireMessage]]] = [(d.name, d.cls) for d in declared_messages()]
    classes += [(d.name, d.cls) for d in declared_event_kinds()]
    for name, cls in classes:
        if name == "EVENT":
            continue  # each kind has its own layout
        head, unit = cls.wire_head(), cls.wire_unit()
        named = [pair for _, codec in cls.wire_fields() for pair in getattr(codec, "named_lengths", ())]
        if named:  # a head, then parts of their own sizes
            lengths[f"{name}_HEAD"] = head
            lengths.update({f"{name}_{part}": size for part, size in named})
        elif unit:
            lengths[f"{name}_HEAD"] = head
            lengths[f"{name}_AXIS"] = unit
        elif head:
            lengths[name] = head
    return lengths


def test_every_payload_length_is_the_same_on_both_sides() -> None:
    assert c_table("LEN") == declared_lengths()


C_TYPES = {"uint8_t": "B", "uint16_t": "H", "uint32_t": "I", "int8_t": "b", "int16_t": "h", "int32_t": "i"}
_STRUCT = re.compile(r"typedef struct \{(.*?)\} (\w+);", re.DOTALL)
_MEMBER = re.compile(r"^\s*(u?int\d+_t)\s+([\w\s,\[\]]+);", re.MULTILINE)


def c_struct_members() -> dict[str, dict[str, str]]:
    """{struct: {member: struct code}} for the integer members of qs_messages.h's structs."""
    structs: dict[str, dict[str, str]] = {}
    for body, name in _STRUCT.findall(MESSAGES_H.read_text()):
        members: dict[str, str] = {}
        for ctype, names in _MEMBER.findall(body):
            for member in names.split(","):
                members[member.split("[")[0].strip()] = C_TYPES[ctype]
        structs[name] = members
    return structs


def wire_codes(cls: type[WireMessage]) -> dict[str, str]:
    codes = {}
    for name, codec in cls.wire_fields():
        if isinstance(codec, (Int, PerAxis)):
            codes[name] = codec.code
    return codes


@pytest.mark.parametrize(
    ("struct", "message", "shared"),
    [
        ("qs_ack", "ACK", 4),
        ("qs_identity", "IDENTIFY_REPLY", 14),
        ("qs_status", "STATUS_REPORT", 7),
        ("qs_counters", "STATUS_REPORT", 6),
        ("qs_error_report", "ERROR", 3),
        ("qs_alarm_report", "ALARM", 3),
        ("qs_hold_msg", "HOLD", 1),
        ("qs_segment_msg", "SEGMENT", 1),
        ("qs_probe_msg", "PROBE", 2),
        ("qs_config_msg", "CONFIG", 4),
        ("qs_input_status", "INPUT_STATUS", 9),
    ],
)
def test_c_struct_fields_have_the_wire_widths(struct: str, message: str, shared: int) -> None:
    """Where a C struct member has a message field's name, it has that field's width and sign."""
    cls = next(d.cls for d in [*declared_messages(), *declared_event_kinds()] if d.name == message)
    members = c_struct_members()[struct]
    codes = wire_codes(cls)
    common = sorted(set(members) & set(codes))
    assert len(common) == shared, common  # the comparison covers what it should
    assert {m: members[m] for m in common} == {m: codes[m] for m in common}


def test_segment_axis_fields_have_the_wire_widths() -> None:
    members = c_struct_members()["qs_segment_msg"]
    assert (members["v0"], members["vn"], members["r"]) == ("H", "H", "h")
    segment = next(d.cls for d in declared_messages() if d.name == "SEGMENT")
    assert segment.model_fields["axes"].metadata[0].unit_code == "HHh"


def test_hold_done_positions_have_the_c_width() -> None:
    hold_done = next(d.cls for d in declared_event_kinds() if d.name == "HOLD_DONE")
    assert wire_codes(hold_done) == {"hold_tick": "I", "motion_ticks": "I", "position": "i"}


@pytest.mark.parametrize(
    ("table", "enum"),
    [("type", MessageType), ("ack_reason", py.AckReason), ("error_code", py.ErrorCode), ("field", py.FieldId),
     ("alarm", py.AlarmCode), ("state", py.State), ("event_kind", EventKind)],
)
def test_the_vectors_name_tables_match_the_declarations(table: str, enum: type[IntEnum]) -> None:
    assert VECTORS["names"][table] == py_table(enum)
