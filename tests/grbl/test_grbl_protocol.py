"""GRBL's byte stream split into lines and realtime commands, and the status report's text."""

from __future__ import annotations

from quadstep.grbl.errors import GrblError, error_for
from quadstep.grbl.protocol import (
    MAX_LINE,
    Line,
    Realtime,
    StatusFields,
    StreamSplitter,
    status_report,
)


def test_realtime_bytes_are_taken_out_of_a_line_as_they_arrive() -> None:
    splitter = StreamSplitter()
    events = list(splitter.feed(b"G1 X?1!0~ F1\x18"))
    events += list(splitter.feed(b"00\x85\n"))
    assert events == [
        Realtime(ord("?")),
        Realtime(ord("!")),
        Realtime(ord("~")),
        Realtime(0x18),
        Realtime(0x85),
        Line("G1 X10 F100"),
    ]


def test_every_line_end_ends_a_line_and_a_long_line_is_an_overflow() -> None:
    splitter = StreamSplitter()
    assert list(splitter.feed(b"G0\r\n\n")) == [Line("G0"), Line(""), Line("")]
    events = list(splitter.feed(b"X" * (MAX_LINE + 5) + b"\nG1\n"))
    assert events == [Line("X" * MAX_LINE, overflow=True), Line("G1")]


def test_a_status_report_in_grbls_form() -> None:
    fields = StatusFields("Hold:0", (1.0, -2.5, 0.0), 1200.0, 8000.0, (50.0, 40.0, -5.0))
    assert (
        status_report(fields)
        == "<Hold:0|MPos:1.000,-2.500,0.000|FS:1200,8000|WCO:50.000,40.000,-5.000>"
    )


def test_quadstep_messages_map_to_grbl_error_numbers() -> None:
    assert error_for("line 3: X 400.000 (machine) is outside the travel 0.000 … 300.000 mm") == 15
    assert (
        error_for("line 1, column 1: 'G81': canned cycles (G73, G81 … G89) are not supported") == 20
    )
    assert error_for("something new") == GrblError.INVALID_TARGET
