"""An image as a laser raster in G-code: rows of G1 X… S… at one feed under M4, one move per run of
equal power, G0 between rows, bidirectional unless asked not to (`quadstep raster`).

`quadstep run` finds such rows again and sends them as RASTER lines (planner/raster_gcode.py), so
the file is also what any GRBL laser would run.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field


class RasterSettings(BaseModel):
    """How an image becomes a raster: pixel size, where its bottom-left corner goes, the feed, the S
    range from white to black."""

    model_config = ConfigDict(frozen=True)

    pixel_mm: float = Field(default=0.1, gt=0, le=10)
    width_mm: float | None = Field(default=None, gt=0, description="None: one image pixel a pixel")
    x_mm: float = 0.0
    y_mm: float = 0.0
    feed_mm_min: float = Field(default=6000.0, gt=0)
    s_min: float = Field(default=0.0, ge=0)
    s_max: float = Field(default=1000.0, gt=0)
    bidirectional: bool = True
    invert: bool = False  # True: white burns (a dark material)


def image_rows(path: Path, settings: RasterSettings) -> list[list[int]]:
    """The image's gray levels (0 black … 255 white), top row first, resampled to the pixel grid."""
    from PIL import Image

    with Image.open(path) as image:
        gray = image.convert("L")
        if settings.width_mm is not None:
            columns = max(1, round(settings.width_mm / settings.pixel_mm))
            rows = max(1, round(gray.height * columns / gray.width))
            gray = gray.resize((columns, rows), Image.Resampling.LANCZOS)
        data = list(gray.tobytes())
    return [data[r * gray.width : (r + 1) * gray.width] for r in range(gray.height)]


def s_value(level: int, settings: RasterSettings) -> float:
    """S for a gray level: s_max at black, 0 (off) at white, s_min … s_max between."""
    darkness = level if settings.invert else 255 - level
    if darkness == 0:
        return 0.0
    return round(settings.s_min + (settings.s_max - settings.s_min) * darkness / 255, 1)


def raster_gcode(levels: list[list[int]], settings: RasterSettings) -> list[str]:
    """The G-code lines: every row (bottom row at y_mm), its white ends left out."""
    w = settings.pixel_mm
    out = [
        "; raster engraving written by quadstep raster",
        "G21 G90",
        "M4 S0",
        f"G1 F{settings.feed_mm_min:g}",
    ]
    forward = True
    for number, row in enumerate(reversed(levels)):
        s = [s_value(level, settings) for level in row]
        lit = [k for k, v in enumerate(s) if v > 0]
        if not lit:
            continue
        first, last = lit[0], lit[-1] + 1
        y = settings.y_mm + number * w
        order = range(first, last) if forward else range(last - 1, first - 1, -1)
        start = first if forward else last
        out.append(f"G0 X{settings.x_mm + start * w:.3f} Y{y:.3f}")
        run = None
        for k in order:
            if run is not None and s[k] != run:
                edge = k if forward else k + 1
                out.append(f"G1 X{settings.x_mm + edge * w:.3f} S{run:g}")
            run = s[k]
        end = last if forward else first
        out.append(f"G1 X{settings.x_mm + end * w:.3f} S{run:g}")
        if settings.bidirectional:
            forward = not forward
    out += ["M5", "G0 X{:.3f} Y{:.3f}".format(settings.x_mm, settings.y_mm), "M2"]
    return out
