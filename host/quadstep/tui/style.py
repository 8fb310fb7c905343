"""The screen's layout and colours (Textual CSS), kept in the package so it installs with it."""

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
    width: 3fr;
    height: auto;
    padding: 0 1;
    border: round $primary;
    border-title-align: left;
}

#machine {
    width: 2fr;
    height: auto;
    padding: 0 1;
    border: round $primary;
}

#jog {
    height: auto;
    padding: 0 1;
}

#job {
    height: auto;
    padding: 0 1;
}

#job-progress {
    width: 100%;
}

#log {
    height: 1fr;
    border: round $secondary;
}

HelpScreen, JobDialog {
    align: center middle;
}

#help {
    width: 88;
    height: 90%;
    border: round $primary;
    background: $surface;
    padding: 0 1;
}

#job-dialog {
    width: 80;
    height: auto;
    border: round $primary;
    background: $surface;
    padding: 1;
}
"""
