"""The dial indicator's arithmetic: the steps before the one that moved the needle; the distance less the
reading; readings that cannot be a backlash refused, naming the value and its limit."""

from __future__ import annotations

import pytest

from quadstep.backlash.dial import DialError, from_jog_back, from_reading


def test_jogging_back_counts_the_steps_before_the_needle_moved() -> None:
    assert from_jog_back(5, 400).steps == 4 and from_jog_back(5, 400).mm == 0.01
    assert from_jog_back(1, 80).steps == 0  # the first step moved it: no backlash to see
    with pytest.raises(DialError, match="steps until the needle moved = 0: must be at least 1"):
        from_jog_back(0, 400)


def test_a_reading_after_a_move_back_gives_the_distance_less_it() -> None:
    result = from_reading(0.5, -0.43, 400)  # the indicator's sign does not matter
    assert abs(result.mm - 0.07) < 1e-12 and abs(result.steps - 28) < 1e-9
    with pytest.raises(DialError, match="reading = 0.6 mm: must be at most the distance moved, 0.5 mm"):
        from_reading(0.5, 0.6, 400)
    with pytest.raises(DialError, match="distance = 0 mm: must be more than 0"):
        from_reading(0, 0, 400)
