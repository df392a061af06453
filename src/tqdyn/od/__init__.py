"""Orbit determination: variational equations (:mod:`.variational`), the estimated
parameters (:mod:`.parameters`), measurement models and the batch estimator."""
