"""Runners: one per command (build a world, run the loop, return a typed result)."""
