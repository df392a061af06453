"""tqdyn: coupled orbit-attitude dynamics of drag-free gravitational-wave
constellations (TianQin by default) in extended (double-double) precision."""

__version__ = "0.1.0"
