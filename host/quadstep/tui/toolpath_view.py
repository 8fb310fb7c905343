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
        # the travel box and the path as last drawn, and what they were drawn for: the tool moves
        # ten times a second while a job runs, and drawing a 3,000-line path dot by dot each time
        # took 40 ms (docs/TUI.md)
        self._drawn: tuple[_Frame, Canvas] | None = None

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
        frame = _Frame(config, self.path, width, height, *self._extent(config))
        if self._drawn is None or not self._drawn[0].same(frame):
            self._drawn = (frame, frame.draw())
        canvas = self._drawn[1].copy()
        origin, tool = canvas.layer("green"), canvas.layer("bold red")
        if self.origin is not None:
            canvas.mark(*frame.at(self.origin[0], self.origin[1]), "+", origin)
        if self.tool is not None:
            canvas.mark(*frame.at(self.tool[0], self.tool[1]), "●", tool)
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


class _Frame:
    """What the view draws the travel box and the path for: the configuration, the path, the
    canvas's size in cells and the extent it fits; where a machine X/Y lands among its dots."""

    def __init__(
        self,
        config: MachineConfig,
        path: Toolpath | None,
        width: int,
        height: int,
        low: tuple[float, float],
        high: tuple[float, float],
    ) -> None:
        self.config, self.path = config, path
        self.size, self.low, self.high = (width, height), low, high
        dots_x, dots_y = width * 2, height * 4
        self._half = ((dots_x - 1) / 2, (dots_y - 1) / 2)
        self._scale = min((dots_x - 1) / (high[0] - low[0]), (dots_y - 1) / (high[1] - low[1]))
        self._centre = ((low[0] + high[0]) / 2, (low[1] + high[1]) / 2)

    def same(self, other: _Frame) -> bool:
        """The same drawing: the same configuration and path (the objects), size and extent."""
        return (
            self.config is other.config
            and self.path is other.path
            and (self.size, self.low, self.high) == (other.size, other.low, other.high)
        )

    def at(self, x: float, y: float) -> tuple[float, float]:
        return (
            self._half[0] + (x - self._centre[0]) * self._scale,
            self._half[1] - (y - self._centre[1]) * self._scale,
        )

    def draw(self) -> Canvas:
        """The travel box, then the path: rapids dotted, cuts solid."""
        canvas = Canvas(*self.size)
        box, rapid, cut = (canvas.layer(s) for s in ("blue", "yellow", "cyan"))
        x_axis, y_axis = self.config.axes[0], self.config.axes[1]
        corners = [
            self.at(x_axis.travel_min, y_axis.travel_min),
            self.at(x_axis.travel_max, y_axis.travel_min),
            self.at(x_axis.travel_max, y_axis.travel_max),
            self.at(x_axis.travel_min, y_axis.travel_max),
        ]
        for a, b in zip(corners, corners[1:] + corners[:1]):
            canvas.line(*a, *b, box)
        for piece in self.path.pieces if self.path is not None else ():
            canvas.line(
                *self.at(piece.start[0], piece.start[1]),
                *self.at(piece.end[0], piece.end[1]),
                rapid if piece.rapid else cut,
                every=2 if piece.rapid else 1,
            )
        return canvas
