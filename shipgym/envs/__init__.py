"""Gymnasium environments of shipgym."""
