"""Probabilistic PDDL: unified-planning's reader plus PPDDL's single-outcome `probabilistic`."""
