#!/usr/bin/env python3
"""Generate protocol/vectors.json, the normative test vectors of PROTOCOL.md §9.

This is an independent reference: it packs every frame straight from the
tables in PROTOCOL.md with its own COBS and CRC, and imports nothing from the
host package, so checking the host codec (or the firmware) against its output
is not circular.

    python3 protocol/make_vectors.py            # rewrite protocol/vectors.json
    python3 protocol/make_vectors.py --check    # exit 1 if the file is stale
"""

from __future__ import annotations

import binascii
import json
import struct
import sys
from pathlib import Path

OUTPUT = Path(__file__).with_name("vectors.json")
PROTOCOL_VERSION = 3
MAX_FRAME = 64

TYPES = {
    "IDENTIFY": 0x01, "STATUS": 0x02, "STOP": 0x03, "HOLD": 0x04, "INPUTS": 0x06, "WATCHDOG": 0x07, "HOLD_ALONG": 0x08,
    "SEGMENT": 0x10, "SET_POSITION": 0x11, "CUBIC_SEGMENT": 0x12, "PROBE": 0x15, "CONFIG": 0x16, "OUTPUTS": 0x17,
    "SEGMENTS": 0x18, "CUBIC_SEGMENTS": 0x19, "RASTER": 0x1A,
    "ACK": 0x80, "IDENTIFY_REPLY": 0x81, "STATUS_REPORT": 0x82, "ERROR": 0x83, "ALARM": 0x84, "EVENT": 0x85,
    "INPUT_STATUS": 0x86,
}
ACK_REASONS = {"ACCEPTED": 0, "GAP": 1, "DUPLICATE": 2, "QUEUE_FULL": 3, "REJECTED": 4, "SPACE": 5, "PARKED": 6}
ERROR_CODES = {
    "FRAME_TOO_LONG": 1, "FRAME_TOO_SHORT": 2, "BAD_COBS": 3, "BAD_CRC": 4,
    "UNKNOWN_TYPE": 5, "BAD_LENGTH": 6, "RX_OVERRUN": 7,
    "BAD_FIELD": 16, "BUSY": 17, "ALARM_ACTIVE": 18, "INPUT_AT_LEVEL": 19,
}
FIELDS = {"N": 1, "AXES": 2, "DIRECTION": 3, "V0": 4, "VN": 5, "RESIDUAL": 6, "DECEL": 7, "INPUT": 8, "LEVEL": 9,
          "INPUTS": 10, "HARD_LIMITS": 11,
          "SPEED": 12, "ACCEL": 13, "POSITION": 14, "TIMEOUT": 15, "OUTPUTS": 16, "REFERENCE": 17,
          "JERK": 18, "RASTER_AXIS": 19, "PIXELS": 20}
POSITION_MAX = 2**31 - 2**24  # the firmware keeps every position within ±this (§5.2)
WATCHDOG_MAX_MS = 4000
ALARMS = {"UNDERRUN": 1, "REJECTED_SEGMENT": 2, "HARD_LIMIT": 3, "HOST_LOST": 4, "E_STOP": 5}
STATES = {"IDLE": 0, "RUNNING": 1, "ALARM": 2, "HOLDING": 3, "STARVED": 4}
EVENT_KINDS = {"HOLD_DONE": 1, "INPUT": 2, "PROBE_MISSED": 3, "HOLD_DONE_ALONG": 4}
INPUTS = {"LIMIT_0": 0, "LIMIT_1": 1, "LIMIT_2": 2, "LIMIT_3": 3, "LIMIT_MAX_0": 4, "LIMIT_MAX_1": 5,
          "LIMIT_MAX_2": 6, "LIMIT_MAX_3": 7, "PROBE": 8, "ABORT": 9, "FEED_HOLD": 10, "CYCLE_START": 11}
CAUSES = {"REPORT": 0, "HARD_LIMIT": 1, "TRIGGER": 2, "E_STOP": 3, "FEED_HOLD": 4, "CYCLE_START": 5}
CONFIG_FIELDS = ["invert", "enabled", "hard_limits"]


# --- framing (PROTOCOL.md §2) -------------------------------------------------

def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE."""
    return binascii.crc_hqx(data, 0xFFFF)


def cobs(block: bytes) -> bytes:
    """Standard COBS: split at zeros into groups of at most 254 bytes."""
    out = bytearray()
    group = bytearray()
    for byte in block:
        if len(group) == 254:  # a full group has no zero after it
            out += b"\xff" + group
            group.clear()
        if byte == 0:
            out += bytes([len(group) + 1]) + group
            group.clear()
        else:
            group.append(byte)
    out += bytes([len(group) + 1]) + group
    return bytes(out)


def wire(body: bytes) -> bytes:
    """A whole frame: COBS(body ‖ crc16 little-endian) ‖ 0x00."""
    return cobs(body + struct.pack("<H", crc16(body))) + b"\x00"


def wire_bad_crc(body: bytes) -> bytes:
    return cobs(body + struct.pack("<H", crc16(body) ^ 0x0001)) + b"\x00"


# --- payloads (PROTOCOL.md §5) -----------------------------------------------

def segment_payload(n: int, axes: list[dict], extra_mask: int = 0) -> bytes:
    mask = extra_mask
    fields = b""
    for a in axes:
        mask |= 1 << a["axis"]
        if a["direction"] < 0:
            mask |= 1 << (4 + a["axis"])
        fields += struct.pack("<HHh", a["v0"], a["vn"], a["r"])
    return struct.pack("<HB", n, mask) + fields


def cubic_payload(n: int, axes: list[dict], extra_mask: int = 0) -> bytes:
    """n, the fields byte (bits 0-3 jerk, 4-7 set), then per named axis its set and its jerk."""
    mask = extra_mask
    out = b""
    for a in sorted(axes, key=lambda a: a["axis"]):
        if "speed" in a:
            mask |= 16 << a["axis"]
            out += struct.pack("<I", a["speed"] | (1 << 31 if a.get("direction", 1) < 0 else 0))
            out += (a.get("accel", 0) & 0xFFFFFF).to_bytes(3, "little")
        if "jerk" in a:
            mask |= 1 << a["axis"]
            out += struct.pack("<h", a["jerk"])
    return struct.pack("<HB", n, mask) + out


# SEGMENTS (§5.2): a record's head holds n's bits 8-9 and what follows it.
REC_AXES, REC_START, REC_RESIDUAL, REC_CRUISE, REC_REPEAT, REC_MIRROR = 0x04, 0x08, 0x10, 0x20, 0x40, 0x80


def varint(value: int) -> bytes:
    """Zigzag, then 7 bits a byte, low first (two bytes at most here)."""
    u = 2 * value if value >= 0 else -2 * value - 1
    return bytes([u]) if u < 128 else bytes([0x80 | (u & 0x7F), u >> 7])


def records_payload(records: list[dict]) -> bytes:
    out, axes = bytearray(), 0
    for rec in records:
        if rec.get("repeat"):
            out.append(REC_REPEAT)
            continue
        head = rec["n"] >> 8
        head |= REC_AXES if "axes" in rec else 0
        head |= REC_START if "start" in rec else 0
        head |= REC_RESIDUAL if "residual" in rec else 0
        head |= 0 if "change" in rec else REC_CRUISE
        head |= REC_MIRROR if rec.get("mirror") else 0
        out += bytes([head, rec["n"] & 0xFF])
        if "axes" in rec:
            axes = rec["axes"]
            out.append(axes)
        for j in range(bin(axes & 0x0F).count("1")):
            for key in ("start", "residual", "change"):
                if key in rec:
                    out += varint(rec[key][j])
    return bytes(out)


def expand_from_rest(records: list[dict]) -> list[dict]:
    """What the records mean to a freshly started firmware, as SEGMENT messages: each axis's speed and
    residual (along +) start at 0 and follow every segment; an axis a segment does not name stops; a
    mirrored change is relative to the axis's last change, negated."""
    speed, rest, last = [0] * 4, [0] * 4, [0] * 4
    out: list[dict] = []
    n = axes = 0
    v0, vn = [0] * 4, [0] * 4
    for rec in records:
        if not rec.get("repeat"):
            n, axes = rec["n"], rec.get("axes", axes)
        active = [a for a in range(4) if axes >> a & 1]
        moves = []
        for j, a in enumerate(active):
            sign = -1 if axes >> (4 + a) & 1 else 1
            r = sign * rest[a]
            if not rec.get("repeat"):
                v0[a] = speed[a] + rec.get("start", [0] * 4)[j]
                if "residual" in rec:
                    r = rec["residual"][j]
                vn[a] = v0[a] + rec.get("change", [0] * 4)[j] - (last[a] if rec.get("mirror") else 0)
            moves.append(ax(a, sign, v0[a], vn[a], r))
        for a in range(4):
            speed[a] = 0
        for m in moves:
            travel = m["r"] + n * (m["v0"] + m["vn"])
            rest[m["axis"]] = m["direction"] * (travel - 8192 * ((travel + 4096) // 8192))
            speed[m["axis"]] = m["vn"]
            if m["vn"] != m["v0"]:
                last[m["axis"]] = m["vn"] - m["v0"]
        out.append({"n": n, "axes": moves})
    return out


def segments_vector(name: str, seq: int, records: list[dict]) -> None:
    valid(name, TO_FW, {"type": "SEGMENTS", "seq": seq, "records": records})
    VECTORS[-1]["expands_to"] = expand_from_rest(records)


def bad_segments(name: str, records: bytes | list[dict], code: str, field: str | None = None,
                 axis: int | None = None, axis_count: int = 4) -> None:
    raw = records if isinstance(records, bytes) else records_payload(records)
    bad(name, TO_FW, wire(bytes([TYPES["SEGMENTS"], 11]) + raw), code, field, axis, axis_count)


# CUBIC_SEGMENTS (§5.2): a record is its jerk codes (2 bits an axis), n·4 + flags, the sets where flagged (each
# set axis's speed change and, flagged, acceleration), then the given jerks; every number a varint (zigzag where
# signed), 7 bits a byte, low first.
C_SETS, C_ACCEL = 0x01, 0x02
C_NONE, C_GIVEN, C_NEGATE, C_SAME = 0, 1, 2, 3


def uvarint(u: int) -> bytes:
    out = b""
    while u >= 128:
        out += bytes([0x80 | (u & 0x7F)])
        u >>= 7
    return out + bytes([u])


def zigzag(value: int) -> int:
    return 2 * value if value >= 0 else -2 * value - 1


def cubic_records_payload(records: list[dict]) -> bytes:
    out = bytearray()
    for rec in records:
        out.append(sum(code << 2 * axis for axis, code in enumerate(rec["codes"])))
        out += uvarint(4 * rec["n"] + (C_SETS if "sets" in rec else 0) + (C_ACCEL if "accels" in rec else 0))
        if "sets" in rec:
            out.append(rec["sets"])
            for k, change in enumerate(rec.get("speeds", [])):
                out += uvarint(zigzag(change))
                if "accels" in rec:
                    out += uvarint(zigzag(rec["accels"][k]))
        for jerk in rec.get("jerks", []):
            out += uvarint(zigzag(jerk))
    return bytes(out)


def cubic_expand_from_rest(records: list[dict]) -> list[dict]:
    """What the records mean to a freshly started firmware, as CUBIC_SEGMENT messages: each axis's advance
    per tick I and its change d start at 0, direction +; a set replaces all three (its speed is the change
    plus I, or minus I when it reverses the axis); a NEGATE or SAME jerk is the axis's last jerk in the frame
    negated or again; after each segment I += n·d + C(n, 2)·r and d += n·r."""
    i, d, negative, last = [0] * 4, [0] * 4, [False] * 4, [0] * 4
    out: list[dict] = []
    for rec in records:
        n, sets, axes = rec["n"], rec.get("sets", 0), {}
        for k, a in enumerate(a for a in range(4) if sets >> a & 1):
            reverse = bool(sets >> (4 + a) & 1)
            speed = (i[a] if reverse == negative[a] else -i[a]) + rec["speeds"][k]
            accel = rec["accels"][k] if "accels" in rec else 0
            axes[a] = {"axis": a, "speed": speed, "accel": accel, "direction": -1 if reverse else 1}
            i[a], d[a], negative[a] = speed, accel, reverse
        given, r = iter(rec.get("jerks", [])), [0] * 4
        for a, code in enumerate(rec["codes"]):
            if code != C_NONE:
                r[a] = last[a] = next(given) if code == C_GIVEN else -last[a] if code == C_NEGATE else last[a]
                axes.setdefault(a, {"axis": a})["jerk"] = r[a]
        for a in range(4):
            i[a] += n * d[a] + n * (n - 1) // 2 * r[a]
            d[a] += n * r[a]
        out.append({"n": n, "axes": [axes[a] for a in sorted(axes)]})
    return out


def cubic_segments_vector(name: str, seq: int, records: list[dict]) -> None:
    valid(name, TO_FW, {"type": "CUBIC_SEGMENTS", "seq": seq, "records": records})
    VECTORS[-1]["expands_to"] = cubic_expand_from_rest(records)


def bad_cubic_segments(name: str, records: bytes | list[dict], code: str, field: str | None = None,
                       axis: int | None = None, axis_count: int = 4) -> None:
    raw = records if isinstance(records, bytes) else cubic_records_payload(records)
    bad(name, TO_FW, wire(bytes([TYPES["CUBIC_SEGMENTS"], 12]) + raw), code, field, axis, axis_count)


def set_position_payload(positions: dict[int, int], extra_mask: int = 0) -> bytes:
    mask = extra_mask
    for axis in positions:
        mask |= 1 << axis
    values = b"".join(struct.pack("<i", positions[axis]) for axis in sorted(positions))
    return bytes([mask]) + values


IDENTIFY_FIELDS = ["protocol_version", "fw_major", "fw_minor", "fw_patch", "board", "axis_count",
                   "queue_capacity", "speed_shift", "n_max", "tick_hz", "capabilities", "next_seq", "boot_id",
                   "raster_ring"]
STATUS_FIELDS = ["state", "alarm", "queue_fill", "next_seq", "segments_done", "motion_ticks",
                 "rx_overrun", "bad_frame", "bad_crc", "seq_gap", "seq_dup", "rejected"]


def payload(msg: dict) -> bytes:
    t = msg["type"]
    if t in ("IDENTIFY", "STATUS", "STOP", "INPUTS"):
        return b""
    if t == "PROBE":
        return struct.pack("<BB4H", INPUTS[msg["input"]], msg["level"], *msg["decel"])
    if t == "CONFIG":
        return struct.pack("<HHB12B4H", msg["invert"], msg["enabled"], msg["hard_limits"], *msg["debounce"],
                           *msg["hold_decel"])
    if t == "OUTPUTS":
        return struct.pack("<BHBH", msg["outputs"], msg["power"], msg["axis"], msg["speed"])
    if t == "INPUT_STATUS":
        armed = 0xFF if msg["armed"] is None else INPUTS[msg["armed"]]
        return struct.pack("<HHHHHBBBH", msg["present"], msg["active"], msg["raw"], msg["invert"], msg["enabled"],
                           msg["hard_limits"], armed, msg["level"], msg["latches_lost"])
    if t == "SEGMENT":
        return segment_payload(msg["n"], msg["axes"])
    if t == "CUBIC_SEGMENT":
        return cubic_payload(msg["n"], msg["axes"])
    if t == "SEGMENTS":
        return records_payload(msg["records"])
    if t == "CUBIC_SEGMENTS":
        return cubic_records_payload(msg["records"])
    if t == "RASTER":
        return struct.pack("<HBBHH", msg["n"], msg["axes"], msg["pixel"], msg["phase"], msg["pitch"]) + bytes(
            msg["power"])
    if t == "SET_POSITION":
        return set_position_payload({int(k): v for k, v in msg["positions"].items()})
    if t == "ACK":
        return struct.pack("<BBBH", msg["next_seq"], msg["free"], ACK_REASONS[msg["reason"]], msg["done"])
    if t == "IDENTIFY_REPLY":
        return struct.pack("<BBBBBBBBHIHBHH", *(msg[f] for f in IDENTIFY_FIELDS))
    if t == "STATUS_REPORT":
        values = [msg[f] for f in STATUS_FIELDS]
        values[0] = STATES[values[0]]
        values[1] = 0 if values[1] is None else ALARMS[values[1]]
        pos = msg["position"]
        return struct.pack(f"<BBBBIIHHHHHH{len(pos)}i", *values, *pos)
    if t == "ERROR":
        field = 0 if msg["field"] is None else FIELDS[msg["field"]]
        axis = 0xFF if msg["axis"] is None else msg["axis"]
        return struct.pack("<BBBBB", ERROR_CODES[msg["code"]], msg["frame_type"], msg["frame_seq"], field, axis)
    if t == "ALARM":
        pos = msg["position"]
        return struct.pack(f"<BI{len(pos)}i", ALARMS[msg["code"]], msg["motion_ticks"], *pos)
    if t == "HOLD":
        return struct.pack("<4H", *msg["decel"])
    if t == "HOLD_ALONG":
        return struct.pack("<4H4HHH", *msg["decel"], *msg["path_decel"], msg["first"], msg["last"])
    if t == "WATCHDOG":
        return struct.pack("<H", msg["timeout_ms"])
    if t == "EVENT" and msg["kind"] in ("HOLD_DONE", "HOLD_DONE_ALONG"):
        pos = msg["position"]
        return struct.pack(f"<BII{len(pos)}i", EVENT_KINDS[msg["kind"]], msg["hold_tick"], msg["motion_ticks"], *pos)
    if t == "EVENT" and msg["kind"] == "INPUT":
        pos = msg["position"]
        return struct.pack(f"<BIHHB{len(pos)}i", EVENT_KINDS["INPUT"], msg["motion_ticks"], msg["active"],
                           msg["changed"], CAUSES[msg["cause"]], *pos)
    if t == "EVENT" and msg["kind"] == "PROBE_MISSED":
        pos = msg["position"]
        return struct.pack(f"<BI{len(pos)}i", EVENT_KINDS["PROBE_MISSED"], msg["motion_ticks"], *pos)
    raise ValueError(t)


def body(msg: dict) -> bytes:
    return bytes([TYPES[msg["type"]], msg["seq"]]) + payload(msg)


# --- vector list ---------------------------------------------------------------

VECTORS: list[dict] = []
TO_FW, TO_HOST = "to_firmware", "to_host"


def valid(name: str, direction: str, msg: dict, axis_count: int | None = None) -> None:
    vector: dict[str, object] = {"name": name, "direction": direction, "frame": wire(body(msg)).hex(),
                                 "message": msg, "error": None}
    if axis_count is not None:
        vector["axis_count"] = axis_count
    VECTORS.append(vector)


def bad(name: str, direction: str, frame: bytes, code: str, field: str | None = None,
        axis: int | None = None, axis_count: int | None = None) -> None:
    vector: dict[str, object] = {"name": name, "direction": direction, "frame": frame.hex(), "message": None,
              "error": {"code": code, "field": field, "axis": axis}}
    if axis_count is not None:
        vector["axis_count"] = axis_count
    VECTORS.append(vector)


def ax(axis: int, direction: int, v0: int, vn: int, r: int) -> dict:
    return {"axis": axis, "direction": direction, "v0": v0, "vn": vn, "r": r}


def seg(seq: int, n: int, *axes: dict) -> dict:
    return {"type": "SEGMENT", "seq": seq, "n": n, "axes": list(axes)}


def bad_segment(name: str, n: int, axes: list[dict], field: str, axis: int | None,
                extra_mask: int = 0, axis_count: int = 4, seq: int = 7) -> None:
    frame = wire(bytes([TYPES["SEGMENT"], seq]) + segment_payload(n, axes, extra_mask))
    bad(name, TO_FW, frame, "BAD_FIELD", field, axis, axis_count)


def cj(axis: int, jerk: int) -> dict:
    """A cubic segment axis with a jerk only."""
    return {"axis": axis, "jerk": jerk}


def cs(axis: int, speed: int, accel: int, direction: int, jerk: int | None) -> dict:
    """A cubic segment axis with a state set, and a jerk unless None."""
    a = {"axis": axis, "speed": speed, "accel": accel, "direction": direction}
    if jerk is not None:
        a["jerk"] = jerk
    return a


def bad_cubic(name: str, n: int, axes: list[dict], field: str, axis: int | None, axis_count: int = 4,
              seq: int = 9) -> None:
    frame = wire(bytes([TYPES["CUBIC_SEGMENT"], seq]) + cubic_payload(n, axes))
    bad(name, TO_FW, frame, "BAD_FIELD", field, axis, axis_count=axis_count)


def raster(seq: int, n: int, axes: int, pixel: int, phase: int, pitch: int, power: list[int]) -> dict:
    return {"type": "RASTER", "seq": seq, "n": n, "axes": axes, "pixel": pixel, "phase": phase, "pitch": pitch,
            "power": power}


def raster_vector(name: str, after: dict, msg: dict, axis_count: int | None = None) -> None:
    """A RASTER read against the chain that `after` (a SEGMENT, run first by a fresh firmware) leaves."""
    valid(name, TO_FW, msg, axis_count)
    VECTORS[-1]["after"] = after


def bad_raster(name: str, after: dict | None, msg: dict, code: str, field: str | None = None,
               axis: int | None = None, axis_count: int | None = None, cut: int = 0) -> None:
    frame = body(msg)
    bad(name, TO_FW, wire(frame[:len(frame) - cut]), code, field, axis, axis_count)
    if after is not None:
        VECTORS[-1]["after"] = after


def hold(seq: int, *decel: int) -> dict:
    return {"type": "HOLD", "seq": seq, "decel": list(decel)}


def bad_hold(name: str, decel: list[int], axis: int, axis_count: int = 4, seq: int = 9) -> None:
    frame = wire(bytes([TYPES["HOLD"], seq]) + struct.pack("<4H", *decel))
    bad(name, TO_FW, frame, "BAD_FIELD", "DECEL", axis, axis_count)


def probe(seq: int, input_name: str, level: int, *decel: int) -> dict:
    return {"type": "PROBE", "seq": seq, "input": input_name, "level": level, "decel": list(decel)}


def config(seq: int, invert: int, enabled: int, hard_limits: int, debounce: list[int], hold_decel: list[int]) -> dict:
    return {"type": "CONFIG", "seq": seq, "invert": invert, "enabled": enabled, "hard_limits": hard_limits,
            "debounce": debounce, "hold_decel": hold_decel}


def outputs(seq: int, bits: int, power: int, axis: int = 0, speed: int = 0) -> dict:
    return {"type": "OUTPUTS", "seq": seq, "outputs": bits, "power": power, "axis": axis, "speed": speed}


def bad_outputs(name: str, bits: int, power: int, axis: int, speed: int, field: str, error_axis: int | None,
                axis_count: int = 4) -> None:
    frame = wire(bytes([TYPES["OUTPUTS"], 6]) + struct.pack("<BHBH", bits, power, axis, speed))
    bad(name, TO_FW, frame, "BAD_FIELD", field, error_axis, axis_count)


def bad_probe(name: str, input_number: int, level: int, decel: list[int], field: str, axis: int | None,
              axis_count: int = 4) -> None:
    frame = wire(bytes([TYPES["PROBE"], 3]) + struct.pack("<BB4H", input_number, level, *decel))
    bad(name, TO_FW, frame, "BAD_FIELD", field, axis, axis_count)


def bad_config(name: str, invert: int, enabled: int, hard_limits: int, hold_decel: list[int], field: str,
               axis: int | None, axis_count: int = 4) -> None:
    frame = wire(bytes([TYPES["CONFIG"], 4]) + struct.pack("<HHB12B4H", invert, enabled, hard_limits, *([0] * 12),
                                                           *hold_decel))
    bad(name, TO_FW, frame, "BAD_FIELD", field, axis, axis_count)


def build() -> list[dict]:
    VECTORS.clear()
    D = 4096

    # Immediate requests.
    for seq in (0, 1, 0x7F, 0xFF):
        valid(f"identify seq {seq}", TO_FW, {"type": "IDENTIFY", "seq": seq})
    valid("status", TO_FW, {"type": "STATUS", "seq": 42})
    valid("stop", TO_FW, {"type": "STOP", "seq": 200})
    # HOLD: a deceleration for every axis the firmware has, 0 for the others.
    valid("hold, 4 axes, extreme decelerations", TO_FW, hold(201, 1, 8191, 4096, 149), 4)
    valid("hold along the path, 3 axes", TO_FW,
          {"type": "HOLD_ALONG", "seq": 17, "decel": [3277, 3277, 1638, 0], "path_decel": [3277, 1092, 1, 0],
           "first": 65530, "last": 4}, 3)
    valid("hold, 3 axes, axis 3 says 0", TO_FW, hold(0, 100, 200, 300, 0), 3)
    valid("hold, 1 axis", TO_FW, hold(0xFF, 8191, 0, 0, 0), 1)
    valid("hold, zero bytes in the body", TO_FW, hold(0, 256, 512, 0x0100, 0x1F00), 4)

    # Inputs: INPUTS (immediate), PROBE and CONFIG (sequenced).
    valid("inputs", TO_FW, {"type": "INPUTS", "seq": 77})
    valid("probe until the probe touches, 4 axes", TO_FW, probe(5, "PROBE", 1, 8191, 1, 200, 4096), 4)
    valid("probe until limit 0 releases, 3 axes", TO_FW, probe(0, "LIMIT_0", 0, 300, 300, 300, 0), 3)
    valid("probe until max limit 3 closes", TO_FW, probe(0xFF, "LIMIT_MAX_3", 1, 1, 1, 1, 1), 4)
    valid("config, every input inverted and enabled", TO_FW,
          config(9, 0x0FFF, 0x0FFF, 1, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 255], [1, 8191, 256, 4096]), 4)
    valid("config, hard limits off, 3 axes", TO_FW, config(0, 0x0100, 0x0F07, 0, [5] * 12, [64, 64, 64, 0]), 3)

    # OUTPUTS: spindle (or laser) on, reversed, a power following an axis's speed, coolant; everything off.
    valid("outputs, everything off", TO_FW, outputs(0, 0, 0), 4)
    valid("outputs, spindle on at full power, flood and mist", TO_FW, outputs(1, 0x31, 0xFFFF), 4)
    valid("outputs, spindle reversed at a third", TO_FW, outputs(0xFF, 0x03, 21845), 3)
    valid("outputs, laser following axis 0 up to full speed", TO_FW, outputs(2, 0x05, 40000, 0, D), 3)
    valid("outputs, laser following axis 2, zero bytes", TO_FW, outputs(3, 0x05, 0x0100, 2, 0x0100), 3)

    # SEGMENT: 0..4 axes, extreme values. A firmware with fewer axes rejects the
    # ones using axis 3 (and 2), so these assume 4 axes (the emulator's default).
    valid("segment, no axes (dwell of 1022 ticks)", TO_FW, seg(0, 1022), 4)
    valid("segment, 1 axis at rest (all zeros but n)", TO_FW, seg(1, 1, ax(0, 1, 0, 0, 0)), 4)
    valid("segment, 1 axis negative, full speed, r = -4096", TO_FW, seg(2, 1022, ax(0, -1, D, D, -D)), 4)
    valid("segment, 1 axis r = +4096 allowed when not at full speed", TO_FW, seg(3, 500, ax(1, 1, D, D - 1, D)), 4)
    valid("segment, 1 axis r = +4096 with v0 = vn = 0", TO_FW, seg(4, 2, ax(2, -1, 0, 0, D)), 4)
    valid("segment, axis 3 only", TO_FW, seg(5, 77, ax(3, -1, 1, 4095, -1)), 4)
    valid("segment, 2 axes", TO_FW, seg(6, 300, ax(0, 1, 100, 2000, 17), ax(2, -1, 4000, 0, -4000)), 4)
    valid("segment, 3 axes", TO_FW,
          seg(0xFE, 1022, ax(0, 1, 1234, 2345, -1000), ax(1, -1, 0, D, 0), ax(2, 1, D, 0, 4095)), 4)
    valid("segment, 4 axes all negative, extreme values", TO_FW,
          seg(0xFF, 1022, ax(0, -1, D, D, -D), ax(1, -1, 0, 0, D), ax(2, -1, D, 0, -D), ax(3, -1, 0, D, D)), 4)
    valid("segment, 4 axes positive, mid values", TO_FW,
          seg(0x80, 511, ax(0, 1, 2048, 2049, 1), ax(1, 1, 1, 2, -2), ax(2, 1, 3, 4, 5), ax(3, 1, 6, 7, -8)), 4)
    # COBS: a long run of non-zero bytes (no zero anywhere in the body).
    valid("segment, 4 axes, body without zero bytes", TO_FW,
          seg(0x11, 0x0101, ax(0, -1, 0x0FFF, 0x0F0F, 0x0101), ax(1, -1, 0x0E0E, 0x0D0D, 0x0C0C),
              ax(2, -1, 0x0B0B, 0x0A0A, -0x0101), ax(3, -1, 0x0909, 0x0808, 0x0707)), 4)
    # COBS: zeros back to back, and a body ending in zero.
    valid("segment, consecutive zero bytes", TO_FW, seg(0, 256, ax(0, 1, 0, 0, 0), ax(1, 1, 0, 0, 0)), 4)
    valid("segment, body ends in zero byte", TO_FW, seg(9, 3, ax(0, 1, 5, 5, 1)), 4)

    valid("set position, one axis", TO_FW, {"type": "SET_POSITION", "seq": 3, "positions": {"1": -1}})
    valid("set position, no axes", TO_FW, {"type": "SET_POSITION", "seq": 4, "positions": {}})
    valid("set position, four axes, extreme values", TO_FW,
          {"type": "SET_POSITION", "seq": 0xFF,
           "positions": {"0": POSITION_MAX, "1": -POSITION_MAX, "2": 0, "3": 123456789}}, 4)
    for axis, value in ((0, POSITION_MAX + 1), (2, -POSITION_MAX - 1), (1, 2**31 - 1), (3, -(2**31))):
        frame = wire(bytes([TYPES["SET_POSITION"], 6]) + set_position_payload({axis: value}))
        bad(f"set position axis {axis} to {value}, past the position range", TO_FW, frame, "BAD_FIELD",
            "POSITION", axis, axis_count=4)

    # WATCHDOG (immediate): 0 turns it off.
    valid("watchdog off", TO_FW, {"type": "WATCHDOG", "seq": 3, "timeout_ms": 0})
    valid("watchdog 500 ms", TO_FW, {"type": "WATCHDOG", "seq": 0x41, "timeout_ms": 500})
    valid("watchdog at its longest", TO_FW, {"type": "WATCHDOG", "seq": 0xFF, "timeout_ms": WATCHDOG_MAX_MS})
    bad("watchdog past its longest", TO_FW, wire(bytes([TYPES["WATCHDOG"], 1]) + struct.pack("<H", WATCHDOG_MAX_MS + 1)),
        "BAD_FIELD", "TIMEOUT", None)
    bad("watchdog with one byte", TO_FW, wire(bytes([TYPES["WATCHDOG"], 1, 5])), "BAD_LENGTH")

    # Reports.
    for i, reason in enumerate(ACK_REASONS):
        seq = 0xFF if reason == "SPACE" else 10 + i
        valid(f"ack {reason.lower()}", TO_HOST,
              {"type": "ACK", "seq": seq, "next_seq": (seq + 1) & 0xFF, "free": 31 - i, "reason": reason,
               "done": [0, 1, 255, 256, 65535, 12345, 7][i]})
    valid("ack, zero bytes everywhere", TO_HOST,
          {"type": "ACK", "seq": 0, "next_seq": 0, "free": 0, "reason": "ACCEPTED", "done": 0})
    valid("identify reply, emulator", TO_HOST,
          {"type": "IDENTIFY_REPLY", "seq": 1, "protocol_version": 3, "fw_major": 0, "fw_minor": 1, "fw_patch": 0,
           "board": 0, "axis_count": 4, "queue_capacity": 32, "speed_shift": 12, "n_max": 1022,
           "tick_hz": 50000, "capabilities": 0x4007, "next_seq": 0, "boot_id": 0, "raster_ring": 1024})
    valid("identify reply, uno", TO_HOST,
          {"type": "IDENTIFY_REPLY", "seq": 0xFF, "protocol_version": 3, "fw_major": 1, "fw_minor": 2,
           "fw_patch": 3, "board": 1, "axis_count": 3, "queue_capacity": 16, "speed_shift": 12, "n_max": 1022,
           "tick_hz": 40000, "capabilities": 0x2003, "next_seq": 0xAB, "boot_id": 0xBEEF, "raster_ring": 0})
    status_common = {"queue_fill": 5, "next_seq": 17, "segments_done": 2**32 - 1, "motion_ticks": 123456789,
                     "rx_overrun": 0, "bad_frame": 1, "bad_crc": 2, "seq_gap": 3, "seq_dup": 4, "rejected": 65535}
    valid("status report, 3 axes, running", TO_HOST,
          {"type": "STATUS_REPORT", "seq": 2, "state": "RUNNING", "alarm": None, **status_common,
           "position": [1, -1, 2**31 - 1]}, 3)
    valid("status report, 4 axes, alarm", TO_HOST,
          {"type": "STATUS_REPORT", "seq": 0, "state": "ALARM", "alarm": "UNDERRUN", **status_common,
           "position": [0, -(2**31), 1000, -1000]}, 4)
    valid("status report, 4 axes, idle, all zero", TO_HOST,
          {"type": "STATUS_REPORT", "seq": 3, "state": "IDLE", "alarm": None, "queue_fill": 0, "next_seq": 0,
           "segments_done": 0, "motion_ticks": 0, "rx_overrun": 0, "bad_frame": 0, "bad_crc": 0, "seq_gap": 0,
           "seq_dup": 0, "rejected": 0, "position": [0, 0, 0, 0]}, 4)
    valid("status report, 4 axes, holding", TO_HOST,
          {"type": "STATUS_REPORT", "seq": 201, "state": "HOLDING", "alarm": None, **status_common,
           "position": [7, -7, 70000, -70000]}, 4)
    valid("status report, 2 axes, starved", TO_HOST,
          {"type": "STATUS_REPORT", "seq": 9, "state": "STARVED", "alarm": None, **status_common,
           "position": [-123456, 654321]}, 2)
    for code in ("FRAME_TOO_LONG", "FRAME_TOO_SHORT", "BAD_COBS", "BAD_CRC", "RX_OVERRUN"):
        valid(f"error {code.lower()}", TO_HOST,
              {"type": "ERROR", "seq": 0xFF, "code": code, "frame_type": 0xFF, "frame_seq": 0xFF,
               "field": None, "axis": None})
    valid("error unknown_type", TO_HOST,
          {"type": "ERROR", "seq": 9, "code": "UNKNOWN_TYPE", "frame_type": 0x12, "frame_seq": 9,
           "field": None, "axis": None})
    valid("error bad_length", TO_HOST,
          {"type": "ERROR", "seq": 8, "code": "BAD_LENGTH", "frame_type": 0x10, "frame_seq": 8,
           "field": None, "axis": None})
    for i, field in enumerate(FIELDS):
        axis = i - 3 if field in ("V0", "VN", "RESIDUAL", "DECEL") else 1 if field in ("SPEED", "ACCEL") else None
        frame_type = (TYPES["HOLD"] if field == "DECEL" else
                      TYPES["CUBIC_SEGMENT"] if field in ("SPEED", "ACCEL") else TYPES["SEGMENT"])
        valid(f"error bad_field {field.lower()}", TO_HOST,
              {"type": "ERROR", "seq": 20 + i, "code": "BAD_FIELD", "frame_type": frame_type, "frame_seq": 20 + i,
               "field": field, "axis": axis})
    valid("error busy", TO_HOST,
          {"type": "ERROR", "seq": 5, "code": "BUSY", "frame_type": 0x11, "frame_seq": 5, "field": None, "axis": None})
    valid("error alarm_active", TO_HOST,
          {"type": "ERROR", "seq": 6, "code": "ALARM_ACTIVE", "frame_type": 0x10, "frame_seq": 6,
           "field": None, "axis": None})
    valid("alarm underrun, 3 axes", TO_HOST,
          {"type": "ALARM", "seq": 0xFF, "code": "UNDERRUN", "motion_ticks": 1022, "position": [10, -20, 0]}, 3)
    valid("alarm rejected segment, 4 axes", TO_HOST,
          {"type": "ALARM", "seq": 0xFF, "code": "REJECTED_SEGMENT", "motion_ticks": 2**32 - 1,
           "position": [2**31 - 1, -(2**31), -1, 1]}, 4)
    valid("event hold done, 4 axes", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "HOLD_DONE", "hold_tick": 123456, "motion_ticks": 130000,
           "position": [2**31 - 1, -(2**31), -1, 1]}, 4)
    valid("event hold done, 3 axes, at rest at once", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "HOLD_DONE", "hold_tick": 2**32 - 1, "motion_ticks": 2**32 - 1,
           "position": [100, 0, -100]}, 3)
    valid("event hold done along the path, 3 axes", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "HOLD_DONE_ALONG", "hold_tick": 5000, "motion_ticks": 6021,
           "position": [4000, -1333, 7]}, 3)
    valid("event hold done, 1 axis", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "HOLD_DONE", "hold_tick": 0, "motion_ticks": 1, "position": [0]},
          1)

    valid("input status, idle, nothing armed", TO_HOST,
          {"type": "INPUT_STATUS", "seq": 77, "present": 0x0F07, "active": 0x0001, "raw": 0x0F06, "invert": 0,
           "enabled": 0x0F07, "hard_limits": 1, "armed": None, "level": 0, "latches_lost": 0})
    valid("input status, probe armed", TO_HOST,
          {"type": "INPUT_STATUS", "seq": 1, "present": 0x0FFF, "active": 0, "raw": 0x0FFF, "invert": 0x0100,
           "enabled": 0x0EFF, "hard_limits": 0, "armed": "PROBE", "level": 1, "latches_lost": 65535})
    valid("event input, probe trigger, 3 axes", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "INPUT", "motion_ticks": 98765, "active": 0x0100,
           "changed": 0x0100, "cause": "TRIGGER", "position": [1200, -30, -2048]}, 3)
    valid("event input, hard limit, 4 axes", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "INPUT", "motion_ticks": 2**32 - 1, "active": 0x0011,
           "changed": 0x0010, "cause": "HARD_LIMIT", "position": [2**31 - 1, -(2**31), 0, 7]}, 4)
    valid("event input, release reported, 1 axis", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "INPUT", "motion_ticks": 0, "active": 0, "changed": 0x0800,
           "cause": "REPORT", "position": [5]}, 1)
    valid("event probe missed, 3 axes", TO_HOST,
          {"type": "EVENT", "seq": 0xFF, "kind": "PROBE_MISSED", "motion_ticks": 4000, "position": [0, 0, -8000]}, 3)
    valid("alarm e-stop, 3 axes", TO_HOST,
          {"type": "ALARM", "seq": 0xFF, "code": "E_STOP", "motion_ticks": 77, "position": [1, 2, 3]}, 3)
    valid("alarm hard limit, 2 axes", TO_HOST,
          {"type": "ALARM", "seq": 0xFF, "code": "HARD_LIMIT", "motion_ticks": 5, "position": [-1, 1]}, 2)
    valid("error input at level", TO_HOST,
          {"type": "ERROR", "seq": 3, "code": "INPUT_AT_LEVEL", "frame_type": 0x15, "frame_seq": 3,
           "field": None, "axis": None})

    # Malformed frames: framing errors, in the order of PROTOCOL.md §2.
    good = body(seg(1, 100, ax(0, 1, 10, 20, 0)))
    for direction in (TO_FW, TO_HOST):
        ack = body({"type": "ACK", "seq": 1, "next_seq": 2, "free": 3, "reason": "ACCEPTED", "done": 4})
        frame_body = good if direction == TO_FW else ack
        bad(f"{direction}: bad crc", direction, wire_bad_crc(frame_body), "BAD_CRC")
        flipped = bytearray(frame_body)
        flipped[-1] ^= 0x40
        bad(f"{direction}: payload bit flipped", direction,
            cobs(bytes(flipped) + struct.pack("<H", crc16(frame_body))) + b"\x00", "BAD_CRC")
    bad("too short: one decoded byte", TO_FW, cobs(b"\x01") + b"\x00", "FRAME_TOO_SHORT")
    bad("too short: three decoded bytes", TO_FW, cobs(b"\x01\x02\x03") + b"\x00", "FRAME_TOO_SHORT")
    bad("too short: a lone code byte decodes to nothing", TO_FW, b"\x01\x00", "FRAME_TOO_SHORT")
    bad("too short: crc only, body empty", TO_HOST, cobs(struct.pack("<H", crc16(b""))) + b"\x00",
        "FRAME_TOO_SHORT")
    bad("too long: 65 decoded bytes", TO_FW, wire(bytes([0x10, 1]) + bytes(range(1, 62))), "FRAME_TOO_LONG")
    bad("too long: 100 bytes of garbage", TO_FW, bytes(range(1, 101)) + b"\x00", "FRAME_TOO_LONG")
    bad("too long beats bad cobs", TO_HOST, b"\x50" + bytes(range(1, 70)) + b"\x00", "FRAME_TOO_LONG")
    bad("bad cobs: code points past the delimiter", TO_FW, b"\x05\x11\x22\x33\x00", "BAD_COBS")
    bad("bad cobs beats too short", TO_FW, b"\x05\x11\x00", "BAD_COBS")
    bad("bad cobs: valid group then overlong code", TO_HOST, b"\x03\x80\x01\x09\x05\x06\x00", "BAD_COBS")
    # 64 decoded bytes is the longest frame that passes framing: it fails on length.
    longest = bytes([0x10, 2]) + struct.pack("<HB", 10, 0x01) + bytes([1] * 57)
    bad("64 decoded bytes pass framing, then bad length", TO_FW, wire(longest), "BAD_LENGTH")

    # Unknown types, immediate and sequenced ranges; reports sent the wrong way.
    for t in (0x00, 0x05, 0x09, 0x0F, 0x13, 0x14, 0x1B, 0x3F, 0x40, 0x7F, 0x80, 0x82, 0x85, 0x86):
        bad(f"unknown type 0x{t:02x} to firmware", TO_FW, wire(bytes([t, 3])), "UNKNOWN_TYPE")
    for t in (0x01, 0x04, 0x06, 0x07, 0x10, 0x15, 0x87, 0xFF):
        bad(f"unknown type 0x{t:02x} to host", TO_HOST, wire(bytes([t, 3, 0, 0, 0, 0, 0])), "UNKNOWN_TYPE")

    # Wrong payload lengths.
    bad("identify with a payload", TO_FW, wire(bytes([0x01, 0, 0])), "BAD_LENGTH")
    bad("stop with a payload", TO_FW, wire(bytes([0x03, 0, 1, 2])), "BAD_LENGTH")
    bad("hold along the path with a HOLD's payload only", TO_FW,
        wire(bytes([TYPES["HOLD_ALONG"], 0]) + struct.pack("<4H", 5, 5, 5, 5)), "BAD_LENGTH")
    bad("segment without payload", TO_FW, wire(bytes([0x10, 0])), "BAD_LENGTH")
    bad("segment with n only", TO_FW, wire(bytes([0x10, 0, 5, 0])), "BAD_LENGTH")
    bad("segment, 2 axes in mask, 1 axis of fields", TO_FW,
        wire(bytes([0x10, 0]) + struct.pack("<HBHHh", 5, 0x03, 1, 1, 0)), "BAD_LENGTH")
    bad("segment, 1 axis in mask, 2 axes of fields", TO_FW,
        wire(bytes([0x10, 0]) + struct.pack("<HBHHhHHh", 5, 0x01, 1, 1, 0, 1, 1, 0)), "BAD_LENGTH")
    bad("segment, direction bits do not count as axes", TO_FW,
        wire(bytes([0x10, 0]) + struct.pack("<HBHHh", 5, 0x10, 1, 1, 0)), "BAD_LENGTH")
    bad("set position without mask", TO_FW, wire(bytes([0x11, 0])), "BAD_LENGTH")
    bad("set position, mask of 2 axes, 1 value", TO_FW, wire(bytes([0x11, 0, 0x03]) + struct.pack("<i", 1)),
        "BAD_LENGTH")
    bad("ack 4 bytes", TO_HOST, wire(bytes([0x80, 0, 1, 2, 0, 0])), "BAD_LENGTH")
    bad("ack 6 bytes", TO_HOST, wire(bytes([0x80, 0, 1, 2, 0, 0, 0, 0])), "BAD_LENGTH")
    bad("identify reply 16 bytes", TO_HOST, wire(bytes([0x81, 0]) + bytes(range(1, 17))), "BAD_LENGTH")
    bad("identify reply 17 bytes (version 1's layout)", TO_HOST, wire(bytes([0x81, 0]) + bytes(range(1, 18))),
        "BAD_LENGTH")
    bad("identify reply 19 bytes (version 2's layout)", TO_HOST, wire(bytes([0x81, 0]) + bytes(range(1, 20))),
        "BAD_LENGTH")
    bad("status report without positions", TO_HOST, wire(bytes([0x82, 0]) + bytes(24)), "BAD_LENGTH")
    bad("status report, 5 axes", TO_HOST, wire(bytes([0x82, 0]) + bytes(44)), "BAD_LENGTH")
    bad("status report, partial position", TO_HOST, wire(bytes([0x82, 0]) + bytes(30)), "BAD_LENGTH")
    bad("error 4 bytes", TO_HOST, wire(bytes([0x83, 0, 16, 0x10, 0, 1])), "BAD_LENGTH")
    bad("alarm without positions", TO_HOST, wire(bytes([0x84, 0xFF, 1, 0, 0, 0, 0])), "BAD_LENGTH")
    bad("alarm, partial position", TO_HOST, wire(bytes([0x84, 0xFF, 1, 0, 0, 0, 0, 9, 9])), "BAD_LENGTH")
    bad("hold without payload", TO_FW, wire(bytes([0x04, 0])), "BAD_LENGTH")
    bad("hold with 3 axes of fields", TO_FW, wire(bytes([0x04, 0]) + struct.pack("<3H", 1, 1, 1)), "BAD_LENGTH")
    bad("hold with 5 axes of fields", TO_FW, wire(bytes([0x04, 0]) + struct.pack("<5H", 1, 1, 1, 1, 1)),
        "BAD_LENGTH")
    bad("hold with an odd byte", TO_FW, wire(bytes([0x04, 0]) + struct.pack("<4HB", 1, 1, 1, 1, 1)), "BAD_LENGTH")
    bad("event without positions", TO_HOST, wire(bytes([0x85, 0xFF, 1]) + bytes(8)), "BAD_LENGTH")
    bad("event, 5 axes", TO_HOST, wire(bytes([0x85, 0xFF, 1]) + bytes(8 + 20)), "BAD_LENGTH")
    bad("event, partial position", TO_HOST, wire(bytes([0x85, 0xFF, 1]) + bytes(8 + 6)), "BAD_LENGTH")

    bad("inputs with a payload", TO_FW, wire(bytes([0x06, 0, 1])), "BAD_LENGTH")
    bad("probe 9 bytes", TO_FW, wire(bytes([0x15, 0]) + bytes(9)), "BAD_LENGTH")
    bad("probe 11 bytes", TO_FW, wire(bytes([0x15, 0]) + bytes(11)), "BAD_LENGTH")
    bad("config 24 bytes", TO_FW, wire(bytes([0x16, 0]) + bytes(24)), "BAD_LENGTH")
    bad("config 26 bytes", TO_FW, wire(bytes([0x16, 0]) + bytes(26)), "BAD_LENGTH")
    bad("outputs 5 bytes", TO_FW, wire(bytes([0x17, 0]) + bytes(5)), "BAD_LENGTH")
    bad("outputs 7 bytes", TO_FW, wire(bytes([0x17, 0]) + bytes(7)), "BAD_LENGTH")
    bad("input status 14 bytes", TO_HOST, wire(bytes([0x86, 0]) + bytes(14)), "BAD_LENGTH")
    bad("event input without positions", TO_HOST, wire(bytes([0x85, 0xFF, 2]) + bytes(9)), "BAD_LENGTH")
    bad("event probe missed, partial position", TO_HOST, wire(bytes([0x85, 0xFF, 3]) + bytes(4 + 6)), "BAD_LENGTH")

    # PROBE content: an input that can end a motion (a limit or the probe),
    # level 0 or 1, then HOLD's rule for the decelerations.
    bad_probe("probe on the abort input", 9, 1, [1, 1, 1, 1], "INPUT", None)
    bad_probe("probe on input 12", 12, 1, [1, 1, 1, 1], "INPUT", None)
    bad_probe("probe input checked before level", 255, 2, [0, 0, 0, 0], "INPUT", None)
    bad_probe("probe level 2", 8, 2, [1, 1, 1, 1], "LEVEL", None)
    bad_probe("probe decel 0 on axis 1", 0, 1, [5, 0, 5, 5], "DECEL", 1)
    bad_probe("probe decel for axis 3 on a 3-axis firmware", 8, 0, [5, 5, 5, 5], "DECEL", 3, axis_count=3)
    # CONFIG content: input bits the wire names, hard_limits 0 or 1, the feed hold's decelerations.
    bad_config("config invert bit 12", 0x1000, 0, 1, [1, 1, 1, 1], "INPUTS", None)
    bad_config("config enabled bit 15", 0, 0x8000, 1, [1, 1, 1, 1], "INPUTS", None)
    bad_config("config hard_limits 2", 0, 0, 2, [1, 1, 1, 1], "HARD_LIMITS", None)
    bad_config("config hold decel 8192 on axis 0", 0, 0, 0, [8192, 1, 1, 1], "DECEL", 0)
    bad_config("config hold decel for axis 2 on a 2-axis firmware", 0, 0, 1, [1, 1, 1, 0], "DECEL", 2,
               axis_count=2)

    # OUTPUTS content: bits an output has; a power following a speed names an axis the firmware has and a
    # speed of 1 ... 4096; a power that follows nothing names neither.
    bad_outputs("outputs bit 3", 0x08, 0, 0, 0, "OUTPUTS", None)
    bad_outputs("outputs bit 7, checked before the reference", 0x81, 0, 9, 9, "OUTPUTS", None)
    bad_outputs("outputs following axis 3 on a 3-axis firmware", 0x05, 100, 3, 100, "REFERENCE", 3, axis_count=3)
    bad_outputs("outputs following a speed of 0", 0x05, 100, 1, 0, "REFERENCE", 1)
    bad_outputs("outputs following a speed of 4097", 0x04, 100, 0, 4097, "REFERENCE", 0)
    bad_outputs("outputs with a reference but no following", 0x01, 100, 0, 10, "REFERENCE", None)

    # SEGMENT content: every field id, in validation order. axis_count is the
    # firmware's axis count the outcome assumes.
    bad_segment("n = 0", 0, [ax(0, 1, 1, 1, 0)], "N", None)
    bad_segment("n = 1023", 1023, [ax(0, 1, 1, 1, 0)], "N", None)
    bad_segment("n = 65535", 0xFFFF, [], "N", None)
    bad_segment("n checked before speeds", 0, [ax(0, 1, 5000, 5000, 5000)], "N", None)
    bad_segment("axis 3 on a 3-axis firmware", 10, [ax(3, 1, 1, 1, 0)], "AXES", None, axis_count=3)
    bad_segment("axes 1 and 2 on a 1-axis firmware", 10, [ax(1, 1, 1, 1, 0), ax(2, 1, 1, 1, 0)], "AXES", None,
                axis_count=1)
    bad_segment("axes checked before direction", 10, [ax(3, 1, 1, 1, 0)], "AXES", None, extra_mask=0x10,
                axis_count=3)
    bad_segment("direction bit on inactive axis 1", 10, [ax(0, 1, 1, 1, 0)], "DIRECTION", None, extra_mask=0x20)
    bad_segment("direction bit with no active axis", 10, [], "DIRECTION", None, extra_mask=0x80)
    bad_segment("direction checked before speeds", 10, [ax(0, 1, 4097, 1, 0)], "DIRECTION", None, extra_mask=0x40)
    bad_segment("v0 = 4097", 10, [ax(0, 1, 4097, 0, 0)], "V0", 0)
    bad_segment("v0 = 65535 on axis 2", 10, [ax(1, 1, 0, 0, 0), ax(2, -1, 0xFFFF, 0, 0)], "V0", 2)
    bad_segment("v0 checked before vn", 10, [ax(1, 1, 4097, 4097, 0)], "V0", 1)
    bad_segment("vn = 4097", 10, [ax(3, -1, 0, 4097, 0)], "VN", 3)
    bad_segment("vn checked before residual", 10, [ax(0, 1, 0, 4097, 4097)], "VN", 0)
    bad_segment("every v0 before any vn", 10, [ax(0, 1, 0, 4097, 0), ax(2, 1, 4097, 0, 0)], "V0", 2)
    bad_segment("every vn before any residual", 10, [ax(1, 1, 0, 0, -4097), ax(3, 1, 0, 4097, 0)], "VN", 3)
    bad_segment("r = 4097", 10, [ax(0, 1, 0, 0, 4097)], "RESIDUAL", 0)
    bad_segment("r = -4097", 10, [ax(2, -1, 1, 1, -4097)], "RESIDUAL", 2)
    bad_segment("r = -32768", 10, [ax(0, 1, 1, 1, 0), ax(1, 1, 1, 1, -32768)], "RESIDUAL", 1)
    bad_segment("r = 4096 with v0 = vn = 4096", 1022, [ax(0, 1, D, D, D)], "RESIDUAL", 0)
    bad_segment("r = 4096 with v0 = vn = 4096, negative, axis 3", 1, [ax(3, -1, D, D, D)], "RESIDUAL", 3)

    # HOLD content: every axis the firmware has needs 1..8191, the others 0; axis by axis.
    bad_hold("hold decel 0 on axis 0", [0, 1, 1, 1], 0)
    bad_hold("hold decel 8192 on axis 2", [1, 1, 8192, 1], 2)
    bad_hold("hold decel 65535 on axis 3", [1, 1, 1, 0xFFFF], 3)
    bad_hold("hold axes checked in order", [1, 0, 9000, 0], 1)
    # HOLD_ALONG: HOLD's decelerations, then the path's, by the same rule.
    for name, decel, path, axis in (("hold along the path, decel 0 on axis 1", [5, 0, 5, 5], [5, 5, 5, 5], 1),
                                    ("hold along the path, path decel 8192 on axis 2", [5, 5, 5, 5], [5, 5, 8192, 5], 2),
                                    ("hold along the path, path decel for axis 3 on a 3-axis firmware",
                                     [5, 5, 5, 0], [5, 5, 5, 5], 3)):
        frame = wire(bytes([TYPES["HOLD_ALONG"], 9]) + struct.pack("<4H4HHH", *decel, *path, 0, 0))
        bad(name, TO_FW, frame, "BAD_FIELD", "DECEL", axis, 3 if axis == 3 else 4)
    bad_hold("hold decel for axis 3 on a 3-axis firmware", [1, 1, 1, 1], 3, axis_count=3)
    bad_hold("hold decel for axis 1 on a 1-axis firmware", [8191, 8191, 0, 0], 1, axis_count=1)
    bad_hold("hold decel 0 on axis 2 of a 3-axis firmware", [5, 5, 0, 0], 2, axis_count=3)

    # CUBIC_SEGMENT: a chained jerk on three axes (15 bytes on the wire), a cruise with nothing
    # named (9 bytes), state sets with both directions and the extremes of every field. Valid ones
    # are valid for a freshly started firmware (every axis at rest).
    valid("cubic segment, jerk on 3 axes", TO_FW,
          {"type": "CUBIC_SEGMENT", "seq": 30, "n": 500, "axes": [cj(0, 3), cj(1, 7), cj(2, 1000)]})
    valid("cubic segment, nothing named: a cruise", TO_FW, {"type": "CUBIC_SEGMENT", "seq": 31, "n": 65535, "axes": []})
    valid("cubic segment, sets and jerks", TO_FW,
          {"type": "CUBIC_SEGMENT", "seq": 32, "n": 1000,
           "axes": [cs(0, 2**30, 1000, -1, 0), cs(1, 0, 0, 1, 30), cs(3, 12345, 1000, -1, None)]})
    valid("cubic segment, extreme set", TO_FW,
          {"type": "CUBIC_SEGMENT", "seq": 33, "n": 1,
           "axes": [cs(0, 2**31 - 1, -(2**23) + 1, 1, None), cs(1, 2**31 - 1, 2**23 - 1, -1, None)]})
    bad("cubic segment without payload", TO_FW, wire(bytes([0x12, 0])), "BAD_LENGTH")
    bad("cubic segment, a jerk missing", TO_FW, wire(bytes([0x12, 0]) + cubic_payload(5, [cj(0, 1)])[:-1]),
        "BAD_LENGTH")
    bad("cubic segment, a set short by a byte", TO_FW,
        wire(bytes([0x12, 0]) + cubic_payload(5, [cs(2, 1, 0, 1, None)])[:-1]), "BAD_LENGTH")
    bad_cubic("cubic n = 0", 0, [cj(0, 1)], "N", None)
    bad_cubic("cubic jerk on axis 3 of a 3-axis firmware", 10, [cj(3, 1)], "AXES", None, axis_count=3)
    bad_cubic("cubic set on axis 3 of a 3-axis firmware", 10, [cs(3, 0, 0, 1, None)], "AXES", None, axis_count=3)
    # content against the state a fresh firmware's axes have: at rest on the ideal
    bad_cubic("cubic negative jerk from rest", 10, [cj(0, 2), cj(1, -5)], "SPEED", 1)
    bad_cubic("cubic set that speeds past a step per tick", 100, [cs(0, 2**31 - 2**16, 100000, 1, None)], "SPEED", 0)
    bad_cubic("cubic acceleration past 24 bits by the end", 100, [cs(2, 2**28, 8388000, 1, 100)], "ACCEL", 2)
    bad_cubic("cubic acceleration checked before speed", 100,
              [cs(0, 2**31 - 2**16, 100000, 1, None), cs(1, 2**28, 8388000, 1, 100)], "ACCEL", 1)
    bad_cubic("cubic speed dipping below zero inside the segment", 1001, [cs(1, 1000000, -4000, 1, 8)], "SPEED", 1)

    # SEGMENTS: records read against a fresh firmware's chain (every axis at rest on the ideal).
    segments_vector("segments: a start, a chained ramp, a cruise, a repeat", 40, [
        {"n": 500, "axes": 0x03, "start": [0, 0], "change": [300, 1200]},
        {"n": 1022, "change": [-10, 64]},
        {"n": 700},
        {"repeat": True},
        {"n": 256, "axes": 0x23, "start": [-290, -1254], "residual": [0, 17], "change": [5, 4]},
    ])
    segments_vector("segments: one record, three axes, negative directions", 41, [
        {"n": 1, "axes": 0x57, "start": [4096, 1, 0], "change": [-4096, 0, 63]},
    ])
    segments_vector("segments: a deceleration mirroring its acceleration", 43, [
        {"n": 300, "axes": 0x13, "change": [800, 1600]},
        {"n": 900},
        {"n": 300, "change": [0, 2], "mirror": True},
        {"n": 40, "axes": 0x03, "change": [-3, 3], "mirror": True},
    ])
    segments_vector("segments: sixteen records", 42,
                    [{"n": 10, "axes": 0x01, "change": [40]}] + [{"n": 10}] * 14 + [{"n": 10, "change": [-40]}])
    bad_segments("segments without records", b"", "BAD_LENGTH")
    bad_segments("segments, a mirrored cruise", bytes([REC_MIRROR | REC_CRUISE | REC_AXES, 10, 0x01]), "BAD_LENGTH")
    bad_segments("segments, a repeat first", bytes([REC_REPEAT]), "BAD_LENGTH")
    bad_segments("segments, a repeat with n", bytes([REC_AXES, 10, 1, 2, REC_REPEAT | 1]), "BAD_LENGTH")
    bad_segments("segments, the first record without axes", bytes([0, 10, 2]), "BAD_LENGTH")
    bad_segments("segments, a varint cut short", bytes([REC_AXES, 10, 0x01, 0x81]), "BAD_LENGTH")
    bad_segments("segments, a three-byte varint", bytes([REC_AXES, 10, 0x01, 0x81, 0x81, 0x01]), "BAD_LENGTH")
    bad_segments("segments, a field too many", bytes([REC_AXES, 10, 0x01, 2, 2]), "BAD_LENGTH")
    bad_segments("segments, seventeen records", [{"n": 10, "axes": 0x01}] + [{"repeat": True}] * 16, "BAD_LENGTH")
    bad_segments("segments, n = 0", [{"n": 0, "axes": 0x01}], "BAD_FIELD", "N")
    bad_segments("segments, n = 1023", [{"n": 1023, "axes": 0x01}], "BAD_FIELD", "N")
    bad_segments("segments, axis 3 of a 3-axis firmware", [{"n": 10, "axes": 0x08, "change": [4]}],
                 "BAD_FIELD", "AXES", axis_count=3)
    bad_segments("segments, a direction without its axis", [{"n": 10, "axes": 0x21, "change": [4]}],
                 "BAD_FIELD", "DIRECTION")
    bad_segments("segments, a start below zero", [{"n": 10, "axes": 0x03, "start": [0, -1]}], "BAD_FIELD", "V0", 1)
    bad_segments("segments, an end speed past a step per tick", [{"n": 10, "axes": 0x01, "change": [4097]}],
                 "BAD_FIELD", "VN", 0)
    bad_segments("segments, a residual past half a step", [{"n": 10, "axes": 0x04, "residual": [4097]}],
                 "BAD_FIELD", "RESIDUAL", 2)
    bad_segments("segments, the second record refused: nothing runs", [
        {"n": 10, "axes": 0x01, "change": [100]}, {"n": 10, "change": [-101]}], "BAD_FIELD", "VN", 0)

    # CUBIC_SEGMENTS: records read against a fresh firmware's chain (every axis at rest on the ideal).
    none = [C_NONE] * 4
    cubic_segments_vector("cubic segments: a jerk-limited move's seven phases", 44, [
        {"n": 200, "codes": [C_GIVEN, C_GIVEN, C_GIVEN, C_NONE], "jerks": [30, 60, 5], "sets": 0x44, "speeds": [0]},
        {"n": 100, "codes": none},
        {"n": 200, "codes": [C_NEGATE, C_NEGATE, C_NEGATE, C_NONE]},
        {"n": 1000, "codes": none},
        {"n": 200, "codes": [C_SAME, C_SAME, C_SAME, C_NONE]},
        {"n": 100, "codes": none},
        {"n": 200, "codes": [C_NEGATE, C_NEGATE, C_NEGATE, C_NONE]},
    ])
    cubic_segments_vector("cubic segments: sets as changes with accelerations, a reversal, four axes", 45, [
        {"n": 10, "codes": none, "sets": 0xAF, "speeds": [1000000, 2000000, 0, 2**30], "accels": [100, -50, 0, 0]},
        {"n": 3, "codes": [C_NONE, C_NONE, C_NONE, C_GIVEN], "jerks": [-1], "sets": 0x33,
         "speeds": [1001000 + 5000, -500000]},
        {"n": 65535, "codes": none, "sets": 0xBF, "speeds": [-5000, -1499500, 0, -(2**30) + 3]},
    ])
    cubic_segments_vector("cubic segments: sixteen records", 46,
                          [{"n": 10, "codes": [C_GIVEN, 0, 0, 0], "jerks": [5]}]
                          + [{"n": 10, "codes": [C_SAME, 0, 0, 0]}] * 14 + [{"n": 10, "codes": [C_NEGATE, 0, 0, 0]}])
    bad_cubic_segments("cubic segments without records", b"", "BAD_LENGTH")
    bad_cubic_segments("cubic segments, n cut short", bytes([0, 0x80]), "BAD_LENGTH")
    bad_cubic_segments("cubic segments, n in four bytes", bytes([0, 0x80, 0x80, 0x80, 0x01]), "BAD_LENGTH")
    bad_cubic_segments("cubic segments, the sets byte missing", bytes([0, 4 * 10 + C_SETS]), "BAD_LENGTH")
    bad_cubic_segments("cubic segments, a speed past 32 bits", bytes([0, 4 * 10 + C_SETS, 0x01, 0x80, 0x80, 0x80, 0x80,
                                                                      0x10]), "BAD_LENGTH")
    bad_cubic_segments("cubic segments, an acceleration missing", bytes([0, 4 * 10 + C_SETS + C_ACCEL, 0x01, 0x02]),
                       "BAD_LENGTH")
    bad_cubic_segments("cubic segments, a given jerk missing", bytes([C_GIVEN, 4 * 10]), "BAD_LENGTH")
    bad_cubic_segments("cubic segments, a jerk in four bytes", bytes([C_GIVEN, 4 * 10, 0x80, 0x80, 0x80, 0x01]),
                       "BAD_LENGTH")
    bad_cubic_segments("cubic segments, seventeen records", [{"n": 10, "codes": none}] * 17, "BAD_LENGTH")
    bad_cubic_segments("cubic segments, n = 0", [{"n": 0, "codes": none}], "BAD_FIELD", "N")
    bad_cubic_segments("cubic segments, n = 65536", [{"n": 65536, "codes": none}], "BAD_FIELD", "N")
    bad_cubic_segments("cubic segments, a jerk on axis 3 of a 3-axis firmware",
                       [{"n": 10, "codes": [0, 0, 0, C_GIVEN], "jerks": [1]}], "BAD_FIELD", "AXES", axis_count=3)
    bad_cubic_segments("cubic segments, a set on axis 3 of a 3-axis firmware",
                       [{"n": 10, "codes": none, "sets": 0x08, "speeds": [0]}], "BAD_FIELD", "AXES", axis_count=3)
    bad_cubic_segments("cubic segments, a direction without its set",
                       [{"n": 10, "codes": none, "sets": 0x21, "speeds": [0]}], "BAD_FIELD", "DIRECTION")
    bad_cubic_segments("cubic segments, a set speed below zero",
                       [{"n": 10, "codes": none, "sets": 0x01, "speeds": [-1]}], "BAD_FIELD", "SPEED", 0)
    bad_cubic_segments("cubic segments, a set speed of a whole step per tick", [
        {"n": 1, "codes": none, "sets": 0x02, "speeds": [2**30]},
        {"n": 1, "codes": none, "sets": 0x02, "speeds": [2**30]}], "BAD_FIELD", "SPEED", 1)
    bad_cubic_segments("cubic segments, a reversal short of the speed it reverses", [
        {"n": 1, "codes": none, "sets": 0x01, "speeds": [1000]},
        {"n": 1, "codes": none, "sets": 0x11, "speeds": [999]}], "BAD_FIELD", "SPEED", 0)
    bad_cubic_segments("cubic segments, a jerk past 16 bits",
                       [{"n": 10, "codes": [0, C_GIVEN, 0, 0], "jerks": [40000]}], "BAD_FIELD", "JERK", 1)
    bad_cubic_segments("cubic segments, a negated jerk past 16 bits", [
        {"n": 1, "codes": [C_GIVEN, 0, 0, 0], "jerks": [-32768], "sets": 0x01, "speeds": [2**30]},
        {"n": 1, "codes": [C_NEGATE, 0, 0, 0]}], "BAD_FIELD", "JERK", 0)
    bad_cubic_segments("cubic segments, an acceleration past 24 bits",
                       [{"n": 10, "codes": none, "sets": 0x04, "speeds": [2**28], "accels": [2**23]}],
                       "BAD_FIELD", "ACCEL", 2)
    bad_cubic_segments("cubic segments, the second record refused: nothing runs", [
        {"n": 10, "codes": [C_GIVEN, 0, 0, 0], "jerks": [3]},
        {"n": 10, "codes": [0, C_GIVEN, 0, 0], "jerks": [-3]}], "BAD_FIELD", "SPEED", 1)

    # RASTER: a line at the speed the segment before leaves, a power per pixel. The segment before
    # reaches 1024/4096 step per tick on X (and 512 on Y), ending on the ideal.
    to_x = seg(6, 64, ax(0, 1, 0, 1024, 0))
    to_xy = seg(6, 64, ax(0, -1, 0, 1024, 0), ax(1, 1, 0, 512, 0))
    raster_vector("raster, 8 pixels of 2 steps along X", to_x,
                  raster(7, 64, 0x01, 0, 512, 512, [0, 255, 128, 0, 1, 2, 3, 254]))
    raster_vector("raster, a diagonal counted on X, reversed, the first pixel a part", to_xy,
                  raster(7, 100, 0x13, 0, 300, 700, [10, 20, 30, 40]))
    raster_vector("raster, one pixel", to_x, raster(7, 1, 0x01, 0, 256, 256, [77]))
    raster_vector("raster, 52 pixels, the most a frame holds", to_x,
                  raster(7, 900, 0x01, 0, 256, 1024, [(k * 5) & 0xFF for k in range(52)]))
    bad_raster("raster without a pixel", None, raster(7, 64, 0x01, 0, 512, 512, [1]), "BAD_LENGTH", cut=1)
    bad_raster("raster, 53 pixels", None, raster(7, 64, 0x01, 0, 512, 512, [1] * 53), "FRAME_TOO_LONG")
    bad_raster("raster n 0", to_x, raster(7, 0, 0x01, 0, 512, 512, [1]), "BAD_FIELD", "N")
    bad_raster("raster n 1023", to_x, raster(7, 1023, 0x01, 0, 512, 512, [1]), "BAD_FIELD", "N")
    bad_raster("raster on axis 3 of a 3-axis firmware", to_x, raster(7, 10, 0x09, 0, 512, 512, [1]),
               "BAD_FIELD", "AXES", axis_count=3)
    bad_raster("raster from rest: no speed to cruise at", None, raster(7, 10, 0x01, 0, 512, 512, [1]),
               "BAD_FIELD", "RASTER_AXIS")
    bad_raster("raster counted on an axis that does not move", to_x, raster(7, 10, 0x03, 1, 512, 512, [1]),
               "BAD_FIELD", "RASTER_AXIS")
    bad_raster("raster counted on the slower axis", to_xy, raster(7, 10, 0x13, 1, 512, 512, [1]),
               "BAD_FIELD", "RASTER_AXIS")
    bad_raster("raster pixel byte with a reserved bit", to_x, raster(7, 10, 0x01, 4, 512, 512, [1]),
               "BAD_FIELD", "RASTER_AXIS")
    bad_raster("raster, pixels under a step", to_x, raster(7, 10, 0x01, 0, 255, 255, [1, 2]),
               "BAD_FIELD", "PIXELS")
    bad_raster("raster, the first boundary past a pixel", to_x, raster(7, 10, 0x01, 0, 1024, 512, [1, 2]),
               "BAD_FIELD", "PIXELS")
    # 64 ticks at 1024/4096 step a tick: 16 steps; 10 pixels of 2 steps put the last boundary at 18.
    bad_raster("raster, a boundary past the line's steps", to_x,
               raster(7, 64, 0x01, 0, 512, 512, [1] * 9 + [2]), "BAD_FIELD", "PIXELS")

    # SET_POSITION content.
    frame = wire(bytes([TYPES["SET_POSITION"], 5]) + set_position_payload({3: 1}))
    bad("set position axis 3 on a 3-axis firmware", TO_FW, frame, "BAD_FIELD", "AXES", None, axis_count=3)
    frame = wire(bytes([TYPES["SET_POSITION"], 5]) + set_position_payload({0: 1, 4: 2}))
    bad("set position mask bit 4", TO_FW, frame, "BAD_FIELD", "AXES", None)
    frame = wire(bytes([TYPES["SET_POSITION"], 5]) + set_position_payload({7: -5}))
    bad("set position mask bit 7", TO_FW, frame, "BAD_FIELD", "AXES", None)
    return list(VECTORS)


def document() -> str:
    doc = {
        "protocol_version": PROTOCOL_VERSION,
        "notes": [
            "Generated by protocol/make_vectors.py; do not edit by hand.",
            "axis_count, when present, is the firmware axis count the vector's outcome assumes; "
            "a vector without it holds for every axis count 1..4.",
            "ERROR reports name the frame they answer in frame_type and frame_seq; field null is 0 "
            "and axis null is 0xFF on the wire; STATUS_REPORT alarm null is 0.",
            "BAD_FIELD axis is the axis number (not its index among active axes) for V0, VN and "
            "RESIDUAL, and null for N, AXES and DIRECTION (mask-wide checks).",
            "HOLD carries decel for all 4 axes the wire names: 1..8191 for each axis below the "
            "firmware's axis count, 0 for the others; BAD_FIELD DECEL names the first axis that breaks it.",
            "SEGMENT fields are checked field by field in the order of the table, each field in "
            "axis order: every axis's V0 before any VN, every VN before any RESIDUAL.",
            "RASTER vectors with after: a fresh firmware runs that SEGMENT (seq one before) first, "
            "and the RASTER is read against the chain it leaves.",
            "PROBE and CONFIG vectors assume a firmware with every input (present 0x0FFF); INPUT_STATUS "
            "armed null is 0xFF on the wire.",
        ],
        "names": {
            "type": TYPES, "ack_reason": ACK_REASONS, "error_code": ERROR_CODES, "field": FIELDS,
            "alarm": ALARMS, "state": STATES, "event_kind": EVENT_KINDS, "input": INPUTS, "cause": CAUSES,
        },
        "vectors": build(),
    }
    return json.dumps(doc, indent=1) + "\n"


def main(argv: list[str]) -> int:
    text = document()
    if "--check" in argv:
        if OUTPUT.read_text() != text:
            print(f"{OUTPUT} is stale: run python3 {Path(__file__).name}", file=sys.stderr)
            return 1
        return 0
    OUTPUT.write_text(text)
    print(f"wrote {len(json.loads(text)['vectors'])} vectors to {OUTPUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
