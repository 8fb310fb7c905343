#!/usr/bin/env python3
"""Turn protocol/vectors.json (PROTOCOL.md section 9) into a C header for the
firmware tests. Names in the JSON become the firmware's own constants
(QS_ERR_BAD_CRC, QS_TYPE_SEGMENT, ...), so a name the firmware does not
know fails to compile, and every number is checked against the frame bytes
by the tests. Any key this script does not understand is an error.

    python3 tests/firmware/gen_vectors.py protocol/vectors.json OUT.h
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

PREFIX = {
    "type": "QS_TYPE_",
    "error_code": "QS_ERR_",
    "field": "QS_FIELD_",
    "ack_reason": "QS_ACK_",
    "alarm": "QS_ALARM_",
    "state": "QS_STATE_",
    "event_kind": "QS_EVENT_",
    "input": "QS_INPUT_",
    "cause": "QS_CAUSE_",
}

MESSAGE_KEYS = {
    "IDENTIFY": set(),
    "STATUS": set(),
    "STOP": set(),
    "HOLD": {"decel"},
    "HOLD_ALONG": {"decel", "path_decel", "first", "last"},
    "INPUTS": set(),
    "WATCHDOG": {"timeout_ms"},
    "PROBE": {"input", "level", "decel"},
    "CONFIG": {"invert", "enabled", "hard_limits", "debounce", "hold_decel"},
    "OUTPUTS": {"outputs", "power", "axis", "speed"},
    "INPUT_STATUS": {"present", "active", "raw", "invert", "enabled", "hard_limits", "armed", "level",
                     "latches_lost"},
    "SEGMENT": {"n", "axes"},
    "SEGMENTS": {"records"},
    "CUBIC_SEGMENTS": {"records"},
    "RASTER": {"n", "axes", "pixel", "phase", "pitch", "power"},
    "CUBIC_SEGMENT": {"n", "axes"},
    "SET_POSITION": {"positions"},
    "ACK": {"next_seq", "free", "reason", "done"},
    "IDENTIFY_REPLY": {"protocol_version", "fw_major", "fw_minor", "fw_patch", "board",
                       "axis_count", "queue_capacity", "speed_shift", "n_max", "tick_hz",
                       "capabilities", "next_seq", "boot_id", "raster_ring"},
    "STATUS_REPORT": {"state", "alarm", "queue_fill", "next_seq", "segments_done",
                      "motion_ticks", "rx_overrun", "bad_frame", "bad_crc", "seq_gap",
                      "seq_dup", "rejected", "position"},
    "ERROR": {"code", "frame_type", "frame_seq", "field", "axis"},
    "ALARM": {"code", "motion_ticks", "position"},
    "EVENT": {"kind", "hold_tick", "motion_ticks", "position", "active", "changed", "cause"},
}
EVENT_KEYS = {
    "HOLD_DONE": {"hold_tick", "motion_ticks", "position"},
    "HOLD_DONE_ALONG": {"hold_tick", "motion_ticks", "position"},
    "INPUT": {"motion_ticks", "active", "changed", "cause", "position"},
    "PROBE_MISSED": {"motion_ticks", "position"},
}
VECTOR_KEYS = {"name", "direction", "frame", "message", "error", "axis_count", "expands_to", "after"}


class VectorError(Exception):
    pass


def constant(kind: str, name: str | int | None) -> str:
    if name is None:
        return {"field": "QS_FIELD_NONE", "alarm": "QS_ALARM_NONE"}.get(kind, "0")
    if isinstance(name, int):
        return str(name)
    return PREFIX[kind] + name


def c_string(text: str) -> str:
    return json.dumps(text)  # a JSON string of ASCII text is a valid C string


def int32(value: int) -> str:
    return f"(int32_t){value}LL"


def positions(values: list[int]) -> str:
    return "{" + ", ".join(int32(v) for v in values) + "}"


def message_fields(msg: dict, axis_count: int) -> list[str]:
    kind = msg["type"]
    if kind not in MESSAGE_KEYS:
        raise VectorError(f"unknown message type {kind!r}")
    extra = set(msg) - MESSAGE_KEYS[kind] - {"type", "seq"}
    if extra:
        raise VectorError(f"unknown keys {sorted(extra)} in {kind}")
    out = [f".type = {constant('type', kind)}", f".seq = {msg['seq']}"]
    if kind in ("SEGMENTS", "CUBIC_SEGMENTS"):
        return out  # its meaning is the vector's expands_to (segment_fields, cubic_fields)
    if kind == "SEGMENT":
        return out + [".host = {.segment = %s}" % segment_fields(msg)]
    if kind == "RASTER":
        return out + [".raster = {.n = %d, .axes = 0x%02X, .pixel = 0x%02X, .phase = %d, .pitch = %d, "
                      ".count = %d, .power = {%s}}"
                      % (msg["n"], msg["axes"], msg["pixel"], msg["phase"], msg["pitch"], len(msg["power"]),
                         ", ".join(map(str, msg["power"])))]
    return out + other_message_fields(msg, kind)


def segment_fields(msg: dict) -> str:
    """A SEGMENT's fields as a qs_segment_msg initialiser."""
    active = negative = 0
    v0 = [0] * 4
    vn = [0] * 4
    r = [0] * 4
    for ax in msg["axes"]:
        i = ax["axis"]
        active |= 1 << i
        if ax["direction"] == -1:
            negative |= 1 << i
        elif ax["direction"] != 1:
            raise VectorError(f"direction must be 1 or -1, not {ax['direction']!r}")
        v0[i], vn[i], r[i] = ax["v0"], ax["vn"], ax["r"]
    return ("{.n = %d, .active = 0x%02X, .negative = 0x%02X, .v0 = {%s}, .vn = {%s}, .r = {%s}}"
            % (msg["n"], active, negative, ", ".join(map(str, v0)), ", ".join(map(str, vn)), ", ".join(map(str, r))))


def cubic_fields(msg: dict) -> str:
    """A CUBIC_SEGMENT's fields as a qs_cubic_msg initialiser."""
    jerk = sets = negative = 0
    speed = [0] * 4
    accel = [0] * 4
    r = [0] * 4
    for ax in msg["axes"]:
        i = ax["axis"]
        if "speed" in ax:
            sets |= 1 << i
            speed[i], accel[i] = ax["speed"], ax.get("accel", 0)
            if ax.get("direction", 1) == -1:
                negative |= 1 << i
        if "jerk" in ax:
            jerk |= 1 << i
            r[i] = ax["jerk"]
    return ("{.n = %d, .jerk = 0x%02X, .set = 0x%02X, .negative = 0x%02X, .speed = {%s}, .accel = {%s}, .r = {%s}}"
            % (msg["n"], jerk, sets, negative, ", ".join(f"{v}UL" for v in speed),
               ", ".join(f"{v}L" for v in accel), ", ".join(map(str, r))))


def other_message_fields(msg: dict, kind: str) -> list[str]:
    out: list[str] = []
    if kind == "CUBIC_SEGMENT":
        out.append(".host = {.cubic = %s}" % cubic_fields(msg))
    elif kind == "SET_POSITION":
        mask = 0
        pos = [0] * 4
        for key, value in msg["positions"].items():
            mask |= 1 << int(key)
            pos[int(key)] = value
        out.append(".host = {.set_position = {.mask = 0x%02X, .position = %s}}"
                   % (mask, positions(pos)))
    elif kind == "HOLD":
        if len(msg["decel"]) != 4:
            raise VectorError("HOLD needs 4 decel values")
        out.append(".host = {.hold = {.decel = {%s}}}" % ", ".join(map(str, msg["decel"])))
    elif kind == "HOLD_ALONG":
        if len(msg["decel"]) != 4 or len(msg["path_decel"]) != 4:
            raise VectorError("HOLD_ALONG needs 4 decel and 4 path_decel values")
        out.append(".host = {.hold_along = {.hold = {.decel = {%s}}, .path = {.hold = {.decel = {%s}}, .first = %d, .last = %d}}}"
                   % (", ".join(map(str, msg["decel"])), ", ".join(map(str, msg["path_decel"])), msg["first"],
                      msg["last"]))
    elif kind == "WATCHDOG":
        out.append(".host = {.watchdog = {.timeout_ms = %d}}" % msg["timeout_ms"])
    elif kind == "PROBE":
        out.append(".host = {.probe = {.input = %s, .level = %d, .hold = {.decel = {%s}}}}"
                   % (constant("input", msg["input"]), msg["level"], ", ".join(map(str, msg["decel"]))))
    elif kind == "CONFIG":
        if len(msg["debounce"]) != 12 or len(msg["hold_decel"]) != 4:
            raise VectorError("CONFIG needs 12 debounce and 4 hold_decel values")
        out.append(".host = {.config = {.invert = 0x%04X, .enabled = 0x%04X, .hard_limits = %d, "
                   ".debounce = {%s}, .hold = {.decel = {%s}}}}"
                   % (msg["invert"], msg["enabled"], msg["hard_limits"], ", ".join(map(str, msg["debounce"])),
                      ", ".join(map(str, msg["hold_decel"]))))
    elif kind == "OUTPUTS":
        out.append(".host = {.outputs = {.outputs = 0x%02X, .axis = %d, .power = %d, .speed = %d}}"
                   % (msg["outputs"], msg["axis"], msg["power"], msg["speed"]))
    elif kind == "INPUT_STATUS":
        armed = "0xFF" if msg["armed"] is None else constant("input", msg["armed"])
        out.append(".input_status = {.present = 0x%04X, .active = 0x%04X, .raw = 0x%04X, .invert = 0x%04X, "
                   ".enabled = 0x%04X, .hard_limits = %d, .armed = %s, .level = %d, .latches_lost = %d}"
                   % (msg["present"], msg["active"], msg["raw"], msg["invert"], msg["enabled"],
                      msg["hard_limits"], armed, msg["level"], msg["latches_lost"]))
    elif kind == "ACK":
        out.append(".ack = {.next_seq = %d, .free = %d, .reason = %s, .done = %d}"
                   % (msg["next_seq"], msg["free"], constant("ack_reason", msg["reason"]),
                      msg["done"]))
    elif kind == "IDENTIFY_REPLY":
        fields = ", ".join(f".{k} = {msg[k]}" for k in sorted(MESSAGE_KEYS[kind]))
        out.append(".identity = {%s}" % fields)
    elif kind == "STATUS_REPORT":
        counters = ", ".join(f".{k} = {msg[k]}" for k in
                             ("rx_overrun", "bad_frame", "bad_crc", "seq_gap", "seq_dup",
                              "rejected"))
        out.append(".status = {.state = %s, .alarm = %s, .queue_fill = %d, .next_seq = %d, "
                   ".segments_done = %dUL, .motion_ticks = %dUL, .counters = {%s}, "
                   ".axis_count = %d, .position = %s}"
                   % (constant("state", msg["state"]), constant("alarm", msg["alarm"]),
                      msg["queue_fill"], msg["next_seq"], msg["segments_done"],
                      msg["motion_ticks"], counters, len(msg["position"]),
                      positions(msg["position"])))
    elif kind == "ERROR":
        axis = 0xFF if msg["axis"] is None else msg["axis"]
        out.append(".error = {.code = %s, .type = %d, .seq = %d, .field = %s, .axis = %d}"
                   % (constant("error_code", msg["code"]), msg["frame_type"],
                      msg["frame_seq"], constant("field", msg["field"]), axis))
    elif kind == "ALARM":
        out.append(".alarm = {.code = %s, .motion_ticks = %dUL, .axis_count = %d, "
                   ".position = %s}"
                   % (constant("alarm", msg["code"]), msg["motion_ticks"],
                      len(msg["position"]), positions(msg["position"])))
    elif kind == "EVENT":
        if msg["kind"] not in EVENT_KEYS:
            raise VectorError(f"unknown EVENT kind {msg['kind']!r}")
        wrong = set(msg) - EVENT_KEYS[msg["kind"]] - {"type", "seq", "kind"}
        if wrong:
            raise VectorError(f"keys {sorted(wrong)} are not EVENT {msg['kind']}'s")
        out.append(".event = {.kind = %s, .hold_tick = %dUL, .motion_ticks = %dUL, "
                   ".active = 0x%04X, .changed = 0x%04X, .cause = %s, .axis_count = %d, .position = %s}"
                   % (constant("event_kind", msg["kind"]), msg.get("hold_tick", 0), msg["motion_ticks"],
                      msg.get("active", 0), msg.get("changed", 0), constant("cause", msg.get("cause")),
                      len(msg["position"]), positions(msg["position"])))
    return out


def vector_entry(index: int, v: dict) -> tuple[str, str]:
    extra = set(v) - VECTOR_KEYS
    if extra:
        raise VectorError(f"unknown keys {sorted(extra)}")
    if v["direction"] not in ("to_firmware", "to_host"):
        raise VectorError(f"bad direction {v['direction']!r}")
    if (v["message"] is None) == (v["error"] is None):
        raise VectorError("needs exactly one of message and error")
    frame = bytes.fromhex(v["frame"])
    axis_count = v.get("axis_count", 4)
    array = (f"static const uint8_t vector_frame_{index}[] = {{"
             + ", ".join(f"0x{b:02X}" for b in frame) + "};")
    fields = [f".name = {c_string(v['name'])}",
              f".to_firmware = {int(v['direction'] == 'to_firmware')}",
              f".frame = vector_frame_{index}", f".frame_len = {len(frame)}",
              f".axis_count = {axis_count}"]
    if "after" in v:
        fields.append(".has_after = 1, .after = %s" % segment_fields(v["after"]))
    if "expands_to" in v:
        segments = v["expands_to"]
        if v["message"]["type"] == "CUBIC_SEGMENTS":
            fields.append(".expands_count = %d, .cubic_expands = {%s}" % (len(segments), ", ".join(map(cubic_fields, segments))))
        else:
            fields.append(".expands_count = %d, .expands = {%s}" % (len(segments), ", ".join(map(segment_fields, segments))))
    if v["message"] is not None:
        fields += message_fields(v["message"], axis_count)
    else:
        err = v["error"]
        fields += [".has_error = 1", f".error_code = {constant('error_code', err['code'])}",
                   f".error_field = {constant('field', err.get('field'))}",
                   f".error_axis = {0xFF if err.get('axis') is None else err['axis']}"]
    return array, "    {" + ", ".join(fields) + "},"


def main() -> int:
    source, target = Path(sys.argv[1]), Path(sys.argv[2])
    data = json.loads(source.read_text())
    if not isinstance(data.get("protocol_version"), int):
        print(f"{source}: no integer protocol_version", file=sys.stderr)
        return 1
    arrays, entries = [], []
    for i, v in enumerate(data["vectors"]):
        try:
            array, entry = vector_entry(i, v)
        except (VectorError, KeyError, ValueError, TypeError) as exc:
            print(f"{source}: vector {i} ({v.get('name', '?')}): {exc}", file=sys.stderr)
            return 1
        arrays.append(array)
        entries.append(entry)
    names = []
    for kind, table in data.get("names", {}).items():
        if kind not in PREFIX:
            print(f"{source}: unknown name table {kind!r}", file=sys.stderr)
            return 1
        for name, value in table.items():
            names.append(f'    {{"{PREFIX[kind]}{name}", {PREFIX[kind]}{name}, {value}}},')
    lines = [f"/* Generated from {source} by tests/firmware/gen_vectors.py. */",
             "#include \"qs_vector_types.h\"", "", *arrays, "",
             "static const qs_vector vectors[] = {", *entries, "};",
             f"#define VECTOR_COUNT {len(entries)}", "",
             "static const qs_vector_name vector_names[] = {",
             *(names or ['    {"none", 0, 0},']), "};",
             f"#define VECTOR_NAME_COUNT {len(names)}",
             f"#define VECTORS_PROTOCOL_VERSION {data['protocol_version']}", ""]
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
