"""Motion planning: a Program of moves becomes exact, limit-respecting segments."""
