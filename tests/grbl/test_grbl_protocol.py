"""GRBL's byte stream split into lines and realtime commands, and the status report's text."""

from __future__ import annotations

from quadstep.grbl.errors import GrblError, error_for
from quadstep.grbl.pins import pin_letters
from quadstep.grbl.protocol import (
    MAX_LINE,
    Line,
    Realtime,
    StatusFields,
    StreamSplitter,
    status_report,
)
from quadstep.protocol import Input


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


def test_a_status_report_carries_its_optional_fields_in_grbls_order() -> None:
    fields = StatusFields(
        "Run",
        (1.0, 2.0, 3.0),
        600.0,
        0.0,
        (0.5, 0.5, 0.5),
        "S",
        (100, 100, 100),
        work=True,
        buffer=(12, 128),
        pins="PZH",
    )
    assert status_report(fields) == (
        "<Run|WPos:1.000,2.000,3.000|Bf:12,128|FS:600,0|Pn:PZH|WCO:0.500,0.500,0.500"
        "|Ov:100,100,100|A:S>"
    )


def test_the_active_inputs_are_lettered_as_grbl_letters_its_pins() -> None:
    axes = ("X", "Y", "Z")
    assert pin_letters(0, axes) == ""
    assert pin_letters(1 << Input.PROBE, axes) == "P"
    both_ends_of_y = 1 << Input.limit(1) | 1 << Input.limit(1, max_end=True)
    assert pin_letters(both_ends_of_y, axes) == "Y"
    controls = 1 << Input.CYCLE_START | 1 << Input.ABORT | 1 << Input.FEED_HOLD
    everything = controls | 1 << Input.limit(2, max_end=True) | 1 << Input.limit(0) | 1 << 8
    assert pin_letters(everything, axes) == "PXZRHS"
    assert pin_letters(1 << Input.limit(3), ("X", "Y", "Z", "A")) == "A"
