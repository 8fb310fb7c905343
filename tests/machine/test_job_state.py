"""The job's states (machine/job_state.py), without a port: the steps the model allows, the ones it refuses,
and what a waiting state tells."""

from __future__ import annotations

import threading

import pytest

from quadstep.machine.job_state import ALWAYS, FINAL, TRANSITIONS, JobState, JobStates, TransitionError

S = JobState


def test_a_job_with_a_pause_a_feed_hold_and_a_starvation_runs_through_its_states() -> None:
    seen: list[JobState] = []
    states = JobStates(on_change=seen.append)
    states.enter(S.PAUSED, line=12)
    assert states.line == 12 and states.state.waiting
    assert states.leave(S.PAUSED, S.RESUMING) and states.line is None
    states.enter(S.STREAMING)
    states.enter(S.HELD, line=30)
    assert states.snapshot() == (S.HELD, 30)
    assert not states.leave(S.PAUSED, S.RESUMING)  # not paused: a resume for a pause does nothing
    assert states.leave(S.HELD, S.RESUMING)
    states.enter(S.STREAMING)
    states.enter(S.STARVED)
    states.enter(S.RESUMING)
    states.enter(S.STREAMING)
    states.enter(S.DONE)
    assert states.starvations == 1
    assert seen == states.history[1:]
    assert states.history == [S.STREAMING, S.PAUSED, S.RESUMING, S.STREAMING, S.HELD, S.RESUMING,
                              S.STREAMING, S.STARVED, S.RESUMING, S.STREAMING, S.DONE]


@pytest.mark.parametrize("start", [s for s in JobState if not s.final])
def test_every_state_but_a_final_one_can_be_stopped_or_fail(start: JobState) -> None:
    for end in ALWAYS:
        states = JobStates()
        states._state = start
        states.enter(end)
        assert states.state is end and end.final


@pytest.mark.parametrize("final", sorted(FINAL, key=lambda s: s.value))
def test_nothing_leaves_a_final_state(final: JobState) -> None:
    for to in JobState:
        states = JobStates()
        states._state = final
        with pytest.raises(TransitionError):
            states.enter(to)


def test_the_model_refuses_steps_it_has_not() -> None:
    refused = [(a, b) for a in JobState for b in JobState
               if not a.final and b not in TRANSITIONS[a] and b not in ALWAYS]
    assert (S.HELD, S.STREAMING) in refused  # a feed hold goes on only through planning the rest again
    assert (S.STARVED, S.PAUSED) in refused
    for a, b in refused:
        states = JobStates()
        states._state = a
        with pytest.raises(TransitionError, match=f"from {a.value} to {b.value}"):
            states.enter(b)
        assert states.state is a  # unchanged


def test_only_a_pause_and_a_feed_hold_wait_for_the_operator() -> None:
    assert {s for s in JobState if s.waiting} == {S.PAUSED, S.HELD}
    assert S.STARVED.label == "starved, going on"


def test_one_of_two_resumes_at_once_wins() -> None:
    states = JobStates()
    states.enter(S.HELD, line=3)
    wins: list[bool] = []
    threads = [threading.Thread(target=lambda: wins.append(states.leave(S.HELD, S.RESUMING)))
               for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(wins) == [False] * 7 + [True]


def test_wait_for_a_state() -> None:
    states = JobStates()
    threading.Timer(0.05, lambda: states.enter(S.DONE)).start()
    assert states.wait_for(lambda s: s.final, timeout=10)
    assert not JobStates().wait_for(lambda s: s.final, timeout=0.01)
