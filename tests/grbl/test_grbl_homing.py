"""`$H` through the GRBL front door: the machine's own homing cycle on the emulator with the example
router's simulated switches; a configuration that requires homing starts in Alarm until then."""

from __future__ import annotations

from pathlib import Path

from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving

from quadstep.config import load_config
from quadstep.link import Link
from quadstep.machine import Machine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml").model_copy(
    update={"homing_required": True}
)


def test_homing_required_starts_in_alarm_and_dollar_h_homes(start_emulator) -> None:
    sim = ["--machine", str(REPO / "examples" / "router-uno-machine.toml")]
    emu = start_emulator(free=True, tick_hz=CONFIG.tick_hz, axes=3, queue=16, extra_args=sim)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            with GrblClient(str(pty.path)) as grbl:
                said = grbl.expect_other(lambda line: line.startswith("[MSG:"))
                assert said[-2:] == ["Grbl 1.1h ['$' for help]", "[MSG:'$H'|'$X' to unlock]"]
                assert report_fields(grbl.status())["state"] == "Alarm"
                assert grbl.command("G0 X10")[1] == "error:9"
                assert grbl.command("$H")[1] == "ok"
                report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
                assert machine.homed
                assert mpos(report) == tuple(round(x, 3) for x in machine.position_mm)
                assert grbl.command("G0 X10 Y10")[1] == "ok"
                report = grbl.wait_status(lambda r: report_fields(r)["state"] == "Idle")
                assert mpos(report)[:2] == (10.0, 10.0)
