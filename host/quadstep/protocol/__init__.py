"""The wire protocol of PROTOCOL.md: constants, message declarations, framing and codec."""

from .codec import DecodeError, Decoder, Frame, decode, decode_body, encode, payload
from .constants import (
    AXIS_NAMES,
    DECEL_MAX,
    DECEL_SHIFT,
    MAX_FRAME,
    POSITION_MAX,
    PROTOCOL_VERSION,
    WATCHDOG_MAX_MS,
    AckReason,
    AlarmCode,
    Board,
    Capability,
    ErrorCode,
    FieldId,
    Input,
    InputCause,
    Output,
    State,
)
from .messages import (
    Ack,
    Alarm,
    Config,
    ErrorReport,
    Event,
    EventKind,
    Hold,
    HoldDone,
    Identify,
    IdentifyReply,
    InputChange,
    Inputs,
    InputStatus,
    Message,
    MessageType,
    Outputs,
    Probe,
    ProbeMissed,
    SetPosition,
    Status,
    StatusReport,
    Stop,
    Watchdog,
    message_type,
)
from .cubic import CubicAxis, CubicSegment
from .segment import D, MAX_AXES, N_MAX, R_MAX, AxisMove, Segment
from .segment_run import RunChain, SegmentRecord, Segments
from .wire import Report, Request

__all__ = [
    "AXIS_NAMES", "Ack", "AckReason", "Alarm", "AlarmCode", "AxisMove", "CubicAxis", "CubicSegment", "Board", "Capability", "Config", "D",
    "DECEL_MAX", "DECEL_SHIFT", "Input", "InputCause", "InputChange", "Output", "Outputs", "InputStatus", "Inputs", "Probe", "ProbeMissed",
    "DecodeError", "Decoder", "ErrorCode", "ErrorReport", "Event", "EventKind", "FieldId", "Hold", "HoldDone",
    "Frame", "Identify", "IdentifyReply", "MAX_AXES", "MAX_FRAME", "Message", "MessageType", "N_MAX",
    "PROTOCOL_VERSION", "R_MAX", "Report", "Request", "RunChain", "Segment", "SegmentRecord", "Segments", "SetPosition", "State", "Status", "StatusReport",
    "Stop", "POSITION_MAX", "WATCHDOG_MAX_MS", "Watchdog", "decode", "decode_body", "encode", "message_type",
    "payload",
]
