"""Text that comes from files or users, shown as data: never as terminal control or formulas.

A file's message, warnings or source name may hold escape sequences (clear the screen, move
the cursor, forge a result line) or begin like a spreadsheet formula (``=HYPERLINK(...)``).
Everything the package prints or tabulates from such text goes through :func:`printable`
(terminals, reports, plots) or :func:`table_cell` (CSV tables).
"""

from __future__ import annotations

import unicodedata

__all__ = ["printable", "table_cell"]

#: Characters kept as they are although Unicode calls them "other": none (tab and newline
#: included: one printed field stays one line).
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def printable(text) -> str:
    """``text`` with every control or format character (C0, C1, DEL, bidirectional
    overrides, zero-width ones) written as an escape (``\\x1b``, ``\\u202e``), so that it shows
    as it is and changes nothing on a terminal.

    >>> from shellbvp.textdata import printable
    >>> printable("ok\\x1b[2J done\\u202e")
    'ok\\\\x1b[2J done\\\\u202e'
    >>> printable("µm, Lepidium (2018)")
    'µm, Lepidium (2018)'
    """
    text = str(text)
    out = []
    for ch in text:
        if unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"):
            code = ord(ch)
            out.append(f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}")
        else:
            out.append(ch)
    return "".join(out)


def table_cell(text) -> str:
    """:func:`printable`, and a leading ``'`` where a spreadsheet would read a formula
    (``=``, ``+``, ``-``, ``@``; OWASP's CSV-injection rule).  Numbers are not text: pass
    them as numbers.

    >>> from shellbvp.textdata import table_cell
    >>> table_cell('=HYPERLINK("http://x","y").csv')
    '\\'=HYPERLINK("http://x","y").csv'
    """
    text = str(text)
    if text.startswith(_FORMULA_START):
        text = "'" + text
    return printable(text)
