"""Integrity of the sweep's netCDF file: written with HDF5 Fletcher-32
checksums on every variable (:func:`write_sweep_netcdf`), read back with
every checksum verified (:func:`read_sweep_netcdf`, one-line
:class:`SweepFileError` on corruption)."""

from __future__ import annotations

import os
from pathlib import Path

from ...formats.netcdf import netcdf_engine, write_netcdf
from ..run import one_line

__all__ = ["SweepFileError", "checksum_encoding", "read_sweep_netcdf", "write_sweep_netcdf"]


class SweepFileError(ValueError):
    """A sweep netCDF file that cannot be read or fails its checksums (one line)."""


def checksum_encoding(dataset) -> dict:
    """xarray encoding asking for the Fletcher-32 filter (chunked storage) on
    every variable that HDF5 can filter (not scalars, not variable-length strings)."""
    enc = {}
    for name, var in dataset.variables.items():
        if var.ndim == 0 or var.size == 0 or var.dtype.kind in "OUS":
            continue
        enc[name] = {"fletcher32": True}
    return enc


def write_sweep_netcdf(dataset, path: str | os.PathLike, what: str = "the sweep file") -> Path:
    """Write ``dataset`` atomically as netCDF-4 (temporary file in the same
    directory, then renamed) with Fletcher-32 checksums (:func:`checksum_encoding`).
    Returns the absolute path; a failed write names the file as ``what``.  The file is built in
    memory (:func:`tqdyn.formats.netcdf.write_netcdf`) with dask's synchronous scheduler: under a
    distributed client xarray would take a distributed
    lock named after the file, which an in-memory file cannot give."""
    import dask

    with dask.config.set(scheduler="synchronous"):
        return write_netcdf(dataset, path, encoding=checksum_encoding(dataset), what=what)


def read_sweep_netcdf(path: str | os.PathLike):
    """The sweep's dataset, loaded into memory with every HDF5 checksum
    verified.  A missing, truncated or corrupted file raises
    :class:`SweepFileError` naming the file (one line)."""
    import xarray as xr

    p = Path(os.path.abspath(os.path.expanduser(os.fspath(path))))
    if not p.is_file():
        raise SweepFileError(f"sweep file {str(p)!r} " + ("is not a file" if p.exists() else "does not exist"))
    try:
        with xr.open_dataset(p, engine=netcdf_engine()) as ds:
            return ds.load()
    except Exception as exc:  # noqa: BLE001 - h5py/netCDF raise OSError, ValueError, KeyError...
        raise SweepFileError(f"sweep file {str(p)!r} is corrupted or unreadable ({one_line(exc)}); "
                             "run the sweep again to rewrite it") from None
