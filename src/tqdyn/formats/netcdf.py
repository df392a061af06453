"""netCDF-4 files (the gathered dataset of a sweep): the xarray engine and an atomic writer."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

from .atomic import replacing

__all__ = ["netcdf_engine", "write_netcdf"]

_NETCDF_ENGINES = (("h5netcdf", "h5netcdf"), ("netCDF4", "netcdf4"))


def netcdf_engine() -> str:
    """The xarray engine used to write the gathered netCDF-4 file: "h5netcdf"
    (preferred: pure Python on h5py) or "netcdf4".  ImportError if neither
    package is installed."""
    for module, engine in _NETCDF_ENGINES:
        if importlib.util.find_spec(module) is not None:
            return engine
    raise ImportError("writing the sweep's netCDF file needs the h5netcdf package (pip install h5netcdf)")


def write_netcdf(dataset, path: str | os.PathLike, encoding: dict | None = None, what: str = "the sweep file") -> Path:
    """Write ``dataset`` atomically as netCDF-4 (engine :func:`netcdf_engine`)
    to ``path`` (temporary file in the same directory, then renamed), with
    xarray's per-variable ``encoding`` (e.g. checksums) if given.  The file is built in memory and
    written with ordinary file writes (:func:`tqdyn.formats.atomic.replacing`, as
    :func:`~tqdyn.formats.atomic.replacing_h5` does: HDF5 never sees a full disk, which becomes
    :class:`~tqdyn.formats.trajectory.OutputIOError`, naming the file as ``what``).  Returns the absolute path."""
    path = Path(os.path.abspath(os.fspath(path)))
    image = dataset.to_netcdf(engine=netcdf_engine(), encoding=encoding)
    with replacing(path, what) as tmp, open(tmp, "xb") as f:
        f.write(image)
    return path
