"""Scenarios: ship + initial state + path + disturbances + sensors + event schedule."""
