"""The panels of the machine screen: positions, machine state, jog settings, job progress."""

from __future__ import annotations

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.widgets import ProgressBar, RichLog, Static

from ..config import MachineConfig
from ..jog import Jogger, JogMode
from ..machine import JobProgress, JobState
from ..protocol import IdentifyReply, State
from .session import Snapshot

STATE_STYLE = {
    State.IDLE: "green",
    State.RUNNING: "cyan",
    State.HOLDING: "yellow",
    State.ALARM: "bold red",
    State.STARVED: "yellow",
}
# A job's states that the board's own state does not tell (the board is IDLE while a job waits).
JOB_SHOWN = {
    JobState.PAUSED: "PAUSED",
    JobState.HELD: "FEED HOLD",
    JobState.STARVED: "STARVED",
    JobState.PROBING: "PROBING",
    JobState.RESUMING: "RESUMING",
}


class Panel(Static):
    """A Static redrawn often: plain Text (cheap to render), relaid out only when its height
    changes."""

    _lines = -1

    def show_text(self, text: Text) -> None:
        lines = len(text.plain.splitlines())
        self.update(text, layout=lines != self._lines)
        self._lines = lines


class PositionPanel(Panel):
    """Per axis: the work position (active system) and the machine position side by side, the steps,
    and the soft limits (machine coordinates)."""

    def show(self, config: MachineConfig, snapshot: Snapshot | None) -> None:
        system = snapshot.system if snapshot is not None else "work"
        text = Text(f"{'':<2}{system:>9}{'machine':>10}{'steps':>9}{'travel':>12}", style="dim")
        for i, axis in enumerate(config.axes):
            if snapshot is None:
                work, mm, steps = "—", "—", "—"
            else:
                work, mm = f"{snapshot.work_mm[i]:.3f}", f"{snapshot.position_mm[i]:.3f}"
                steps = str(snapshot.steps[i])
            text.append(f"\n{axis.name:<2}", style="bold")
            text.append(f"{work:>9}", style="bold")
            text.append(f"{mm:>10}")
            text.append(f"{steps:>9}")
            text.append(f"{f'{axis.travel_min:g}…{axis.travel_max:g}':>12}", style="dim")
        self.show_text(text)


class MachinePanel(Panel):
    """State, alarm, the rapid and spindle overrides (when not 100 %), queue fill, feed and link
    health."""

    def show(
        self,
        identity: IdentifyReply | None,
        snapshot: Snapshot | None,
        lost: str | None,
        job: JobState | None = None,
        position_lost: bool = False,
        overrides: tuple[int, int] = (100, 100),
    ) -> None:
        text = Text("state ", style="dim")
        if lost is not None:
            text.append("DISCONNECTED", style="bold white on red")
        elif snapshot is None or identity is None:
            text.append("connecting…", style="yellow")
        else:
            st = snapshot.status
            if job in JOB_SHOWN and st.state != State.ALARM:
                text.append(f"{JOB_SHOWN[job]} (job)", style="bold yellow")
            else:
                text.append(st.state.name, style=STATE_STYLE.get(st.state, ""))
            if st.alarm:
                text.append(f" {st.alarm.name}", style="bold red")
            elif (
                position_lost
            ):  # a hard limit or the abort button: cleared, but machine zero is gone
                text.append(" position lost: h homes", style="bold red")
            elif overrides != (100, 100):  # R: rapid, S: spindle, % (fits after FEED HOLD (job))
                text.append(f" R{overrides[0]} S{overrides[1]}", style="bold yellow")
            health = snapshot.link
            bad = (
                health["retransmits"]
                or health["errors"]
                or health["decode_errors"]
                or health["timeouts"]
            )
            text.append("\nqueue ", style="dim")
            text.append(f"{st.queue_fill}/{identity.queue_capacity}")
            text.append("  feed ", style="dim")
            text.append(f"{snapshot.feed:.0f} mm/min")
            text.append("\nlink  ", style="bold yellow" if bad else "green")  # yellow: degraded
            text.append(f"retries {health['retransmits']}  t/o {health['timeouts']}")
            text.append(f"\n      errors {health['errors']}  bad frames {health['decode_errors']}")
        self.show_text(text)


class JogPanel(Panel):
    """The jog mode, the X/Y and Z steps, the speed, and the distance still to go of the steps
    pressed."""

    def show(self, jogger: Jogger | None, console: bool = False) -> None:
        if jogger is None:
            self.show_text(Text(""))
            return
        if console:  # the jog keys type into the console line now
            self.show_text(
                Text.assemble(
                    ("jog keys off: ", "bold yellow"),
                    "the console (MDI) has the keys; Esc gives them back",
                )
            )
            return
        text = Text.assemble(("jog ", "dim"), (_jog_mode(jogger), "bold"))
        text.append_text(
            Text.assemble(
                ("  XY ", "dim"),
                f"{jogger.distance:g}",
                ("  Z ", "dim"),
                f"{jogger.z_distance:g} mm",
                ("  speed ", "dim"),
                f"{jogger.speed_fraction * 100:g} %",
            )
        )
        queued = jogger.queue.queued_mm()
        if queued:
            names = jogger.config.axes
            text.append("  to go ", style="dim")
            text.append(
                " ".join(f"{names[a].name}{mm:+g}" for a, mm in sorted(queued.items())),
                style="yellow",
            )
        else:
            text.append(f"  ({jogger.speed(0) * 60:.0f} mm/min)", style="dim")
        self.show_text(text)


def _jog_mode(jogger: Jogger) -> str:
    """The mode, and for continuous jogs what the terminal allows: a key held until its release, or
    (no release reported) a tap that moves a little and repeats that go on."""
    if jogger.mode != JogMode.CONTINUOUS:
        return "INCREMENTAL"
    return "CONTINUOUS (taps: no key-up)" if jogger.taps else "CONTINUOUS (to key-up)"


class JobPanel(Horizontal):
    """The running job: file, line (and its text), feed override, progress, time left."""

    def compose(self) -> ComposeResult:
        yield Panel("no job  (o opens one, : types a line)", id="job-label")
        bar = ProgressBar(total=1, show_eta=False, id="job-progress")
        bar.display = False
        yield bar

    def show(
        self,
        name: str | None,
        progress: JobProgress | None,
        outcome: str = "",
        source: str = "",
        pause: str = "",
        feed: int = 100,
    ) -> None:
        label = self.query_one("#job-label", Panel)
        bar = self.query_one("#job-progress", ProgressBar)
        bar.display = name is not None
        if name is None:
            label.show_text(Text(outcome or "no job  (o opens one, : types a line)"))
            return
        if progress is None:
            label.show_text(Text(f"{name}: {outcome}"))
            return
        text = Text(f"{name} ", style="bold")
        if progress.paused_at is not None:  # what it waits for and the key first: it must show
            held = progress.state is JobState.HELD
            text.append(
                f"{'FEED HOLD' if held else 'PAUSED'} at {progress.paused_at}"
                f"{': ' + pause if pause and not held else ''}: g goes on",
                style="yellow",
            )
        else:
            text.append(f"{progress.line}", style="bold")
            if source:
                text.append(f" {source.strip()}", style="cyan")
        if feed != 100 or progress.paused_at is None:
            text.append(f"  feed {feed} %", style="bold yellow" if feed != 100 else "dim")
        text.append(f"  {progress.seconds_left:.1f} s left", style="dim")
        if progress.paused_at is None and (
            progress.state is JobState.STARVED or progress.starvations
        ):
            text.append(f"  ran dry {progress.starvations}×, went on", style="yellow")
        label.show_text(text)
        bar.update(total=max(progress.total, 1), progress=progress.done)


class MessageLog(RichLog, can_focus=False):
    """What happened, newest last; not focusable, so every key reaches the jog bindings."""
