"""The machine panel tells the truth: a job waiting is never IDLE, and a machine whose zero a hard limit or the
abort button lost says so after the alarm is cleared."""

from __future__ import annotations

from textual.app import App, ComposeResult

from quadstep.machine import JobState
from quadstep.protocol import IdentifyReply, State, StatusReport
from quadstep.tui.panels import MachinePanel
from quadstep.tui.session import Snapshot

IDENTITY = IdentifyReply(protocol_version=3, fw_major=1, fw_minor=0, fw_patch=0, board=1, axis_count=3,
                         queue_capacity=14, speed_shift=12, n_max=1022, tick_hz=32000, capabilities=0,
                         next_seq=0, boot_id=1)
LINK = {"retransmits": 0, "timeouts": 0, "errors": 0, "decode_errors": 0}


def snapshot(state: State) -> Snapshot:
    status = StatusReport(state=state, alarm=None, queue_fill=0, next_seq=0, segments_done=0, motion_ticks=0,
                          rx_overrun=0, bad_frame=0, bad_crc=0, seq_gap=0, seq_dup=0, rejected=0,
                          position=(0, 0, 0))
    return Snapshot(status, LINK, 0.0, (0.0,) * 3, (0.0,) * 3, "G54", (0, 0, 0))


class PanelApp(App[None]):
    def compose(self) -> ComposeResult:
        yield MachinePanel()


async def shown(job: JobState | None, lost: bool = False) -> str:
    app = PanelApp()
    async with app.run_test():
        panel = app.query_one(MachinePanel)
        panel.show(IDENTITY, snapshot(State.IDLE), None, job, lost)
        return str(panel.render()).splitlines()[0]


async def test_a_waiting_job_is_never_shown_idle() -> None:
    assert await shown(None) == "state IDLE"
    assert await shown(JobState.HELD) == "state FEED HOLD (job)"
    assert await shown(JobState.PAUSED) == "state PAUSED (job)"
    assert await shown(JobState.STARVED) == "state STARVED (job)"
    assert await shown(JobState.STREAMING) == "state IDLE"  # between segments: the board's own word


async def test_a_lost_position_is_shown_after_the_alarm_is_cleared() -> None:
    assert await shown(None, lost=True) == "state IDLE position lost: h homes"
