"""File formats (I/O only): the trajectory file (:mod:`.trajectory`), run
checkpoints (:mod:`.checkpoint`), LISA orbit files (:mod:`.lisa`), CCSDS
orbit ephemeris messages (:mod:`.oem`) and the netCDF dataset of a sweep
(:mod:`.netcdf`)."""
