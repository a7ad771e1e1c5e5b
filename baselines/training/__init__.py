"""Training the learned agents: their configs, the trainers (SB3, DAgger, the plant
identifier's network), the announcement of a sweep and model selection against the oracle."""
