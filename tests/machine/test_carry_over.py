"""What a machine opened anew keeps of its state file: everything for the same boot of the board (a
boot id where the firmware reports one, else a motion clock that did not go back), only the work
offsets for a reset board."""

from __future__ import annotations

from pathlib import Path

import pytest

from backlash_helpers import backlash_config
from quadstep.backlash.band import Band, BandAxis, BandRecord
from quadstep.coordinates import WorkCoordinates
from quadstep.machine.board_identity import board_mark, boot_id, was_reset
from quadstep.machine.carry_over import MOVED_NOTICE, RESET_NOTICE, carry_over
from quadstep.machine.state import StateFile, read_state, write_state
from quadstep.protocol import IdentifyReply, State, StatusReport

CONFIG = backlash_config((0.1, 0.05, 0.0))
MOTOR = (4000, -120, 7)


def identity(boot: int = 0) -> IdentifyReply:
    return IdentifyReply(protocol_version=3, fw_major=1, fw_minor=0, fw_patch=0, board=0, axis_count=3,
                         queue_capacity=32, speed_shift=12, n_max=1022, tick_hz=CONFIG.tick_hz,
                         capabilities=0, next_seq=0, boot_id=boot)


def status(ticks: int, motor: tuple[int, ...] = MOTOR) -> StatusReport:
    return StatusReport(state=State.IDLE, alarm=None, queue_fill=0, next_seq=0, segments_done=0,
                        motion_ticks=ticks, rx_overrun=0, bad_frame=0, bad_crc=0, seq_gap=0,
                        seq_dup=0, rejected=0, position=motor)


def kept(boot: int | None, ticks: int = 50_000) -> StateFile:
    """What a command left: homed, a band known on every axis, a work offset, on this board."""
    band = Band(tuple(BandAxis(a.backlash_steps, a.backlash_steps, -a.backlash_steps)
                      for a in CONFIG.axes))
    coordinates = WorkCoordinates()
    coordinates.set_offset(1, "X", 12.5)
    return StateFile(coordinates=coordinates, homed=True, band=BandRecord.of(band, MOTOR),
                     board=board_mark(identity(boot or 0), ticks, MOTOR).model_copy(update={"boot_id": boot}))


def test_the_boot_id_is_the_firmware_s() -> None:
    assert boot_id(identity(513)) == 513


@pytest.mark.parametrize(("recorded", "now", "ticks", "reset"), [
    (None, 0, 50_000, False),  # recorded without a boot id: the clock as recorded
    (None, 0, 90_000, False),  # ran on since
    (None, 0, 49_999, True),  # went back: reset
    (7, 7, 10, False),  # same boot id: whatever the clock says
    (7, 8, 90_000, True),  # another boot id: reset, however long it ran since
    (None, 8, 90_000, False),  # recorded without one: the clock decides
    (None, 8, 0, True),
])
def test_a_reset_is_told_by_the_boot_id_else_by_the_motion_clock(
        recorded: int | None, now: int, ticks: int, reset: bool) -> None:
    mark = kept(recorded).board
    assert mark is not None and was_reset(mark, identity(now), status(ticks)) is reset


def test_the_same_boot_carries_everything_over() -> None:
    state = kept(7)
    carried = carry_over(state, CONFIG, identity(7), status(50_000))
    assert carried.homed and carried.notice is None and carried.coordinates == state.coordinates
    assert state.band is not None and carried.band == state.band.restore(CONFIG, MOTOR)
    assert carried.band.axes[0].w == 40


def test_a_reset_board_keeps_only_the_work_offsets_and_is_named() -> None:
    state = kept(7)
    carried = carry_over(state, CONFIG, identity(8), status(50_000))
    assert (carried.homed, carried.position_lost, carried.notice) == (False, True, RESET_NOTICE)
    assert carried.band == Band.of(CONFIG) and carried.coordinates == state.coordinates


def test_an_emulator_started_for_the_machine_is_a_new_board_without_a_word() -> None:
    carried = carry_over(kept(None), CONFIG, identity(), status(0), new_board=True)
    assert not carried.homed and carried.notice is None and carried.band == Band.of(CONFIG)


def test_step_counts_changed_behind_the_state_leave_the_band_unknown_and_say_so() -> None:
    carried = carry_over(kept(None), CONFIG, identity(), status(60_000, (4100, -120, 7)))
    assert carried.homed and carried.band == Band.of(CONFIG) and carried.notice == MOVED_NOTICE


def test_a_file_without_a_board_keeps_its_band_where_the_counts_agree(tmp_path: Path) -> None:
    path = tmp_path / "state.json"
    path.write_text(kept(None).model_copy(update={"board": None, "homed": False, "version": 1})
                    .model_dump_json())
    old = read_state(path)
    carried = carry_over(old, CONFIG, identity(), status(0))
    assert old.band is not None and carried.band == old.band.restore(CONFIG, MOTOR)
    assert carried.band != Band.of(CONFIG)
    assert not carried.homed and carried.notice is None
    write_state(path, old)
    assert read_state(path).version == 2
