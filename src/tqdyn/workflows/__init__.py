"""Workflows: compose the library into jobs -- one scenario to a file
(:mod:`.run`), sweeps on Dask (:mod:`.sweep`), the paper's studies
(:mod:`.studies`) and report (:mod:`.report`), exports (:mod:`.export`) and
benchmarks (:mod:`.bench`, against the peers of :mod:`tqdyn.peers`)."""
