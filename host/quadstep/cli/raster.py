"""`quadstep raster IMAGE -o JOB.nc`: an image as a laser raster in G-code, which `quadstep run`
sends as RASTER lines (a power per pixel) where the board has them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..raster_image import RasterSettings, image_rows, raster_gcode
from .options import CliError


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "raster", help="turn an image into a laser raster job (G-code for quadstep run)"
    )
    parser.add_argument("image", type=Path, help="PNG, JPEG, ... (gray levels: black burns most)")
    parser.add_argument("-o", "--output", type=Path, help="G-code file to write (default: stdout)")
    size = parser.add_mutually_exclusive_group()
    size.add_argument("--pixel", type=float, default=None, metavar="MM", help="pixel size (0.1)")
    size.add_argument("--dpi", type=float, default=None, help="pixels per inch instead of --pixel")
    parser.add_argument(
        "--width",
        type=float,
        metavar="MM",
        help="resample the image to this width (default: one image pixel a pixel)",
    )
    parser.add_argument(
        "--origin",
        type=float,
        nargs=2,
        default=(0.0, 0.0),
        metavar=("X", "Y"),
        help="mm where the image's bottom-left corner goes",
    )
    parser.add_argument(
        "--feed",
        type=float,
        default=6000.0,
        metavar="MM_MIN",
        help="feed along the rows (6000 mm/min)",
    )
    parser.add_argument("--s-min", type=float, default=0.0, help="S of the lightest gray burned")
    parser.add_argument("--s-max", type=float, default=1000.0, help="S of black")
    parser.add_argument(
        "--unidirectional", action="store_true", help="burn every row left to right"
    )
    parser.add_argument("--invert", action="store_true", help="white burns, black does not")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    pixel = 25.4 / args.dpi if args.dpi else (args.pixel or 0.1)
    try:
        settings = RasterSettings(
            pixel_mm=pixel,
            width_mm=args.width,
            x_mm=args.origin[0],
            y_mm=args.origin[1],
            feed_mm_min=args.feed,
            s_min=args.s_min,
            s_max=args.s_max,
            bidirectional=not args.unidirectional,
            invert=args.invert,
        )
    except ValueError as error:
        raise CliError(f"raster: {error}") from None
    if not args.image.is_file():
        raise CliError(f"{args.image}: no such image")
    try:
        rows = image_rows(args.image, settings)
    except OSError as error:
        raise CliError(f"{args.image}: not an image Pillow reads ({error})") from None
    text = "\n".join(raster_gcode(rows, settings)) + "\n"
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text)
        print(
            f"{args.output}: {len(rows)} rows of {len(rows[0]) if rows else 0} pixels, "
            f"{pixel:g} mm each"
        )
    return 0
