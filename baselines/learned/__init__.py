"""Learned agents (stable-baselines3) and their plumbing."""
