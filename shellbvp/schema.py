"""Reading HDF5 files that may be damaged or hostile: every value checked before it is used.

A file's attributes and datasets are claims, not facts.  These helpers read one item each and
check its kind, shape, dtype, range and size first -- the size from the dataset's shape and
dtype, before a compressed dataset is expanded -- and parse JSON text with a size and a nesting
limit.  Each failure is a ``ValueError`` naming the item (the reader adds the file's name).
"""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["MAX_DATASET_BYTES", "MAX_JSON_BYTES", "MAX_JSON_DEPTH", "dataset", "text_dataset", "attr_text",
           "attr_bool", "attr_int", "text", "scalar", "parse_json", "format_version"]

#: The most bytes one dataset may hold once expanded (a 27 KB file's compressed datasets
#: claimed 3 GB each): 256 MiB, far above any curve or record the package writes.
MAX_DATASET_BYTES = 256 * 2**20
#: JSON text in an attribute: size and nesting limits (the package writes flat, short JSON).
MAX_JSON_BYTES = 2**20
MAX_JSON_DEPTH = 32


def _node(group, name):
    import h5py

    if name not in group:
        raise ValueError(f"{name} is missing")
    item = group[name]
    if not isinstance(item, h5py.Dataset):
        raise ValueError(f"{name} must be a dataset")
    return item


def dataset(group, name, *, kind="float", ndim=1, length=None, max_bytes=MAX_DATASET_BYTES):
    """A numeric dataset as an array: dtype kind (``float`` also takes integers and booleans;
    ``int``; ``bool``), dimensions and, for ``ndim`` 1, ``length``; its expanded size checked
    before it is read."""
    item = _node(group, name)
    kinds = {"float": "fiub", "int": "iub", "bool": "biu"}[kind]
    if item.dtype.kind not in kinds:
        raise ValueError(f"{name} must hold numbers ({kind}); it holds {item.dtype}")
    if len(item.shape) != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s); it has shape {item.shape}")
    if length is not None and item.shape[0] != length:
        raise ValueError(f"{name} must have {length} values; it has {item.shape[0]}")
    size = int(np.prod(item.shape, dtype=np.int64)) * item.dtype.itemsize
    if size > max_bytes:
        raise ValueError(f"{name} would expand to {size / 2**20:.0f} MiB (more than {max_bytes / 2**20:.0f})")
    value = item[()]
    if kind == "bool":
        value = np.asarray(value)
        if value.dtype.kind != "b" and not np.all(np.isin(value, (0, 1))):
            raise ValueError(f"{name} must hold 0 or 1")
        return value.astype(bool)
    return np.asarray(value, dtype=float if kind == "float" else np.int64)


def text_dataset(group, name, *, ndim=1, length=None, max_bytes=MAX_DATASET_BYTES):
    """A dataset of strings (UTF-8; undecodable bytes replaced) as a list, or one string for
    ``ndim`` 0; checked like :func:`dataset`."""
    item = _node(group, name)
    if item.dtype.kind not in "OSU":
        raise ValueError(f"{name} must hold text; it holds {item.dtype}")
    if len(item.shape) != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s); it has shape {item.shape}")
    if length is not None and item.shape[0] != length:
        raise ValueError(f"{name} must have {length} values; it has {item.shape[0]}")
    if int(np.prod(item.shape, dtype=np.int64)) * 64 > max_bytes:  # variable-length strings: a bound on count
        raise ValueError(f"{name} holds too many strings ({item.shape})")
    value = item[()]
    if ndim == 0:
        return text(value, name, max_bytes)
    return [text(v, name, max_bytes) for v in value]


def text(v, name, max_bytes=MAX_JSON_BYTES):
    """A string value (bytes decoded as UTF-8, undecodable bytes replaced), at most ``max_bytes`` long."""
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v[()]
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    if not isinstance(v, str):
        raise ValueError(f"{name} must be text; got {type(v).__name__}")
    if len(v) > max_bytes:
        raise ValueError(f"{name} is longer than {max_bytes} characters")
    return v


def attr_text(obj, name, *, max_bytes=MAX_JSON_BYTES) -> str:
    """A text attribute."""
    if name not in obj.attrs:
        raise ValueError(f"attribute {name} is missing")
    return text(obj.attrs[name], f"attribute {name}", max_bytes)


def attr_bool(obj, name) -> bool:
    """A true/false attribute: a boolean, or the integers 0 and 1 (never text: ``"False"`` is
    not false)."""
    if name not in obj.attrs:
        raise ValueError(f"attribute {name} is missing")
    v = obj.attrs[name]
    if isinstance(v, np.ndarray) and v.shape == ():
        v = v[()]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)) and int(v) in (0, 1):
        return bool(v)
    raise ValueError(f"attribute {name} must be true or false; got {v!r}")


def attr_int(obj, name, *, low=None, high=None) -> int:
    """An integer attribute within [low, high]."""
    if name not in obj.attrs:
        raise ValueError(f"attribute {name} is missing")
    v = obj.attrs[name]
    if isinstance(v, np.ndarray) and v.shape == ():
        v = v[()]
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
        raise ValueError(f"attribute {name} must be an integer; got {v!r}")
    v = int(v)
    if (low is not None and v < low) or (high is not None and v > high):
        raise ValueError(f"attribute {name} must be in [{low}, {high}]; got {v}")
    return v


def scalar(group, name, *, low=-math.inf, high=math.inf, finite=True, required=True):
    """A numeric scalar dataset in [low, high] (NaN allowed only with ``finite=False``); NaN
    when absent and not ``required``."""
    if not required and name not in group:
        return math.nan
    v = dataset(group, name, kind="float", ndim=0)
    v = float(v)
    if math.isnan(v):
        if finite:
            raise ValueError(f"{name} must be a number; got NaN")
        return v
    if not (low <= v <= high):
        raise ValueError(f"{name} must be in [{low:g}, {high:g}]; got {v!r}")
    return v


def parse_json(text, name, *, max_bytes=MAX_JSON_BYTES, max_depth=MAX_JSON_DEPTH):
    """JSON text with a size and a nesting limit (checked before parsing: Python's parser
    recurses, and 200,000 brackets end in RecursionError)."""
    if len(text) > max_bytes:
        raise ValueError(f"{name}: JSON longer than {max_bytes} characters")
    depth = deepest = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > max_depth:
                raise ValueError(f"{name}: JSON nested deeper than {max_depth}")
        elif ch in "]}":
            depth -= 1
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{name} is not valid JSON ({exc})") from None


def format_version(h, newest: int) -> int:
    """The file's ``format_version``: an integer from 1 to ``newest`` (a newer file names the
    package version that can read it)."""
    v = attr_int(h, "format_version", low=1)
    if v > newest:
        raise ValueError(f"format_version {v} is newer than this package reads ({newest}); "
                         f"written by shellbvp {attr_text(h, 'package_version') if 'package_version' in h.attrs else '?'}")
    return v
