"""The toolpath view: the job's X/Y path (cuts solid, rapids dotted), the travel box, the work
origin and the tool where it stands now. `v` switches between the job's extent and the whole
travel."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rich.text import Text
from textual.widget import Widget

from ..config import MachineConfig
from ..toolpath import Toolpath
from .canvas import Canvas

MARGIN = 0.05  # of the extent, around what the view fits


class ToolpathView(Widget, can_focus=False):
    def __init__(self, **kwargs: Any) -> None:  # the Widget's own options
        super().__init__(**kwargs)
        self.config: MachineConfig | None = None
        self.path: Toolpath | None = None
        self.tool: tuple[float, ...] | None = None  # machine mm
        self.origin: tuple[float, ...] | None = None  # the active work zero, machine mm
        self.whole_travel = False

    def show(
        self,
        config: MachineConfig | None,
        tool: Sequence[float] | None,
        origin: Sequence[float] | None,
    ) -> None:
        tool_, origin_ = (tuple(tool) if tool else None), (tuple(origin) if origin else None)
        if (config, tool_, origin_) != (self.config, self.tool, self.origin):
            self.config, self.tool, self.origin = config, tool_, origin_
            self.refresh()

    def show_path(self, path: Toolpath | None) -> None:
        self.path = path
        self.whole_travel = path is None
        self.refresh()

    def toggle_extent(self) -> None:
        self.whole_travel = not self.whole_travel
        self.refresh()

    def render(self) -> Text:
        config = self.config
        width, height = self.content_size.width, self.content_size.height
        if config is None or len(config.axes) < 2 or width < 4 or height < 2:
            return Text("no X/Y to draw" if config is not None else "", style="dim")
        canvas = Canvas(width, height)
        low, high = self._extent(config)
        dots_x, dots_y = canvas.dots
        scale = min((dots_x - 1) / (high[0] - low[0]), (dots_y - 1) / (high[1] - low[1]))
        cx, cy = (low[0] + high[0]) / 2, (low[1] + high[1]) / 2

        def at(x: float, y: float) -> tuple[float, float]:
            return (dots_x - 1) / 2 + (x - cx) * scale, (dots_y - 1) / 2 - (y - cy) * scale

        box, rapid, cut, origin, tool = (
            canvas.layer(s) for s in ("blue", "yellow", "cyan", "green", "bold red")
        )
        x_axis, y_axis = config.axes[0], config.axes[1]
        corners = [
            at(x_axis.travel_min, y_axis.travel_min),
            at(x_axis.travel_max, y_axis.travel_min),
            at(x_axis.travel_max, y_axis.travel_max),
            at(x_axis.travel_min, y_axis.travel_max),
        ]
        for a, b in zip(corners, corners[1:] + corners[:1]):
            canvas.line(*a, *b, box)
        for piece in self.path.pieces if self.path is not None else ():
            canvas.line(
                *at(piece.start[0], piece.start[1]),
                *at(piece.end[0], piece.end[1]),
                rapid if piece.rapid else cut,
                every=2 if piece.rapid else 1,
            )
        if self.origin is not None:
            canvas.mark(*at(self.origin[0], self.origin[1]), "+", origin)
        if self.tool is not None:
            canvas.mark(*at(self.tool[0], self.tool[1]), "●", tool)
        return canvas.render()

    def _extent(self, config: MachineConfig) -> tuple[tuple[float, float], tuple[float, float]]:
        """What the view fits: the travel, or the job's box with the tool and the origin."""
        x, y = config.axes[0], config.axes[1]
        points = [(x.travel_min, y.travel_min), (x.travel_max, y.travel_max)]
        box = self.path.machine_box if self.path is not None else None
        if box is not None and not self.whole_travel:
            points = [(box.low[0], box.low[1]), (box.high[0], box.high[1])]
            points += [(p[0], p[1]) for p in (self.tool, self.origin) if p is not None]
        xs, ys = [p[0] for p in points], [p[1] for p in points]
        span = max(max(xs) - min(xs), max(ys) - min(ys), 1.0) * MARGIN
        return (min(xs) - span, min(ys) - span), (max(xs) + span, max(ys) + span)
