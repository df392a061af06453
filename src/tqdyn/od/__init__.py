"""Orbit determination: estimation of initial states and acceleration parameters from tracking data."""
