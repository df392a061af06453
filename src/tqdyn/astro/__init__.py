"""Astronomy: constants, time scales, reference systems, Earth and Moon orientation, ephemerides, elements.

:mod:`.constants` (values with unit and source), :mod:`.timescales` (UTC ->
TAI -> TT -> TDB, TCB -> TDB), :mod:`.reference` (origin, frame and time scale of a
propagation), :mod:`.earth_orientation`, :mod:`.eop` and :mod:`.eop_sources`
(GCRS <-> ITRS, IERS EOP: measured, predicted, long-term model),
:mod:`.ephemeris` (JPL DE files), :mod:`.elements` (Keplerian elements <->
states in mpmath), :mod:`.lunar_orientation`, :mod:`.tidal_arguments`,
:mod:`.constellation_design` (LISA/Taiji equal-arm Keplerian initial states),
:mod:`.oem_states` (states from CCSDS OEM files: interpolation, segments, frame bias, tqdyn's systems).
"""
