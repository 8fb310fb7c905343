"""Whether a TUI screen fits its terminal: no widget leaves the screen, and no line of text is cut
(a Static's lines fit its width, a footer's keys all show)."""

from __future__ import annotations

from typing import Any

from rich.text import Text
from textual.widgets import Static


def plain_lines(widget: Any) -> list[str]:
    """The text a widget renders, line by line, without markup."""
    rendered = widget.render()
    plain = getattr(rendered, "plain", None)
    if plain is None:
        plain = Text.from_markup(str(rendered)).plain
    return str(plain).splitlines() or [""]


def cut_text(app: Any) -> list[str]:
    """Every widget of the screen shown that leaves the terminal or whose text does not fit."""
    width, height = app.size
    found = []
    for widget in app.screen.query("*"):
        region = widget.region
        if not widget.display or not region.area:
            continue
        name = f"{type(widget).__name__}#{widget.id}"
        scrolled = any(
            a is not app.screen and getattr(a, "styles", None) is not None
            and a.styles.overflow_y in ("auto", "scroll")
            for a in widget.ancestors
        )  # inside a box that scrolls (the help): its text goes on below
        if not scrolled and (region.right > width or region.bottom > height):
            found.append(f"{name} leaves the screen: {region}")
        if type(widget).__name__ == "FooterKey":
            footer = widget.parent
            while footer is not None and type(footer).__name__ != "Footer":
                footer = footer.parent
            if footer is not None and region.right > footer.region.right:
                keys = [" ".join(plain_lines(k)) for k in footer.query("FooterKey")]
                found.append(f"{name} beyond the footer: {' '.join(plain_lines(widget))!r} {keys}")
        elif isinstance(widget, Static) and widget.styles.text_wrap == "nowrap":
            widest = max(len(line) for line in plain_lines(widget))
            if widest > widget.content_size.width:
                found.append(f"{name} cut: {plain_lines(widget)!r} in {widget.content_size.width}")
    return found


def assert_nothing_cut(app: Any) -> None:
    found = cut_text(app)
    assert not found, "\n".join(found)
