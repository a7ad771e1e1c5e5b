"""The leaderboard's figures: per-scenario small multiples, the ranking and the performance
profiles, the learning curves, one look per controller, and the files they are written to."""
