"""The key map: arrows jog X/Y, Page Up/Down jog Z (as in bCNC and most senders), number keys pick
the step."""

from __future__ import annotations

from collections.abc import Sequence

from textual.binding import Binding, BindingType

from ..macro_settings import Macro

JOG = Binding.Group("jog", compact=True)
STEP = Binding.Group("step", compact=True)
SPEED = Binding.Group("speed", compact=True)
STOP = Binding.Group("stop", compact=True)

JOG_KEYS = (
    ("left", 0, -1, "←", "X−"),
    ("right", 0, 1, "→", "X+"),
    ("up", 1, 1, "↑", "Y+"),
    ("down", 1, -1, "↓", "Y−"),
    ("pageup", 2, 1, "PgUp", "Z+"),
    ("pagedown", 2, -1, "PgDn", "Z−"),
)


def bindings(step_presets: int) -> list[BindingType]:
    """Every binding of the machine screen, in the order the footer and the help screen show
    them."""
    keys: list[BindingType] = [
        Binding(key, f"jog({axis}, {direction})", label, key_display=display, group=JOG)
        for key, axis, direction, display, label in JOG_KEYS
    ]
    keys += [
        Binding(str(i + 1), f"step_preset({i})", "step", group=STEP)
        for i in range(min(step_presets, 9))
    ]
    keys += [
        Binding("left_square_bracket", "z_step(-1)", "Z step down", key_display="[", show=False),
        Binding("right_square_bracket", "z_step(1)", "Z step up", key_display="]", show=False),
        Binding("minus", "speed(-1)", "slower", key_display="-", group=SPEED),
        Binding("plus,equals_sign", "speed(1)", "faster", key_display="+", group=SPEED),
        Binding("c", "toggle_mode", "cont/incr"),
        Binding("space", "space", "hold/resume", key_display="Space", group=STOP),
        Binding("escape", "halt", "stop", key_display="Esc", group=STOP),
        Binding("x", "zero(0)", "zero X", show=False),
        Binding("y", "zero(1)", "zero Y", show=False),
        Binding("z", "zero(2)", "zero Z", show=False),
        Binding("a", "zero(3)", "zero A", show=False),
        Binding("0", "zero_all", "zero all"),
        Binding("o", "open_job", "job"),
        Binding("enter", "run_preview", "run the job shown", show=False),
        Binding("colon", "console", "MDI", key_display=":"),
        Binding("v", "toggle_view", "fit path", show=False),
        Binding("h", "home", "home", show=False),
        Binding("p", "probe('38.2')", "probe Z", show=False),
        Binding("P", "probe('38.4')", "probe off", show=False),
        Binding("t", "touch_off", "touch-off", show=False),
        Binding("b", "backlash", "backlash", show=False),
        Binding("g", "resume", "go on", show=False),
        Binding("R", "resume_kept", "resume the stopped job", show=False),
        Binding("asterisk", "feed_override(0)", "feed 100 %", key_display="*", show=False),
        Binding("r", "rapid_override", "rapid 100/50/25 %", show=False),
        Binding(
            "less_than_sign", "spindle_override(-1)", "spindle −10 %", key_display="<", show=False
        ),
        Binding(
            "greater_than_sign", "spindle_override(1)", "spindle +10 %", key_display=">", show=False
        ),
        Binding("ctrl+x", "reset", "STOP now", show=False),
        Binding("ctrl+r", "reconnect", "reconnect", show=False),
        Binding("question_mark,f1", "help", "help", key_display="?"),
    ]
    return keys


def taken_keys() -> set[str]:
    """The keys the machine screen uses itself: a macro may not take them."""
    taken = set()
    for binding in bindings(9):
        assert isinstance(binding, Binding)
        taken.update(binding.key.split(","))
    return taken | {"colon", "t"}


def macro_key_problems(macros: Sequence[Macro], source: str) -> list[str]:
    taken = taken_keys()
    return [
        f"{source}: macros[{i}] ({m.name}): key {m.key!r} is the TUI's own"
        for i, m in enumerate(macros)
        if m.key in taken
    ]


HELP = """\
[b]Jogging[/b]
  ← →            X− / X+
  ↑ ↓            Y+ / Y−
  PgUp PgDn      Z+ / Z−
  1 … {steps}          X/Y step: {step_list} mm
  [ ]            Z step smaller / larger (the same sizes)
  - +            speed: {speed_list} % of each axis's max
  c              switch incremental ↔ continuous

  Incremental: one press moves exactly the step size. A held key's
  repeats beyond what runs within {queue:g} s are dropped; "to go" shows the
  distance still to move.
  Continuous: the axis moves while the key is held and decelerates to rest
  {first:g} s after the press if the key does not repeat, {repeat:g} s after
  the last repeat, or at once on Space/Esc. It never passes a soft limit:
  it comes to rest exactly on it.

[b]Stopping[/b]
  Space, Esc     controlled stop (HOLD): decelerate to rest, drop the rest
  Ctrl+X         immediate STOP (no deceleration); also clears an alarm

[b]Position[/b]
  x y z a        make the current position of that axis 0 in the active
                 work coordinates (G54 … G59: a work offset, kept)
  0              the same on every axis
  Machine coordinates (the steps) never change: the soft limits are the
  configured travel in machine coordinates.

[b]Homing and probing[/b]
  h              home: each axis with \\[axes.homing], Z first (seek, back
                 off, locate slowly, pull off); machine zero from the latch
  p              G38.2: Z down toward its travel_min at 1 mm/s until the
                 probe touches (a touch plate); the contact is logged
  P              G38.4: Z up until the probe lets go
  t              touch-off: Z on a plate (its thickness asked; a fast
                 touch, back off, a slow one; zero on the surface below),
                 an edge, a corner (tool diameter asked), a bore's or a
                 boss's centre; each sets the work zero. Esc stops it
  b              backlash: measure an axis's (probe or switch, k tries) or
                 use a dial indicator (d); written to the configuration
                 after a confirm

[b]Jobs[/b]
  o              open a G-code or move file (→ completes the path): it is
                 planned whole and shown (path, box, time, warnings);
                 Enter runs it, Esc drops it. Nothing moves before Enter,
                 nor at all if any line is wrong
  :              console (MDI): type a G-code line, Enter runs it (checked
                 first), ↑ ↓ earlier lines, Esc back to the jog keys
  v              path view: fit the job ↔ the whole travel (cuts solid,
                 rapids dotted, + the work zero, ● the tool)
  g              go on after a pause (M0, or a tool change: jog, zero,
                 probe, touch off there first) or a feed hold
  Space          feed hold (keeps the rest of the job); g goes on (Space
                 again too)
  R              resume the job that stopped before its end (the host
                 crashed or quit, the port dropped): offered on connect
  Esc            stop the job (HOLD)
  - + *          while a job runs: feed override −10 % / +10 % / back to
                 100 % (10 … 200 %; rapids keep their speed), shown on the
                 job line. It applies to what is not yet sent: from the
                 first move boundary after the motion queued on the board
                 (at most host_timeout + 0.5 s: 1.5 s by default)
  r              rapid override: 100 → 50 → 25 → 100 % (moves without a
                 feed; not in laser mode, where they keep the laser off)
  < >            spindle (laser power) override −10 % / +10 % (10 … 200 %)
                 Both apply to a running job as the feed override does, and
                 to what runs next; shown on the machine panel's state line

[b]Connection[/b]
  Ctrl+R         reconnect after the link was lost
  ?, F1          this help (↑ ↓ PgUp PgDn scroll);  Esc or q closes it
  Ctrl+Q         quit (brings any motion to rest first)
  Ctrl+C         the same, and the command exits with 130 (interrupted)
"""

# The screen's bottom line: the main keys, within 80 columns; another while a job runs.
KEY_LINE = (
    "[b]←→↑↓ PgUp/Dn[/b] jog [b]1-4 \\[ ][/b] XY/Z step [b]-+[/b] speed [b]c[/b] mode "
    "[b]Esc[/b] stop [b]:[/b] MDI [b]o[/b] job [b]?[/b] help"
)
JOB_KEY_LINE = (
    "[b]Space[/b] hold  [b]g[/b] go on  [b]Esc[/b] stop  [b]- + *[/b] feed  [b]r[/b] rapid  "
    "[b]< >[/b] spindle  [b]?[/b] help"
)
CONSOLE_KEY_LINE = (
    "[b reverse] MDI has the keys [/] [b]Enter[/b] runs the line  [b]↑ ↓[/b] history  "
    "[b]Esc[/b] back to jogging"
)
