"""docs/BENCHMARKS.md's AVR rows say what the AVR bench measured: the figures come from one file,
docs/figures/avr.json, which tests/bench/bench_avr.py writes (`python3 tests/bench/bench_avr.py`)."""

from __future__ import annotations

import json

from avr_sim import REPO

FIGURES = REPO / "docs" / "figures" / "avr.json"
RATES = ("32000", "40000", "50000")


def firmware_table() -> list[list[str]]:
    """The cells of each row of BENCHMARKS.md's table of firmware figures."""
    text = (REPO / "docs" / "BENCHMARKS.md").read_text()
    section = text.split("## Firmware on the ATmega328P", 1)[1].split("\n## ", 1)[0]
    return [
        [cell.strip() for cell in line.split("|")[1:-1]]
        for line in section.splitlines()
        if line.startswith("| ") and not line.startswith("| figure |")
    ]


def firmware_rows() -> dict[str, str]:
    return {row[0]: row[1] for row in firmware_table()}


def test_the_firmware_rows_are_the_measured_figures() -> None:
    avr = json.loads(FIGURES.read_text())["avr"]
    rows = firmware_rows()
    isr = avr["isr"]
    assert rows["step interrupt, 3 axes stepping, steady"].startswith(
        f"{isr['3 axes stepping']['min']} cycles (idle {isr['idle']['mean']:.0f}, resting {isr['idle']['min']})"
    )
    uno = avr["boards"]["uno"]
    in_a_hold = avr["stack"]["status_in_a_hold"]
    assert rows["flash / RAM (Uno)"] == (
        f"{uno['flash']:,} / {uno['ram']:,} bytes; worst stack "
        f"{avr['stack']['max_bytes']} bytes, {avr['stack']['spare']} spare (a STATUS during a hold: "
        f"{in_a_hold['max_bytes']}, {in_a_hold['spare']} spare)"
    )
    held = avr["hold_tick"]
    assert rows["a hold's tick, every axis decelerating from near full speed"].startswith(
        f"{held['uno']:.0f} cycles with 3 axes (Uno), {held['mega']:.0f} with 4 (Mega)"
    )
    rates = avr["rates"]
    assert rows["segments/s taken while 3 axes step every tick"] == "; ".join(
        f"{rates[r]['segments_per_s']:,} at {int(r) // 1000} kHz" for r in RATES
    )
    label = "HOLDs sent at 32 moments: taken, longest lock, longest tick, timer periods lost"
    assert rows[label].split(" (")[0] == "; ".join(
        f"{int(r) // 1000} kHz: {rates[r]['hold']['answered']}, {rates[r]['hold']['lock']}, "
        f"{rates[r]['hold']['first_tick']}, {rates[r]['hold']['periods_lost']}"
        for r in RATES
    )
    assert all(rates[r]["hold"]["holds"] == 32 for r in RATES)
    stops = avr["underrun"]
    assert rows["an underrun's stop at 32 kHz, 3 axes near full speed: longest tick, timer periods lost"].split(
        " (")[0] == (
        f"behind quadratic segments {stops['quadratic']['longest_tick']:,} cycles, "
        f"{stops['quadratic']['periods_lost']} in {stops['quadratic']['underruns']} underruns; "
        f"behind cubic ones {stops['cubic']['longest_tick']:,}, "
        f"{stops['cubic']['periods_lost']} in {stops['cubic']['underruns']}"
    )


def test_no_peer_figure_without_its_source() -> None:
    """A peer's figure in the firmware table names where it is published."""
    for row in firmware_table():
        assert row[2] == "—" or "(source:" in row[2], row
