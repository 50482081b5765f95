"""NeXus conventions shared by every HDF5 file the package writes.

Every dataset carries a ``units`` attribute (NeXus: a unit string; here ``"1"`` for
nondimensional numbers -- lengths over R_L, forces over mu H R_L, counts, flags --
and ``""`` for text, which is not a quantity).  :func:`label_units` adds the units
of curve files; :func:`missing_units` is the check a test runs on every file.
"""

from __future__ import annotations

from contextlib import contextmanager

from .paths import atomic_hdf5, check_output_path
from .version import __version__

__all__ = ["CURVE_DATASET_UNITS", "DIMENSIONLESS", "label_units", "missing_units", "string_dataset",
           "number_dataset", "file_header", "new_file"]

#: The unit of a nondimensional number.
DIMENSIONLESS = "1"
#: Curve datasets that are not nondimensional numbers (every other numeric dataset of a
#: curve file is: delta/R_L, F/(mu H R_L), energies, residuals, counts, flags).
CURVE_DATASET_UNITS = {"wall_time": "s", "delta_m": "m", "force_N": "N"}


def label_units(target, units: dict | None = None) -> None:
    """Give every dataset under ``target`` without a ``units`` attribute its unit.

    Parameters
    ----------
    target : h5py.Group or str or Path
        A group (walked recursively) or a file (opened read-write).
    units : dict, optional
        Dataset name -> unit; default :data:`CURVE_DATASET_UNITS`.  Other datasets
        get ``""`` when they hold text and ``"1"`` (nondimensional) otherwise.
    """
    import h5py

    table = CURVE_DATASET_UNITS if units is None else units
    if not isinstance(target, h5py.Group):
        with h5py.File(target, "r+") as f:
            label_units(f, units)
        return

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs:
            base = name.rsplit("/", 1)[-1]
            text = obj.dtype.kind in "OSU"
            obj.attrs["units"] = table.get(base, "" if text else DIMENSIONLESS)

    target.visititems(visit)


def missing_units(path) -> list:
    """Paths of the datasets in the HDF5 file ``path`` without a ``units`` attribute."""
    import h5py

    missing = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs:
            missing.append(name)

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return missing


def number_dataset(group, name, data, units, long_name=None):
    """Create a numeric dataset with its ``units`` (and ``long_name``)."""
    ds = group.create_dataset(name, data=data)
    ds.attrs["units"] = units
    if long_name:
        ds.attrs["long_name"] = long_name
    return ds


def string_dataset(group, name, values, long_name=None):
    """Create a dataset of UTF-8 strings (``units`` ``""``: text is not a quantity)."""
    import h5py
    import numpy as np

    if isinstance(values, str):
        ds = group.create_dataset(name, data=values, dtype=h5py.string_dtype())
    else:
        ds = group.create_dataset(name, data=np.array(list(values), dtype=object), dtype=h5py.string_dtype())
    ds.attrs["units"] = ""
    if long_name:
        ds.attrs["long_name"] = long_name
    return ds


def file_header(f, fmt: str, version: int) -> None:
    """The root attributes every file of the package carries: NX_class (NXroot), format,
    format_version, package_version and the time it was created (UTC)."""
    import datetime as _dt

    f.attrs["NX_class"] = "NXroot"
    f.attrs["format"] = fmt
    f.attrs["format_version"] = version
    f.attrs["package_version"] = __version__
    f.attrs["created"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


@contextmanager
def new_file(path, fmt: str, version: int, *, overwrite: bool = False):
    """An HDF5 file of the package written atomically: refused if ``path`` exists and not
    ``overwrite``; yields the open file with its :func:`file_header`; on success the datasets get
    their units (:func:`label_units`) and the file replaces ``path``, on any error nothing does."""
    from pathlib import Path

    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (CLI: --overwrite) to replace it")
    check_output_path(path, overwrite=True)
    with atomic_hdf5(path) as f:  # built in memory: a full disk is one OSError naming the file
        file_header(f, fmt, version)
        yield f
        label_units(f)  # every dataset says its unit (nondimensional: "1")
