"""Analyses of propagated trajectories (force budgets, spectra, metrics)."""
