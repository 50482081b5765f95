"""Tally kinds of ``benchmarks/trust_tally.py`` for AFM files (issue 59, items 4 and 5).

* ``afmdamaged`` -- damaged AFM data: seeded mutations of a JPK curve, a JPK force map and an
  Asylum ``.ibw`` (a flipped CRC, a broken deflate stream, a member dropped, a property set to
  NaN, junk, an escape sequence or a huge number, bytes flipped in a header, a file cut short)
  read by ``shellbvp.afm.read_afm``; one in four also through ``shellbvp fit FILE --json``, and a
  batch of a good file and damaged ones (a row per file, the good one's fitted, one JSON document).
* ``afmsizes`` -- oversized inputs: archives inflating to 1 GiB, a central directory declared
  at 100 MB, ``.ibw`` headers declaring gigabytes, a map header declaring a 100000 x 100000 grid,
  pixel tables of 1 and 10.9 million rows; each ``shellbvp fit`` run in a process capped at
  1.5 GB of address space, its peak resident memory measured (``/usr/bin/time``).

A read is a clear error (one-line ValueError, no control character of the file in it) or a
result with finite numbers; anything else -- another exception, a traceback, afmformats'
log on stderr, a --json stdout that is not one document, a peak over :data:`RSS_LIMIT_MB` --
is a DEFECT.  Run only these kinds::

    python3 benchmarks/trust_tally.py --only afmdamaged,afmsizes
"""

from __future__ import annotations

import json
import logging
import os
import re
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
AFM_DATA = ROOT / "tests" / "data" / "afm"
SPOT = AFM_DATA / "spot3-0192.jpk-force"
IBW = AFM_DATA / "SiN_FD_plot.ibw"
CAP_BYTES = int(1.5 * 2**30)   # address space of each CLI run: a regression cannot take the machine down
RSS_LIMIT_MB = 1024            # a peak above this (under the cap) is a DEFECT
TIMEOUT = 300

KINDS = {"afmdamaged": "13. damaged AFM data", "afmsizes": "14. oversized AFM archives, headers and tables"}
KIND_NOTES = {
    "afmdamaged": "Seeded mutations of tests/data/afm/spot3-0192.jpk-force, of a 2 x 2 JPK force map made from "
                  "it and of SiN_FD_plot.ibw, read by `read_afm` (a clear error or finite curves; afmformats and "
                  "igor2 must log nothing at WARNING or above); one in four also by `shellbvp fit FILE --json`; and "
                  "batches of the good curve with damaged ones (`fit GOOD BAD... --json`).",
    "afmsizes": f"Each input fitted by `shellbvp fit` in a process limited to {CAP_BYTES / 2**30:.1f} GB of address "
                f"space; the outcome's detail gives the peak resident memory (DEFECT above {RSS_LIMIT_MB} MB, or "
                "any MemoryError or traceback).",
}


def hook(kinds, notes):
    """Add this module's kinds to trust_tally's tables (its ``main`` takes :func:`functions` and
    :func:`sizes`)."""
    kinds.update(KINDS)
    notes.update(KIND_NOTES)


def functions() -> dict:
    return {"afmdamaged": kind_afmdamaged, "afmsizes": kind_afmsizes}


def sizes(quick) -> dict:
    """Inputs per kind."""
    return {"afmdamaged": 16 if quick else 120, "afmsizes": 4 if quick else 20}


def _tt():
    import trust_tally  # the script's helpers (rec, call, judge_exception); imported when a kind runs

    return trust_tally


# -- mutations --------------------------------------------------------------------------------------------
def _members(src):
    with zipfile.ZipFile(src) as z:
        return [(i, z.read(i.filename)) for i in z.infolist()]


def rewrite(src, dst, edit=None, drop=(), extra=()):
    """A copy of the archive ``src``: property files through ``edit(name, text)``, members dropped or added."""
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zo:
        for info, data in _members(src):
            if info.filename in drop:
                continue
            if edit and info.filename.endswith(".properties"):
                data = edit(info.filename, data.decode("latin-1")).encode("utf-8")  # junk values: any text
            zo.writestr(info.filename, data)
        for name, data in extra:
            zo.writestr(name, data)
    return dst


def _data_offset(raw, info):
    n, m = struct.unpack("<HH", raw[info.header_offset + 26:info.header_offset + 30])
    return info.header_offset + 30 + n + m


JUNK = ["NaN", "nan", "inf", "-inf", "", "1e308", "-1", "0", "abc", "\x1b[2J\x1b[31mforged", "1e-320",
        "99999999999999999999", "signedshort signedshort", "\u202eevil"]


def mutate_archive(src, dst, rng):
    """One seeded damage to a JPK archive; returns its description."""
    with zipfile.ZipFile(src) as z:
        infos = [i for i in z.infolist() if i.file_size > 0]
    what = rng.choice(["crc", "deflate", "drop", "property", "property", "truncate", "flip"])
    info = rng.choice(infos)
    raw = bytearray(Path(src).read_bytes())
    if what == "crc":
        raw[info.header_offset + 14] ^= 0xFF
        at = raw.find(b"PK\x01\x02")
        while at >= 0:
            n = struct.unpack("<H", raw[at + 28:at + 30])[0]
            if raw[at + 46:at + 46 + n] == info.filename.encode():
                raw[at + 16] ^= 0xFF
            at = raw.find(b"PK\x01\x02", at + 4)
        Path(dst).write_bytes(bytes(raw))
        return f"CRC of {info.filename} flipped"
    if what == "deflate":
        k = _data_offset(raw, info) + rng.randrange(max(1, info.compress_size))
        raw[k] ^= rng.randrange(1, 256)
        Path(dst).write_bytes(bytes(raw))
        return f"a byte of {info.filename}'s deflate stream flipped"
    if what == "drop":
        rewrite(src, dst, drop=(info.filename,))
        return f"{info.filename} dropped"
    if what == "property":
        props = [i for i in infos if i.filename.endswith(".properties")]
        name = rng.choice(props).filename
        text = dict((i.filename, d) for i, d in _members(src))[name].decode("latin-1").splitlines()
        keys = [ln.split("=")[0] for ln in text if "=" in ln and any(w in ln for w in (
            "encoder", "scaling", "spring", "sensitivity", "channels.list", "point-count", "grid", "position",
            "segment", "name"))]
        key, value = rng.choice(keys), rng.choice(JUNK)
        rewrite(src, dst, edit=lambda n, t: "\n".join(f"{key}={value}" if n == name and ln.split("=")[0] == key
                                                      else ln for ln in t.splitlines()))
        return f"{name}: {key}={value!r}"
    if what == "truncate":
        cut = rng.randrange(len(raw) // 10, len(raw))
        Path(dst).write_bytes(bytes(raw[:cut]))
        return f"cut at byte {cut} of {len(raw)}"
    for _ in range(rng.randint(1, 8)):
        raw[rng.randrange(len(raw))] ^= rng.randrange(1, 256)
    Path(dst).write_bytes(bytes(raw))
    return "bytes flipped anywhere"


def mutate_ibw(src, dst, rng):
    raw = bytearray(Path(src).read_bytes())
    what = rng.choice(["field", "field", "header bytes", "truncate"])
    if what == "field":
        offset = rng.choice(range(4, 64, 4)) if rng.random() < 0.7 else rng.choice(range(64, 384, 4))
        value = rng.choice([0x7FFFFFF0, -5, 2**30, 0, 1, 123456789, -2**31])
        raw[offset:offset + 4] = struct.pack("<l", value)
        desc = f"int32 at byte {offset} set to {value}"
    elif what == "header bytes":
        for _ in range(rng.randint(1, 6)):
            raw[rng.randrange(384)] ^= rng.randrange(1, 256)
        desc = "header bytes flipped"
    else:
        cut = rng.randrange(16, len(raw))
        raw = raw[:cut]
        desc = f"cut at byte {cut}"
    Path(dst).write_bytes(bytes(raw))
    return desc


def make_map(dst):
    """A 2 x 2 JPK force map of the shell model (benchmarks/make_force_map.py, 200 points a curve)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from make_force_map import write_map

    if not Path(dst).exists():
        write_map(dst, n=2, points=200)
    return Path(dst)


# -- judging ----------------------------------------------------------------------------------------------
class _AfmLog(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.records = []

    def emit(self, record):
        self.records.append(record.getMessage()[:200])


def judge_afm_read(path):
    """(outcome, detail, seconds) of ``read_afm(path)``."""
    from shellbvp.afm import read_afm

    tt = _tt()
    log = _AfmLog()
    for name in ("afmformats", "igor2"):
        logging.getLogger(name).addHandler(log)
    try:
        out = tt.call(lambda: read_afm(path), limit=60)
    finally:
        for name in ("afmformats", "igor2"):
            logging.getLogger(name).removeHandler(log)
    if log.records:
        return "DEFECT", f"a reader logged: {log.records[0]}", out["seconds"]
    if out["exc"] is not None:
        o, d = tt.judge_exception(out)
        if o == "clear error" and re.search(r"[\x00-\x08\x0b-\x1f\x7f\u202e]", str(out["exc"])):
            return "DEFECT", f"control characters in the message: {str(out['exc'])[:200]!r}", out["seconds"]
        return o, d, out["seconds"]
    curves = out["result"]
    bad = [c.index for c in curves if not (np.all(np.isfinite(c.record.displacement))
                                           and np.all(np.isfinite(c.record.force)) and len(c.record) >= 3)]
    if bad:
        return "DEFECT", f"curves {bad} with non-finite numbers accepted", out["seconds"]
    return "correct result", f"{len(curves)} curves of {sum(len(c.record) for c in curves)} rows", out["seconds"]


def run_capped(args, cwd, json_mode=True, stdout=None):
    """``python -m shellbvp ARGS`` under :data:`CAP_BYTES` of address space: (outcome, detail, seconds)
    classified as trust_tally's ``run_cli`` does, the peak resident memory in the detail; the
    run's stdout appended to the list ``stdout`` when given."""
    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (CAP_BYTES, CAP_BYTES))

    timer = shutil.which("time") or "/usr/bin/time"
    rss_file = Path(cwd) / ".maxrss"
    cmd = [sys.executable, "-m", "shellbvp", *args]
    if os.path.exists(timer):
        cmd = [timer, "-f", "%M", "-o", str(rss_file), *cmd]
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL,
                           preexec_fn=cap, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    except subprocess.TimeoutExpired:
        return "DEFECT", f"no exit within {TIMEOUT} s", time.perf_counter() - t0
    dt = time.perf_counter() - t0
    try:
        rss = int(rss_file.read_text().split()[-1]) // 1024
    except (OSError, ValueError, IndexError):
        rss = -1
    code, out, err = p.returncode, p.stdout, p.stderr
    if stdout is not None:
        stdout.append(out)
    peak = f"peak {rss} MB" if rss >= 0 else "peak not measured"
    if "Traceback" in err or "MemoryError" in err:
        return "DEFECT", f"{peak}; traceback; exit {code}; {err.strip()[-300:]!r}", dt
    if rss > RSS_LIMIT_MB:
        return "DEFECT", f"{peak} > {RSS_LIMIT_MB} MB; exit {code}", dt
    if json_mode:
        try:
            doc = json.loads(out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
        except ValueError as exc:
            return "DEFECT", f"{peak}; --json stdout not one strict JSON document ({exc}); exit {code}", dt
        if not isinstance(doc, dict) or doc.get("exit_status", code) != code:
            return "DEFECT", f"{peak}; exit_status of the document != exit {code}", dt
    lines = err.strip().splitlines()
    if code == 2:
        if err.startswith("shellbvp: error:") and len(lines) == 1:
            return "clear error", f"{peak}; {err.strip()[:300]}", dt
        return "DEFECT", f"{peak}; exit 2 but stderr {err.strip()[:300]!r}", dt
    if lines:
        return "DEFECT", f"{peak}; exit {code} with stderr {err.strip()[:300]!r}", dt
    if code == 0:
        return ("warning" if re.search(r'"warnings": \[[^\]]', out) else "correct result"), f"{peak}; exit 0", dt
    if code == 1:
        return "failed status", f"{peak}; exit 1", dt
    return "DEFECT", f"{peak}; exit {code}", dt


# -- kinds ------------------------------------------------------------------------------------------------
def kind_afmdamaged(n, rng, tmp):
    tt = _tt()
    sources = [SPOT, make_map(tmp / "map.jpk-force-map"), IBW]
    records, damaged = [], []
    for k in range(n):
        src = sources[k % 3]
        dst = tmp / f"d{k}{''.join(src.suffixes[-1:])}"
        desc = (mutate_ibw if src.suffix == ".ibw" else mutate_archive)(src, dst, rng)
        o, d, dt = judge_afm_read(dst)
        records.append(tt.rec("afmdamaged", "read_afm", f"{src.name}: {desc}", o, d, dt))
        if o == "clear error":
            damaged.append((dst, desc))
        if k % 4 == 0:
            # -q: a slow fit prints progress lines to a stderr that is not a terminal (not an error)
            o, d, dt = run_capped(["fit", dst.name, "--preset", "fit", "--radius", "10um", "--json", "-q"], tmp)
            records.append(tt.rec("afmdamaged", "fit --json", f"{src.name}: {desc}", o, d, dt))
    good = tmp / "good.csv"
    from shellbvp.fitting import example_data_path

    shutil.copyfile(example_data_path(), good)
    for j in range(0, min(len(damaged), 6), 3):
        batch = [d for d, _ in damaged[j:j + 3]]
        t0 = time.perf_counter()
        printed = []
        o, d, _ = run_capped(["fit", "good.csv", *[b.name for b in batch], "--preset", "fit", "--radius", "0.3mm",
                              "--json", "-q"], tmp, stdout=printed)
        if o != "DEFECT":
            doc = json.loads(printed[0])
            status = [f["status"] for f in doc["files"]]
            ok = len(status) == 1 + len(batch) and doc["files"][0].get("success") is True and \
                all(f["status"] == "error" for f in doc["files"][1:])
            o, d = ("failed status", f"{d}; rows: the good file fitted, {len(batch)} errors") if ok else \
                ("DEFECT", f"rows {status}")
        records.append(tt.rec("afmdamaged", "fit (batch) --json", "good.csv + " + ", ".join(
            desc for _, desc in damaged[j:j + 3]), o, d, time.perf_counter() - t0))
    return records


def _bomb(dst, member=None, size=2**30):
    """SPOT with ``member`` (or a new one) inflating to ``size`` bytes of zeros."""
    with zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zo:
        for info, data in _members(SPOT):
            if info.filename != member:
                zo.writestr(info.filename, data)
        with zo.open(member or "segments/0/channels/big.dat", "w", force_zip64=True) as fh:
            block = bytes(2**20)
            for _ in range(size // 2**20):
                fh.write(block)
    return dst


def _central_directory_declared(dst, cd_size):
    raw = bytearray(SPOT.read_bytes())
    at = raw.rfind(b"PK\x05\x06")
    raw[at + 12:at + 16] = struct.pack("<L", cd_size)
    Path(dst).write_bytes(bytes(raw))
    return dst


def kind_afmsizes(n, rng, tmp):
    tt = _tt()
    fit = ["--preset", "fit", "--radius", "10um", "--json", "-q"]
    inputs = [
        ("an archive with a member inflating to 1 GiB (1 MB on disk)", lambda: _bomb(tmp / "bomb.jpk-force")),
        ("the force channel inflating to 1 GiB", lambda: _bomb(tmp / "bomb2.jpk-force",
                                                                "segments/0/channels/vDeflection.dat")),
        ("a central directory declared at 100 MB", lambda: _central_directory_declared(tmp / "cd.jpk-force",
                                                                                       100 * 2**20)),
        ("a JPK curve with 30,000 empty members (within the bound)",
         lambda: rewrite(SPOT, tmp / "many.jpk-force", extra=[(f"junk/{i}", b"") for i in range(30000)])),
    ]
    for name, offset in (("wfmSize", 4), ("noteSize", 12), ("dimLabelsSize[0]", 36), ("sIndicesSize", 52),
                         ("npnts", 76), ("nDim[0]", 132)):
        for value in (0x7FFFFFF0, 2**30):
            def make(offset=offset, value=value, name=name):
                raw = bytearray(IBW.read_bytes())
                raw[offset:offset + 4] = struct.pack("<l", value)
                p = tmp / f"ibw-{name}-{value}.ibw"
                p.write_bytes(bytes(raw))
                return p
            inputs.append((f".ibw header {name} = {value}", make))

    def grid_map():
        src = make_map(tmp / "map.jpk-force-map")
        return rewrite(src, tmp / "grid.jpk-force-map", edit=lambda n, t: t.replace(
            "grid.ilength=2\n", "grid.ilength=100000\n").replace("grid.jlength=2\n", "grid.jlength=100000\n"))
    inputs.append(("a map header declaring a 100000 x 100000 grid (4 curves)", grid_map))

    def table(rows, name):
        side = int(np.ceil(np.sqrt(rows)))
        with open(tmp / name, "w") as fh:
            fh.write("ix,iy,thickness_um\n")
            for i in range(side):
                fh.write("".join(f"{i},{j},0.5\n" for j in range(min(side, rows - i * side))))
        return tmp / name
    inputs.append(("a pixel table of 10.9 million rows (145 MB) for a 2 x 2 map",
                   lambda: ("pixels", table(10_890_000, "big-pixels.csv"))))
    inputs.append(("a pixel table of 1,048,576 rows (the bound, 12 MB) for a 2 x 2 map",
                   lambda: ("pixels", table(1024 * 1024, "mega-pixels.csv"))))
    records = []
    make_map(tmp / "map.jpk-force-map")
    for desc, make in inputs[:max(n, 1)]:
        made = make()
        if isinstance(made, tuple):
            args = ["fit", "map.jpk-force-map", "--pixel-table", made[1].name, *fit]
        else:
            args = ["fit", made.name, *fit]
        o, d, dt = run_capped(args, tmp)
        records.append(tt.rec("afmsizes", "fit (capped)", desc, o, d, dt))
    return records


if __name__ == "__main__":
    sys.exit(subprocess.call([sys.executable, str(Path(__file__).with_name("trust_tally.py")), "--only",
                              ",".join(KINDS), *sys.argv[1:]]))
