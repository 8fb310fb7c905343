#!/usr/bin/env python3
"""The AVR firmware's figures, measured in simavr on the real binary:
step-interrupt cycles by stepping axes, the highest tick rate at which three
axes stepping every tick still leave the CPU to take 1,000 segments/s (and
the highest at which beginning a HOLD loses no tick either), the
segments/s the board takes while stepping, the main loop's cycles per
segment, the CPU spent at rest, flash, RAM and stack, beside GRBL's and Klipper's published
figures for the same 16 MHz chip.

    python3 tests/bench/bench_avr.py [--quick]

Prints figures only; nothing here is a pass/fail test. Builds variants of
the firmware under build/bench-avr/ (each tick rate is a compile-time setting).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests" / "simavr"))

import avr_figures  # noqa: E402
import avr_scenarios  # noqa: E402
import avr_sim  # noqa: E402
from quadstep.kernel.motion import AxisMove
from quadstep.protocol import Config, Identify, Segment, State, Status, encode
from quadstep.kernel.fixed import D, N_MAX

F_CPU = avr_sim.F_CPU
WORK = avr_sim.BUILD / "bench-avr"
# Tick rates that divide 16 MHz exactly (the firmware insists on an exact rate).
TICK_RATES = [20_000, 25_000, 31_250, 32_000, 40_000, 50_000]
TARGET_SEGMENTS = 1_000
DEFAULT_BAUD = 500_000
# Published by the projects themselves, not measured here: each with where it is published.
PEERS = [
    ("GRBL 1.1, ATmega328P @ 16 MHz", "about 30 kHz step rate, 115200 baud",
     "GRBL's README (github.com/gnea/grbl), its stated tested limit"),
    ("Klipper, 16 MHz AVR (simulavr)", "157K steps/s one stepper, 99K steps/s total with three, 250000 baud",
     "Klipper's docs/Benchmarks.md, AVR step rate table"),
]


@dataclass(frozen=True)
class Variant:
    tick_hz: int
    baud: int
    defaults: bool = False  # each board at its own default rate (the Mega's differs)

    @property
    def build(self) -> Path:
        return WORK / ("defaults" if self.defaults else f"tick{self.tick_hz}-baud{self.baud}")

    @property
    def elf(self) -> Path:
        return self.build / "avr" / "uno.elf"


def line_baud(tick_hz: int) -> int:
    """The default baud rate where the tick can serve it (at most two bytes per tick, uart.c), else the
    next slower: 500000 baud carries 1,850 segment frames a second, more than any rate here takes."""
    return next(b for b in (DEFAULT_BAUD, 250_000, 115_200) if b // 10 <= 2 * tick_hz)


def make(*args: str) -> str:
    result = subprocess.run(["make", "-C", str(REPO), "-s", *args], capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"make {' '.join(args)} failed:\n{result.stdout[-2000:]}{result.stderr[-2000:]}")
    return result.stdout


def build(v: Variant) -> Variant:
    rates = [] if v.defaults else [f"AVR_TICK_HZ={v.tick_hz}"]
    make("firmware", f"BUILD={v.build}", *rates, f"AVR_BAUD={v.baud}")
    return v


def three_axes_every_tick(n: int, count: int) -> bytes:
    """A dwell (so the queue fills first, as a host would start a job), then
    count segments of n ticks, every axis at one step per tick, the last one stopping."""
    b = avr_scenarios.ChainBuilder(3)
    segments = [avr_scenarios.dwell()]
    segments += [b.segment(n, {a: (-1 if a == 1 else 1, D, D) for a in range(3)}) for _ in range(count - 1)]
    segments.append(b.segment(n, {a: (-1 if a == 1 else 1, D, 0) for a in range(3)}))
    return b"".join(encode(s, i & 0xFF) for i, s in enumerate(segments))


def feed(v: Variant, frames: bytes, name: str, seconds: float, profile: bool = False, board: str = "uno") -> dict:
    out = avr_sim.Outputs(v.build / f"{name}-trace.csv", v.build / f"{name}-edges.csv", v.build / f"{name}.json")
    elf = v.build / "avr" / f"{board}.elf"
    args = [*avr_sim.harness(board, elf), "--feed",
            str(v.build / f"{name}.feed"), "--max-cycles", str(int(seconds * F_CPU)), "--stats", str(out.stats)]
    if profile:
        args += ["--profile", str(v.build / f"{name}-profile.csv")]
    (v.build / f"{name}.feed").write_bytes(frames)
    subprocess.run(args, capture_output=True, check=True)
    return out.load_stats()


def clean(stats: dict) -> bool:
    """Every frame accepted in turn, nothing lost, no alarm, no tick lost or more than a quarter tick late."""
    f, m = stats["feed"], stats["motion"]
    return (f["accepted"] == f["frames"] and f["alarms"] == 0 and f["errors"] == 0 and f["gap"] == 0
            and stats["wire"]["lost"] == 0 and m["ticks_missed"] == 0
            and m["tick_late_max"] <= stats["tick_cycles"] // 4)


def main_loop_cycles(stats: dict) -> float:
    """Cycles the main loop was busy (neither asleep nor in the step interrupt), per frame."""
    isr = stats["isr"]["timer"]
    busy = stats["cycles"] - stats["sleep_cycles"] - isr["count"] * isr["mean"]
    return busy / stats["feed"]["frames"]


def sustains(v: Variant, n: int, seconds: float) -> tuple[bool, dict]:
    """Segments of n ticks, three axes stepping every tick, for about `seconds` of motion."""
    count = max(40, int(seconds * v.tick_hz / n))
    motion = (count * n + N_MAX) / v.tick_hz
    stats = feed(v, three_axes_every_tick(n, count), f"n{n}", motion * 1.5 + 0.2)
    return clean(stats), stats


def max_segment_rate(v: Variant, seconds: float) -> tuple[float, dict]:
    """The most segments/s the board takes while every axis steps every tick:
    the shortest segment length it keeps up with (bisection on n)."""
    lo, hi = 1, N_MAX  # hi: known good (checked below), lo: known bad
    ok, stats = sustains(v, hi, seconds)
    if not ok:
        return 0.0, stats
    best = stats
    while hi - lo > 1:
        mid = (lo + hi) // 2
        ok, stats = sustains(v, mid, seconds)
        if ok:
            hi, best = mid, stats
        else:
            lo = mid
    return v.tick_hz / hi, best


def isr_table(v: Variant) -> dict:
    """Stats of a stream that steps 0, 1, 2 and 3 axes in various ticks."""
    b = avr_scenarios.ChainBuilder(3)
    segments = [avr_scenarios.dwell(200)]
    for speeds in [(D, 0, 0), (D, D, 0), (D, D, D), (D // 2, D // 3, D // 5), (1000, 3000, 2000)]:
        segments.append(b.segment(1000, {a: (1, s, s) for a, s in enumerate(speeds) if s}))
    segments.append(b.segment(500, {0: (1, 1000, 0), 1: (1, 3000, 0), 2: (1, 2000, 0)}))
    frames = b"".join(encode(s, i) for i, s in enumerate(segments))
    return feed(v, frames, "isr", 1.0, profile=True)


def status_while_moving(v: Variant) -> dict:
    """Three axes moving while the host asks for STATUS every few milliseconds
    (no flow control needed: three segments)."""
    b = avr_scenarios.ChainBuilder(3)
    data = b"\x00" + encode(Identify(), 0)
    for i in range(3):
        data += encode(b.segment(N_MAX, {a: (1, D // 2, D // 2 if i < 2 else 0) for a in range(3)}), i)
    data += b"".join(encode(Status(), 1) + b"\x00" * 40 for _ in range(20))
    out = avr_sim.Outputs(v.build / "status-trace.csv", v.build / "status-edges.csv", v.build / "status.json")
    path = v.build / "status.input"
    path.write_bytes(data)
    subprocess.run([*avr_sim.harness("uno", v.elf), "--input", str(path),
                    "--output", "/dev/null", "--exit-when-idle", "--max-cycles", str(F_CPU), *out.args()],
                   capture_output=True, check=True)
    return out.load_stats()


HOLD_JOBS = (15, 10)  # segments queued before the HOLDs: its moments fall differently in each


def hold_begin(v: Variant) -> tuple[int, int, int, int]:
    """HOLDs begun at many moments of a 300-tick segment (whose rescale multiplies, the costliest case),
    three axes near full speed, behind jobs of two lengths: the HOLDs the board answered (the others'
    bytes found its receive ring full: avr_scenarios.hold_answered, and its queue ran dry instead), and
    over those the longest the main loop held the tick off (beginning the hold), the longest step
    interrupt and the ticks lost."""
    lock = isr = lost = answered = 0
    for segments in HOLD_JOBS:
        for pad in range(0, 200, 13):  # the HOLD arrives at a different phase of the tick each time
            path, replies = v.build / "hold.input", v.build / "hold-replies.bin"
            path.write_bytes(avr_scenarios.hold_from_full_speed(3, pad, segments))
            out = avr_sim.Outputs(v.build / "hold-trace.csv", v.build / "hold-edges.csv", v.build / "hold.json")
            subprocess.run([*avr_sim.harness("uno", v.elf), "--input", str(path), "--output", str(replies),
                            "--max-cycles", str(F_CPU // 4), *out.args()], capture_output=True, check=True)
            if not avr_scenarios.hold_answered(replies.read_bytes(), 3):
                continue
            st = out.load_stats()
            lock = max(lock, st["irq_off"]["max"])
            isr = max(isr, st["isr"]["timer"]["max"])
            lost += st["motion"]["ticks_missed"]
            answered += 1
    return lock, isr, lost, answered


def underrun_stops(v: Variant) -> dict[str, dict[str, int]]:
    """Underruns, three axes near full speed when the queue runs dry: behind quadratic segments of 14
    lengths, and behind cubic ones in jerk phases of 9 lengths. The longest step interrupt (the stop planned
    and begun in the tick that finds the queue dry) and the timer periods lost over them all."""
    jobs = {
        "quadratic": [[Segment(n=n, axes=tuple(AxisMove(axis=a, direction=1, v0=D - 1, vn=D - 1, r=0)
                                               for a in range(3)))] * 3 for n in range(300, 340, 3)],
        "cubic": [avr_scenarios.jerk_phases(n, 6)[:-1] for n in range(60, 120, 7)],  # no stop at the end
    }
    figures = {}
    for kind, segment_lists in jobs.items():
        isr = lost = 0
        for i, segments in enumerate(segment_lists):
            out = avr_sim.Outputs.in_dir(v.build, f"underrun-{kind}-{i}")
            job = b"\x00" + b"".join(encode(s, k) for k, s in enumerate(segments))
            st = avr_sim.run_input(job, out, v.build / "underrun-replies.bin", elf=v.elf, max_cycles=F_CPU // 4,
                                   until_idle=False)
            assert st["motion"]["state"] == State.HOLDING, st["motion"]  # the stop under way
            isr = max(isr, st["isr"]["timer"]["max"])
            lost += st["motion"]["ticks_missed"]
        figures[kind] = {"underruns": len(segment_lists), "longest_tick": isr, "periods_lost": lost}
    return figures


def hold_tick(work: Path, elf: Path, board: str, axes: int) -> float:
    """The step interrupt's mean cycles in a hold's ticks, every axis decelerating from near full speed:
    two runs that end 1/16 s and 1/8 s in, both inside the hold, so that the ticks before it cancel out."""
    path = work / f"hold-tick-{board}.input"
    path.write_bytes(avr_scenarios.hold_from_full_speed(axes))
    timer = []
    for cycles in (F_CPU // 16, F_CPU // 8):
        out = avr_sim.Outputs.in_dir(work, f"hold-tick-{board}-{cycles}")
        subprocess.run([*avr_sim.harness(board, elf), "--input", str(path), "--max-cycles", str(cycles), *out.args()],
                       capture_output=True, check=True)
        st = out.load_stats()
        assert st["motion"]["state"] == State.HOLDING and st["motion"]["ticks_missed"] == 0, st["motion"]
        timer.append(st["isr"]["timer"])
    return (timer[1]["total"] - timer[0]["total"]) / (timer[1]["count"] - timer[0]["count"])


def at_rest(v: Variant, seconds: float, debounce: int | None = None) -> dict:
    """Nothing queued for `seconds`; with `debounce`, every input debounced that many ticks (a
    CONFIG) and the cycle start button, pressed at power-up, released a third of the way in: one
    window of `debounce` ticks."""
    name = "rest" if debounce is None else f"rest-debounce{debounce}"
    args = [*avr_sim.harness("uno", v.elf), "--output", str(v.build / f"{name}-replies.bin"),
            "--max-cycles", str(int(seconds * F_CPU))]
    frames = b""
    if debounce is not None:
        config = Config(invert=0, enabled=0x0FFF, hard_limits=0, debounce=(debounce,) * 12,
                        hold_decel=(3000, 3000, 3000, 0))
        frames = encode(config, 0)
        machine = v.build / f"{name}.toml"
        machine.write_text(f'[[press]]\ninput = "cycle_start"\nat_tick = 0\n'
                           f'ticks = {int(seconds * v.tick_hz / 3)}\n')
        args += ["--machine", str(machine)]
    (v.build / f"{name}.input").write_bytes(frames)
    out = avr_sim.Outputs(v.build / f"{name}-trace.csv", v.build / f"{name}-edges.csv",
                          v.build / f"{name}.json")
    subprocess.run([*args, "--input", str(v.build / f"{name}.input"), *out.args()],
                   capture_output=True, check=True)
    return out.load_stats()


def print_at_rest(v: Variant, seconds: float) -> None:
    st = at_rest(v, seconds)
    cycles, isr = st["cycles"], st["isr"]["timer"]
    awake = cycles - st["sleep_cycles"]
    print(f"\nat rest (nothing queued, no hold, no input debounced), {seconds:g} s at "
          f"{v.tick_hz} Hz:")
    print(f"  step interrupt {isr['total'] * F_CPU / cycles:,.0f} cycles/s = "
          f"{100 * isr['total'] / cycles:.1f} % of the CPU ({isr['count']} ticks, {isr['min']} "
          f"cycles each but the first); awake in all {100 * awake / cycles:.1f} % "
          f"(main loop {100 * (awake - isr['total']) / cycles:.1f} %)")
    window = 200
    quick, slow = at_rest(v, seconds, debounce=0), at_rest(v, seconds, debounce=window)
    extra = slow["isr"]["timer"]["total"] - quick["isr"]["timer"]["total"]
    per_tick = isr["min"] + extra / (window - 1)
    print(f"  with a debounce in progress: {per_tick:.0f} cycles a tick = "
          f"{100 * per_tick / st['tick_cycles']:.0f} % of the CPU while its window is open "
          "(the whole tick and the inputs' rare path, every tick)")


def sizes() -> dict[str, tuple[int, int]]:
    out = {}
    for line in make("firmware").splitlines():
        parts = line.split()
        if len(parts) >= 8 and parts[2] == "flash":
            out[parts[0]] = (int(parts[3]), int(parts[6]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs, fewer tick rates")
    args = parser.parse_args()
    seconds = 0.2 if args.quick else 1.0
    make("firmware", "harness")
    default = Variant(avr_sim.avr_define("QS_TICK_HZ"), avr_sim.avr_define("QS_BAUD"), defaults=True)
    build(default)

    print("AVR firmware on the ATmega328P (Uno, 3 axes) at 16 MHz, measured in simavr")
    print(f"  defaults: Uno {default.tick_hz} Hz, Mega {avr_sim.avr_define('QS_TICK_HZ', 'mega')} Hz, "
          f"{default.baud} baud")
    figures: dict = {"tick_hz": default.tick_hz, "baud": default.baud, "boards": {}, "rates": {}}
    for board, (flash, ram) in sizes().items():
        figures["boards"][board] = {"flash": flash, "ram": ram}
        chip = {"uno": "ATmega328P: 32256 flash / 2048 RAM", "uno-laser": "ATmega328P: 32256 flash / 2048 RAM",
                "mega": "ATmega2560: 253952 flash / 8192 RAM"}[board]
        print(f"  {board:9} flash {flash:6} bytes, static RAM {ram:5} bytes   ({chip})")

    stats = isr_table(default)
    print(f"\nstep interrupt at {default.tick_hz} Hz ({stats['tick_cycles']} cycles per tick), "
          "cycles from interrupt response to the end of RETI:")
    print(f"  {'ticks':>16} {'count':>7} {'min':>5} {'mean':>7} {'max':>5}   share of a tick (mean)")
    bins = [("idle", stats["tick_isr"]["idle"])] + [(f"{k} axes stepping", stats["tick_isr"][f"steps{k}"])
                                                    for k in range(4)]
    figures["isr"] = {name: {"min": b["min"], "mean": round(b["mean"], 1), "max": b["max"]}
                      for name, b in bins if b["count"]}
    for name, b in bins:
        if b["count"]:
            print(f"  {name:>16} {b['count']:7} {b['min']:5} {b['mean']:7.1f} {b['max']:5}   "
                  f"{100 * b['mean'] / stats['tick_cycles']:5.1f} %")
    stack = stats["stack"]
    print(f"  stack high-water mark {stack['max_bytes']} bytes; "
          f"{stack['deepest'] - stack['static_end']} bytes free above static data")
    m = stats["motion"]
    print(f"  step edges: shortest pulse {m['min_pulse']} cycles; tick entered at most {m['tick_late_max']} cycles "
          f"after its timer match, {m['ticks_missed']} ticks missed; interrupts held off by the main loop "
          f"at most {stats['irq_off']['max']} cycles ({stats['irq_off']['from'] or '-'})")
    out = avr_sim.Outputs.in_dir(default.build, "stress")
    st = avr_sim.run_input(avr_scenarios.every_message_kind(3), out, default.build / "stress-replies.bin",
                           elf=default.elf)
    figures["stack"] = {"max_bytes": st["stack"]["max_bytes"],
                        "spare": st["stack"]["deepest"] - st["stack"]["static_end"]}
    print(f"  stack high-water mark under every message kind while moving: {st['stack']['max_bytes']} bytes; "
          f"{st['stack']['deepest'] - st['stack']['static_end']} bytes free above static data")
    out = avr_sim.Outputs.in_dir(default.build, "hold-status")
    st = avr_sim.run_input(avr_scenarios.status_during_a_hold(3), out, default.build / "hold-status-replies.bin",
                           elf=default.elf, max_cycles=F_CPU // 2, until_idle=False)
    figures["stack"]["status_in_a_hold"] = {"max_bytes": st["stack"]["max_bytes"],
                                            "spare": st["stack"]["deepest"] - st["stack"]["static_end"]}
    print(f"  ... with STATUS requests during a hold: {st['stack']['max_bytes']} bytes; "
          f"{st['stack']['deepest'] - st['stack']['static_end']} bytes free above static data")
    st = status_while_moving(default)
    print(f"  with STATUS requests while moving: interrupts held off at most {st['irq_off']['max']} cycles "
          f"({st['irq_off']['from'] or '-'}), a tick entered up to {st['motion']['tick_late_max']} cycles late")
    profile = (default.build / "isr-profile.csv").read_text().splitlines()[1:8]
    busy = stats["cycles"] - stats["sleep_cycles"]
    print("  where the busy cycles went: " + ", ".join(
        f"{name} {100 * int(c) / busy:.1f} %" for name, c in (row.split(",") for row in profile)))

    print_at_rest(default, seconds)

    b4 = avr_scenarios.ChainBuilder(4)
    four = [avr_scenarios.dwell(200)] + [b4.segment(1000, {a: (1, D, D) for a in range(4)}) for _ in range(3)]
    four.append(b4.segment(1000, {a: (1, D, 0) for a in range(4)}))
    st = feed(default, b"".join(encode(s, i) for i, s in enumerate(four)), "mega4", 1.0, board="mega")
    m4 = st["tick_isr"]["steps4"]
    print(f"  Mega ({st['tick_cycles']} cycles a tick), 4 axes stepping: {m4['count']} ticks, min {m4['min']}, "
          f"mean {m4['mean']:.1f}, max {m4['max']} cycles")
    held = {"uno": round(hold_tick(default.build, default.elf, "uno", 3), 1),
            "mega": round(hold_tick(default.build, default.build / "avr" / "mega.elf", "mega", 4), 1)}
    figures["hold_tick"] = held
    print(f"  a hold's tick, every axis decelerating from near full speed: {held['uno']} cycles with 3 axes (Uno), "
          f"{held['mega']} with 4 (Mega)")
    stops = figures["underrun"] = underrun_stops(default)
    for kind, u in stops.items():
        print(f"  an underrun's stop behind {kind} segments, three axes near full speed: longest tick "
              f"{u['longest_tick']} cycles, {u['periods_lost']} timer periods lost in {u['underruns']} underruns")

    rates = sorted({default.tick_hz, 40_000, 50_000}) if args.quick else TICK_RATES
    print(f"\nsegments/s the board takes while three axes step every tick (flow-controlled, "
          f"{seconds:g} s of motion after a dwell that fills the queue; no tick lost or over a quarter tick late):")
    print(f"  {'tick rate':>10} {'baud':>8} {'steps/s total':>14} {'segments/s':>11}   "
          f"step interrupt (3 axes)        main loop per segment   beginning a HOLD: lock, tick, ticks lost")
    best = best_with_holds = None
    for tick in rates:
        v = build(Variant(tick, line_baud(tick)))
        rate, st = max_segment_rate(v, seconds)
        isr = st["tick_isr"]["steps3"]
        lock, first, lost, answered = hold_begin(v)
        figures["rates"][str(tick)] = {
            "baud": v.baud, "segments_per_s": round(rate), "isr_3_axes_mean": round(isr["mean"]),
            "main_loop_per_segment": round(main_loop_cycles(st)),
            "hold": {"lock": lock, "first_tick": first, "periods_lost": lost, "answered": answered,
                     "holds": 16 * len(HOLD_JOBS)}}
        print(f"  {tick:>7} Hz {v.baud:>8} {3 * tick:>14,} {rate:>11,.0f}   "
              f"{isr['mean']:.0f} of {st['tick_cycles']} cycles (max {isr['max']})   "
              f"{main_loop_cycles(st):>9,.0f} cycles       {lock}, {first} cycles, {lost} lost "
              f"in the {answered} of {16 * len(HOLD_JOBS)} HOLDs the board took")
        if rate >= TARGET_SEGMENTS:
            best = v
            if lost == 0 and answered == 16 * len(HOLD_JOBS):
                best_with_holds = v
    if best is None:
        print(f"  no tick rate tried takes {TARGET_SEGMENTS} segments/s")
    else:
        print(f"  highest tick rate taking {TARGET_SEGMENTS} segments/s: {best.tick_hz} Hz "
              f"= {3 * best.tick_hz:,} steps/s in total")
    if best_with_holds is not None:
        print(f"  ... and beginning a HOLD without losing a tick: {best_with_holds.tick_hz} Hz "
              f"= {3 * best_with_holds.tick_hz:,} steps/s in total")

    v = default
    b = avr_scenarios.ChainBuilder(3)
    # One window of one-tick, zero-speed 3-axis segments: the rate at which
    # frames are taken when running them costs nothing (one window only: a
    # line kept full at this rate outruns the receive ring, see docs/AVR.md).
    quiet = [b.segment(1, {a: (1, 0, 0) for a in range(3)}) for _ in range(14)]
    st = feed(v, b"".join(encode(s, i & 0xFF) for i, s in enumerate(quiet)), "idle", 1.0)
    f = st["feed"]
    span = (f["last_accept_cycle"] - f["first_accept_cycle"]) / F_CPU
    print(f"segments/s at {v.tick_hz} Hz, {v.baud} baud, when running them costs nothing "
          f"(a window of 3-axis frames): {(f['accepted'] - 1) / span:,.0f} ({f['errors']} errors)")

    print("\npeers on the same chip (published figures, not measured here):")
    for name, figure, source in PEERS:
        print(f"  {name}: {figure} (source: {source})")
    figures["idle_segments_per_s"] = round((f["accepted"] - 1) / span)
    avr_figures.record("avr" if not args.quick else "avr_quick", figures)
    print(f"\nfigures written to {avr_figures.FIGURES.relative_to(REPO)}")


if __name__ == "__main__":
    main()
