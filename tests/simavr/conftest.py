"""Fixtures for the board tests: the AVR firmware and the simavr harness, built once."""

from __future__ import annotations

import pytest

import avr_sim


@pytest.fixture(scope="session")
def avr_build() -> None:
    """`make firmware harness` once per session (a no-op when up to date)."""
    try:
        avr_sim.build()
    except avr_sim.SimAvrError as exc:
        pytest.fail(str(exc))
