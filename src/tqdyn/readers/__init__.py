"""Readers of the model data files, apart from the theory that uses them.

Gravity fields (:mod:`.gravity_fields`: ICGEM, SHADR), FES2004 ocean tides
(:mod:`.fes2004`), the Biancale & Bode S1/S2 atmospheric tides
(:mod:`.bb2006`), the IERS Conventions tables (:mod:`.iers_tables`), the IERS
EOP 14 / 20 C04 series (:mod:`.eop_c04`), finals2000A (:mod:`.eop_finals`), the
leap-second table (:mod:`.leap_seconds`; these three from the
``astropy-iers-data`` package), NAIF kernels (:mod:`.naif`, :mod:`.pck`), CCSDS orbit ephemeris messages
(:mod:`.oem`: OEM files as arrays and segments; their states are :mod:`tqdyn.astro.oem_states`),
GNSS precise orbits in SP3-c/d (:mod:`.sp3`; their GCRS states are :mod:`tqdyn.od.gnss_sp3`),
the Doodson notation (:mod:`.doodson`), the shipped data (:mod:`.files`) and the calendar checks
of the dates read from files (:mod:`.dates`).
This layer imports nothing of tqdyn but :mod:`tqdyn.astro.constants`.
"""
