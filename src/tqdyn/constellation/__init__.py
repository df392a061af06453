"""Constellation geometry, pointing laws and attitude of the three satellites."""
