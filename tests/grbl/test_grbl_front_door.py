"""`quadstep grbl`: a sender written from GRBL's documentation (tests/helpers/grbl_client.py) drives the
real emulator through the front door on a real pseudo-terminal (and TCP), and the machine ends exactly
where an independent reading of the file says."""

from __future__ import annotations

import queue
import re
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import serial
from grbl_client import GrblClient, mpos, report_fields
from grbl_door import serving
from laser_raster import record_jobs
from waiting import wait_until

from quadstep.config import load_config
from quadstep.coordinates import WorkCoordinates
from quadstep.grbl.server import PtyServer, TcpServer
from quadstep.grbl.settings import settings
from quadstep.job import load_job
from quadstep.link import Link
from quadstep.machine import JobState, Machine

REPO = Path(__file__).resolve().parents[2]
CONFIG = load_config(REPO / "examples" / "router-uno.toml")
# A CAM-like job: a work offset, the spindle, a plunge, straight cuts and arcs both ways, a retract.
CAM_JOB = """\
(pocket corner, G54 at X50 Y40 Z-5)
G21 G90 G94
G10 L2 P1 X50 Y40 Z-5
G54
M3 S8000
G0 X0 Y0 Z5
G1 Z-1 F300
G1 X20 F1200
G3 X30 Y10 I0 J10
G1 Y20
G2 X20 Y30 I-10 J0
G1 X0
Y0
G0 Z5
M5
X2.5 Y1.25
M30
"""
REPORT = re.compile(
    r"^<(Idle|Run|Hold:[01]|Jog|Alarm|Home|Check)\|MPos:-?\d+\.\d{3}(,-?\d+\.\d{3}){2}"
    r"\|FS:\d+,\d+(\|WCO:-?\d+\.\d{3}(,-?\d+\.\d{3}){2})?(\|Ov:\d+,\d+,\d+(\|A:[SCFM]+)?)?>$"
)


class FrontDoor:
    def __init__(self, machine: Machine, pty: PtyServer) -> None:
        self.machine = machine
        self.pty = pty

    def steps(self) -> tuple[int, ...]:
        """The emulator's own step counts."""
        return tuple(self.machine.link.status().position[:3])


def serve(start_emulator, free: bool) -> Iterator[FrontDoor]:
    emu = start_emulator(axes=3, tick_hz=CONFIG.tick_hz, free=free)
    with Link.open(emu.url) as link:
        machine = Machine(link, CONFIG)
        with serving(machine) as pty:
            yield FrontDoor(machine, pty)


@pytest.fixture
def free_door(start_emulator) -> Iterator[FrontDoor]:
    """The emulator free-running: where timing does not matter."""
    yield from serve(start_emulator, free=True)


@pytest.fixture
def timed_door(start_emulator) -> Iterator[FrontDoor]:
    """The emulator ticking in real time: holds and jog cancels land mid-move."""
    yield from serve(start_emulator, free=False)


def client(door: FrontDoor) -> GrblClient:
    grbl = GrblClient(str(door.pty.path))
    grbl.wait_banner()
    return grbl


def file_end(tmp_path: Path) -> tuple[int, ...]:
    path = tmp_path / "cam.nc"
    path.write_text(CAM_JOB)
    return load_job(path, CONFIG, (0, 0, 0), coordinates=WorkCoordinates()).plan.end


def at_rest(report: str) -> bool:
    return report_fields(report)["state"] == "Idle"


def test_a_cam_job_streamed_by_character_counting_ends_exactly_where_the_file_says(
    free_door: FrontDoor, tmp_path: Path
) -> None:
    lines = CAM_JOB.splitlines()
    with client(free_door) as grbl:
        answers = grbl.stream_counting(lines)
        assert answers == ["ok"] * len(lines)
        assert "[MSG:Pgm End]" in grbl.drain_other()  # M30's, before its ok
        report = grbl.wait_status(at_rest)
        assert REPORT.match(report), report
        end = file_end(tmp_path)
        assert mpos(report) == tuple(round(x, 3) for x in CONFIG.to_mm(end))
        assert free_door.steps() == end
        assert (
            report_fields(grbl.wait_status(lambda r: "WCO" in r))["WCO"] == "50.000,40.000,-5.000"
        )


def test_a_program_end_is_answered_once_its_motion_is_done(timed_door: FrontDoor) -> None:
    """M2/M30 as GRBL answers it: after the moves before it have run, with [MSG:Pgm End]; the lines
    after it are read as a new program."""
    with client(timed_door) as grbl:
        assert grbl.stream_counting(["G0 X20 Y5", "M30"]) == ["ok", "ok"]
        report = grbl.status()
        assert at_rest(report) and mpos(report) == (20.0, 5.0, 0.0)
        assert grbl.drain_other() == ["[MSG:Pgm End]"]
        assert grbl.command("G0 X0") == ([], "ok")
        assert mpos(grbl.wait_status(at_rest)) == (0.0, 5.0, 0.0)


def test_the_feed_reported_is_the_running_lines_not_the_last_read(timed_door: FrontDoor) -> None:
    """A sender streams far ahead of the machine: FS shows the feed of the line that runs."""
    with client(timed_door) as grbl:
        lines = ["G1 X4 F300", "G1 X30 F1200", "G0 X0"]
        assert grbl.stream_counting(lines) == ["ok"] * 3  # all read while the first runs (0.8 s)
        first = grbl.wait_status(lambda r: r.startswith("<Run") and 0.5 < mpos(r)[0] < 3.5)
        assert report_fields(first)["FS"] == "300,0"
        second = grbl.wait_status(lambda r: r.startswith("<Run") and 8 < mpos(r)[0] < 25)
        assert report_fields(second)["FS"] == "1200,0"
        grbl.wait_status(lambda r: mpos(r)[0] > 29.9)
        rapid = grbl.wait_status(lambda r: r.startswith("<Run") and 5 < mpos(r)[0] < 25)
        assert report_fields(rapid)["FS"] == f"{40 * 60},0"  # the rapid, at X's top speed
        grbl.wait_status(at_rest)


def test_send_response_over_tcp_one_sender_at_a_time(free_door: FrontDoor, tmp_path: Path) -> None:
    tcp = TcpServer(free_door.machine, 0).start()
    try:
        with GrblClient(f"socket://127.0.0.1:{tcp.port}") as grbl:
            grbl.wait_banner()
            with GrblClient(f"socket://127.0.0.1:{tcp.port}") as second:
                refused = second.expect_other(lambda line: line.startswith("[MSG:"))
                assert "one at a time" in refused[-1]
            lines = CAM_JOB.splitlines()
            assert grbl.stream_send_response(lines) == ["ok"] * len(lines)
            grbl.wait_status(at_rest)
            assert free_door.steps() == file_end(tmp_path)
    finally:
        tcp.close()


def test_feed_hold_and_cycle_start(timed_door: FrontDoor) -> None:
    with client(timed_door) as grbl:
        assert grbl.command("G1 X30 F1200")[1] == "ok"
        running = grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
        assert REPORT.match(running), running
        grbl.realtime(ord("!"))
        held = grbl.wait_status(lambda r: r.startswith("<Hold:0"))
        assert 0 < mpos(held)[0] < 30
        assert mpos(grbl.status()) == mpos(held)  # at rest while held
        grbl.realtime(ord("~"))
        done = grbl.wait_status(at_rest)
        assert mpos(done) == (30.0, 0.0, 0.0)
        assert timed_door.steps() == CONFIG.to_steps((30.0, 0.0, 0.0))


def test_jog_cancel_stops_a_jog_and_lines_go_on_from_where_it_stopped(
    timed_door: FrontDoor,
) -> None:
    with client(timed_door) as grbl:
        assert grbl.command("G1 F1500")[1] == "ok"  # a program's feed: not the jog's
        assert grbl.command("$J=G91 X50 F600")[1] == "ok"
        jogging = grbl.wait_status(lambda r: r.startswith("<Jog") and mpos(r)[0] > 0.5)
        assert report_fields(jogging)["FS"].startswith("600,")  # the jog's own feed
        grbl.realtime(0x85)
        stopped = mpos(grbl.wait_status(at_rest))
        assert 0.5 < stopped[0] < 50
        steps = timed_door.steps()
        assert grbl.command("G91 G0 X1")[1] == "ok"
        after = mpos(grbl.wait_status(at_rest))
        assert after[0] == pytest.approx(stopped[0] + 1, abs=0.0011)
        assert timed_door.steps() == (steps[0] + 400, 0, 0)  # 1 mm from the rest, exactly


def test_a_stream_of_short_jogs_runs_as_one_motion_until_jog_cancel(
    timed_door: FrontDoor,
) -> None:
    """A joystick or a pendant streams short `$J=` increments by character counting, as GRBL's
    jogging documentation describes: they are planned together, as GRBL's planner does, so the
    carriage goes on without stopping between them; a jog cancel stops it at once, and the jogs
    still queued are dropped."""
    jobs = record_jobs(timed_door.machine)
    with client(timed_door) as grbl:
        jogs = ["$J=G91 X0.5 F1200"] * 24  # 25 ms of motion each at 20 mm/s
        assert grbl.stream_counting(jogs) == ["ok"] * 24
        assert mpos(grbl.wait_status(at_rest)) == (12.0, 0.0, 0.0)
        assert timed_door.steps() == CONFIG.to_steps((12.0, 0.0, 0.0))
        assert len(jobs) == 1  # one motion
        (job,) = jobs
        assert job.states.history == [JobState.STREAMING, JobState.DONE]  # never at rest between
        # continuous: 12 mm at 20 mm/s and the ramps, 0.64 s (each jog alone: 24 × 63 ms)
        assert job.plan.duration_s < 0.7

        assert grbl.stream_counting(["$J=G91 Y2 F600"] * 10) == ["ok"] * 10  # 2 s of jogs
        grbl.wait_status(lambda r: r.startswith("<Jog") and mpos(r)[1] > 1)
        grbl.realtime(0x85)
        stopped = mpos(grbl.wait_status(at_rest))
        assert 1 < stopped[1] < 6
        time.sleep(0.3)  # the jogs queued behind it stay dropped
        assert mpos(grbl.status()) == stopped
        assert timed_door.steps()[1] == round(stopped[1] * 400)
        assert len(jobs) == 2


def test_a_joystick_streaming_jogs_is_paced_as_grbls_planner_paces_it(
    timed_door: FrontDoor,
) -> None:
    """A joystick held: jogs streamed by character counting as fast as the answers come. They are
    answered as GRBL's 15 planner blocks would answer them, a few ahead of the carriage, not all at
    once: so a change of direction or a release (jog cancel) acts within a fraction of a second."""
    with client(timed_door) as grbl:
        jogs = ["$J=G91 X0.5 F1200"] * 40  # 20 mm, 1 s of motion at 20 mm/s
        assert grbl.stream_counting(jogs) == ["ok"] * 40
        # when the last is answered, at most 15 wait and the job is planned less than 0.5 s
        # ahead (jogs are added to it once it runs under 0.125 s ahead, all that wait at once): the
        # carriage has run the rest, 2.5 mm at least (every one answered at once: none)
        answered_at = mpos(grbl.status())[0]
        assert answered_at >= 2.0
        grbl.realtime(0x85)
        stopped = mpos(grbl.wait_status(at_rest))[0]
        assert answered_at <= stopped < 20.0
        assert timed_door.steps()[0] == round(stopped * 400)


def test_soft_reset_in_motion_alarms_and_unlock_goes_on(timed_door: FrontDoor) -> None:
    with client(timed_door) as grbl:
        assert grbl.command("G1 X30 F1200")[1] == "ok"
        grbl.wait_status(lambda r: r.startswith("<Run") and mpos(r)[0] > 1)
        grbl.realtime(0x18)
        said = grbl.expect_other(lambda line: line.startswith("Grbl 1.1h"))
        assert "ALARM:3" in said
        report = grbl.wait_status(lambda r: r.startswith("<Alarm"))
        assert 0 < mpos(report)[0] < 30
        assert grbl.command("G0 X0")[1] == "error:9"
        assert grbl.command("$X")[1] == "ok"
        assert grbl.command("G0 X0")[1] == "ok"
        assert mpos(grbl.wait_status(at_rest)) == (0.0, 0.0, 0.0)


def test_system_commands_answer_in_grbls_formats(free_door: FrontDoor) -> None:
    with client(free_door) as grbl:
        assert grbl.command("$I") == (["[VER:1.1h.quadstep:]", "[OPT:V,15,128]"], "ok")
        lines, answer = grbl.command("$$")
        assert answer == "ok"
        shown = dict(line.split("=") for line in lines)
        for number, value in settings(CONFIG):
            assert float(shown[f"${number}"]) == pytest.approx(value, abs=1e-3)
        assert shown["$100"] == "400" and shown["$110"] == "2400" and shown["$22"] == "1"
        assert grbl.command("G10 L2 P2 X1 Y2 Z-3")[1] == "ok"
        assert grbl.command("G55 G91 G1 F500")[1] == "ok"
        lines, answer = grbl.command("$#")
        assert answer == "ok"
        assert lines[:2] == ["[G54:0.000,0.000,0.000]", "[G55:1.000,2.000,-3.000]"]
        assert lines[-2:] == ["[TLO:0.000]", "[PRB:0.000,0.000,0.000:0]"]
        assert len(lines) == 11 and all(
            re.match(r"^\[[A-Z0-9]+:[-\d.,:]+\]$", line) for line in lines
        )
        lines, answer = grbl.command("$G")
        assert (lines, answer) == (["[GC:G1 G55 G17 G21 G91 G94 M5 M9 T0 F500 S0]"], "ok")
        assert grbl.command("$N") == (["$N0=", "$N1="], "ok")
        assert grbl.command("$100=80")[1] == "error:3"
        assert grbl.command("$Q")[1] == "error:3"


def test_the_status_mask_10_chooses_work_or_machine_position_and_the_buffer_field(
    free_door: FrontDoor,
) -> None:
    with client(free_door) as grbl:
        assert grbl.command("G10 L2 P1 X10 Y20 Z-5")[1] == "ok"
        assert grbl.command("G0 X30 Y25 Z-10")[1] == "ok"
        machine = mpos(grbl.wait_status(at_rest))
        assert machine == (40.0, 45.0, -15.0)  # G54's X30 Y25 Z-10
        assert grbl.command("$10=0") == ([], "ok")
        fields = report_fields(grbl.status())
        assert "MPos" not in fields and "Bf" not in fields
        assert fields["WPos"] == "30.000,25.000,-10.000"  # GRBL's WPos = MPos - WCO
        assert grbl.command("$10=3") == ([], "ok")  # MPos, and Bf
        fields = report_fields(grbl.status())
        assert fields["MPos"] == "40.000,45.000,-15.000" and fields["Bf"] == "15,128"
        assert "[MSG:" in grbl.command("$10=2.5")[0][0] and grbl.command("$10=2.5")[1] == "error:3"
        assert grbl.command("$10=-1")[1] == "error:4"
        lines, answer = grbl.command("$$")
        assert answer == "ok" and "$10=3" in lines
    wait_until(lambda: not free_door.pty.connected.is_set())  # the server saw it close
    with client(free_door) as grbl:  # a sender connecting again finds it as it was left
        assert "Bf" in report_fields(grbl.status())
        assert grbl.command("$10=1") == ([], "ok")
        assert "Bf" not in report_fields(grbl.status())


def test_a_senders_tool_length_offset_g43_1_shifts_z_until_g49(free_door: FrontDoor) -> None:
    """Sender tool-change routines (a new tool probed, then G43.1 Z by how much longer it is) rely
    on GRBL's dynamic tool length offset: `$#` shows it, WCO includes it, and Z moves by it."""
    with client(free_door) as grbl:
        assert grbl.command("G10 L2 P1 Z-20")[1] == "ok"
        assert grbl.command("G43.1 Z-1.5") == ([], "ok")
        lines, answer = grbl.command("$#")
        assert answer == "ok" and "[TLO:-1.500]" in lines
        assert "[G54:0.000,0.000,-20.000]" in lines  # the offset itself unchanged
        assert grbl.command("G0 X5 Z-3")[1] == "ok"
        report = grbl.wait_status(lambda r: at_rest(r) and "WCO" in r)
        assert mpos(report) == (5.0, 0.0, -24.5)  # -3 in G54, 1.5 mm further for the longer tool
        assert report_fields(report)["WCO"] == "0.000,0.000,-21.500"
        assert grbl.command("G43.1 X1")[1] == "error:37"
        assert grbl.command("G49 G0 Z-3")[1] == "ok"
        assert mpos(grbl.wait_status(at_rest)) == (5.0, 0.0, -23.0)
        assert "[TLO:0.000]" in grbl.command("$#")[0]
    assert free_door.steps() == CONFIG.to_steps((5.0, 0.0, -23.0))


def test_sleep_refuses_every_line_until_a_reset_which_leaves_an_alarm(free_door: FrontDoor) -> None:
    with client(free_door) as grbl:
        assert grbl.command("M3 S500")[1] == "ok"
        assert grbl.command("$SLP") == (["[MSG:Sleeping]"], "ok")
        report = report_fields(grbl.status())
        assert report["state"] == "Sleep"
        assert "A" not in report or "S" not in report["A"]  # the spindle off
        assert grbl.command("G0 X1")[1] == "error:9"
        assert grbl.command("$X")[1] == "error:9"
        grbl.realtime(0x18)
        said = grbl.expect_other(lambda line: "unlock" in line)
        assert said[-1] == "[MSG:'$H'|'$X' to unlock]" and "ALARM:3" not in said
        assert report_fields(grbl.status())["state"] == "Alarm"
        assert grbl.command("$X")[1] == "ok"
        assert grbl.command("G0 X1")[1] == "ok"
        assert mpos(grbl.wait_status(at_rest)) == (1.0, 0.0, 0.0)


def test_rst_hash_zeroes_the_work_offsets_and_stored_positions(free_door: FrontDoor) -> None:
    with client(free_door) as grbl:
        for line in ("G10 L2 P1 X5 Y6", "G10 L2 P3 Z-2", "G0 X7", "G28.1", "G92 X1"):
            assert grbl.command(line)[1] == "ok"
        assert grbl.command("$RST=#") == ([], "ok")
        lines, _ = grbl.command("$#")
        assert lines[:6] == [f"[G{54 + k}:0.000,0.000,0.000]" for k in range(6)]
        assert "[G28:0.000,0.000,0.000]" in lines
        assert "[G92:6.000,0.000,0.000]" in lines  # machine 12 read X1 over G54 X5: G92 stays
        assert free_door.machine.coordinates.offsets[0] == {}  # kept so for the next sender
        assert grbl.command("$RST=$")[1] == "error:3"  # the settings are the file


def test_bad_lines_are_answered_with_grbls_errors_and_nothing_moves(free_door: FrontDoor) -> None:
    before = free_door.steps()
    with client(free_door) as grbl:
        assert grbl.command("G1 X500 F100")[1] == "error:15"  # beyond the travel
        assert grbl.command("G1 X10")[1] == "error:22"  # no feed yet
        assert grbl.command("G2 X10 Y10 F100")[1] == "error:35"  # no I/J nor R
        assert grbl.command("G38.2 Z-100 F100")[1] == "error:15"  # a probe beyond the travel
        assert grbl.command("G81 X1 Y1 Z-1 R1")[1] == "error:20"
        assert grbl.command("G0 G1 X1")[1] == "error:21"
        assert grbl.command("G91 X1 X2")[1] == "error:25"
        assert grbl.command("$J=X5")[1] == "error:16"  # a jog needs F
        # nothing of the bad lines was kept, not even their modal words
        assert grbl.command("$G") == (["[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]"], "ok")
        assert at_rest(grbl.status())
    assert free_door.steps() == before


def test_check_mode_reads_lines_and_moves_nothing(free_door: FrontDoor) -> None:
    with client(free_door) as grbl:
        assert grbl.command("$C") == (["[MSG:Enabled]"], "ok")
        assert grbl.status().startswith("<Check")
        assert grbl.stream_counting(["G0 X10", "G1 X500 F100", "M6 T2", "G1 Y5 F100"]) == [
            "ok",
            "error:15",
            "ok",
            "ok",
        ]
        assert grbl.command("$C") == (["[MSG:Disabled]"], "ok")
        assert at_rest(grbl.status())
    assert free_door.steps() == (0, 0, 0)


def test_grbl_streamer_from_pypi_streams_the_cam_job(free_door: FrontDoor, tmp_path: Path) -> None:
    """An independent sender from PyPI (grbl-streamer, in the test extra), counting characters.
    Its threads write to the port and count the bytes in flight without a lock, so the job is started
    from its reading thread once its own $$ is answered, and its polling only after the job."""
    import grbl_streamer

    events: queue.Queue[tuple[str, tuple[object, ...]]] = queue.Queue()
    path = tmp_path / "cam.nc"
    path.write_text(CAM_JOB)
    end = file_end(tmp_path)
    booted = threading.Event()

    def callback(event: str, *data: object) -> None:
        if event == "on_boot":
            booted.set()
        elif event == "on_rx_buffer_percent" and booted.is_set() and streamer.buffer_size == 0:
            streamer.incremental_streaming = False
            streamer.load_file(str(path))
            streamer.job_run()
        events.put((event, data))

    def until(name: str, predicate: Callable[[tuple[object, ...]], bool] = lambda _: True) -> None:
        while True:
            event, data = events.get(timeout=20)
            assert event not in ("on_error", "on_alarm"), data
            if event == name and predicate(data):
                return

    streamer = grbl_streamer.GrblStreamer(callback)
    streamer.cnect(str(free_door.pty.path), 115200)
    try:
        until("on_boot")
        until("on_job_completed")
        streamer.poll_interval = 0.05
        streamer.poll_start()
        expected = tuple(round(x, 3) for x in CONFIG.to_mm(end))
        until("on_stateupdate", lambda data: data[0] == "Idle" and data[1] == expected)
    finally:
        streamer.disconnect()
    assert free_door.steps() == end


def test_a_status_request_in_the_middle_of_a_line_is_answered_at_once(free_door: FrontDoor) -> None:
    with client(free_door) as grbl:
        grbl.port.write(b"G0 X")
        grbl.port.write(b"?")
        assert REPORT.match(grbl.reports.get(timeout=20))  # before the line is complete
        assert grbl.answers.empty()
        grbl.port.write(b"2\n")
        assert grbl.answer() == "ok"
        assert mpos(grbl.wait_status(at_rest)) == (2.0, 0.0, 0.0)


def test_a_sender_that_reads_late_loses_no_answer(free_door: FrontDoor) -> None:
    """A sender busy elsewhere (a GUI redrawing) reads nothing for a while: what the front door has
    to say waits for it, whole and in order, rather than being dropped or cut where the
    pseudo-terminal is full."""
    lines = 300
    port = serial.serial_for_url(str(free_door.pty.path), timeout=5)
    try:
        assert port.read_until(b"for help]\r\n").endswith(b"for help]\r\n")  # the banner
        for _ in range(lines):  # far more than a pseudo-terminal holds, and nothing read
            port.write(b"?" * 10 + b"$G\n")
        text = b""
        while text.count(b"ok\r\n") < lines:
            chunk = port.read(max(1, port.in_waiting))
            assert chunk, f"an answer never came: {text.count(b'ok')} of {lines}"
            text += chunk
    finally:
        port.close()
    said = [line for line in text.decode().split("\r\n") if line and not line.startswith("Grbl")]
    reports = [line for line in said if line.startswith("<")]
    assert all(REPORT.match(report) for report in reports) and reports
    answers = [line for line in said if not line.startswith("<")]
    assert answers == ["[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]", "ok"] * lines
