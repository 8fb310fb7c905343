"""The firmware's alarms through the GRBL front door, on the emulator's simulated machine: a limit
switch closing during a batch is GRBL's ALARM:1 with quadstep's message, said once; lines are then
refused (error:9) until `$X`, which clears the board's alarm too; and the mapping covers every
firmware alarm and homing's failures."""

from __future__ import annotations

from pathlib import Path

from grbl_client import GrblClient, report_fields
from grbl_door import serving

from quadstep.config import load_config
from quadstep.grbl.alarms import FIRMWARE, fault_alarm, homing_alarm
from quadstep.grbl.errors import GrblAlarm
from quadstep.link import Link
from quadstep.machine import Machine
from quadstep.protocol import AlarmCode

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
SIM = """
seed = 1
[[axis]]
start = 0
[axis.limit_max]         # a switch at X 10 mm
at = 4000.0
hysteresis = 8
[[axis]]
start = 0
[[axis]]
start = 0
"""


def test_a_hard_limit_during_a_batch_is_alarm_1_until_unlocked(
    start_emulator, tmp_path: Path
) -> None:
    sim = tmp_path / "machine.toml"
    sim.write_text(SIM)
    emu = start_emulator(
        axes=3, tick_hz=CONFIG.tick_hz, free=True, queue=16, extra_args=["--machine", str(sim)]
    )
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                grbl.wait_banner()
                assert grbl.command("G1 X20 F600")[1] == "ok"
                said = grbl.expect_other(lambda line: line.startswith("ALARM:"))
                assert said[-1] == "ALARM:1"
                assert "HARD_LIMIT" in said[-2]
                assert report_fields(grbl.status())["state"] == "Alarm"
                assert grbl.command("G0 X0")[1] == "error:9"
                assert grbl.command("$J=G91 X-1 F600")[1] == "error:8"  # as GRBL: not idle
                assert not any(line.startswith("ALARM:") for line in grbl.drain_other())
                assert grbl.command("$X")[1] == "ok"
                assert grbl.command("G0 X0")[1] == "ok"
                report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
                assert report_fields(report)["MPos"] == "0.000,0.000,0.000"


def test_every_firmware_alarm_and_homing_failure_has_a_grbl_alarm() -> None:
    assert set(FIRMWARE) == set(AlarmCode)
    assert FIRMWARE[AlarmCode.HARD_LIMIT] == GrblAlarm.HARD_LIMIT
    assert fault_alarm("firmware alarm E_STOP at motion tick 5, …") == GrblAlarm.RESET_IN_MOTION
    assert fault_alarm("line 3: the plan exceeds …") == GrblAlarm.SOFT_LIMIT
    assert homing_alarm("axis X: no switch within 450.0 mm (LIMIT_0)") == (
        GrblAlarm.HOMING_FAIL_APPROACH
    )
    assert homing_alarm("axis Z: the switch did not open within 8.0 mm") == (
        GrblAlarm.HOMING_FAIL_PULLOFF
    )
