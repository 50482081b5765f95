"""Trust tally classes of the code cache and of writes (issue 59), run by ``trust_tally.py``:

9. tampered kept model curves -> ``shellbvp fit``: must give the fit of an untouched cache (the
   bad file set aside, the curve computed again), never another mu*H, never a failed fit;
10. unusable cache folders (read-only, a file, a directory for an entry, another user's,
    writable by all) -> ``shellbvp fit``: the same fit, the cache skipped with a warning;
11. damaged compiled kernels (numba's cache files) -> ``shellbvp compile`` then ``fit``: compiled
    again, no traceback, and the run after it does not warn (needs numba; else not tried);
12. a full disk (``RLIMIT_FSIZE``, SIGXFSZ ignored: writes fail with EFBIG; and a 16 kB tmpfs,
    ENOSPC, where ``unshare -rm`` is allowed) while writing a kept curve, ``fit -o`` (with and
    without ``--json``) and ``curve -o``: the result printed, one ``shellbvp: error:`` line naming
    the file, exit 2, no partial or hidden ``.tmp`` file left, no traceback or crash.

Every input is a fresh ``python -m shellbvp`` process on the packaged example record; the
reference is the same fit with a clean cache.  Run only these::

    python3 benchmarks/trust_tally.py --only keptcurves,cachefolders,kernels,fulldisk \
        --out benchmarks/results/trust_cache.md     # ~8.5 min on 2 cores; --quick: ~2 min
"""

from __future__ import annotations

import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

KINDS = {
    "keptcurves": "9. tampered kept model curves",
    "cachefolders": "10. unusable cache folders",
    "kernels": "11. damaged compiled kernels",
    "fulldisk": "12. a full disk while writing",
}
KIND_NOTES = {
    "keptcurves": "Inputs: the kept curve of `fit --example --preset fit --radius 0.3mm` with one change: a bit "
                  "flipped in the force (several positions), the force doubled or scaled by 1.01, a NaN, half "
                  "the points, delta shifted, another scene attribute, the checksum removed, the file replaced by "
                  "random bytes or emptied, mode 0666, a symbolic link, a directory in its place, another "
                  "scene's curve under its name. Correct = exit 0 with the clean cache's mu*H; a different mu*H "
                  "or a failed fit is a DEFECT.",
    "cachefolders": "Inputs: `curves/` read-only (a read-only tmpfs, where `unshare -rm` is allowed), a regular "
                    "file, mode 0777, owned by another user; the curve's entry a directory; the whole code cache "
                    "writable by all. Correct = exit 0 with the clean cache's mu*H.",
    "kernels": "Inputs (numba installed): numba's cache files of the fit preset's kernels with a data file of "
               "random bytes, emptied, an index file cut short. `shellbvp compile --preset fit` must exit 0 "
               "having compiled them again, then a fit must run with no WARNING line.",
    "fulldisk": "Inputs: `fit -o` (text and --json), a kept curve being written, `curve -o`, under file-size "
                "limits of 2-30 kB (EFBIG) and on a 16 kB tmpfs (ENOSPC). Clear error = exit 2, one "
                "`shellbvp: error:` line naming the file, the fit's result printed first (the JSON document "
                "says write_error), no file or hidden .tmp left, no traceback.",
}
SIZES = {"keptcurves": 16, "cachefolders": 6, "kernels": 3, "fulldisk": 10}
QUICK = {"keptcurves": 4, "cachefolders": 3, "kernels": 1, "fulldisk": 4}
FIT = ["fit", "--example", "--preset", "fit", "--radius", "0.3mm"]
TIMEOUT = 600


def sizes(quick):
    return dict(QUICK if quick else SIZES)


def rec(kind, target, text, outcome, detail="", seconds=0.0):
    return {"kind": kind, "target": target, "input": text, "outcome": outcome, "detail": detail,
            "seconds": seconds}


def _env(cache, kernels="numpy"):
    here = str(Path(__file__).resolve().parent.parent)
    return dict(os.environ, SHELLBVP_CACHE_DIR=str(cache), SHELLBVP_KERNELS=kernels,
                PYTHONPATH=here + os.pathsep + os.environ.get("PYTHONPATH", ""))


def _run(args, cwd, env, preexec=None, wrap=()):
    t0 = time.perf_counter()
    try:
        r = subprocess.run([*wrap, sys.executable, "-m", "shellbvp", *args], cwd=cwd, env=env, capture_output=True,
                           text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL, preexec_fn=preexec)
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - t0
    return r, time.perf_counter() - t0


def _mu(r):
    m = re.search(r"(?m)^mu\*H\s+=\s+(\S+)", r.stdout)
    return m.group(1) if m else None


def _judge_fit(r, ref):
    """A fit that must give the reference mu*H whatever the cache holds."""
    if r is None:
        return "DEFECT", f"no exit within {TIMEOUT} s"
    if "Traceback" in r.stderr or r.returncode != 0:
        return "DEFECT", f"exit {r.returncode}; stderr: {r.stderr.strip()[-300:]!r}"
    mu = _mu(r)
    if mu != ref:
        return "DEFECT", f"mu*H {mu} instead of {ref} (silently changed)"
    said = [ln for ln in r.stderr.splitlines() if ln.startswith("WARNING")]
    return "correct result", f"mu*H {mu}; {said[0][:200] if said else 'no warning'}"


def _warm(tmp):
    """A code cache with the fit preset's code and its kept curve; the reference mu*H."""
    cache = tmp / "cache"
    r, _ = _run(FIT, tmp, _env(cache))
    if r is None or r.returncode != 0:
        raise RuntimeError(f"the reference fit failed: {r.stderr if r else 'timeout'}")
    (kept,) = (cache / "curves").glob("curve_*.h5")
    shutil.copyfile(kept, tmp / "kept.h5")
    return cache, kept, _mu(r)


def _restore(cache, kept, tmp):
    shutil.rmtree(cache / "curves", ignore_errors=True)
    if (cache / "curves").exists():
        (cache / "curves").chmod(0o700)
        (cache / "curves").unlink()
    (cache / "curves").mkdir(mode=0o700)
    shutil.copyfile(tmp / "kept.h5", kept)
    kept.chmod(0o644)


def _edit(path, fn):
    with h5py.File(path, "r+") as h:
        fn(h["entry/curve"])


def _flip(i, bit):
    def edit(g):
        bits = g["force"][()].view(np.uint64).copy()
        bits[i] ^= np.uint64(1) << np.uint64(bit)
        g["force"][...] = bits.view(float)
    return edit


def _set(name, fn):
    def edit(g):
        g[name][...] = fn(g[name][()])
    return edit


def _halve(path):
    import shellbvp as sb

    c = sb.read_curve(path)
    n = len(c) // 2
    c.points = {k: np.asarray(v)[:n] for k, v in c.points.items()}
    c.flags = list(c.flags[:n])
    c.to_hdf5(path, overwrite=True)


def _other_scene(g):
    scene = json.loads(g.attrs["scene"])
    scene["beta"] = 0.02
    g.attrs["scene"] = json.dumps(scene)


def _no_checksum(g):
    settings = json.loads(g.attrs["settings"])
    settings.pop("kept_sha256", None)
    g.attrs["settings"] = json.dumps(settings)


def _another_curve(path):
    import shellbvp as sb

    c = sb.curve(sb.Scene.preset("base"), deltas=np.linspace(0.02, 0.2, 6), estimate_error=False)
    c.settings.update({k: v for k, v in sb.read_curve(path).settings.items() if k in ("model_curve_key",
                                                                                      "kept_sha256")})
    c.to_hdf5(path, overwrite=True)


def _replace(path, data):
    path.write_bytes(data)


def _symlink(path):
    other = path.with_name("elsewhere.h5")
    os.replace(path, other)
    path.symlink_to(other)


def _directory(path):
    path.unlink()
    path.mkdir()


TAMPERINGS = [
    ("one bit flipped in the force (mantissa, point 20)", lambda p: _edit(p, _flip(20, 40))),
    ("one bit flipped in the force (exponent, point 5)", lambda p: _edit(p, _flip(5, 55))),
    ("the force doubled", lambda p: _edit(p, _set("force", lambda a: 2 * a))),
    ("a NaN in the force", lambda p: _edit(p, _set("force", lambda a: np.where(np.arange(a.size) == 7, np.nan, a)))),
    ("half the points", _halve),
    ("mode 0666", lambda p: p.chmod(0o666)),
    ("a symbolic link to a copy", _symlink),
    ("a directory in its place", _directory),
    ("random bytes", lambda p: _replace(p, np.random.default_rng(0).bytes(4096))),
    ("an empty file", lambda p: _replace(p, b"")),
    ("another scene attribute", lambda p: _edit(p, _other_scene)),
    ("the checksum removed", lambda p: _edit(p, _no_checksum)),
    ("the force scaled by 1.01", lambda p: _edit(p, _set("force", lambda a: 1.01 * a))),
    ("delta shifted by 1e-9", lambda p: _edit(p, _set("delta", lambda a: a + 1e-9))),
    ("the last bit of every force flipped", lambda p: _edit(p, _set(
        "force", lambda a: (a.view(np.uint64) ^ np.uint64(1)).view(float)))),
    ("another scene's curve with this one's key and checksum", _another_curve),
]


def kind_keptcurves(n, rng, tmp):
    cache, kept, ref = _warm(tmp)
    records = []
    for text, tamper in TAMPERINGS[:n]:
        _restore(cache, kept, tmp)
        tamper(kept)
        r, dt = _run(FIT, tmp, _env(cache))
        o, d = _judge_fit(r, ref)
        records.append(rec("keptcurves", "fit (kept curve)", text, o, d, dt))
    return records


def _unshare_ok():
    return shutil.which("unshare") is not None and subprocess.run(
        ["unshare", "-rm", "true"], capture_output=True).returncode == 0


def kind_cachefolders(n, rng, tmp):
    cache, kept, ref = _warm(tmp)
    curves = cache / "curves"

    def as_file():
        shutil.rmtree(curves)
        curves.write_text("not a folder")

    def foreign():
        os.chown(curves, 65534, 65534)

    cases = [("curves/ a regular file", as_file, ()),
             ("curves/ mode 0777", lambda: curves.chmod(0o777), ()),
             ("the kept curve's entry a directory", lambda: _directory(kept), ()),
             ("curves/ owned by another user", foreign if os.geteuid() == 0 else None, ()),
             ("the code cache mode 0777", lambda: cache.chmod(0o777), ()),
             ("curves/ read-only (a read-only tmpfs)", (lambda: shutil.rmtree(curves) or curves.mkdir())
              if _unshare_ok() else None,
              ("unshare", "-rm", "sh", "-c", f'mount -t tmpfs -o ro,mode=0700 none "{curves}" && exec "$0" "$@"'))]
    records = []
    for text, make, wrap in cases[:n]:
        if make is None:
            continue  # not possible here (not root, or no user namespaces)
        _restore(cache, kept, tmp)
        cache.chmod(0o700)
        make()
        r, dt = _run(FIT, tmp, _env(cache), wrap=wrap)
        o, d = _judge_fit(r, ref)
        records.append(rec("cachefolders", "fit (cache folder)", text, o, d, dt))
    cache.chmod(0o700)
    return records


def kind_kernels(n, rng, tmp):
    import importlib.util

    if importlib.util.find_spec("numba") is None:
        return []
    cache = tmp / "cache"
    r, _ = _run(["compile", "--preset", "fit"], tmp, _env(cache, "auto"))
    if r is None or r.returncode != 0:
        return [rec("kernels", "compile", "a first compile", "DEFECT", r.stderr[-300:] if r else "timeout")]
    damages = [("a data file (.nbc) of random bytes", "*.nbc", lambda p: p.write_bytes(os.urandom(200))),
               ("a data file (.nbc) emptied", "*.nbc", lambda p: p.write_bytes(b"")),
               ("an index file (.nbi) cut short", "*.nbi", lambda p: p.write_bytes(p.read_bytes()[:40]))]
    records = []
    for text, pattern, damage in damages[:n]:
        files = sorted((cache / "__pycache__").glob(f"kernels_*{pattern[1:]}"))
        damage(files[len(files) // 2])
        r, dt = _run(["compile", "--preset", "fit"], tmp, _env(cache, "auto"))
        if r is None or r.returncode != 0 or "Traceback" in r.stderr or "1 structure(s) ready" not in r.stdout:
            records.append(rec("kernels", "compile", text, "DEFECT",
                               f"exit {r.returncode if r else None}; {(r.stderr if r else 'timeout')[-300:]!r}", dt))
            continue
        r2, dt2 = _run(FIT, tmp, _env(cache, "auto"))
        warned = [ln for ln in r2.stderr.splitlines() if ln.startswith("WARNING")] if r2 else ["timeout"]
        ok = r2 is not None and r2.returncode == 0 and not warned
        records.append(rec("kernels", "compile, then fit", text, "correct result" if ok else "DEFECT",
                           f"{r.stdout.splitlines()[0][:80]}; the next fit ran without a warning" if ok else
                           f"next fit: exit {r2.returncode if r2 else None}; {warned[:1]}", dt + dt2))
    return records


def _limit(n_bytes):
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (n_bytes, n_bytes))
    return limit


def _judge_write(r, out_name, folder, printed, json_mode=False):
    """A run whose output cannot be written: a clear error, the result printed, nothing left."""
    if r is None:
        return "DEFECT", f"no exit within {TIMEOUT} s"
    listed = [ln[6:] for ln in r.stderr.splitlines() if ln.startswith("LEFT: ")]  # inside a tmpfs
    names = listed[0].split() if listed else [p.name for p in folder.iterdir()]
    left = [x for x in names if x.startswith(("." + out_name, out_name))]
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("shellbvp: error:")]
    where = f"exit {r.returncode}; stderr: {r.stderr.strip()[-300:]!r}"
    if "Traceback" in r.stderr or r.returncode != 2 or len(errors) != 1 or out_name not in errors[0]:
        return "DEFECT", where
    if left:
        return "DEFECT", f"left {left}; {where}"
    if json_mode:
        try:
            doc = json.loads(r.stdout)
        except ValueError:
            return "DEFECT", f"stdout not one JSON document: {r.stdout[:200]!r}"
        if doc.get("exit_status") != 2 or out_name not in str(doc.get("write_error")):
            return "DEFECT", f"the JSON document does not say the write failed: {doc.get('exit_status')}"
    elif printed not in r.stdout:
        return "DEFECT", f"the result was not printed; {where}"
    return "clear error", errors[0][:300]


def kind_fulldisk(n, rng, tmp):
    cache, kept, ref = _warm(tmp)
    out = tmp / "out"
    out.mkdir()
    cases = [(f"fit -o under a {k // 1000} kB file-size limit{' (kept curve being written too)' if fresh else ''}",
              [*FIT, "-o", "r.h5"], "r.h5", "mu*H", _limit(k), (), fresh, False)
             for k, fresh in ((2000, False), (8000, True), (20000, False), (30000, True))]
    cases += [("fit -o --json under an 8 kB limit", [*FIT, "-o", "r.h5", "--json"], "r.h5", "", _limit(8000), (),
               True, True),
              ("curve -o under a 4 kB limit", ["curve", "--preset", "fit", "--delta-max", "0.1", "-o", "c.h5"], "c.h5",
               "", _limit(4000), (), False, False)]
    if _unshare_ok():
        mount = ("unshare", "-rm", "sh", "-c", f'mount -t tmpfs -o size=16k none "{out}" && cd "{out}" && '
                 '{ "$0" "$@"; rc=$?; echo "LEFT: $(ls -A)" >&2; exit $rc; }')
        cases += [("fit -o on a full 16 kB tmpfs", [*FIT, "-o", "r.h5"], "r.h5", "mu*H", None, mount, False, False),
                  ("fit -o --json on a full 16 kB tmpfs", [*FIT, "-o", "r.h5", "--json"], "r.h5", "", None, mount,
                   False, True),
                  ("curve -o on a full 16 kB tmpfs",
                   ["curve", "--preset", "fit", "--delta-max", "0.1", "-o", "c.h5"], "c.h5", "", None, mount,
                   False, False)]
    cases.append(("a kept curve on a full disk only (no -o)", FIT, None, "mu*H", _limit(8000), (), True, False))
    records = []
    for text, args, name, printed, preexec, wrap, fresh, json_mode in cases[:n]:
        _restore(cache, kept, tmp)
        shutil.rmtree(out)
        out.mkdir()
        if fresh:
            kept.unlink()  # the fit writes its curve into the cache, past the limit
        r, dt = _run(args, out, _env(cache), preexec=preexec, wrap=wrap)
        if name is None:
            o, d = _judge_fit(r, ref)
            if o == "correct result" and "cannot keep model curves" not in r.stderr:
                o, d = "DEFECT", "no word that the curve was not kept"
        else:
            o, d = _judge_write(r, name, out, printed, json_mode)
        records.append(rec("fulldisk", args[0], text, o, d, dt))
    return records


FUNCS = {"keptcurves": kind_keptcurves, "cachefolders": kind_cachefolders, "kernels": kind_kernels,
         "fulldisk": kind_fulldisk}
