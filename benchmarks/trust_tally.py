"""How shellbvp answers hostile and malformed input: a tally per kind of input.

For each kind below the script builds many inputs (seeded, deterministic) and
classifies the package's answer to each as exactly one of

* ``clear error``    -- ValueError or TypeError with a non-empty one-line message;
                        for the CLI: exit status 2, stderr starting ``shellbvp: error:``,
                        no ``Traceback`` (and with ``--json``: stdout one strict JSON document);
* ``warning``        -- a result that carries warnings (Python ``warnings``, WARNING log
                        records of shellbvp, a successful Solution with ``flags``, a CLI run
                        printing ``warning:``);
* ``correct result`` -- success with finite numbers (and, where the input is known to be
                        valid, the right numbers);
* ``failed status``  -- a result with ``success`` False, an integer status and a message
                        (NaN numbers allowed); for the CLI exit status 1 without a traceback;
* ``DEFECT``         -- anything else: another exception, a traceback, non-finite numbers in
                        a successful result, a payload that ran, a --json stdout that is not
                        exactly one JSON document, a malformed input accepted as valid, a valid
                        input refused, a call that does not return within its time limit.

Kinds:

1. formulas with injection payloads -> ``StrainEnergy``, ``UserShell``, ``UserTip``
   (plus valid formulas that must be accepted and read right);
2. tampered HDF5 curve files -> ``read_curve`` (and ``shellbvp info`` for one in five);
3. malformed CSV files -> ``read_force_csv`` (plus well-formed ones whose numbers are checked);
4. extreme scene values -> ``Scene`` then ``solve`` (max_nodes 3000, tol 1e-4);
5. command-line calls -> ``python3 -m shellbvp ...`` in a temporary directory.

Run from the repository root::

    python3 benchmarks/trust_tally.py            # full tally (~4-5 min on 2 cores)
    python3 benchmarks/trust_tally.py --quick    # a few inputs per kind (~1 min)

Writes ``benchmarks/results/trust_tally.md`` (``trust_tally-quick.md`` with ``--quick``,
so the committed result is not overwritten; ``--out`` chooses another file) and prints
the summary table.  Only the package is measured; this script fixes nothing.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

import h5py
import numpy as np
import sympy as sp

import shellbvp as sb
import trust_afm
import trust_cache
import trust_work  # issue 59: oversized work, dead options (its kinds join KINDS)

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
OUTCOMES = ("clear error", "warning", "failed status", "correct result", "DEFECT")
KINDS = {
    "formulas": "1. formulas with injection payloads",
    "hdf5": "2. tampered HDF5 files",
    "csv": "3. malformed CSV files",
    "scenes": "4. extreme scene values",
    "cli": "5. CLI calls",
    "fitrecords": "6. tampered fit records",
    "sweepfiles": "7. tampered sweep files",
    "inputs": "8. hostile inputs to fit and batches",
}
KINDS.update(trust_cache.KINDS)  # issue 59: the code cache and full disks (benchmarks/trust_cache.py)
FORMULA_LIMIT = 30.0  # s: a formula call that has not returned by then is recorded as a DEFECT (hang)
SLOW_SOLVE = 30.0  # s: solves slower than this are listed in the report
CLI_TIMEOUT = 120  # s


KIND_NOTES = {**trust_cache.KIND_NOTES,
    "formulas": "Inputs: 20 valid formulas (must be accepted and read as SymPy reads them; a user shell is "
                "rescaled to R(L) = 1, as documented), each payload against each of the four constructors, "
                "~50 special strings (3000-character formulas, parentheses nested 50-5000 deep, huge powers, "
                "1e999, division by zero, control and full-width characters, comparisons, f-strings), then "
                "random concatenations of names, numbers, operators, quotes, brackets and payloads. An accepted "
                "text is a DEFECT if it holds a quote, bracket, colon, comma, caret, attribute access, dunder, "
                "open/exec/eval/lambda/getattr/Symbol/for/import or the unknown name x, or reads as a "
                "non-finite expression. The marker file of the payloads is checked after every call.",
    "hdf5": "Inputs: the untouched file, a few non-HDF5 files (random bytes, empty, a CSV, the valid file cut "
            "short, an empty HDF5 file, a directory), then copies of a valid 3-point curve with one mutation "
            "each (an attribute deleted or set to junk: random text, payloads, scene JSON whose formulas hold "
            "payloads, numbers, NaN, lists, bools, bytes; a dataset deleted, truncated, replaced by strings or "
            "a scalar). A read curve must have a Scene, finite 1-D delta and force, every point field of their "
            "length, string flags, a str stop_reason, bool complete/interrupted, a dict of settings. Every "
            "fifth file also goes through `shellbvp info`.",
    "csv": "Inputs: well-formed files (unit headers, `,` `;` tab, decimal commas under `;`, comments, NaN "
           "rows; UTF-8, UTF-8-BOM, UTF-16, Latin-1) whose numbers must come back exactly (SI, sorted); "
           "near-valid files, the same with one or two cells replaced by a missing value (the row must be "
           "dropped, the rest read exactly) or by a cell the README calls an error (`5_0`, `inf`, `1e999`, "
           "full-width or Arabic digits, `0x10`, text, or a force of 1e308 under a kN header, which "
           "overflows) that must be refused; and junk files of random cells, headers, separators, line "
           "endings and encodings, raw random bytes included, which must be refused or read as finite, "
           "equal-length arrays.",
    "scenes": "Inputs: 0-3 of (gamma, rho, beta, the material parameter, delta) drawn from {nan, inf, -inf, "
              "0, 1e-300, -1, 1e300, 1e-12, 0.2, 1, 3, 99.9999999, '0.2', None, True}, the rest plausible; "
              "xi and contact mostly valid; a scene that is accepted is solved with max_nodes=3000, "
              "tol=1e-4, estimate_error=False. A successful solve must have finite force, delta and Sc "
              "(lambda0 finite except for a point load); 'warning' = success with validity flags.",
    "fitrecords": "Inputs: copies of a valid fit record (`shellbvp fit --example -o`) with one item changed: any "
                  "attribute or dataset deleted, or set to junk (text, payloads, numbers, NaN, lists, bools, "
                  "bytes, deep JSON), or a dataset replaced by a compressed one that claims 3 GB. `read_fit` must "
                  "return a record whose data are numeric and of one length, with success agreeing with status, "
                  "or raise one line; every fifth also through `shellbvp info` with escape sequences in the "
                  "message (the terminal must not see them).",
    "sweepfiles": "Inputs: copies of a valid 2-cell sweep file with one item changed as for fit records, plus "
                  "completeness lies (a complete cell whose curve is deleted, a cell naming another's curve). "
                  "`read_sweep` must return or raise one line; a cell read as complete must have its own curve.",
    "inputs": "Inputs: `shellbvp fit` on a FIFO with no writer, /dev/zero, a folder named x.csv, a symlink loop, "
              "a file named =HYPERLINK(...) in a batch with a table (the cell must not start a formula), a "
              "record with two loading passes (a warning must name them), `sweep` with 1e8 combinations and "
              "bad --scheduler addresses (one line each, no hang).",
    "cli": "Inputs: hand-written calls (bad output paths, `5_0`/`inf`/`nan`/`1e999` for numbers, huge or "
           "negative point counts, `solve --json` with bad values, `fit` on malformed CSVs, `info` and "
           "`plot` on non-files, unknown commands) in a temporary directory, timeout 120 s; with --json "
           "stdout must parse as one strict JSON document (no NaN) whose exit_status is the exit status.",
}
KINDS.update(trust_work.KINDS)
KIND_NOTES.update(trust_work.KIND_NOTES)

trust_afm.hook(KINDS, KIND_NOTES)  # issue 59: damaged and oversized AFM files (benchmarks/trust_afm.py)


# -- recording and classifying ------------------------------------------------------------------------
def rec(kind, target, text, outcome, detail="", seconds=0.0):
    assert outcome in OUTCOMES, outcome
    return {"kind": kind, "target": target, "input": text, "outcome": outcome, "detail": detail,
            "seconds": seconds}


class _Hang(Exception):
    pass


class _LogCapture(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.records = []

    def emit(self, record):
        self.records.append(f"{record.name}: {record.getMessage()}")


def call(fn, limit=None):
    """Run ``fn()``; return dict(result, exc, tb, warned, seconds).  ``limit``: seconds
    after which SIGALRM interrupts it (recorded as a hang)."""
    cap = _LogCapture()
    loggers = [logging.getLogger("shellbvp"), logging.getLogger("symbolic")]
    for lg in loggers:
        lg.addHandler(cap)
    out = {"result": None, "exc": None, "tb": "", "warned": [], "seconds": 0.0}
    old = None
    if limit:
        def _alarm(signum, frame):
            raise _Hang(f"did not return within {limit:g} s")
        old = signal.signal(signal.SIGALRM, _alarm)
        signal.setitimer(signal.ITIMER_REAL, limit)
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                out["result"] = fn()
            finally:
                if limit:
                    signal.setitimer(signal.ITIMER_REAL, 0)
        out["warned"] = [f"{w.category.__name__}: {w.message}" for w in caught]
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 -- everything else is what we classify
        out["exc"] = exc
        out["tb"] = traceback.format_exc()
    finally:
        out["seconds"] = time.perf_counter() - t0
        if limit:
            signal.signal(signal.SIGALRM, old)
        for lg in loggers:
            lg.removeHandler(cap)
    out["warned"] += cap.records
    return out


def tail(tb, n=4):
    lines = [ln for ln in tb.strip().splitlines() if ln.strip()]
    return " | ".join(ln.strip() for ln in lines[-n:])


def judge_exception(out):
    """(outcome, detail) of a call that raised."""
    exc = out["exc"]
    if isinstance(exc, _Hang):
        return "DEFECT", f"hang: {exc}"
    if isinstance(exc, (ValueError, TypeError)):
        msg = str(exc).strip()
        if not msg:
            return "DEFECT", f"{type(exc).__name__} with an empty message"
        if "\n" in msg or "\r" in msg:
            return "DEFECT", f"{type(exc).__name__} message of {len(msg.splitlines())} lines: {msg[:300]!r}"
        return "clear error", f"{type(exc).__name__}: {msg[:300]}"  # subclasses (e.g. UnicodeError) too
    return "DEFECT", f"{type(exc).__name__}: {str(exc)[:200]} -- {tail(out['tb'])}"


def judge_read(read, check, marker, describe):
    """(outcome, detail, seconds) of ``read()`` on a possibly hostile file: a payload that ran or
    a result ``check`` finds wrong (a list of problems) is a DEFECT; ``describe(result)`` says
    what a correct read gave."""
    out = call(read, limit=60)
    if marker.exists():
        marker.unlink()
        return "DEFECT", "PAYLOAD RAN: marker file created", out["seconds"]
    if out["exc"] is not None:
        return (*judge_exception(out), out["seconds"])
    bad = check(out["result"])
    if bad:
        return "DEFECT", "accepted: " + "; ".join(bad), out["seconds"]
    if out["warned"]:
        return "warning", "; ".join(out["warned"])[:300], out["seconds"]
    return "correct result", describe(out["result"]), out["seconds"]


def _strict(constant):
    raise ValueError(f"{constant} is not strict JSON")


def run_cli(args, cwd, json_mode=False, timeout=CLI_TIMEOUT):
    """Run ``python3 -m shellbvp ARGS``; return (outcome, detail, seconds)."""
    t0 = time.perf_counter()
    try:
        p = subprocess.run([sys.executable, "-m", "shellbvp", *args], cwd=cwd, capture_output=True,
                           text=True, timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return "DEFECT", f"no exit within {timeout} s", time.perf_counter() - t0
    dt = time.perf_counter() - t0
    code, out, err = p.returncode, p.stdout, p.stderr
    where = f"exit {code}; stderr: {err.strip()[-300:]!r}"
    if "Traceback" in err or "Traceback" in out:
        return "DEFECT", f"traceback; exit {code}; {tail(err or out)}", dt
    if json_mode:
        try:
            doc = json.loads(out, parse_constant=_strict)
        except ValueError as exc:
            return "DEFECT", f"--json stdout is not exactly one strict JSON document ({exc}); {where}; " \
                             f"stdout: {out[:200]!r}", dt
        if not isinstance(doc, dict) or doc.get("exit_status", code) != code:
            return "DEFECT", f"--json document's exit_status {doc.get('exit_status') if isinstance(doc, dict) else doc!r}" \
                             f" != exit {code}", dt
    if code == 2:
        lines = err.strip().splitlines()
        if err.startswith("shellbvp: error:") and len(lines) == 1:
            return "clear error", err.strip()[:300], dt
        return "DEFECT", f"exit 2 but stderr not one 'shellbvp: error:' line: {err.strip()[:300]!r}", dt
    if code == 0:
        if re.search(r"(?m)^warning:", out + err) or (json_mode and doc.get("warnings")):
            return "warning", where, dt
        return "correct result", f"exit 0; stdout: {out.strip()[:120]!r}", dt
    if code == 1:
        if err.strip() or out.strip():
            return "failed status", f"exit 1; stdout: {out.strip()[:200]!r}; stderr: {err.strip()[-200:]!r}", dt
        return "DEFECT", "exit 1 without any message", dt
    return "DEFECT", f"unexpected exit status; {where}", dt


# -- 1. formulas ----------------------------------------------------------------------------------------
def payloads(marker):
    m = str(marker)
    return [f"__import__('os').system('touch {m}')", f"open('{m}','w')", f"exec(\"open('{m}','w')\")",
            f"eval(\"open('{m}','w')\")", "lambda: 0", "[x for x in ()]", "().__class__.__mro__", "getattr",
            "Symbol('x')", f"getattr(__builtins__,'open')('{m}','w')",
            f"(lambda: open('{m}','w'))()", f"S.__class__.__init__.__globals__['__builtins__']['open']('{m}','w')"]


NAMES = ["S", "omega", "lambda_s", "lambda_theta", "pi", "E", "sin", "cos", "exp", "log", "sqrt", "Abs", "x"]
NUMBERS = ["0", "1", "2", "2.5", "0.1", "1e300", "1e-300", "10**10**10", "1e999", "9" * 40, "1_0", "0x10", ".5"]
OPS = ["+", "-", "*", "/", "**", "^", "(", ")", "(", ")", "'", '"', ".", "[", "]", ",", ":", " "]
TARGETS = ("StrainEnergy(text)", 'UserShell(text, "0", "1")', 'UserShell("sin(S)", "-cos(S)", text)',
           'UserTip(text, "omega**2")')
VALID_FORMULAS = [  # (target index, text): valid formulas; must be accepted and read as SymPy reads them
    (0, "(lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)/2"),
    (0, "0.5*(lambda_s**2 + lambda_theta**2 + 1/(lambda_s**2*lambda_theta**2) - 3)"),
    (0, "(lambda_s**2+lambda_theta**2+lambda_s**-2*lambda_theta**-2-3)/2"
        " + 0.01*(lambda_s**2+lambda_theta**2+lambda_s**-2*lambda_theta**-2-3)**2"),
    (0, "((lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)"
        " + (1/lambda_s**2+1/lambda_theta**2+(lambda_s*lambda_theta)**2-3))/4"),
    # Mooney-Rivlin (alpha = 0.1) and Gent (Jm = 97.2) written out with decimal coefficients
    (0, "((lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)"
        " + 0.1*(1/lambda_s**2+1/lambda_theta**2+(lambda_s*lambda_theta)**2-3))/2"),
    (0, "-97.2/2*log(1-(lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)/97.2)"),
    (1, "sin(S)"), (1, "2*sin(S/2)"), (1, "S"), (1, "sinh(S)"), (1, "S/sqrt(1+S**2)"), (1, "sin(S)*(1+0*S)"),
    (2, "pi/2"), (2, "1.2"), (2, "1"), (2, "atan(1)*2"),
    (3, "omega"), (3, "sin(omega)"), (3, "0.5*sin(omega)"), (3, "tanh(omega)"),
]
# accepted text holding any of these would be a payload or non-formula slipping through
FORBIDDEN = re.compile(r"__|\bopen\b|\bexec\b|\beval\b|\blambda\b(?!_)|getattr|Symbol|\bfor\b|\bimport\b|[\[\]'\":^;,]"
                       r"|[A-Za-z_)\]]\s*\.\s*[A-Za-z_]|\bx\b")


def formula_inputs(n, rng, marker):
    P = payloads(marker)
    out = []
    # every payload against every target
    for p in P:
        for t in range(4):
            out.append((t, p))
    specials = ["S+" * 1499 + "S", "1" * 3000, ("sin(S)*" * 500)[:2999] + "S", "(" * 50 + "S" + ")" * 50,
                "(" * 300 + "S" + ")" * 300, "(" * 5000 + "S" + ")" * 5000, "sin(" * 100 + "S" + ")" * 100,
                "sin(" * 1000 + "S" + ")" * 1000, "-" * 10000 + "S", "S**" * 200 + "2", "2**2**2**2**2**2",
                "(S+1)**1000000", "exp(exp(exp(exp(1000))))", "10**10**10", "1e999", "1e999*S", "1/0", "S/0",
                "log(0)", "sqrt(-1)", "", "   ", "\x00", "S\x00", "Ｓ", "S\u200b", "sin(S) if S else 0",
                "S == S", "S; S", "S # comment", "b'S'", "f'{S}'", "S @ S", "~S", "not S", "S and S", "*S",
                "**S", "S," * 3, "{S}", "{'a': 1}", "(S for S in ())", "Symbol('S')", "Integer(10)**Integer(10)**9"]
    for i, s in enumerate(specials):
        out.append((i % 4, s))
    tokens = NAMES + NUMBERS + OPS
    while len(out) < n:
        r = rng.random()
        if r < 0.55:  # random concatenation of tokens, payloads among them
            k = rng.randint(1, 12)
            s = "".join(rng.choice(P) if rng.random() < 0.12 else rng.choice(tokens) for _ in range(k))
        elif r < 0.75:  # a formula with a payload spliced in
            base = rng.choice(["sin(S)", "lambda_s**2", "omega", "1+S", "pi/2"])
            s = f"{base}{rng.choice(['+', '*', '-', '**', ''])}{rng.choice(P)}"
        elif r < 0.9:  # plausible arithmetic of names and numbers (often valid)
            k = rng.randint(1, 5)
            s = rng.choice(NAMES[:6])
            for _ in range(k):
                s += rng.choice(["+", "-", "*", "/", "**"]) + rng.choice(NAMES[:6] + NUMBERS[:7])
            if rng.random() < 0.5:
                s = f"{rng.choice(['sin', 'exp', 'log', 'sqrt', 'Abs', 'cos'])}({s})"
        else:  # very long random token strings (~3000 characters)
            s = ""
            while len(s) < 3000:
                s += rng.choice(tokens)
            s = s[:3000]
        out.append((rng.randrange(4), s))
    return out if n >= len(out) else rng.sample(out, n)


def build_formula(target, text):
    if target == 0:
        return sb.StrainEnergy(text)
    if target == 1:
        return sb.UserShell(text, "0", "1")
    if target == 2:
        return sb.UserShell("sin(S)", "-cos(S)", text)
    return sb.UserTip(text, "omega**2")


def formula_exprs(target, obj):
    if target == 0:
        return [obj.W]
    g = obj.geometry
    if target in (1, 2):
        return [g.R, g.Z] + ([g.L] if hasattr(g, "L") else [])
    return [g.A, g.B]


def finite_expr(e):
    e = sp.sympify(e)
    return not e.has(sp.oo, -sp.oo, sp.zoo, sp.nan)


def plain(e):
    e = sp.sympify(e)
    return e.xreplace({s: sp.Symbol(s.name) for s in e.free_symbols})


def kind_formulas(n, rng, tmp):
    marker = tmp / "MARKER"
    records = []
    for target, text in VALID_FORMULAS:
        out = call(lambda: build_formula(target, text), limit=FORMULA_LIMIT)
        label = f"valid: {TARGETS[target]}"
        if out["exc"] is not None:
            o, d = judge_exception(out)
            records.append(rec("formulas", label, text, "DEFECT", f"valid formula refused: {d}", out["seconds"]))
            continue
        exprs = formula_exprs(target, out["result"])
        mine = plain(exprs[0] if target != 2 else exprs[2])
        ref = sp.sympify(text, locals={n_: sp.Symbol(n_) for n_ in NAMES[:4]} | {"E": sp.E})
        if target == 1:  # documented: the meridian is rescaled so that R(L) = 1
            ref = ref / ref.subs(sp.Symbol("S"), plain(exprs[2]))
        if sp.simplify(mine - ref) != 0:
            records.append(rec("formulas", label, text, "DEFECT", f"read as {mine}, SymPy reads {ref}",
                               out["seconds"]))
        elif out["warned"]:
            records.append(rec("formulas", label, text, "warning", "; ".join(out["warned"])[:300], out["seconds"]))
        else:
            records.append(rec("formulas", label, text, "correct result", str(mine)[:120], out["seconds"]))
    for target, text in formula_inputs(n, rng, marker):
        out = call(lambda: build_formula(target, text), limit=FORMULA_LIMIT)
        label = TARGETS[target]
        if marker.exists():
            records.append(rec("formulas", label, text, "DEFECT", "PAYLOAD RAN: marker file created",
                               out["seconds"]))
            marker.unlink()
            continue
        if out["exc"] is not None:
            o, d = judge_exception(out)
        else:
            exprs = formula_exprs(target, out["result"])
            m = FORBIDDEN.search(text)
            if m:
                o, d = "DEFECT", f"accepted a text holding {m.group(0)!r}: read as {exprs}"
            elif not all(finite_expr(e) for e in exprs):
                o, d = "DEFECT", f"accepted a non-finite formula: {exprs}"
            elif out["warned"]:
                o, d = "warning", "; ".join(out["warned"])[:300]
            else:
                o, d = "correct result", f"read as {str(exprs)[:120]}"
        records.append(rec("formulas", label, text, o, d, out["seconds"]))
    return records


# -- 2. tampered HDF5 files -------------------------------------------------------------------------------
ROOT_ATTRS = ["format", "format_version", "package_version"]
CURVE_ATTRS = ["scene", "settings", "stop_reason", "complete", "interrupted"]
DATASETS = ["delta", "force", "lambda0", "Sc", "valid", "topology", "flags"]


def junk_values(rng, marker, scene_dict):
    P = payloads(marker)
    pick = rng.random()
    if pick < 0.15:
        return "".join(rng.choice("abcxyz019 .,;:{}[]\"'\\\nµ") for _ in range(rng.randint(0, 30)))
    if pick < 0.3:
        return rng.choice(P)
    if pick < 0.5:  # a scene whose formulas hold payloads (or other rot)
        d = json.loads(json.dumps(scene_dict))
        which = rng.choice(["W", "srepr", "R", "Z", "L", "A", "B", "gamma", "rho", "material", "contact"])
        p = rng.choice(P)
        if which == "W":
            d["material"] = {"family": "user", "W": p}
        elif which == "srepr":
            d["material"] = {"family": "user", "W": f"Add(Symbol('lambda_s'), {p})"}
        elif which in "RZL":
            d["shell"] = {"kind": "user", "R": "sin(S)", "Z": "-cos(S)", "L": "pi/2", which: p}
        elif which in "AB":
            d["tip"] = {"kind": "user", "A": "omega", "B": "omega**2/2", which: p}
        elif which in ("gamma", "rho"):
            d[which] = rng.choice([float("nan"), float("inf"), "0.2", None, [1], -1.0, 1e300])
        elif which == "material":
            d["material"] = rng.choice([[], "x", {"family": 3}, {"family": "mooney-rivlin", "alpha": "0.1"},
                                        {"family": "gent", "Jm": -1}, {}])
        else:
            d["contact"] = rng.choice(["x", 1, None, ""])
        return json.dumps(d)
    if pick < 0.6:
        return rng.choice(['{"gamma": 1}', "[]", "null", "{}", '"x"', "{", '{"a": NaN}', "1e999", "true"])
    if pick < 0.7:
        return [rng.choice([0.0, 1.0, float("nan"), 1e300]) for _ in range(rng.randint(0, 3))]
    if pick < 0.8:
        return rng.choice([0, 1, 2, 3, -1, 2**62, 99])
    if pick < 0.9:
        return rng.choice([float("nan"), float("inf"), -0.0, 1.5, 1e-300])
    return rng.choice([True, False, b"bytes", np.bool_(True)])


def set_attr(obj, key, value):
    if isinstance(value, list):
        value = np.asarray(value, float)
    obj.attrs[key] = value


def mutate_file(good, path, rng, marker, scene_dict):
    """Copy ``good`` to ``path`` with one random mutation; return its description."""
    shutil.copyfile(good, path)
    with h5py.File(path, "r+") as f:
        g = f["entry/curve"]
        r = rng.random()
        if r < 0.55:
            key = rng.choice(ROOT_ATTRS + CURVE_ATTRS)
            obj = f if key in ROOT_ATTRS else g
            where = "/" if key in ROOT_ATTRS else "/entry/curve"
            if rng.random() < 0.2:
                if key in obj.attrs:
                    del obj.attrs[key]
                return f"attribute {where}:{key} deleted"
            v = junk_values(rng, marker, scene_dict)
            set_attr(obj, key, v)
            return f"attribute {where}:{key} = {v!r}"
        name = rng.choice(DATASETS)
        data = g[name][()]
        how = rng.choice(["delete", "truncate", "strings", "scalar", "scalar"])
        del g[name]
        if how == "delete":
            return f"dataset /curve/{name} deleted"
        if how == "truncate":
            k = rng.choice([0, 1, 2])
            g.create_dataset(name, data=data[:k])
            return f"dataset /curve/{name} truncated to {k}"
        if how == "strings":
            vals = [rng.choice(["x", "", "nan", "1.5", payloads(marker)[0], "µ"]) for _ in range(len(data))]
            g.create_dataset(name, data=vals, dtype=h5py.string_dtype())
            return f"dataset /curve/{name} = strings {vals!r}"
        v = rng.choice([0.1, 7, float("nan"), "x", True])
        g[name] = v
        return f"dataset /curve/{name} = scalar {v!r}"


def not_hdf5_files(tmp, good, rng):
    files = []
    for i, size in enumerate([0, 16, 800, 5000]):
        p = tmp / f"bytes{i}.h5"
        p.write_bytes(bytes(rng.randrange(256) for _ in range(size)))
        files.append((p, f"{size} random bytes" if size else "empty file"))
    p = tmp / "table.h5"
    p.write_text("displacement (mm),force (mN)\n0.1,1\n0.2,2\n")
    files.append((p, "a CSV file"))
    p = tmp / "half.h5"
    raw = good.read_bytes()
    p.write_bytes(raw[: len(raw) // 2])
    files.append((p, "the valid file truncated to half its bytes"))
    p = tmp / "hdr.h5"
    p.write_bytes(raw[:2048])
    files.append((p, "the valid file's first 2048 bytes"))
    p = tmp / "emptyh5.h5"
    with h5py.File(p, "w"):
        pass
    files.append((p, "an empty HDF5 file"))
    p = tmp / "foreign.h5"
    with h5py.File(p, "w") as f:
        f.attrs["format"] = "shellbvp-curve"
        f["entry/curve"] = np.arange(3.0)
    files.append((p, "format attribute right, /entry/curve a dataset"))
    p = tmp / "adir.h5"
    p.mkdir()
    files.append((p, "a directory"))
    return files


def check_curve(c):
    """Problems of a curve that read_curve returned (empty list: fine)."""
    bad = []
    if not isinstance(c.scene, sb.Scene):
        bad.append(f"scene is {type(c.scene).__name__}")
    n = len(c.points.get("delta", []))
    for k, v in c.points.items():
        v = np.asarray(v)
        if v.ndim != 1 or len(v) != n:
            bad.append(f"{k} has shape {v.shape} (delta: {n})")
    for k in ("delta", "force"):
        v = np.asarray(c.points.get(k, []))
        if v.dtype.kind not in "fiu":
            bad.append(f"{k} of dtype {v.dtype}")
        elif not np.all(np.isfinite(v)):
            bad.append(f"{k} not finite: {v}")
    if not (isinstance(c.flags, list) and len(c.flags) == n and all(isinstance(s, str) for s in c.flags)):
        bad.append(f"flags {c.flags!r}")
    if not isinstance(c.stop_reason, str):
        bad.append(f"stop_reason {c.stop_reason!r}")
    for k in ("complete", "interrupted"):
        if not isinstance(getattr(c, k), bool):
            bad.append(f"{k} = {getattr(c, k)!r} ({type(getattr(c, k)).__name__})")
    if not isinstance(c.settings, dict):
        bad.append(f"settings {c.settings!r}")
    return bad


def kind_hdf5(n, rng, tmp):
    marker = tmp / "MARKER"
    good = tmp / "good.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.05, 0.1, 0.2]).to_hdf5(good)
    scene_dict = sb.read_curve(good).scene.to_dict()
    cases = [(good, "the untouched valid file")]
    others = not_hdf5_files(tmp, good, rng)
    k_other = min(len(others), max(3, n // 12))
    cases += others[:k_other]
    i = 0
    while len(cases) < n:
        p = tmp / f"mut{i:04d}.h5"
        cases.append((p, mutate_file(good, p, rng, marker, scene_dict)))
        i += 1
    records = []
    for j, (path, desc) in enumerate(cases):
        o, d, dt = judge_read(lambda: sb.read_curve(path), check_curve, marker, lambda c: f"{len(c)} points")
        records.append(rec("hdf5", "read_curve(path)", desc, o, d, dt))
        if j % 5 == 0:
            o, d, dt = run_cli(["info", str(path)], cwd=tmp)
            if marker.exists():
                o, d = "DEFECT", "PAYLOAD RAN (info): marker file created"
                marker.unlink()
            records.append(rec("hdf5", "shellbvp info PATH", desc, o, d, dt))
    return records


# -- 3. malformed CSV files -------------------------------------------------------------------------------
LEN_UNITS = {"mm": 1e-3, "um": 1e-6, "µm": 1e-6, "m": 1.0, "nm": 1e-9}
FORCE_UNITS = {"mN": 1e-3, "µN": 1e-6, "μN": 1e-6, "uN": 1e-6, "N": 1.0, "kN": 1e3}
HEADERS = ["Displacement (um)", "Force (µN)", "Force (μN)", "Force (kN)", "disp (mm)", "force [mN]",
           "Displacement", "Force", "time (s)", "", "Depth (blorp)", "x (µm)"]
CELLS = ["5_0", "inf", "-inf", "1e999", "nan", "NaN", "", "abc", "N/A", "null", "1,5", "１２", "٣",
         "0x10", "1.2.3", "+1", "-0", " 3 ", "1e-400", '"1.5"', "\x00", "Force (kN)", "µN", "1e308", "-1e308",
         "1.5e", "e5", ".", "--1"]


def random_cell(rng):
    r = rng.random()
    if r < 0.5:
        x = rng.uniform(-10, 10) * 10 ** rng.randint(-3, 3)
        return rng.choice([repr(x), f"{x:.3f}", f"{x:e}", str(int(x))])
    return rng.choice(CELLS)


def encode(text, enc, rng):
    if enc == "raw":
        raw = bytes(rng.randrange(256) for _ in range(rng.randint(0, 200)))
        return raw if rng.random() < 0.5 else text.encode("utf-8", "replace") + raw
    return text.encode(enc, errors="replace")


def malformed_csv(rng):
    sep = rng.choice([",", ";", "\t", " ", "|", ", "])
    lines = []
    if rng.random() < 0.6:
        lines.append(sep.join(rng.choice(HEADERS) for _ in range(rng.randint(1, 3))))
    for _ in range(rng.randint(0, 14)):
        if rng.random() < 0.1:
            lines.append(rng.choice(["# comment", "#", "   # indented comment", "#Force (kN)"]))
        else:
            lines.append(sep.join(random_cell(rng) for _ in range(rng.randint(0, 4))))
    enc = rng.choice(["utf-8", "utf-8-sig", "utf-16", "latin-1", "raw"])
    eol = rng.choice(["\n", "\r\n", "\r"])
    return encode(eol.join(lines), enc, rng), f"sep {sep!r}, {enc}: " + repr(eol.join(lines)), None


REFUSE = ["5_0", "inf", "-inf", "1e999", "１２", "٣", "0x10", "1.2.3", "1.5e", "e5", ".", "--1", "abc", "N/A",
          "null", "1e308 (x 1e3 = inf)"]  # cells the README says are errors (the last: overflow after kN)
DROP = ["nan", "NaN", ""]  # missing values: the row is dropped


def wellformed_csv(rng, inject=False):
    """A valid file (or one with a bad or missing cell injected into a data row) and what
    read_force_csv must answer: ("values", (displacement_m, force_N)) or ("refuse", cell)."""
    sep = rng.choice([",", ";", "\t"])
    lu = rng.choice(list(LEN_UNITS))
    fu = rng.choice(list(FORCE_UNITS))
    enc = rng.choice(["utf-8", "utf-8-sig", "utf-16"] + (["latin-1"] if "μ" not in fu else []))
    npts = rng.randint(4, 20)
    d = [v / 1000 for v in rng.sample(range(1, 100000), npts)]
    f = [round(rng.uniform(0, 500), 4) for _ in range(npts)]
    comma = sep == ";" and rng.random() < 0.5
    fmt = (lambda v: repr(v).replace(".", ",")) if comma else repr
    cells = [[fmt(a), fmt(b)] for a, b in zip(d, f)]
    keep = [True] * npts
    expect = None
    if inject:
        for _ in range(rng.choice([1, 1, 2])):
            i, col = rng.randrange(npts), rng.randrange(2)
            if rng.random() < 0.6:
                cell = rng.choice(REFUSE)
                if cell.startswith("1e308"):
                    if fu != "kN":
                        fu = "kN"
                        enc = rng.choice(["utf-8", "utf-16"])
                    cell, col = "1e308", 1
                cells[i][col] = cell
                expect = ("refuse", cell)
            else:
                cells[i][col] = rng.choice(DROP)
                keep[i] = False
    lines = [f"Displacement ({lu}){sep}Force ({fu})"]
    for row in cells:
        if rng.random() < 0.1:
            lines.append(rng.choice(["# a comment", f"nan{sep}nan", f"{sep}", "#Force (kN)"]))
        lines.append(sep.join(row))
    if expect is None:
        dk = np.asarray(d)[keep]
        fk = np.asarray(f)[keep]
        order = np.argsort(dk, kind="stable")
        expect = ("values", (dk[order] * LEN_UNITS[lu], fk[order] * FORCE_UNITS[fu]))
        if dk.size < 3:  # documented: fewer than 3 rows with numbers is an error
            expect = ("refuse", "fewer than 3 rows")
    text = "\n".join(lines) + "\n"
    label = "near-valid" if inject else "well-formed"
    return text.encode(enc, errors="replace"), f"{label}, sep {sep!r}, {enc}: " + repr(text), expect


def kind_csv(n, rng, tmp):
    records = []
    for i in range(n):
        r = rng.random()
        data, desc, expected = (wellformed_csv(rng) if r < 0.25 else wellformed_csv(rng, inject=True) if r < 0.6
                                else malformed_csv(rng))
        path = tmp / f"data{i:04d}.csv"
        path.write_bytes(data)
        out = call(lambda: sb.read_force_csv(path), limit=60)
        target = ("read_force_csv (junk)" if expected is None
                  else f"read_force_csv ({desc.split(',')[0]})")
        if out["exc"] is not None:
            o, d = judge_exception(out)
            if expected is not None and expected[0] == "values" and o == "clear error":
                o, d = "DEFECT", f"valid file refused: {d}"
        else:
            res = out["result"]
            try:
                dd, ff = (np.asarray(v, float) for v in res)
                ok = dd.ndim == ff.ndim == 1 and dd.size == ff.size >= 1 and np.all(np.isfinite(dd)) \
                    and np.all(np.isfinite(ff))
            except Exception as exc:  # noqa: BLE001
                ok, dd, ff = False, exc, None
            if not ok:
                o, d = "DEFECT", f"success with bad arrays: {str(res)[:200]}"
            elif expected is not None and expected[0] == "refuse" and expected[1] == "1e308":
                o, d = "DEFECT", (f"accepted: the force 1e308 kN (= 1e311 N) overflows to inf and its row was "
                                  f"silently dropped like a missing value ({dd.size} rows read)")
            elif expected is not None and expected[0] == "refuse":
                o, d = "DEFECT", f"accepted a file holding {expected[1]!r} ({dd.size} rows read)"
            elif expected is not None and not (dd.shape == expected[1][0].shape
                                               and np.allclose(dd, expected[1][0], rtol=1e-12)
                                               and np.allclose(ff, expected[1][1], rtol=1e-12)):
                o, d = "DEFECT", (f"wrong numbers: got {dd.size} rows {dd[:3]}, {ff[:3]}; expected "
                                  f"{expected[1][0].size} rows {expected[1][0][:3]}, {expected[1][1][:3]}")
            elif out["warned"]:
                o, d = "warning", "; ".join(out["warned"])[:300]
            else:
                o, d = "correct result", f"{dd.size} rows"
        records.append(rec("csv", target, desc, o, d, out["seconds"]))
    return records


# -- 4. extreme scene values ------------------------------------------------------------------------------
EXTREME = [float("nan"), float("inf"), float("-inf"), 0.0, 1e-300, -1.0, 1e300, 1e-12, 0.2, 1.0, 3.0,
           99.9999999, "0.2", None, True]


def scene_inputs(n, rng):
    """n scenes: each has 0-3 of (gamma, rho, beta, material parameter, delta) drawn from EXTREME,
    the others plausible; xi and contact mostly valid."""
    out = []
    for _ in range(n):
        hostile = set(rng.sample(["gamma", "rho", "beta", "mat", "delta"], rng.choice([0, 0, 1, 1, 1, 2, 2, 3])))

        def pick(name, plausible):
            return rng.choice(EXTREME) if name in hostile else plausible()

        kw = {"gamma": pick("gamma", lambda: round(rng.uniform(-2, 4), 3)),
              "rho": pick("rho", lambda: round(rng.uniform(0.05, 0.5), 3)),
              "beta": pick("beta", lambda: float(f"{10 ** rng.uniform(-4, -1):.3g}"))}
        fam = rng.choice(["mr", "gent", "nh"])
        mat = (fam, pick("mat", lambda: round(rng.uniform(0, 1), 2)) if fam == "mr"
               else pick("mat", lambda: round(10 ** rng.uniform(-0.5, 2), 2)) if fam == "gent" else None)
        kw["xi"] = rng.choice([0, 1] * 20 + [2, 1.0, "1", None, True, 0.5])
        kw["contact"] = rng.choice(["smooth", "paper"] * 20 + ["x", "", None, 1])
        delta = pick("delta", lambda: round(rng.uniform(0.01, 0.6), 3))
        out.append((kw, mat, delta))
    return out


def material(mat):
    fam, v = mat
    return sb.MooneyRivlin(v) if fam == "mr" else sb.Gent(v) if fam == "gent" else sb.NeoHookean()


def kind_scenes(n, rng, tmp):
    records = []
    for kw, mat, delta in scene_inputs(n, rng):
        text = (f"Scene({', '.join(f'{k}={v!r}' for k, v in kw.items())}, material="
                f"{ {'mr': 'MooneyRivlin', 'gent': 'Gent', 'nh': 'NeoHookean'}[mat[0]] }"
                f"({'' if mat[1] is None else repr(mat[1])})); solve(delta={delta!r})")
        out = call(lambda: sb.Scene(material=material(mat), **kw))
        if out["exc"] is not None:
            o, d = judge_exception(out)
            records.append(rec("scenes", "Scene(...)", text, o, d, out["seconds"]))
            continue
        scene = out["result"]
        out = call(lambda: sb.solve(scene, delta=delta, max_nodes=3000, tol=1e-4, estimate_error=False))
        if out["exc"] is not None:
            o, d = judge_exception(out)
        else:
            s = out["result"]
            nums = {k: getattr(s, k) for k in ("force", "delta", "Sc", "lambda0")}
            if not isinstance(s.status, (int, np.integer)) or not s.message:
                o, d = "DEFECT", f"no integer status or no message: status {s.status!r}"
            elif s.success:
                finite = all(isinstance(nums[k], (float, int, np.floating)) and math.isfinite(nums[k])
                             for k in ("force", "delta", "Sc"))
                if not finite:
                    o, d = "DEFECT", f"success with non-finite numbers: {nums}"
                elif not (math.isfinite(nums["lambda0"]) or s.topology == "point"):
                    o, d = "DEFECT", f"success, lambda0 NaN on a {s.topology} state: {nums}"
                elif s.flags or out["warned"]:
                    o, d = "warning", "; ".join(list(s.flags) + out["warned"])[:300]
                else:
                    o, d = "correct result", f"F = {s.force:.6g}, {s.topology}"
            else:
                o, d = "failed status", f"status {s.status}: {s.message[:200]}"
        records.append(rec("scenes", "Scene + solve", text, o, d, out["seconds"]))
        odd = [f"{k}={v!r}" for k, v in [*kw.items(), ("material parameter", mat[1])]
               if k != "contact" and (isinstance(v, (bool, str)) or (v is None and k != "material parameter"))]
        if odd:  # Scene itself refuses bools and strings for its numbers; note where one got through
            records[-1]["note"] = f"accepted {', '.join(odd)} (a bool or string where a number belongs)"
    return records


# -- 5. command-line calls --------------------------------------------------------------------------------
def cli_inputs(tmp, n):
    fast = ["--delta-max", "0.02", "--points", "3"]
    (tmp / "exists.h5").write_bytes(b"")
    csvs = {"empty.csv": "", "text.csv": "hello\nworld\n", "one.csv": "displacement (mm),force (mN)\n0.1,1\n",
            "falling.csv": "displacement (mm),force (mN)\n" + "".join(f"{0.01 * i},{10 - i}\n" for i in range(1, 9)),
            "inf.csv": "displacement (mm),force (mN)\n0.01,1\n0.02,inf\n0.03,3\n0.04,4\n",
            "underscore.csv": "displacement (mm),force (mN)\n0.01,1\n0.02,5_0\n0.03,3\n",
            "nounits.csv": "0.01,1\n0.02,2\n0.03,3\n0.04,4\n",
            "bytes.csv": None}
    for name, text in csvs.items():
        p = tmp / name
        p.write_bytes(bytes(range(256)) * 3 if text is None else text.encode())
    cases = [
        (["curve", *fast, "-o", ""], False), (["curve", *fast, "-o", "."], False),
        (["curve", *fast, "-o", "/proc/x.h5"], False), (["curve", *fast, "-o", "nonexistent/x.h5"], False),
        (["curve", *fast, "-o", "exists.h5"], False), (["curve", *fast, "-o", "/"], False),
        (["curve", *fast, "--gamma", "5_0", "-o", "g.h5"], False), (["curve", *fast, "--gamma", "inf", "-o", "g.h5"], False),
        (["curve", *fast, "--gamma", "nan", "-o", "g.h5"], False), (["curve", *fast, "--gamma", "1e999", "-o", "g.h5"], False),
        (["curve", *fast, "--rho", "5_0", "-o", "r.h5"], False), (["curve", *fast, "--rho", "nan", "-o", "r.h5"], False),
        (["curve", *fast, "--rho", "0", "-o", "r.h5"], False), (["curve", *fast, "--rho", "-inf", "-o", "r.h5"], False),
        (["curve", "--delta-max", "inf", "--points", "3", "-o", "d.h5"], False),
        (["curve", "--delta-max", "nan", "--points", "3", "-o", "d.h5"], False),
        (["curve", "--delta-max", "1e999", "--points", "3", "-o", "d.h5"], False),
        (["curve", "--delta-max", "5_0", "--points", "3", "-o", "d.h5"], False),
        (["curve", "--delta-max", "0.02", "--points", "1000000000", "-o", "p.h5"], False),
        (["curve", "--delta-max", "0.02", "--points", "0", "-o", "p.h5"], False),
        (["curve", "--delta-max", "0.02", "--points", "-3", "-o", "p.h5"], False),
        (["curve", "--delta-max", "0.02", "--points", "3.5", "-o", "p.h5"], False),
        (["curve", *fast, "--max-nodes", "-1", "-o", "m.h5"], False),
        (["curve", *fast, "--tol", "0", "-o", "t.h5"], False),
        (["curve", *fast, "--beta", "1e300", "-o", "b.h5"], False),
        (["curve", *fast, "-o", "ok.h5"], False),
        (["solve", "--json", "--delta", "5_0"], True), (["solve", "--json", "--delta", "inf"], True),
        (["solve", "--json", "--delta", "nan"], True), (["solve", "--json", "--delta", "1e999"], True),
        (["solve", "--json", "--delta", "-1"], True), (["solve", "--json", "--delta", "100"], True),
        (["solve", "--json", "--gamma", "1e999", "--delta", "0.1"], True),
        (["solve", "--json", "--rho", "0", "--delta", "0.1"], True),
        (["solve", "--json", "--lambda0", "nan"], True), (["solve", "--json", "--load", "inf"], True),
        (["solve", "--json", "--delta", "0.1", "--load", "0.2"], True),
        (["solve", "--json", "--delta", "0.1", "--bogus"], True), (["solve", "--json", "--preset", "nope"], True),
        (["solve", "--json", "--delta", "0.1", "--tol", "nan"], True),
        (["solve", "--json", "--delta", "0.1", "--max-nodes", "3000", "--tol", "1e-4"], True),
        (["solve", "--delta", "0.1", "--tol", "1e-4"], False),
        (["solve", "--json", "--gamma", "4.9", "--delta", "0.3", "--max-nodes", "50", "--tol", "1e-4"], True),
        (["fit", "--preset", "fit", "empty.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "text.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "one.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "falling.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "inf.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "underscore.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "nounits.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "bytes.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "missing.csv", "--radius", "0.3mm"], False),
        (["fit", "--preset", "fit", "falling.csv", "--radius", "0.3mm", "--json"], True),
        (["fit", "--preset", "fit", "text.csv", "--radius", "0.3mm", "--json"], True),
        (["fit", "--preset", "fit", "nounits.csv", "--radius", "abc", "--json"], True),
        (["fit", "--preset", "fit", "nounits.csv", "--radius", "0", "--units", "mm,mN"], False),
        (["fit", "--preset", "fit", "nounits.csv", "--radius", "0.3mm", "--units", "blorp,mN"], False),
        (["info", "/nonexistent/x.h5"], False), (["info", "."], False), (["info", "/dev/null"], False),
        (["info", "empty.csv"], False), (["plot", "/nonexistent/x.h5", "-o", "x.png"], False),
        (["presets"], False), (["nosuchcommand"], False), ([], False),
        (["curve", *fast, "--rho=-inf", "-o", "r2.h5"], False), (["solve", "--json", "--xi", "2"], True),
        (["solve", "--json", "--delta", "0.1", "--beta", "1e300", "--max-nodes", "3000", "--tol", "1e-4"], True),
        (["fit", "--preset", "fit", "falling.csv", "--radius", "0.3mm", "--columns", "5,6"], False),
        (["fit", "--preset", "fit", "--example", "--radius", "0.3mm", "--beta-range", "5_0,1", "--fit-beta", "--json"], True),
        (["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--json"], True),
    ]
    return cases if n >= len(cases) else cases[:: len(cases) // n][:n]  # quick: a spread of them


def kind_cli(n, rng, tmp):
    cwd = tmp / "cli"
    cwd.mkdir()
    records = []
    for args, json_mode in cli_inputs(cwd, n):
        o, d, dt = run_cli(args, cwd=cwd, json_mode=json_mode)
        text = "python3 -m shellbvp " + " ".join(repr(a) if (not a or " " in a) else a for a in args)
        records.append(rec("cli", args[0] if args else "(none)", text, o, d, dt))
    if Path("/proc/x.h5").exists() or (cwd / "nonexistent").exists():
        records.append(rec("cli", "files", "output paths", "DEFECT", "a refused output path was created"))
    return records


# -- 6, 7. tampered fit records and sweep files ----------------------------------------------------------
def _items(path):
    out = []
    with h5py.File(path, "r") as h:
        out += [("attr", "", a) for a in h.attrs]

        def visit(name, obj):
            out.append(("dataset" if isinstance(obj, h5py.Dataset) else "group", name, None))
            out.extend(("attr", name, a) for a in obj.attrs)

        h.visititems(visit)
    return out


def _mutate(good, path, rng, marker, scene_dict, items):
    """Copy ``good`` to ``path`` with one item deleted or set to junk; return its description."""
    shutil.copyfile(good, path)
    kind, name, attr = rng.choice(items)
    with h5py.File(path, "r+") as h:
        obj = h[name] if name else h
        if kind == "attr":
            if rng.random() < 0.2:
                del obj.attrs[attr]
                return f"attribute {name or '/'}:{attr} deleted"
            v = junk_values(rng, marker, scene_dict) if rng.random() < 0.8 else "[" * 100_000 + "]" * 100_000
            try:
                set_attr(obj, attr, v)
            except (TypeError, ValueError):
                return "unchanged (h5py cannot store the junk)"
            return f"attribute {name or '/'}:{attr} = {str(v)[:60]!r}"
        parent, leaf = name.rsplit("/", 1) if "/" in name else ("", name)
        del h[name]
        g = h[parent] if parent else h
        how = rng.choice(["delete", "strings", "scalar", "bomb"])
        if how == "delete":
            return f"{kind} /{name} deleted"
        if how == "bomb":
            g.create_dataset(leaf, shape=(400_000_000,), dtype="f8", compression="gzip", chunks=(1_000_000,))
            return f"{kind} /{name} = a compressed dataset claiming 3.2 GB"
        if how == "strings":
            g.create_dataset(leaf, data=["x", payloads(marker)[0], "nan"], dtype=h5py.string_dtype())
            return f"{kind} /{name} = strings"
        v = rng.choice([0.1, float("nan"), -1.0, 99])
        g[leaf] = v
        return f"{kind} /{name} = scalar {v!r}"


def _check_fit(fr):
    bad = []
    n = len(fr.data.get("displacement", []))
    for k, v in fr.data.items():
        if np.ndim(v) != 1 or len(v) != n:
            bad.append(f"data/{k} of shape {np.shape(v)}")
    for k in ("displacement", "force"):
        if np.asarray(fr.data[k]).dtype.kind not in "fiu":
            bad.append(f"data/{k} of dtype {np.asarray(fr.data[k]).dtype}")
    if fr.success != (fr.status == 0):
        bad.append(f"success {fr.success} with status {fr.status}")
    if fr.success and not (np.isfinite(fr.parameters["mu_H"]) and fr.parameters["mu_H"] > 0):
        bad.append(f"successful with mu_H {fr.parameters['mu_H']}")
    if not fr.parameters["R_L"] > 0:
        bad.append(f"R_L {fr.parameters['R_L']}")
    return bad


def kind_fitrecords(n, rng, tmp):
    marker = tmp / "MARKER"
    good = tmp / "good.h5"
    r = subprocess.run([sys.executable, "-m", "shellbvp", "fit", "--example", "--preset", "fit", "--radius", "0.3mm",
                        "-o", str(good)], cwd=tmp, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    scene_dict = sb.read_fit(good).scene.to_dict()
    items = _items(good)
    records = []
    for i in range(n):
        path = tmp / f"mut{i:04d}.h5"
        desc = _mutate(good, path, rng, marker, scene_dict, items) if i else "the untouched valid file"
        if i == 0:
            shutil.copyfile(good, path)
        o, d, dt = judge_read(lambda: sb.read_fit(path), _check_fit, marker, lambda fr: "read")
        records.append(rec("fitrecords", "read_fit(path)", desc, o, d, dt))
        if i % 5 == 0:
            with h5py.File(path, "r+") as h:
                if "fit" in h and isinstance(h["fit"], h5py.Group):
                    h["fit"].attrs["message"] = "\x1b[2J\x1b[1;1Hforged"
            o, d, dt = run_cli(["info", str(path)], cwd=tmp)
            r = subprocess.run([sys.executable, "-m", "shellbvp", "info", str(path)], cwd=tmp, capture_output=True)
            if b"\x1b" in r.stdout + r.stderr:
                o, d = "DEFECT", "an escape sequence from the file reached the terminal"
            records.append(rec("fitrecords", "shellbvp info PATH (message with escapes)", desc, o, d, dt))
    return records


def _check_sweep(sw):
    lies = [i for i, st in enumerate(sw.index["status"]) if st == "complete" and i not in sw.curves]
    return [f"cells {lies} read as complete without a curve"] if lies else []


def kind_sweepfiles(n, rng, tmp):
    from shellbvp.sweeps import sweep

    marker = tmp / "MARKER"
    good = tmp / "good.h5"
    sweep(sb.Scene.preset("base"), {"beta": [0.005, 0.01]}, delta_max=0.1, out=good, workers=1, deltas=[0.05, 0.1],
          estimate_error=False)
    scene_dict = sb.Scene.preset("base").to_dict()
    items = _items(good)
    cases = []
    p = tmp / "nocurve.h5"
    shutil.copyfile(good, p)
    with h5py.File(p, "r+") as h:
        del h["sweep/curves/curve_000001"]
    cases.append((p, "a complete cell whose curve is deleted"))
    p = tmp / "other.h5"
    shutil.copyfile(good, p)
    with h5py.File(p, "r+") as h:
        g = [x.decode() if isinstance(x, bytes) else x for x in h["sweep/index/group"][()]]
        del h["sweep/index/group"]
        h["sweep/index"].create_dataset("group", data=[g[0], g[0]], dtype=h5py.string_dtype())
    cases.append((p, "a cell naming another cell's curve"))
    i = 0
    while len(cases) < n:
        p = tmp / f"mut{i:04d}.h5"
        cases.append((p, _mutate(good, p, rng, marker, scene_dict, items)))
        i += 1
    records = []
    for path, desc in cases:
        o, d, dt = judge_read(lambda: sb.read_sweep(path), _check_sweep, marker, lambda sw: f"{sw.counts()}")
        records.append(rec("sweepfiles", "read_sweep(path)", desc, o, d, dt))
    return records


# -- 8. hostile inputs to fit and batches ----------------------------------------------------------------
def kind_inputs(n, rng, tmp):
    import os

    from shellbvp.fitting import example_data_path

    good = tmp / "good.csv"
    shutil.copyfile(example_data_path(), good)
    os.mkfifo(tmp / "pipe.csv")
    (tmp / "sub.csv").mkdir()
    os.symlink(tmp / "loop.csv", tmp / "loop.csv")
    formula = '=HYPERLINK("http:x","y").csv'
    shutil.copyfile(example_data_path(), tmp / formula)
    d, F = np.loadtxt(example_data_path(), delimiter=",", skiprows=2, unpack=True)
    rows = [(x, y) for x, y in zip(d, F)] + [(x, 0.5 * y) for x, y in zip(d[::-1], F[::-1])] + \
        [(x, 3 * y) for x, y in zip(d, F)]
    (tmp / "two.csv").write_text("displacement (mm),force (mN)\n" + "\n".join(f"{x:.6f},{y:.6f}" for x, y in rows))
    fit = ["fit", "--preset", "fit", "--radius", "0.3mm"]
    calls = [(["fit", "pipe.csv", "--preset", "fit", "--radius", "0.3mm"], "a FIFO with no writer", None),
             (["fit", "/dev/zero", "--preset", "fit", "--radius", "0.3mm"], "/dev/zero", None),
             (["fit", "sub.csv", "--preset", "fit", "--radius", "0.3mm"], "a folder named sub.csv", None),
             (["fit", "loop.csv", "--preset", "fit", "--radius", "0.3mm"], "a symlink loop", None),
             (["sweep", "--beta", "0.005:0.02:100", "--rho", "0.1:0.3:100", "--gamma", "0.5:1.5:100",
               "--alpha", "0:1:100", "-o", "g.h5"], "a sweep grid of 1e8 combinations", None)]
    calls += [(["sweep", "--beta", "0.01", "--delta-max", "0.1", "--scheduler", a, "-o", "g.h5"],
               f"--scheduler {a!r}", None) for a in ("", "ucx://h:1", "tls://h:1", "inproc://foo", "h:99999")]
    records = []
    for args, desc, _ in calls[:n]:
        o, d, dt = run_cli(args, cwd=tmp, timeout=60)
        records.append(rec("inputs", args[0], desc, o, d, dt))
    # a batch with the bad inputs, the good file and a formula-named one: rows for all, table escaped
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "shellbvp", *fit, ".", "/dev/zero", "--table", "t.csv"], cwd=tmp,
                       capture_output=True, text=True, timeout=300)
    table = (tmp / "t.csv").read_text() if (tmp / "t.csv").exists() else ""
    cells = [ln.split(",")[0] for ln in table.splitlines()[1:]]
    bad = [c for c in cells if c.startswith(("=", "+", "-", "@"))]
    o = ("DEFECT", f"exit {r.returncode}; table cells starting a formula: {bad}" if bad or not table
         else "") if (bad or not table or "Traceback" in r.stderr) else \
        ("failed status", f"exit {r.returncode}: {len(cells)} rows, every bad input a row")
    records.append(rec("inputs", "fit (batch)", "a folder with a FIFO, a folder, a loop, a formula name; and "
                       "/dev/zero", o[0], o[1], time.perf_counter() - t0))
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "shellbvp", *fit[:1], "two.csv", *fit[1:]], cwd=tmp, capture_output=True,
                       text=True, timeout=300)
    o = ("warning", "the two passes named") if "loading passes" in r.stdout else ("DEFECT", "no word of the passes")
    records.append(rec("inputs", "fit", "two loading passes, the second at 3x the force", o[0], o[1],
                       time.perf_counter() - t0))
    return records


# -- report -------------------------------------------------------------------------------------------------
def tally(records):
    counts = {o: 0 for o in OUTCOMES}
    for r in records:
        counts[r["outcome"]] += 1
    return counts


def report(records, *, args, wall, head, dirty, kind_times):
    lines = ["# Trust tally: hostile and malformed input", "",
             f"Commit measured: `{head}`" + (f" plus uncommitted changes in {dirty}" if dirty else "") + ".  ",
             f"Command: `python3 benchmarks/trust_tally.py{' --quick' if args.quick else ''}"
             f"{' --only ' + args.only if args.only else ''}` "
             f"(Python {sys.version.split()[0]}, each kind seeded with `random.Random(0)`).  ",
             f"Wall time: {wall:.1f} s on a 2-core shared machine.", "",
             "Each input is classified as exactly one of: **clear error** (ValueError/TypeError with a "
             "non-empty one-line message; CLI: exit 2, one `shellbvp: error:` line on stderr, no traceback, "
             "and with `--json` one strict JSON document on stdout), **warning** (a result carrying warnings: "
             "Python warnings or shellbvp WARNING log records, a successful Solution with `flags`, a CLI "
             "`warning:` line), **failed status** (success False with a status and a message; CLI exit 1), "
             "**correct result** (success with finite numbers, and the right ones where the input is known "
             "valid), **DEFECT** (anything else: other exceptions, tracebacks, non-finite numbers in a "
             "success, a payload that ran, --json stdout not one JSON document, a malformed input "
             "accepted or a valid one refused, a call that hangs).", "",
             "## Summary", ""]
    summary = ["| kind | tried | clear error | warning | failed status | correct result | DEFECT | time (s) |",
               "|---|---|---|---|---|---|---|---|"]
    total = {o: 0 for o in OUTCOMES}
    for key, title in KINDS.items():
        rs = [r for r in records if r["kind"] == key]
        if not rs:
            continue
        c = tally(rs)
        for o in OUTCOMES:
            total[o] += c[o]
        summary.append(f"| {title} | {len(rs)} | " + " | ".join(str(c[o]) for o in OUTCOMES)
                       + f" | {kind_times.get(key, 0):.0f} |")
    summary.append(f"| **all** | {len(records)} | " + " | ".join(str(total[o]) for o in OUTCOMES)
                   + f" | {sum(kind_times.values()):.0f} |")
    lines += summary + [""]
    for key, title in KINDS.items():
        rs = [r for r in records if r["kind"] == key]
        if not rs:
            continue
        targets = list(dict.fromkeys(r["target"] for r in rs))
        lines += [f"## {title}", "", "| outcome | " + " | ".join(f"`{t}`" for t in targets) + " | total |",
                  "|---|" + "---|" * (len(targets) + 1)]
        for o in OUTCOMES:
            row = [sum(1 for r in rs if r["target"] == t and r["outcome"] == o) for t in targets]
            lines.append(f"| {o} | " + " | ".join(map(str, row)) + f" | {sum(row)} |")
        lines.append("| tried | " + " | ".join(str(sum(1 for r in rs if r["target"] == t)) for t in targets)
                     + f" | {len(rs)} |")
        slow = max(rs, key=lambda r: r["seconds"])
        lines += ["", f"Slowest input: {slow['seconds']:.2f} s ({slow['outcome']}): `{_short(slow['input'], 120)}`."]
        if key == "scenes":
            slows = [r for r in rs if r["seconds"] > SLOW_SOLVE]
            lines.append(f"Solves over {SLOW_SOLVE:g} s: {len(slows)}" + (":" if slows else "."))
            lines += [f"* {r['seconds']:.1f} s: `{_short(r['input'], 200)}`" for r in slows]
        lines += ["", KIND_NOTES[key]]
        if key == "hdf5":
            acc = list(dict.fromkeys(r["input"] for r in rs if r["target"] == "read_curve(path)"
                                     and r["outcome"] in ("correct result", "warning")))
            lines += ["", f"Files read without complaint ({len(acc)}; a mutation of free text or a documented "
                      "alternative):", ""] + [f"* `{_short(a, 140)}`" for a in acc]
        if key == "cli":
            lines += ["", "| call | outcome | answer |", "|---|---|---|"]
            lines += [f"| `{_short(r['input'][20:], 110)}` | {r['outcome']} | {_short(r['detail'], 130)} |"
                      for r in rs]
        examples = {}
        for r in rs:
            examples.setdefault(r["outcome"], r)
        lines += ["", "One example per outcome:", ""]
        for o, r in examples.items():
            lines.append(f"* {o}: `{_short(r['input'], 100)}` -> {_short(r['detail'], 200)}")
        lines.append("")
    notes = [r for r in records if r.get("note")]
    if notes:
        lines += ["## Observations (not counted as defects)", "",
                  "Inputs answered with a result although they hold a value the rest of the API refuses "
                  "(e.g. `Scene(gamma=True)` and `solve(delta=True)` are ValueErrors):", ""]
        lines += [f"* `{_short(r['input'], 200)}` -> {r['outcome']}: {r['note']}" for r in notes]
        lines.append("")
    defects = [r for r in records if r["outcome"] == "DEFECT"]
    lines += ["## Defects found", ""]
    if not defects:
        lines.append("None.")
    for i, r in enumerate(defects, 1):
        lines += [f"{i}. **{KINDS[r['kind']]}**, `{r['target']}`", f"   * input: `{_short(r['input'], 200)}`",
                  f"   * answer: {_short(r['detail'], 600)}"]
    return "\n".join(lines) + "\n", "\n".join(summary)


def _short(text, n):
    s = repr(text)[1:-1] if not isinstance(text, str) else text.encode("unicode_escape").decode("ascii")
    s = s.replace("`", "'").replace("|", "\\|")
    return s if len(s) <= n else s[: n - 3] + "..."


def git(*cmd):
    try:
        return subprocess.run(["git", *cmd], cwd=ROOT, capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "?"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="a few inputs per kind (about a minute)")
    p.add_argument("--only", help="comma-separated kinds: " + ",".join(KINDS))
    p.add_argument("--out", type=Path, help="markdown report (default benchmarks/results/trust_tally[-quick].md)")
    args = p.parse_args(argv)
    sizes = {"formulas": 300, "hdf5": 150, "csv": 200, "scenes": 80, "cli": 100, "fitrecords": 120,
             "sweepfiles": 80, "inputs": 20}
    if args.quick:
        sizes = {"formulas": 60, "hdf5": 15, "csv": 20, "scenes": 8, "cli": 10, "fitrecords": 15, "sweepfiles": 10,
                 "inputs": 20}
    sizes.update(trust_cache.sizes(args.quick))
    sizes.update(trust_afm.sizes(args.quick))
    kinds = args.only.split(",") if args.only else list(KINDS)
    head = git("rev-parse", "--short", "HEAD")
    dirty = sorted({ln[3:].split("/")[0] for ln in git("status", "--porcelain").splitlines()
                    if ln[3:].startswith(("shellbvp/", "symbolic/"))})
    dirty = ", ".join(f"`{d}/`" for d in dirty)
    funcs = {"formulas": kind_formulas, "hdf5": kind_hdf5, "csv": kind_csv, "scenes": kind_scenes, "cli": kind_cli,
             "fitrecords": kind_fitrecords, "sweepfiles": kind_sweepfiles, "inputs": kind_inputs, **trust_cache.FUNCS,
             **trust_afm.functions()}
    funcs.update(trust_work.FUNCS)
    sizes = {**trust_work.SIZES, **sizes}
    records, kind_times = [], {}
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="trust-tally-") as td:
        for key in kinds:
            tmp = Path(td) / key
            tmp.mkdir()
            t1 = time.perf_counter()
            records += funcs[key](sizes[key], random.Random(0), tmp)
            kind_times[key] = time.perf_counter() - t1
            print(f"{KINDS[key]}: {sum(1 for r in records if r['kind'] == key)} inputs, "
                  f"{kind_times[key]:.0f} s", file=sys.stderr, flush=True)
        for r in records:  # temporary paths differ from run to run
            r["input"], r["detail"] = (str(r[k]).replace(td, "$TMP") for k in ("input", "detail"))
    wall = time.perf_counter() - t0
    text, summary = report(records, args=args, wall=wall, head=head, dirty=dirty, kind_times=kind_times)
    out = args.out or RESULTS / ("trust_tally-quick.md" if args.quick else "trust_tally.md")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    print(summary)
    n_def = sum(1 for r in records if r["outcome"] == "DEFECT")
    print(f"\n{n_def} defects; commit {head}; wall {wall:.1f} s; report: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
