"""A braille canvas: every terminal cell holds 2 × 4 dots, so an 38 × 11 cell view draws 76 × 44
points.

Dots are set in layers; a cell takes the colour of the highest layer among its dots (the tool over
the origin over cuts over rapids over the travel box)."""

from __future__ import annotations

from rich.text import Text

BRAILLE = 0x2800
# dot bit for (column 0–1, row 0–3) inside a cell (Unicode's braille numbering)
DOT = ((0x01, 0x08), (0x02, 0x10), (0x04, 0x20), (0x40, 0x80))


class Canvas:
    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height  # cells
        self._bits = [[0] * width for _ in range(height)]
        self._layer = [[-1] * width for _ in range(height)]
        self._styles: list[str] = []
        self._marks: dict[tuple[int, int], tuple[str, int]] = {}

    def copy(self) -> Canvas:
        """Another canvas with these dots, layers and marks, drawn on apart from this one."""
        other = Canvas(self.width, self.height)
        other._bits = [list(row) for row in self._bits]
        other._layer = [list(row) for row in self._layer]
        other._styles = list(self._styles)
        other._marks = dict(self._marks)
        return other

    @property
    def dots(self) -> tuple[int, int]:
        return self.width * 2, self.height * 4

    def layer(self, style: str) -> int:
        """A new layer drawn in `style`, above every earlier one."""
        self._styles.append(style)
        return len(self._styles) - 1

    def dot(self, x: int, y: int, layer: int) -> None:
        """Dot (x, y), y down; outside the canvas: nothing."""
        if 0 <= x < self.width * 2 and 0 <= y < self.height * 4:
            row, col = y // 4, x // 2
            self._bits[row][col] |= DOT[y % 4][x % 2]
            self._layer[row][col] = max(self._layer[row][col], layer)

    def line(self, x0: float, y0: float, x1: float, y1: float, layer: int, every: int = 1) -> None:
        """Dots along a straight line; `every` 2 or more leaves gaps (a dotted line)."""
        steps = max(int(max(abs(x1 - x0), abs(y1 - y0))), 1)
        for i in range(0, steps + 1, every):
            t = i / steps
            self.dot(round(x0 + (x1 - x0) * t), round(y0 + (y1 - y0) * t), layer)

    def mark(self, x: float, y: float, char: str, layer: int) -> None:
        """A whole cell shown as `char` (the tool, the origin) at dot position (x, y)."""
        col, row = int(x) // 2, int(y) // 4
        if 0 <= col < self.width and 0 <= row < self.height:
            self._marks[(row, col)] = (char, layer)

    def render(self) -> Text:
        """The cells as text, a span per run of cells in one style (a span a cell made the screen's
        redraw several times slower)."""
        text = Text()
        for row in range(self.height):
            if row:
                text.append("\n")
            run: list[str] = []
            run_style = ""
            for col in range(self.width):
                char, style = self._cell(row, col)
                if style != run_style and run:
                    text.append("".join(run), style=run_style)
                    run = []
                run_style = style
                run.append(char)
            text.append("".join(run), style=run_style)
        return text

    def _cell(self, row: int, col: int) -> tuple[str, str]:
        """What cell (row, col) shows, and in which style."""
        mark = self._marks.get((row, col))
        if mark is not None:
            return mark[0], self._styles[mark[1]]
        bits, layer = self._bits[row][col], self._layer[row][col]
        return (
            chr(BRAILLE + bits) if bits else " ",
            self._styles[layer] if layer >= 0 else "",
        )
