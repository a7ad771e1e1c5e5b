"""How a run is scored: each episode's cost ratio C / C_oracle (the one definition the
leaderboard, the tuner and model selection share), the intervals, the headroom, the change
share, the ranking, the rows and the scenario splits."""
