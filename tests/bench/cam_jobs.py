"""Three CAM-shaped G-code jobs, made here so the wire benchmark has the shapes of real ones without huge files.

- pocket: a 40,000-line adaptive-style pocket (Fusion-like output: modal G1 X Y lines of 0.2–3 mm, G2/G3 arcs
  at every turn, layers 0.5 mm deeper with a ramped entry, F words on changes);
- engraving: a 16,000-line V-carve of short moves (0.05–0.6 mm polylines in X Y Z, plunges and lifts);
- four_axis: a 51,000-line rotary job on X Y Z A (short moves, long cruises along X with A turning, arcs).

Every number is deterministic (a fixed seed), every line is what a CAM post-processor writes (3 decimals,
words omitted when modal).
"""

from __future__ import annotations

import math
import random


def _num(x: float) -> str:
    text = f"{x:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


class _Writer:
    def __init__(self, axes: str) -> None:
        self.lines: list[str] = []
        self.axes = axes
        self.at = {a: math.nan for a in axes}
        self.mode = ""
        self.feed = math.nan

    def move(self, mode: str, feed: float | None = None, **target: float) -> None:
        words = [mode] if mode != self.mode else []
        for a in self.axes:
            if a in target and not math.isclose(target[a], self.at[a], abs_tol=5e-4):
                words.append(f"{a}{_num(target[a])}")
                self.at[a] = round(target[a], 3)
        if feed is not None and feed != self.feed:
            words.append(f"F{_num(feed)}")
            self.feed = feed
        if len(words) > (mode != self.mode):
            self.mode = mode
            self.lines.append(" ".join(words))

    def arc(self, mode: str, x: float, y: float, i: float, j: float) -> None:
        words = [mode] if mode != self.mode else []
        words += [f"X{_num(x)}", f"Y{_num(y)}", f"I{_num(i)}", f"J{_num(j)}"]
        self.mode = mode
        self.at["X"], self.at["Y"] = round(x, 3), round(y, 3)
        self.lines.append(" ".join(words))

    def text(self) -> str:
        return "\n".join(self.lines) + "\n"


def _header(w: _Writer, title: str) -> None:
    w.lines += ["%", f"(quadstep benchmark: {title})", "G90 G94 G17", "G21", "G54", "S12000 M3"]


def _footer(w: _Writer) -> None:
    w.move("G0", Z=5.0)
    w.lines += ["M5", "M30", "%"]


def pocket(lines: int = 40_000, seed: int = 1) -> str:
    """Adaptive clearing of a 120 × 80 mm pocket: trochoidal-ish passes with arcs at every turn."""
    rng = random.Random(seed)
    w = _Writer("XYZ")
    _header(w, "pocket")
    w.move("G0", Z=5.0)
    depth = 0.0
    while len(w.lines) < lines - 10:
        depth -= 0.5
        w.move("G0", X=10.0, Y=10.0)
        w.move("G1", 300.0, Z=depth + 0.5)
        w.move("G1", Z=depth)
        y = 10.0
        direction = 1
        while y < 88.0 and len(w.lines) < lines - 10:
            x0, x1 = (10.0, 130.0) if direction > 0 else (130.0, 10.0)
            x = x0
            w.move("G1", 1800.0)
            while (x1 - x) * direction > 3.0:  # a pass of short segments, following a slightly wavy wall
                x += direction * rng.uniform(0.2, 3.0)
                w.move("G1", X=x, Y=y + 0.05 * math.sin(x / 3.0))
            w.move("G1", X=x, Y=y)  # the wall's end, where the turn begins
            y_next = y + 1.2
            r = (y_next - y) / 2
            w.arc("G3" if direction > 0 else "G2", x, y_next, 0.0, r)
            w.at["Y"] = round(y_next, 3)
            y = y_next
            direction = -direction
        w.move("G0", Z=5.0)
    _footer(w)
    return w.text()


def engraving(lines: int = 16_000, seed: int = 2) -> str:
    """V-carved lettering: polylines of short moves with the depth following the stroke width."""
    rng = random.Random(seed)
    w = _Writer("XYZ")
    _header(w, "engraving")
    w.move("G0", Z=2.0)
    while len(w.lines) < lines - 10:
        x, y = rng.uniform(5, 195), rng.uniform(5, 95)
        w.move("G0", X=x, Y=y)
        w.move("G1", 400.0, Z=-0.2)
        w.move("G1", 1200.0)
        heading = rng.uniform(0, 2 * math.pi)
        for _ in range(rng.randint(20, 120)):
            heading += rng.uniform(-0.5, 0.5)
            step = rng.uniform(0.05, 0.6)
            x = min(199.0, max(1.0, x + step * math.cos(heading)))
            y = min(99.0, max(1.0, y + step * math.sin(heading)))
            w.move("G1", X=x, Y=y, Z=-0.2 - 0.3 * abs(math.sin(heading * 2)))
        w.move("G0", Z=2.0)
    _footer(w)
    return w.text()


def four_axis(lines: int = 51_000, seed: int = 3) -> str:
    """Rotary finishing on X Y Z A: long cruises along X while A turns, short stepovers, arcs in X Y."""
    rng = random.Random(seed)
    w = _Writer("XYZA")
    _header(w, "four-axis rotary")
    w.move("G0", Z=30.0)
    a = 0.0
    while len(w.lines) < lines - 10:
        w.move("G0", X=0.0, Y=0.0, A=a)
        w.move("G1", 500.0, Z=20.0 + rng.uniform(-0.5, 0.5))
        w.move("G1", 2000.0, X=150.0, A=a + 90.0)  # a long cruise
        for k in range(rng.randint(100, 300)):  # a profile of short moves
            x = 150.0 - 0.5 * k
            w.move("G1", X=x, Z=20.0 + 2.0 * math.sin(x / 7.0), A=a + 90.0 + 0.4 * k)
        x = w.at["X"]
        w.arc("G3", x - 10.0, 10.0, -10.0, 0.0)  # a quarter circle out of the profile, and back
        w.move("G1", Y=0.0)
        a += 1.5
    _footer(w)
    return w.text()


JOBS = {"pocket": pocket, "engraving": engraving, "four_axis": four_axis}
