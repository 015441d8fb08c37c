"""Thin Drake LeafSystems and diagram builders wrapping vic_drake's pure functions."""
