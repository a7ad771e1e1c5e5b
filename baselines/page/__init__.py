"""The leaderboard rendered: the verdict's sentences, the markdown tables and
``leaderboard.html`` (its sections, cells and embedded figures)."""
