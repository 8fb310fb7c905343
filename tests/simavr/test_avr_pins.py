"""Step and direction pin timing of the real firmware, measured in CPU cycles
from the pin edges simavr records: what a stepper driver needs."""

from __future__ import annotations

from collections import Counter

import pytest

import avr_scenarios
from avr_sim import F_CPU, Outputs, avr_define, run_feed
from quadstep.kernel.engine_model import predict
from quadstep.protocol import encode

US = F_CPU // 1_000_000  # cycles per microsecond


@pytest.fixture(scope="module")
def run(avr_build: None, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, list, object]:
    """Full speed on every axis, then ramps with direction reversals, fed as fast as flow control allows."""
    runs = avr_scenarios.full_speed(3) + avr_scenarios.ramps_and_reversals(3)
    segments = [s for r in runs for s in r]
    frames = b"".join(encode(s, i % 256) for i, s in enumerate(segments))
    outputs = Outputs.in_dir(tmp_path_factory.mktemp("pins"))
    stats = run_feed(frames, outputs)
    assert stats["feed"]["accepted"] == len(segments), stats["feed"]
    return stats, outputs.load_edges(), predict(segments, axis_count=3)


def pulses(edges: list) -> dict[int, list[tuple[int, int]]]:
    """(rise, fall) cycles of every step pulse, per axis."""
    out: dict[int, list[tuple[int, int]]] = {}
    rise: dict[int, int] = {}
    for cycle, pin, axis, level in edges:
        if pin != "step":
            continue
        if level:
            assert axis not in rise, f"axis {axis}: step pin raised twice without falling (cycle {cycle})"
            rise[axis] = cycle
        else:
            out.setdefault(axis, []).append((rise.pop(axis), cycle))
    assert not rise, f"step pins left high: {rise}"
    return out


def test_every_step_is_a_full_pulse(run: tuple) -> None:
    stats, edges, expected = run
    minimum = avr_define("QS_STEP_PULSE_US") * US
    by_axis = pulses(edges)
    assert [len(by_axis.get(a, [])) for a in range(3)] == expected.per_axis_steps
    widths = [fall - rise for axis in by_axis.values() for rise, fall in axis]
    assert min(widths) >= minimum, f"shortest step pulse {min(widths)} cycles, minimum {minimum}"
    assert stats["motion"]["min_pulse"] == min(widths)


def test_direction_settles_around_the_steps(run: tuple) -> None:
    """Each direction change comes at least 1 µs after that axis's previous
    step pulse ended and at least 1 µs before its next step rises."""
    _, edges, _ = run
    by_axis = pulses(edges)
    changes = [(cycle, axis) for cycle, pin, axis, _ in edges if pin == "dir"]
    assert len(changes) >= 4, "the scenario reverses directions; the pins must show it"
    for cycle, axis in changes:
        before = [fall for _, fall in by_axis.get(axis, []) if fall <= cycle]
        after = [rise for rise, _ in by_axis.get(axis, []) if rise > cycle]
        assert all(rise > cycle or fall <= cycle for rise, fall in by_axis.get(axis, [])), \
            f"axis {axis}: direction changed during a step pulse at cycle {cycle}"
        if before:
            assert cycle - max(before) >= US, f"axis {axis}: direction {cycle - max(before)} cycles after a pulse"
        if after:
            assert min(after) - cycle >= US, f"axis {axis}: direction only {min(after) - cycle} cycles before a step"


def test_steps_keep_to_the_tick_grid(run: tuple) -> None:
    """Rising edges sit on the timer's grid, late by at most a quarter tick
    (interrupt latency), and never skip or double a tick."""
    stats, edges, _ = run
    period = stats["tick_cycles"]
    assert period * avr_define("QS_TICK_HZ") == F_CPU
    rises = sorted({cycle for cycle, pin, _, level in edges if pin == "step" and level})
    phase = Counter(c % period for c in rises)
    usual = phase.most_common(1)[0][0]
    # Offsets from the usual phase, signed: the interrupt's response varies
    # by a few cycles with the instruction it interrupts.
    offset = [(c - usual + period // 2) % period - period // 2 for c in rises]
    on_time = usual + min(offset)
    late = [o - min(offset) for o in offset]
    assert max(late) <= period // 4, f"a step edge came {max(late)} cycles late"
    ticks = [(c - on_time) // period for c in rises]
    assert all(b > a for a, b in zip(ticks, ticks[1:])), "two steps of one axis fell in the same tick"
    # From the interrupt's side: every timer match got its interrupt, soon.
    assert stats["motion"]["ticks_missed"] == 0
    assert stats["motion"]["tick_late_max"] <= period // 4
