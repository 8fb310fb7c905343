"""The screen's layout and colours (Textual CSS), kept in the package so it installs with it.
Everything fits 80 × 24: the panels take the lines they need, the messages and the path view share
what is left."""

CSS = """
#banner {
    background: $error;
    color: $text;
    text-style: bold;
    padding: 0 1;
}

#top {
    height: auto;
}

#positions {
    width: 46;
    height: auto;
    padding: 0 1;
    border: round $primary;
    border-title-align: left;
}

#machine {
    width: 1fr;
    height: auto;
    padding: 0 1;
    border: round $primary;
}

#jog, #job-label, #keys {
    height: 1;
    padding: 0 1;
    text-wrap: nowrap;
    text-overflow: ellipsis;
}

#job {
    height: 1;
}

#job-label {
    width: 1fr;
}

#job-progress {
    width: 18;
}

#job-progress Bar {
    width: 12;
}

#console {
    height: 1;
    border: none;
    padding: 0 1;
    background: $surface;
}

#console:focus {
    background: $boost;
}

#bottom {
    height: 1fr;
}

#log {
    width: 1fr;
    scrollbar-gutter: stable;
    scrollbar-size-vertical: 1;
    border: round $secondary;
}

#toolpath {
    width: 40%;
    max-width: 44;
    border: round $secondary;
}

#keys {
    background: $panel;
}

HelpScreen, JobDialog, PortPicker, ConfirmScreen {
    align: center middle;
}

#help {
    width: 100%;
    max-width: 84;
    height: 100%;
    border: round $primary;
    background: $surface;
    padding: 0 1;
}

#port-picker {
    width: 100%;
    max-width: 80;
    height: auto;
    max-height: 100%;
    border: round $primary;
    background: $surface;
    padding: 0 1;
}

#ports {
    height: auto;
    max-height: 18;
}

#job-dialog {
    width: 100%;
    max-width: 80;
    height: auto;
    border: round $primary;
    background: $surface;
    padding: 0 1;
}

#backlash, #dial {
    height: 1fr;
    border: round $primary;
    padding: 0 1;
}

#backlash-result, #dial-result {
    margin-top: 1;
}

#confirm {
    width: 70;
    height: auto;
    border: round $warning;
    background: $surface;
    padding: 1;
}
"""
