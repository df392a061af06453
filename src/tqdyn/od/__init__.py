"""Orbit determination: measurement models of the tracking data (GNSS, satellite
laser ranging, inter-satellite ranging, deep-space ground stations), the
variational equations and the batch least-squares estimator that calibrate the
spacecraft's self-gravity from tracking (docs/orbit-determination.md)."""
