"""Formulas from users and files never run as code (issue 11, part 1).

Every payload below would run under ``sympy.sympify`` (which is ``eval``): it
creates a marker file.  The tests assert the marker never appears and that
the only exceptions are ValueError/TypeError naming the formula.
"""

import importlib.util
import json
import logging
import os
import sys
from pathlib import Path

import h5py
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import shellbvp as sb
from shellbvp import model
from symbolic import materials as sm
from symbolic.formula import FUNCTIONS, formula_text, parse_formula

S = sp.Symbol("S", positive=True)
W_TEXT = "(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2"


def payloads(marker):
    m = str(marker)
    return [
        f"__import__('os').system('touch {m}')",
        f"open('{m}', 'w')",
        f"exec(\"open('{m}','w')\")",
        f"eval(\"open('{m}','w')\")",
        f"(lambda: open('{m}', 'w'))()",
        f"[open('{m}', 'w') for _ in (1,)]",
        f"S.__class__.__init__.__globals__['__builtins__']['open']('{m}', 'w')",
        "().__class__.__bases__[0].__subclasses__()",
        f"getattr(__builtins__, 'open')('{m}', 'w')",
        f"sin(S) + __import__('os').system('touch {m}')",
        f"Symbol('S').func.__globals__['os'].system('touch {m}')",
        f"f'{{open(\"{m}\", \"w\")}}'",
        f"sin(S)\nopen('{m}', 'w')",
        f"sin(S); open('{m}', 'w')",
        f"Lambda(S, open('{m}', 'w'))",
        f"sin(x=open('{m}', 'w'))",
    ]


def test_payloads_are_refused_everywhere(tmp_path):
    marker = tmp_path / "PWNED"
    for text in payloads(marker):
        for make in (lambda t: sb.StrainEnergy(t), lambda t: sb.UserShell(t, "0", "1"),
                     lambda t: sb.UserShell("sin(S)", "-cos(S)", t), lambda t: sb.UserTip(t, "omega**2"),
                     lambda t: parse_formula(t, {"S": S}, name="R(S)", legacy_srepr=True)):
            with pytest.raises(ValueError) as err:
                make(text)
            assert "not allowed" in str(err.value) or "not a formula" in str(err.value), str(err.value)
    assert not marker.exists()


def test_error_names_the_formula_and_the_offending_piece():
    with pytest.raises(ValueError, match=r"R\(S\): .*'os\.system' \(attribute access\)"):
        sb.UserShell("os.system('x') + sin(S)", "0", "1")
    with pytest.raises(ValueError, match=r"W: .*'c' \(unknown name\)"):
        sb.StrainEnergy("c*(lambda_s - 1)**2")
    with pytest.raises(ValueError, match=r"'__builtins__' \(dunder"):
        parse_formula("__builtins__", {"S": S}, name="R(S)")
    with pytest.raises(ValueError, match=r"use \*\* for powers"):
        parse_formula("S^2", {"S": S}, name="R(S)")
    with pytest.raises(ValueError, match="too large"):
        parse_formula("10**10**10", {"S": S}, name="R(S)")  # would hang computing the integer
    with pytest.raises(ValueError, match="finite"):
        parse_formula("1e999*S", {"S": S}, name="R(S)")
    with pytest.raises(ValueError, match="longer than"):
        parse_formula("S+" * 2000 + "S", {"S": S}, name="R(S)")


@pytest.mark.parametrize("bad", [None, [1, 2], {"W": 1}, b"lambda_s", True, sp.Eq(sm.LS, sm.LT)])
def test_non_expressions_are_type_errors(bad):
    with pytest.raises(TypeError, match="W"):
        sb.StrainEnergy(bad)


def test_a_bare_name_is_an_expression():
    """SymPy's Symbol is also a Boolean: a formula that is a bare name ("omega", the paraboloid
    tip's A) must pass as an expression, parsed again from a scene's stored description (it was
    refused there, so a UserTip("omega", ...) scene could not be solved)."""
    from symbolic.build import structure_from_description

    omega = sp.Symbol("omega")
    assert parse_formula(omega, {"omega": omega}, name="A(omega)") == omega
    scene = sb.Scene(tip=sb.UserTip("omega", "omega**2/2"))
    assert structure_from_description(scene.structure()).tip is not None


@pytest.mark.parametrize("bad", ["lambda_s == lambda_theta", "lambda_s < 1", "1 if lambda_s else 2",
                                 "lambda_s and lambda_theta", "'lambda_s'", "", "   ", "(", "1,2"])
def test_non_formulas_are_value_errors(bad):
    with pytest.raises(ValueError, match="W"):
        sb.StrainEnergy(bad)


# -- the grammar: random formulas round-trip through the stored plain text ----------------------------
leaves = st.one_of(st.just("S"), st.just("pi"), st.just("E"), st.integers(-50, 50).map(str),
                   st.floats(-1e6, 1e6, allow_nan=False).map(lambda x: repr(float(f"{x:.12g}"))))
unary = sorted(k for k, (_, n) in FUNCTIONS.items() if n == 1)


def extend(children):
    return st.one_of(
        st.tuples(children, st.sampled_from(["+", "-", "*", "/"]), children).map(lambda t: f"({t[0]}){t[1]}({t[2]})"),
        st.tuples(children, st.integers(-3, 3)).map(lambda t: f"({t[0]})**{t[1]}"),
        st.tuples(st.sampled_from(unary), children).map(lambda t: f"{t[0]}({t[1]})"),
        children.map(lambda c: f"-({c})"),
    )


formulas = st.recursive(leaves, extend, max_leaves=8)


@settings(max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(formulas)
def test_random_formulas_parse_like_sympy_and_round_trip(text):
    try:
        e = parse_formula(text, {"S": S}, name="f")
    except ValueError as exc:  # only for formulas that are not finite (e.g. 1/0 -> zoo)
        assert any(w in str(exc) for w in ("finite", "real", "double precision")), str(exc)
        return
    # the same as SymPy's own reading of this (harmless, generated) text; its floats have 12 digits,
    # which sympify keeps exactly too (it rounds longer literals to 15)
    assert e == sp.sympify(text, locals={"S": S, "E": sp.E})
    assert parse_formula(formula_text(e), {"S": S}, name="f") == e


def test_full_precision_floats_round_trip():
    e = parse_formula("0.12345678901234568*S + 1e-300", {"S": S}, name="f")
    assert parse_formula(formula_text(e), {"S": S}, name="f") == e


# -- files: plain text written, old srepr files read through the same whitelist ----------------------
def user_scene():
    return sb.Scene.preset("base", material=sb.StrainEnergy(W_TEXT),
                           shell=sb.UserShell("sin(S)", "-2*cos(S)", "pi/2"), tip=sb.UserTip("omega", "omega**2/2"))


def test_scene_data_holds_plain_formulas_and_rebuilds_the_scene():
    scene = user_scene()
    d = scene.to_dict()
    assert d["shell"] == {"kind": "user", "R": "sin(S)", "Z": "-2*cos(S)", "L": "pi/2"}
    assert d["tip"] == {"kind": "user", "A": "omega", "B": "omega**2/2"}
    assert "Symbol" not in json.dumps(d)
    assert sb.Scene.from_dict(json.loads(json.dumps(d))) == scene


def test_old_srepr_scene_data_is_read_through_the_whitelist():
    old = user_scene().to_dict()
    old["material"]["W"] = sp.srepr(sb.StrainEnergy(W_TEXT).W)
    old["shell"].update(R=sp.srepr(sp.sin(S)), Z=sp.srepr(-2 * sp.cos(S)), L=sp.srepr(sp.pi / 2))
    omega = sp.Symbol("omega", positive=True)
    old["tip"].update(A=sp.srepr(omega), B=sp.srepr(omega**2 / 2))
    assert "Symbol(" in old["material"]["W"]
    assert sb.Scene.from_dict(old) == user_scene()


@pytest.fixture(scope="module")
def curve_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("curve") / "c.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.05, 0.1]).to_hdf5(path)
    return path


def tamper(src, dst, scene_dict):
    dst.write_bytes(src.read_bytes())
    with h5py.File(dst, "r+") as f:
        f["entry/curve"].attrs["scene"] = json.dumps(scene_dict)


@pytest.mark.parametrize("where", ["material", "shell", "tip", "srepr"])
def test_tampered_file_never_runs_its_payload(curve_file, tmp_path, cli_main, where):
    marker = tmp_path / "PWNED"
    payload = f"__import__('os').system('touch {marker}')"
    d = sb.read_curve(curve_file).scene.to_dict()
    if where == "material":
        d["material"] = {"family": "user", "W": payload}
    elif where == "shell":
        d["shell"] = {"kind": "user", "R": payload, "Z": "0", "L": "1"}
    elif where == "tip":
        d["tip"] = {"kind": "user", "A": "omega", "B": payload}
    else:  # dressed as an old srepr formula
        d["material"] = {"family": "user", "W": f"Add(Symbol('lambda_s'), {payload})"}
    bad = tmp_path / "bad.h5"
    tamper(curve_file, bad, d)
    with pytest.raises(ValueError, match="not allowed"):
        sb.read_curve(bad)
    for cmd in (["info", str(bad)], ["plot", str(bad), "-o", str(tmp_path / "x.png")]):
        r = cli_main(*cmd)  # the command's main in this process: a payload run would leave the marker
        assert r.returncode == 2, (cmd, r.stdout, r.stderr)
        assert r.stderr.startswith("shellbvp: error:") and "Traceback" not in r.stderr and "not allowed" in r.stderr
    assert not marker.exists()


@pytest.mark.parametrize("scene_data", [[], "x", {"material": []}, {"material": {"family": 3}},
                                        {"material": {"family": "mooney-rivlin", "alpha": "0.1"}}])
def test_malformed_scene_data_is_a_value_error(curve_file, tmp_path, scene_data):
    bad = tmp_path / "bad.h5"
    tamper(curve_file, bad, scene_data)
    with pytest.raises(ValueError, match="attribute scene (does not describe a scene|must be)"):
        sb.read_curve(bad)


# -- the code cache: never import what another user may have written ----------------------------------
def test_cached_module_writable_by_others_is_not_imported(tmp_path, monkeypatch, caplog, base_derivation):
    cache = tmp_path / "cache"
    cache.mkdir(mode=0o700)
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(cache))
    scene = sb.Scene.preset("base")
    desc = scene.structure()
    path = model.module_path(desc)
    marker = tmp_path / "PWNED"
    key = model.description_key(desc)
    path.write_text(f"open({str(marker)!r}, 'w').close()\nKEY = {key!r}\n")
    os.chmod(path, 0o666)
    monkeypatch.setattr(model, "_loaded", {})
    with caplog.at_level(logging.WARNING, logger="shellbvp.model"):
        mod = model.load_module(desc)
    assert not marker.exists()
    assert "writable by other users" in caplog.text
    assert hasattr(mod, "free_rhs") and len(base_derivation) == 1
    assert model.untrusted_reason(path) is None  # replaced by our own, private file


def test_cache_directory_writable_by_others_is_not_used(tmp_path, monkeypatch, caplog, base_derivation):
    cache = tmp_path / "shared"
    cache.mkdir()
    os.chmod(cache, 0o777)
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(cache))
    monkeypatch.setattr(model, "_loaded", {})
    with caplog.at_level(logging.WARNING, logger="shellbvp.model"):
        mod = model.load_module(sb.Scene.preset("base").structure())
    assert "not using the code cache" in caplog.text
    assert not any(cache.iterdir())  # nothing written to, nothing read from the shared directory
    assert model.untrusted_reason(__import__("pathlib").Path(mod.__file__).parent) is None


@pytest.fixture
def cache_with_base_module(tmp_path, monkeypatch):
    """An empty private cache holding only the base structure's numpy module (copied: no derivation)."""
    desc = sb.Scene.preset("base").structure()
    src = Path(model.load_module(desc).__file__)
    cache = tmp_path / "cache"
    cache.mkdir(mode=0o700)
    (cache / src.name).write_bytes(src.read_bytes())
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(cache))
    monkeypatch.setattr(model, "_loaded", {})
    return cache, desc


def test_generated_module_bytecode_is_written_even_under_dont_write_bytecode(cache_with_base_module, monkeypatch):
    cache, desc = cache_with_base_module
    monkeypatch.setattr(sys, "dont_write_bytecode", True)  # as PYTHONDONTWRITEBYTECODE=1 sets it
    src = Path(model.load_module(desc).__file__)
    assert src.parent == cache
    pyc = Path(importlib.util.cache_from_source(str(src)))
    head, st = pyc.read_bytes()[:16], src.stat()
    # the header the import checks: magic, flags 0 (time stamp based), the source's mtime and size
    assert head[:4] == importlib.util.MAGIC_NUMBER and int.from_bytes(head[4:8], "little") == 0
    assert int.from_bytes(head[8:12], "little") == int(st.st_mtime) & 0xFFFFFFFF
    assert int.from_bytes(head[12:16], "little") == st.st_size & 0xFFFFFFFF
    assert model.untrusted_reason(pyc) is None and model.untrusted_reason(pyc.parent) is None


@pytest.mark.parametrize("what", ["__pycache__", "pyc"])
def test_bytecode_writable_by_others_is_not_used(cache_with_base_module, monkeypatch, caplog, what):
    cache, desc = cache_with_base_module
    pyc = Path(importlib.util.cache_from_source(str(Path(model.load_module(desc).__file__))))
    os.chmod(pyc.parent if what == "__pycache__" else pyc, 0o777 if what == "__pycache__" else 0o666)
    private = cache.parent / "private"  # the private directory, with the module too: no derivation
    private.mkdir(mode=0o700)
    src = next(cache.glob("model_*.py"))
    (private / src.name).write_bytes(src.read_bytes())
    monkeypatch.setattr(model, "_private", private)
    monkeypatch.setattr(model, "_loaded", {})
    with caplog.at_level(logging.WARNING, logger="shellbvp.model"):
        mod = model.load_module(desc)
    assert "not using the code cache" in caplog.text and "writable by other users" in caplog.text
    assert Path(mod.__file__).parent == private
    assert hasattr(mod, "free_rhs")


@pytest.mark.parametrize("W", [
    "((1-0.1)*(lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)"
    " + 0.1*(1/lambda_s**2+1/lambda_theta**2+lambda_s**2*lambda_theta**2-3))/2",  # Mooney-Rivlin 0.1
    "-97.2/2*log(1-(lambda_s**2+lambda_theta**2+1/(lambda_s*lambda_theta)**2-3)/97.2)",  # Gent 97.2
])
def test_built_in_energies_written_out_with_decimals_are_accepted(W):
    """W(1, 1) of these is 2e-16 and -1e-14 in floating point: zero to rounding, accepted."""
    assert sb.StrainEnergy(W).shear_modulus == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("W, what", [("(lambda_s - 1)**2 + (lambda_theta - 1)**2 + 1e-6", "vanish"),
                                     ("0.5*(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3.001)",
                                      "vanish"),
                                     ("(lambda_s - 1)**2 + 2.0*(lambda_theta - 1)**2", "symmetric")])
def test_small_but_real_defects_of_decimal_energies_are_still_refused(W, what):
    with pytest.raises(ValueError, match=what):
        sb.StrainEnergy(W)


def test_numbers_too_large_to_evaluate_are_a_value_error():
    with pytest.raises(ValueError, match="cannot be evaluated"):
        sb.StrainEnergy("exp(exp(exp(exp(1000))))")


def test_a_cached_module_that_is_a_symlink_is_not_imported(tmp_path, monkeypatch, caplog, base_derivation):
    """The trust check followed links: a module linked to a 0644 file of ours in a world-writable
    directory ran (issue 42).  A linked module is refused whatever it points to."""
    cache = tmp_path / "cache"
    cache.mkdir(mode=0o700)
    shared = tmp_path / "shared"
    shared.mkdir()
    os.chmod(shared, 0o1777)
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(cache))
    desc = sb.Scene.preset("base").structure()
    path = model.module_path(desc)
    marker = tmp_path / "PWNED"
    target = shared / "m.py"
    target.write_text(f"open({str(marker)!r}, 'w').close()\nKEY = {model.description_key(desc)!r}\n")
    os.chmod(target, 0o644)
    path.symlink_to(target)
    assert "symbolic link" in model.untrusted_reason(path)
    monkeypatch.setattr(model, "_loaded", {})
    with caplog.at_level(logging.WARNING, logger="shellbvp.model"):
        mod = model.load_module(desc)
    assert not marker.exists() and hasattr(mod, "free_rhs") and len(base_derivation) == 1
    assert "symbolic link" in caplog.text


def test_an_import_error_of_an_optional_part_is_one_line(monkeypatch, capsys):
    """SHELLBVP_KERNELS=numba with a refused cache raised a raw ImportError traceback (issue 42)."""
    from shellbvp import cli
    from shellbvp.cli.handlers import solve

    def refuse(args):
        raise ImportError("not loading compiled kernels: it belongs to another user (uid 1234)")

    # the handler, which the parser's `run` imports on dispatch: the real dispatch runs
    monkeypatch.setattr(solve, "run", refuse)
    assert cli.main(["solve", "--delta", "0.1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "another user" in err and "Traceback" not in err
