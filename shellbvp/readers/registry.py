"""The registry of instrument readers: :class:`Reader`, how the package finds its reader
modules (:func:`discover`, :func:`install`) and the look-ups every caller asks
(:func:`reader_for`, :func:`read_record`, :func:`read_curves`, :func:`iter_curves`,
:func:`read_table`, :func:`check_options`).  The readers themselves are declared in the other
modules of :mod:`shellbvp.readers`, one module per format; nothing outside this package
compares a file's name or first bytes with a format.
"""

from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ..textdata import printable

__all__ = ["Reader", "READERS", "OPTION_GROUPS", "register", "discover", "install", "reader", "reader_for",
           "takers", "check_options", "read_record", "read_curves", "iter_curves", "read_table", "curve_suffixes",
           "folder_suffixes"]

#: The reading options, by group: a text table's columns and a cantilever's calibration
OPTION_GROUPS = {"text": ("columns", "units", "invert"), "calibration": ("spring_constant", "sensitivity")}
#: How a calibration value is named in messages
_CALIBRATION_NAMES = {"spring_constant": "spring constant", "sensitivity": "sensitivity"}


@dataclass(frozen=True)
class Reader:
    """One format of instrument file (or a family a loader reads alike).

    Attributes
    ----------
    name : str
        Its name in messages and documentation (``"text table"``, ``"JPK"``, ``"NT-MDT Nova"``).
    order : int
        Where it stands: the readers are asked in this order whether they recognise a file.
    what : str
        What such a file is, for messages: ``"a JPK archive"``.
    hint : str
        How such a file is read, for a file given where another kind is wanted (a force map
        given as a pixel table).
    read : callable
        ``read(path, **options)``, with the options it takes (:attr:`options`) that were
        given: an :class:`~shellbvp.instrument_record.InstrumentRecord`, or with :attr:`curves`
        a list of :class:`~shellbvp.afm_read.AFMCurve` (a force map: more than one).
    suffixes : tuple of str
        File name endings (lower case) it recognises by name alone.
    folder_suffixes : tuple of str
        The endings of the files a folder given as a batch takes for it (single curves, not
        force maps: a map is fitted on its own).
    sniff : callable, optional
        ``sniff(path) -> bool``: it recognises the file by its content (its first bytes; never a
        FIFO opened).  Called for files no reader before it recognised.
    fallback : bool
        It reads what no other reader of its kind (:attr:`curves`) recognises.
    curves : bool
        It gives a file's curves (:class:`~shellbvp.afm_read.AFMCurve`), possibly a force map.
    options : tuple of str
        The reading options it takes (of :data:`OPTION_GROUPS`).
    requires : tuple of str
        Options it cannot read a file without (refused with ``refusals["requires"]``).
    refusals : dict
        The message (after the file's name) when options of a group it does not take are given
        (``"text"``, ``"calibration"``), or ``"requires"`` options are missing; ``{takers}``
        becomes the names of the readers that take that group (:func:`takers`).
    iterate : callable, optional
        ``iterate(path, **options)`` of a reader of :attr:`curves`: its curves one at a time, in
        file order (a force map is never all in memory; :func:`iter_curves`); without it
        :attr:`read`'s list is handed out one by one.
    table : callable, optional
        ``table(path, max_rows=None, what="table")``: the file split into a table (the text
        reader's :func:`shellbvp.readers.text_table.read_table`), for tables of other kinds (a
        force map's pixel table).
    """

    name: str
    order: int
    what: str
    hint: str
    read: Callable
    suffixes: tuple = ()
    folder_suffixes: tuple = ()
    sniff: Callable = None
    fallback: bool = False
    curves: bool = False
    options: tuple = ()
    requires: tuple = ()
    refusals: dict = field(default_factory=dict)
    iterate: Callable = None
    table: Callable = None

    def recognises(self, path) -> bool:
        """Whether ``path`` is this reader's by its name or its first bytes (a fallback
        recognises nothing itself)."""
        if self.fallback:
            return False
        return (bool(self.suffixes) and str(path).lower().endswith(self.suffixes)) or \
            (self.sniff is not None and self.sniff(path))


#: Every reader, in the order they are asked (:attr:`Reader.order`)
READERS: list = []


def register(new: Reader) -> Reader:
    """Add a reader; ValueError for a second reader of the same name or order."""
    for old in READERS:
        if old.name == new.name or old.order == new.order:
            raise ValueError(f"reader {new.name!r} (order {new.order}) clashes with {old.name!r} (order {old.order})")
    READERS.append(new)
    READERS.sort(key=lambda r: r.order)
    return new


def discover(package) -> list:
    """The modules of ``package`` (this one's package) that declare readers (``READERS``)."""
    found = []
    for info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        if getattr(module, "READERS", READERS) is not READERS:  # this module's list is the registry itself
            found.append(module)
    return found


def install(module) -> None:
    """Register the readers a module declares in its ``READERS``."""
    for r in module.READERS:
        register(r)


def reader(name) -> Reader:
    """The reader called ``name``."""
    for r in READERS:
        if r.name == name:
            return r
    raise ValueError(f"no reader named {name!r}; the readers are {', '.join(r.name for r in READERS)}")


def reader_for(path, *, curves=None) -> Reader:
    """The reader of ``path``: the first (by order) that recognises it by name or content, else
    the fallback; with ``curves`` True or False, among the readers that give curves or not."""
    kind = [r for r in READERS if curves is None or r.curves == curves]
    found = next((r for r in kind if r.recognises(path)), None)
    if found is None:
        found = next(r for r in kind if r.fallback and r.curves == bool(curves))
    return found


def takers(group) -> str:
    """The names of the readers that take the options of ``group`` (``"AFM Workshop, NT-MDT Nova"``)."""
    options = OPTION_GROUPS[group]
    return ", ".join(r.name for r in READERS if any(o in r.options for o in options))


def _given(name, value) -> bool:
    return bool(value) if name in OPTION_GROUPS["text"] else value is not None


def check_options(found: Reader, path, options: dict) -> dict:
    """The options of ``options`` that ``found`` takes, given (its call's keywords); ValueError
    naming the file for options it does not take (pointing to the readers that do), a
    calibration value that is not a finite number > 0, or options it requires and lacks."""
    given = {k for k, v in options.items() if _given(k, v)}
    for group, names in OPTION_GROUPS.items():
        refused = [n for n in names if n in given and n not in found.options]
        if refused:
            message = found.refusals.get(group, f"{found.what} takes no "
                                                f"{', '.join('--' + n.replace('_', '-') for n in refused)}")
            raise ValueError(f"{printable(path)}: {message.format(takers=takers(group))}")
    for name in OPTION_GROUPS["calibration"]:
        value = options.get(name)
        if name in given and not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"the {_CALIBRATION_NAMES[name]} must be a finite number > 0; got {value!r}")
    if any(n not in given for n in found.requires):
        raise ValueError(f"{printable(path)}: {found.refusals['requires']}")
    return {k: options[k] for k in found.options if k in given}


def read_record(path, *, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None,
                curves=None):
    """One record (:class:`~shellbvp.instrument_record.InstrumentRecord`) from a file, read by
    its reader (:func:`reader_for`; with ``curves`` among the readers that give curves or not);
    a file of several curves (a force map) is refused, pointing to its own fit."""
    found = reader_for(path, curves=curves)
    taken = check_options(found, path, {"columns": columns, "units": units, "invert": invert,
                                        "spring_constant": spring_constant, "sensitivity": sensitivity})
    out = found.read(path, **taken)
    if not found.curves:
        return out
    if len(out) > 1:
        raise ValueError(f"{printable(path)}: a force map of {len(out)} curves: fit it on its own "
                         f"(shellbvp fit {printable(Path(path).name)} ... -o map.h5; in Python "
                         f"shellbvp.afm.read_afm and shellbvp.batch.fit_map)")
    return out[0].record


def read_curves(path, *, spring_constant=None, sensitivity=None) -> list:
    """The curves of a file (:class:`~shellbvp.afm_read.AFMCurve`, in file order) read by its
    reader among those that give curves (:func:`reader_for` with ``curves=True``)."""
    found = reader_for(path, curves=True)
    taken = check_options(found, path, {"spring_constant": spring_constant, "sensitivity": sensitivity})
    return found.read(path, **taken)


def iter_curves(path, *, spring_constant=None, sensitivity=None):
    """:func:`read_curves` one curve at a time (the reader's :attr:`Reader.iterate`, else its
    list): the options are checked when this is called, the file read as the curves are asked
    for."""
    found = reader_for(path, curves=True)
    taken = check_options(found, path, {"spring_constant": spring_constant, "sensitivity": sensitivity})
    return found.iterate(path, **taken) if found.iterate is not None else iter(found.read(path, **taken))


def read_table(path, *, max_rows=None, what="table"):
    """The text table of ``path`` split into rows (the text reader's
    :func:`~shellbvp.readers.text_table.read_table`); a file another reader recognises is
    refused in one line saying what it is and how it is read."""
    found = reader_for(path)
    if found.table is None:
        raise ValueError(f"{printable(path)}: {found.what}, not a text table: {found.hint}")
    return found.table(path, max_rows=max_rows, what=what)


def folder_suffixes() -> tuple:
    """The file name endings a folder given as a batch takes (:attr:`Reader.folder_suffixes`)."""
    return tuple(s for r in READERS for s in r.folder_suffixes)


def curve_suffixes() -> tuple:
    """The file name endings the readers of curves recognise by name (``.jpk-force``, ``.ibw``, ...)."""
    return tuple(s for r in READERS if r.curves for s in r.suffixes)
