"""The text-table reader: delimited text exports of force-displacement records.

:func:`read_table` is the text layer: encodings, ``#``/``%`` comment lines, ``,`` ``;``, tab or
whitespace delimiters, decimal commas, one or two header rows (names, then units; also as
comment lines just above the data), plain numbers only.  :func:`read_text` finds the
displacement and force (and time) columns by unit and name, converts them to SI and returns an
:class:`~shellbvp.instrument_record.InstrumentRecord` in the file's (time) order, segmented.

:data:`READER` declares it to the registry (:mod:`shellbvp.readers.registry`): it reads what no
other reader recognises, takes ``columns``, ``units`` and ``invert``, and refuses the
cantilever's calibration, pointing to the readers that take it.
"""

from __future__ import annotations

import codecs
import csv
import math
import re
from dataclasses import dataclass

import numpy as np

from ..instrument_record import InstrumentRecord, record_from_arrays
from ..paths import read_input_bytes
from ..textdata import printable
from ..units import PLAIN_NUMBER, normalize_unit, unit_factor, unit_kind
from .registry import Reader

__all__ = ["READERS", "Table", "read_table", "read_text", "header_name_and_unit", "cell_number", "bare_name",
           "unit_of", "MAX_PREAMBLE_LINES"]

_NAMES = {
    "displacement": (("displacement", "indentation", "depth", "disp", "delta", "deformation"),
                     ("position", "distance", "extension", "separation", "z", "height", "piezo", "d")),
    "force": (("force", "load"), ("f",)),
    "time": (("time",), ("t",)),
}
#: Lines of header and comments a table bounded in rows (``read_table(max_rows=...)``) may add.
MAX_PREAMBLE_LINES = 1000

_KIND = {"displacement": "length", "force": "force", "time": "time"}

_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"), (codecs.BOM_UTF8, "utf-8-sig"),
         (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))


def _decode(raw, path):
    """Text of a file: a BOM's encoding, else UTF-8, else UTF-16 (no BOM), else cp1252/Latin-1."""
    for bom, enc in _BOMS:
        if raw.startswith(bom):
            try:
                return raw.decode(enc)
            except UnicodeDecodeError as exc:
                raise ValueError(f"{path}: cannot decode as {enc} (its byte-order mark says so): {exc.reason} "
                                 f"at byte {exc.start}") from None
    tries = ["utf-8"]
    if len(raw) >= 4 and raw.count(b"\x00") >= len(raw) // 4:  # ASCII text in UTF-16 without a BOM
        tries += ["utf-16-le" if raw[1::2].count(0) > raw[0::2].count(0) else "utf-16-be"]
    for enc in tries + ["cp1252", "latin-1"]:
        try:
            text = raw.decode(enc)
        except UnicodeDecodeError:
            continue
        if not re.search(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]", text):  # control characters: not this encoding
            return text
    raise ValueError(f"{path}: not a text file in a known encoding (tried UTF-8, UTF-16, Windows-1252, Latin-1; "
                     "it holds control characters): save it as CSV text, e.g. UTF-8")


def _number(s):
    """float of a cell: "" and "nan" are NaN; a decimal comma (``1,5``) is read as ``1.5``;
    anything but a plain finite number is None."""
    t = s.strip()
    if t.count(",") == 1 and "." not in t:  # a decimal comma (the delimiter is then not a comma)
        t = t.replace(",", ".")
    if not t or t.lower() == "nan":
        return math.nan
    if not PLAIN_NUMBER.fullmatch(t):
        return None
    v = float(t)
    return v if math.isfinite(v) else None


def _unit_suffix(name):
    """The unit after a column name's last underscore (``'displacement_mm'``), where the unit
    tables know it (a name such as ``'vertical_deflection'`` has none), else None."""
    m = re.search(r"_([^\W_]+(?:/[^\W_]+)?)\s*$", name)
    return m.group(1) if m and unit_kind(m.group(1)) else None


def unit_of(name):
    """The unit in a column name: ``'Force (uN)'``, ``'force [µN]'``, ``'Time / s'``,
    ``'force_uN'`` -> the unit or None."""
    m = re.search(r"[\(\[]\s*([^\)\]]+?)\s*[\)\]]\s*$", name) or re.search(r"\s/\s*(\S+)\s*$", name)
    if m:
        return normalize_unit(m.group(1))
    suffix = _unit_suffix(name)
    return normalize_unit(suffix) if suffix else None


def header_name_and_unit(name):
    """``(bare lower-case name, unit or None)`` of a column header: ``'Thickness (um)'`` and
    ``'thickness_um'`` give ``('thickness', 'um')`` (other tables, such as a force map's pixel
    table, name their columns as instrument files do)."""
    return bare_name(name), unit_of(name)


def cell_number(text):
    """A table cell as a float as the instrument reader reads it (a decimal comma allowed; ""
    and "nan" NaN), or None when it is no plain finite number."""
    return _number(text)


def bare_name(name):
    """A column header's lower-case name without its unit: ``'Force (uN)'`` -> ``'force'``."""
    bare = re.sub(r"\s*([\(\[][^\)\]]*[\)\]]|/\s*\S+)\s*$", "", name).strip()
    suffix = _unit_suffix(bare)
    return (bare[:-len(suffix) - 1] if suffix else bare).strip().lower()


@dataclass
class Table:
    """The text of a delimited file, split (:func:`read_table`).

    Attributes
    ----------
    header : list of str
        Column names ('' where the file gives none; empty list without a header).
    header_units : list of str or None
        The units row (second header row) when the file has one.
    rows : list of list of str
        The data rows' cells.
    line : list of int
        Each data row's line number in the file (comment and blank lines counted).
    delimiter : str
    """

    header: list
    header_units: list
    rows: list
    line: list
    delimiter: str


def read_table(path, *, max_rows=None, what="table") -> Table:
    """Split a delimited text file into header rows and data rows.

    ``#`` and ``%`` start comment lines; blank lines are skipped; the delimiter
    (``,`` ``;`` or tab, else whitespace) is sniffed.  Leading rows that are not all
    numbers are header rows: the last one before the data (or the last two, when the
    second names units, e.g. ``um``, ``(µN)``, ``s``) -- earlier ones (an instrument's
    preamble) are skipped.  Without such rows, the header may be in the comment lines
    just above the data, as many cells as the data after an optional ``columns:`` or
    ``units:`` label (``# columns: height vDeflection`` / ``# units: m N``).

    ``max_rows`` bounds the data rows (``what`` names the table in the message): a file with
    more lines than that and :data:`MAX_PREAMBLE_LINES` is refused before it is split.

    Raises
    ------
    ValueError
        The file cannot be read or decoded, or holds no data, or more than ``max_rows`` rows.
    """
    raw = read_input_bytes(path)  # a regular file of bounded size: never a FIFO, a device or a folder
    text = _decode(raw, path)
    del raw
    if max_rows is not None and text.count("\n") > max_rows + MAX_PREAMBLE_LINES:
        raise ValueError(f"{path}: {text.count(chr(10))} lines; a {what} has at most {max_rows} rows (and "
                         f"{MAX_PREAMBLE_LINES} lines of header and comments)")
    all_lines = text.splitlines()
    del text
    numbered = [(i, ln) for i, ln in enumerate(all_lines, start=1)
                if ln.strip() and not ln.lstrip().startswith(("#", "%"))]
    if not numbered:
        raise ValueError(f"{path}: no data")
    lines = [ln for _, ln in numbered]
    sample = lines[-20:]
    if not any(c in ln for ln in sample for c in ",;\t"):
        delim = " "  # whitespace-separated columns (e.g. JPK's ASCII export)
    else:
        try:
            delim = csv.Sniffer().sniff("\n".join(lines[:20]), delimiters=",;\t").delimiter
        except csv.Error:
            delim = "\t" if "\t" in lines[-1] else (";" if ";" in lines[-1] else ",")
    delim = _numeric_delimiter(sample, delim)
    rows = [_split(ln, delim) for ln in lines]
    line_no = [i for i, _ in numbered]
    first = next((k for k, r in enumerate(rows) if r and all(_number(c) is not None for c in r)), len(rows))
    if first == len(rows):
        raise ValueError(f"{path}: fewer than 3 rows with numbers (no row is all numbers)")
    if max_rows is not None and len(rows) - first > max_rows:
        raise ValueError(f"{path}: {len(rows) - first} rows; a {what} has at most {max_rows}")
    heads = [_header_cells(ln, delim, len(rows[first])) for ln in lines[:first]]
    if not heads:  # no header among the data lines: one in the comment lines just above them
        heads = _commented_header(all_lines[:line_no[0] - 1], delim, len(rows[first]))
    header, header_units = [], None
    if heads:
        width = len(rows[first]) if first < len(rows) else len(heads[-1])
        heads = [h for h in heads if len(h) == width] or heads[-1:]  # a preamble of other widths: skipped
        if len(heads) >= 2 and all(not c.strip() or unit_kind(c) for c in heads[-1]) and \
                any(c.strip() for c in heads[-1]):
            header, header_units = [c.strip() for c in heads[-2]], [normalize_unit(c) for c in heads[-1]]
        else:
            header = [c.strip() for c in heads[-1]]
    return Table(header=header, header_units=header_units, rows=rows[first:], line=line_no[first:], delimiter=delim)


def _numeric_delimiter(sample, delim):
    """``delim``, unless the data lines (``sample``, the last of the file) split by it are not
    all numbers while another delimiter splits them into equal rows of numbers: a headerless
    table with decimal commas (``0,5<TAB>1,5``) is tab-separated, not comma-separated."""
    def numbers(d):
        cells = [_split(ln, d) for ln in sample]
        return len({len(c) for c in cells}) == 1 and len(cells[0]) >= 2 and \
            all(x.strip() and _number(x) is not None for c in cells for x in c)

    if numbers(delim):
        return delim
    return next((d for d in ("\t", ";", " ") if d != delim and numbers(d)), delim)


def _header_cells(line, delim, width):
    """The cells of a header line; in a whitespace-separated table, names with spaces or a unit
    (``displacement (mm)   force (mN)``) are split at runs of two or more spaces or tabs, or
    each ``(unit)``/``[unit]`` is joined to the name before it, when that gives ``width`` cells."""
    cells = _split(line, delim)
    if delim != " " or len(cells) == width:
        return cells
    wide = [c for c in re.split(r"\t|\s{2,}", line.strip()) if c]
    if len(wide) == width:
        return wide
    joined = []
    for c in cells:
        if joined and c[:1] in "([":
            joined[-1] += " " + c
        else:
            joined.append(c)
    return joined if len(joined) == width else cells


def _split(line, delim):
    """The cells of one line: ``delim``-separated, or whitespace-separated for ``" "``."""
    if delim == " ":
        return next(csv.reader([line.strip()], delimiter=" ", skipinitialspace=True), [])
    return next(csv.reader([line], delimiter=delim), [])


#: Labels an instrument puts before a commented header row (``# columns: height vDeflection``).
_HEADER_LABELS = ("columns", "fancynames", "names", "units", "header")


def _commented_header(comments, delim, width):
    """Header rows from the comment lines above the data: those (nearest first, up to 40 lines)
    with as many cells as the data once the comment mark and a ``label:`` are removed, as
    [names] or [names, units] (a row of units only is the units row)."""
    found = []
    for line in reversed(comments[-40:]):
        body = line.strip()
        if not body.startswith(("#", "%")):
            break  # the comment block above the data has ended
        body = body.lstrip("#%").strip()
        label, sep, rest = body.partition(":")
        labelled = sep and label.strip().lower().replace(" ", "") in _HEADER_LABELS
        cells = [c.strip() for c in _header_cells(rest if labelled else body, delim, width)]
        if len(cells) == width and all(cells):
            found.append((label.strip().lower() if labelled else "", cells))
    units = next((c for lab, c in found if all(unit_kind(x) for x in c)), None)
    names = [c for lab, c in found if not all(unit_kind(x) for x in c) and not any(_number(x) is not None for x in c)]
    preferred = [c for lab, c in found if lab in ("columns", "names", "header")]
    if not names:
        return []
    best = next((c for c in preferred if c in names), names[0])
    return [best, units] if units else [best]


def _column_unit(table, i):
    if table.header_units is not None and i < len(table.header_units) and table.header_units[i]:
        return table.header_units[i]
    return unit_of(table.header[i]) if i < len(table.header) else None


def _describe_header(table):
    if not table.header:
        return "the file has no header row"
    cols = [h + (f" [{table.header_units[i]}]" if table.header_units and i < len(table.header_units)
                 and table.header_units[i] else "") for i, h in enumerate(table.header)]
    return "its columns are " + ", ".join(f"{i}: {c!r}" for i, c in enumerate(cols))


def _find_column(table, role, path, taken):
    """Index of the column holding ``role`` (displacement, force, time), by unit and name; None if absent."""
    n = len(table.header)
    kind = _KIND[role]
    by_unit = [i for i in range(n) if i not in taken and unit_kind(_column_unit(table, i) or "", extended=True) == kind]
    tiers = _NAMES[role]

    def rank(i):
        """0: a plain name, 1: a generic one, 2: neither."""
        bare = bare_name(table.header[i])
        words = re.split(r"[\s_\-./]+", bare)
        for k, names in enumerate(tiers):
            if any(w == bare or (len(w) > 1 and w in words) for w in names):
                return k
        return len(tiers)

    pool = by_unit or [i for i in range(n) if i not in taken and rank(i) < len(tiers)]
    if len(pool) <= 1:
        return pool[0] if pool else None
    ranked = sorted(pool, key=rank)
    if rank(ranked[0]) < rank(ranked[1]):
        return ranked[0]
    raise ValueError(f"{path}: more than one column could be the {role} ({', '.join(repr(table.header[i]) for i in pool)}); "
                     f"{_describe_header(table)}; choose with --columns DISPLACEMENT,FORCE")


def _pick_columns(table, columns, path):
    """(displacement, force, time or None) column indices."""
    n = len(table.header)
    if columns is not None:
        cols = []
        for c in columns:
            if isinstance(c, int) or (isinstance(c, str) and c.strip().isdigit()):
                cols.append(int(c))
                continue
            if not table.header:
                raise ValueError(f"{path}: column {c!r} given by name but the file has no header")
            key = str(c).strip().lower()
            names = [bare_name(h) for h in table.header]
            full = [h.strip().lower() for h in table.header]
            if key in full:
                cols.append(full.index(key))
            elif key in names:
                cols.append(names.index(key))
            else:
                raise ValueError(f"{path}: no column named {c!r}; {_describe_header(table)}")
        if len(cols) not in (2, 3):
            raise ValueError(f"{path}: columns must be two (displacement, force) or three (and time); got {columns!r}")
        return cols[0], cols[1], (cols[2] if len(cols) == 3 else None)
    if n == 0:
        return 0, 1, None  # no header: the first two columns
    disp = _find_column(table, "displacement", path, set())
    force = _find_column(table, "force", path, {disp} if disp is not None else set())
    if (disp is None or force is None) and n == 2 and len(table.rows[0]) == 2:
        return 0, 1, None  # two columns named neither way: displacement, then force
    if disp is None or force is None:
        missing = " and ".join(r for r, c in (("displacement", disp), ("force", force)) if c is None)
        raise ValueError(f"{path}: cannot tell which column is the {missing} (by unit or name); "
                         f"{_describe_header(table)}; choose with --columns DISPLACEMENT,FORCE "
                         f"(names or 0-based indices) and give units with --units, e.g. um,uN")
    time = _find_column(table, "time", path, {disp, force})
    return disp, force, time


def read_text(path, *, columns=None, units=None, invert=()) -> InstrumentRecord:
    """The record of a delimited text export (:func:`shellbvp.instrument.read_instrument` says
    what ``columns``, ``units`` and ``invert`` do)."""
    flip = _check_invert(invert)
    table = read_table(path)
    dcol, fcol, tcol = _pick_columns(table, columns, path)
    roles = [("displacement", dcol), ("force", fcol)] + ([("time", tcol)] if tcol is not None else [])
    given = list(units) if units is not None else []
    unit_names, factors, notes = {}, {}, []
    for k, (role, col) in enumerate(list(roles)):
        by_user = k < len(given) and bool(given[k])
        u = given[k] if by_user else (_column_unit(table, col) if table.header else None)
        if u is None:
            if role == "time":
                u = "s"
            else:
                raise ValueError(f"{path}: units of the {role} column unknown; {_describe_header(table)}; give "
                                 "them in the header, e.g. 'Displacement (um)', or with --units um,uN")
        try:
            factors[role] = unit_factor(u, _KIND[role])
        except ValueError as exc:
            if role == "time" and not by_user:
                # the time only orders the rows: a header unit that is not a time drops the column, not the file
                roles.remove((role, col))
                notes.append(_dropped_time_note(table, col, u, exc))
                continue
            raise ValueError(f"{path}: {role} column: {exc}") from None
        unit_names[role] = normalize_unit(u)
    values = {role: [] for role, _ in roles}
    lines = []
    for n, row in zip(table.line, table.rows):
        if all(not c.strip() for c in row):
            continue
        try:
            cells = [row[col].strip() for _, col in roles]
        except IndexError:
            raise ValueError(f"{path}: line {n} has {len(row)} columns; need column "
                             f"{max(c for _, c in roles)}") from None
        nums = [_number(c) for c in cells]
        if any(v is None for v in nums):
            raise ValueError(f"{path}: line {n}: cannot read {', '.join(repr(c) for c in cells)} as numbers (plain "
                             "finite decimals such as 1.5, -2e-3 or 1,5; empty or nan for a missing value)")
        si = [v * factors[role] for v, (role, _) in zip(nums, roles)]
        if any(math.isinf(v) for v in si):
            raise ValueError(f"{path}: line {n}: {', '.join(repr(c) for c in cells)} overflow when converted to "
                             f"SI units ({', '.join(unit_names.values())})")
        for v, (role, _) in zip(si, roles):
            values[role].append(v)
        lines.append(n)
    arr = {role: np.array(v, float) for role, v in values.items()}
    ok = np.all([np.isfinite(a) for a in arr.values()], axis=0) if lines else np.zeros(0, bool)
    if ok.sum() < 3:
        raise ValueError(f"{path}: fewer than 3 rows with numbers")
    arr = {role: -a[ok] if role in flip else a[ok] for role, a in arr.items()}
    name = (lambda c: table.header[c] if c < len(table.header) and table.header[c] else c)
    return record_from_arrays(path, arr["displacement"], arr["force"], arr.get("time"), np.array(lines)[ok],
                              columns={role: name(col) for role, col in roles}, units=unit_names,
                              header=list(table.header), inverted=tuple(sorted(flip)), notes=tuple(notes))


def _dropped_time_note(table, col, unit, exc):
    """The record's note on a time column left out for its unit; the file's text in it escaped
    (:func:`shellbvp.textdata.printable`): it is shown and stored as data."""
    name = table.header[col] if col < len(table.header) else col
    return printable(f"time column {name!r} not used: its unit {unit!r} is not a time ({exc}); the rows are "
                     f"in the file's order")


def _check_invert(invert):
    """The roles of ``invert`` (displacement, force) as a set; ValueError naming the parameter."""
    if isinstance(invert, str):
        invert = [invert]
    roles = set()
    for role in invert or ():
        if role not in ("displacement", "force"):
            raise ValueError(f"invert must name displacement and/or force; got {role!r}")
        roles.add(role)
    return roles


#: The reader of text exports: what no other reader recognises
READERS = (Reader(
    name="text table", order=100, fallback=True, folder_suffixes=(".csv", ".tsv", ".txt", ".dat"),
    what="a text table (delimited columns of numbers)",
    hint="a text export: `shellbvp fit FILE` and shellbvp.read_instrument read it (--columns, --units, --invert)",
    options=("columns", "units", "invert"),
    refusals={"calibration": "not an AFM file: --spring-constant and --sensitivity are for AFM text exports "
                             "({takers})"},
    read=read_text, table=read_table),)
