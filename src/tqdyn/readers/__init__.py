"""Readers of the model data files, apart from the theory that uses them.

Gravity fields (:mod:`.gravity_fields`: ICGEM, SHADR), FES2004 ocean tides
(:mod:`.fes2004`), the IERS Conventions tables (:mod:`.iers_tables`), the IERS
EOP C04 series (:mod:`.eop_c04`), NAIF kernels (:mod:`.naif`, :mod:`.pck`), the
Doodson notation (:mod:`.doodson`) and the shipped data (:mod:`.files`).
This layer imports nothing of tqdyn but :mod:`tqdyn.astro.constants`.
"""
