"""Compiled kernels (issue 14 item 2): the loop-over-nodes form of the hot functions, numba.

The numpy module is the reference: the compiled kernels (right-hand sides, Jacobians and
profiles) must give its values to 1e-13
(relative to each value, or to the size of its output row where a value is small by
cancellation).  Tests that compile are skipped when numba is absent; the base
structure is compared in the default suite, the others under ``--runslow``.
"""

import importlib.util
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

import shellbvp as sb
from shellbvp import kernels as sk
from shellbvp import model as sbm

needs_numba = pytest.mark.skipif(importlib.util.find_spec("numba") is None,
                                 reason="numba is not installed (pip install 'shellbvp[fast]'): "
                                        "the compiled kernels are optional")

SCENES = {
    "base": sb.Scene.preset("base"),
    "base-xi0": sb.Scene.preset("base-xi0"),
    "gent": sb.Scene.preset("gent1", material=sb.Gent(5.0)),
    "neo-hookean": sb.Scene.preset("base", material=sb.NeoHookean()),
    "rotation-bending": sb.Scene.preset("base", bending=sb.RotationBending()),
    "user-shell-tip": sb.Scene(gamma=1.0, rho=0.2, beta=0.01,
                               shell=sb.UserShell("sin(S)", "-1.2*cos(S)", "pi/2"),
                               tip=sb.UserTip("sin(omega)", "1 - cos(omega)")),
}
RTOL = 1e-13


def _states(kind, rng, m):
    """Random states in the solver's ranges: (S, y) of a region kind, m nodes."""
    if kind == "free":
        S = np.sort(rng.uniform(0.05, 1.5, m))
        y = np.vstack([rng.uniform(0.8, 1.2, m), rng.uniform(0.3, 1.5, m), rng.uniform(0.8, 1.25, m),
                       rng.uniform(0.3, 3, m), rng.uniform(-0.3, 0.3, m), rng.uniform(-1, 0, m)])
    else:  # on the cylinder (r = rho = 0.2) lambda_theta = rho / R(S) is O(1) only for S near 0.2
        S = np.sort(rng.uniform(1e-3, 0.3, m) if kind == "contact" else rng.uniform(0.12, 0.3, m))
        y = np.vstack([rng.uniform(0.8, 1.2, m), rng.uniform(0.8, 1.25, m)])
    return S, y


def _relative_error(ref, got):
    """max |got - ref| / max(|ref|, floor).  The floor is the size of the output's row (one
    right-hand side component, or its derivatives, over all nodes): a value that is small by
    cancellation (d g_ls/d beta vanishes for xi = 0 but is computed as a difference of O(1)
    terms) is compared at the size of its neighbours, not at its own."""
    ref, got = np.asarray(ref), np.asarray(got)
    assert ref.shape == got.shape
    row = np.max(np.abs(ref).reshape(ref.shape[0], -1), axis=1).reshape((-1,) + (1,) * (ref.ndim - 1))
    floor = np.maximum(row, 1e-3 * np.max(np.abs(ref)))  # a row that vanishes identically
    return float(np.max(np.abs(got - ref) / np.maximum(np.abs(ref), np.maximum(floor, 1e-300))))


def compare_with_numpy(scene, active):
    """The compiled functions of ``active`` against the numpy module at 300 random nodes, with
    C-ordered states and with row slices of a Fortran-ordered array (as solve_bvp passes them)."""
    mod = scene.model()
    par = scene.parameters(mod)
    rng = np.random.default_rng(11)
    worst = {}
    for kind in ("free", "contact", "cylinder"):
        if not hasattr(mod, f"{kind}_rhs"):
            continue
        S, y = _states(kind, rng, 300)
        stacked = np.asfortranarray(np.vstack([np.ones((3, 300)), y]))
        for fun in ("rhs", "jac", "jac_par", "energy"):
            name = f"{kind}_{fun}"
            ref, got = getattr(mod, name)(S, y, par), getattr(active, name)(S, stacked[3:], par)
            ref, got = (ref, got) if isinstance(ref, tuple) else ((ref,), (got,))
            worst[name] = max(_relative_error(r, g) for r, g in zip(ref, got))
        if kind == "free":
            worst["free_legendre"] = _relative_error(mod.free_legendre(S, y, par),
                                                     active.free_legendre(S, stacked[3:], par))
        name = f"{kind}_profile"  # a dict of fields: compared as the rows of one array
        ref, got = getattr(mod, name)(S, y, par), getattr(active, name)(S, stacked[3:], par)
        assert list(got) == list(ref)
        worst[name] = _relative_error(np.vstack([np.broadcast_to(v, S.shape) for v in ref.values()]),
                                      np.vstack(list(got.values())))
    return worst


@pytest.mark.parametrize("name", ["base", "gent", "user-shell-tip"])
def test_the_energy_kernel_is_the_profiles_energy_density(name):
    """``<region>_energy`` (the energy's integrand alone, numpy module) gives the profile's
    ``energy_density`` to rounding, for every region kind of the structure."""
    scene = SCENES[name]
    mod = scene.model()
    par = scene.parameters(mod)
    rng = np.random.default_rng(5)
    for kind in ("free", "contact", "cylinder"):
        if not hasattr(mod, f"{kind}_rhs"):
            continue
        S, y = _states(kind, rng, 200)
        ref = np.broadcast_to(getattr(mod, f"{kind}_profile")(S, y, par)["energy_density"], S.shape)
        got = getattr(mod, f"{kind}_energy")(S, y, par)
        assert got.shape == (1, S.size)
        assert _relative_error(ref[None], got) <= RTOL, kind


# -- the choice ------------------------------------------------------------------------------------
def test_the_choice_is_read_from_the_environment_and_checked(monkeypatch):
    for raw, want in (("", "auto"), ("numpy", "numpy"), (" NUMBA ", "numba"), ("auto", "auto")):
        monkeypatch.setenv("SHELLBVP_KERNELS", raw)
        assert sk.kernel_choice() == want
    monkeypatch.setenv("SHELLBVP_KERNELS", "fast")
    with pytest.raises(ValueError, match=r"SHELLBVP_KERNELS must be one of auto, numpy, numba; got 'fast'"):
        sk.kernel_choice()
    with pytest.raises(ValueError, match="SHELLBVP_KERNELS"):  # where a user meets it: the first solve
        sb.solve(SCENES["base"], delta=0.1)


def test_numpy_keeps_the_generated_numpy_functions(monkeypatch):
    monkeypatch.setenv("SHELLBVP_KERNELS", "numpy")
    scene = SCENES["base"]
    ks = sk.kernel_set(scene.model(), scene.structure)
    assert ks.settled.is_set() and ks.status == "numpy" and ks.active is scene.model()
    assert ks is sk.kernel_set(scene.model(), scene.structure)  # one per structure and choice


def test_without_numba_auto_serves_numpy_and_numba_is_an_error(monkeypatch):
    scene = SCENES["base"]
    monkeypatch.setattr(sk, "_numba_version", lambda: None)
    monkeypatch.setattr(sk, "_sets", {})
    monkeypatch.setenv("SHELLBVP_KERNELS", "auto")
    ks = sk.kernel_set(scene.model(), scene.structure)
    assert ks.settled.is_set() and ks.active is scene.model() and "not installed" in ks.reason
    sol = sb.solve(scene, delta=0.1)
    assert sol.status == 0
    monkeypatch.setenv("SHELLBVP_KERNELS", "numba")
    with pytest.raises(ImportError, match=r"SHELLBVP_KERNELS=numba needs numba: pip install 'shellbvp\[fast\]'"):
        sk.kernel_set(scene.model(), scene.structure)


def test_the_kernel_module_is_generated_beside_the_numpy_one_and_deterministic():
    from symbolic.build import generate_sources

    scene = SCENES["base"]
    desc = scene.structure()
    path = sbm.kernel_source_path(desc)
    assert path.parent == Path(scene.model().__file__).parent
    text = path.read_text()
    assert text == generate_sources(desc)[1]  # byte-identical when generated again
    assert text.startswith("# Generated by shellbvp's symbolic/codegen_numba.py -- DO NOT EDIT BY HAND.")
    assert f"\nKEY = {scene.model().KEY!r}\n" in text and f"\nPARAMS = {scene.model().PARAMS!r}\n" in text
    kernels = {f"{k}_{f}" for k in ("free", "contact", "cylinder") for f in ("rhs", "jac", "jac_par", "profile", "energy")}
    kernels.add("free_legendre")
    elimination = ("collocation_factor", "collocation_solve")
    assert f"KERNELS = {tuple(sorted(kernels, key=text.index)) + elimination!r}" in text
    assert text.count("@numba.njit(") == len(kernels) + 3 and "for _node in range(_m):" in text
    assert text.count("_profile_rows(S, y, par)))") == 3  # a profile's dict is made outside the kernel
    mtime = path.stat().st_mtime_ns
    assert sbm.kernel_source_path(desc) == path and path.stat().st_mtime_ns == mtime  # never rewritten


def test_numba_cache_files_are_loaded_only_from_a_trusted_directory(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    src = tmp_path / "kernels_0123.py"
    src.write_text("raise SystemExit('imported')\n")
    pycache = tmp_path / "__pycache__"
    pycache.mkdir(mode=0o700)
    (pycache / "kernels_0123.free_rhs-18.py311.nbi").write_bytes(b"")
    assert sk._untrusted_cache(src) is None
    os.chmod(pycache / "kernels_0123.free_rhs-18.py311.nbi", 0o666)
    assert "writable by other users" in sk._untrusted_cache(src)
    with pytest.raises(ImportError, match="not loading compiled kernels"):
        sk._import_kernels(src, "0123")  # refused before anything is imported
    os.chmod(pycache / "kernels_0123.free_rhs-18.py311.nbi", 0o600)
    os.chmod(pycache, 0o777)
    assert "writable by other users" in sk._untrusted_cache(src)


def test_with_numba_cache_dir_the_kernels_bytecode_is_still_checked(tmp_path, monkeypatch):
    # numba's files then live where the user says; the import still reads the module's .pyc here
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    src = tmp_path / "kernels_0123.py"
    src.write_text("raise SystemExit('imported')\n")
    pycache = tmp_path / "__pycache__"
    pycache.mkdir(mode=0o700)
    (pycache / "kernels_0123.free_rhs-18.py311.nbi").write_bytes(b"")
    os.chmod(pycache / "kernels_0123.free_rhs-18.py311.nbi", 0o666)
    assert sk._untrusted_cache(src) is None  # numba's file here is not the one numba reads
    pyc = Path(importlib.util.cache_from_source(str(src)))
    pyc.write_bytes(b"")
    os.chmod(pyc, 0o666)
    assert "writable by other users" in sk._untrusted_cache(src)
    with pytest.raises(ImportError, match="not loading compiled kernels"):
        sk._import_kernels(src, "0123")


def test_a_live_compile_lock_is_respected_and_a_dead_one_taken(tmp_path):
    lock = tmp_path / "kernels_0123.lock"
    lock.write_text(str(os.getpid()))
    assert not sk._acquire(lock)  # this process is alive
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True)
    lock.write_text(done.stdout.strip())  # a process that has ended
    assert sk._acquire(lock) and lock.read_text() == str(os.getpid())
    lock.unlink()
    scene = SCENES["base"]
    src = sbm.kernel_path(scene.structure())
    src.with_suffix(".lock").write_text(str(os.getpid()))
    try:  # another live process compiles this structure: the compiler leaves it to that one
        assert sk.compile_kernels(src, scene.structure()) == sk._BUSY
    finally:
        src.with_suffix(".lock").unlink()


# -- compiled ----------------------------------------------------------------------------------------
_AUTO: dict = {}


def _auto_base():
    """The base structure's kernel set under ``auto``, made once: counts, then compiles in the
    background (the threshold set to zero, so that the first timed call starts them)."""
    if "ks" not in _AUTO:
        scene = SCENES["base"]
        src = sbm.kernel_path(scene.structure())
        _AUTO["cold"] = not sk._compiled(src)
        with mock.patch.dict(os.environ, {"SHELLBVP_KERNELS": "auto"}), mock.patch.object(sk, "START_AFTER_S", 0.0), \
                sb.options(compile_in_background=True):
            ks = sk.kernel_set(scene.model(), scene.structure)
            _AUTO["before"] = (ks.status, ks.active.free_rhs is scene.model().free_rhs)
            sol = sb.solve(scene, delta=0.1)  # served by numpy while the kernels are started
        _AUTO["after_first_solve"] = (ks.status, sol.status)
        ks.settled.wait(600)
        _AUTO["ks"] = ks
    return _AUTO["ks"]


@pytest.mark.slow  # a numba compilation in a second process (~25 s)
@needs_numba
def test_auto_compiles_in_a_background_process_once_then_loads_from_the_cache():
    ks = _auto_base()
    assert _AUTO["before"] == ("counting", False)  # numpy, timed
    if _AUTO["cold"]:
        assert _AUTO["after_first_solve"] == ("waiting", 0)  # numpy served while they compile
    assert ks.status == "numba", ks.reason
    src = sbm.kernel_path(SCENES["base"].structure())
    mark = json.loads(src.with_suffix(".ready").read_text())
    assert mark["source_size"] == src.stat().st_size and mark["compile_s"] > 0
    if _AUTO["cold"]:
        assert "compiled kernels_" in src.with_suffix(".log").read_text()  # by the background process
    # a new process finds them compiled: numba loads its cache, compiles nothing
    code = ("import time, shellbvp as sb; from shellbvp import kernels as sk; sc = sb.Scene.preset('base'); "
            "t = time.perf_counter(); ks = sk.kernel_set(sc.model(), sc.structure); "
            "f = ks.compiled.free_rhs; print(ks.status, len(f.stats.cache_hits), len(f.stats.cache_misses))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ, SHELLBVP_KERNELS="numba")).stdout.split()
    assert out == ["numba", "1", "0"]
    assert json.loads(src.with_suffix(".ready").read_text()) == mark  # not compiled again


@needs_numba
def test_compiled_kernels_equal_numpy_on_the_base_structure():
    worst = compare_with_numpy(SCENES["base"], _auto_base().active)
    assert len(worst) == 16 and max(worst.values()) <= RTOL, worst


@needs_numba
def test_the_compiled_collocation_elimination_solves_as_superlu():
    """The kernels' collocation_factor and collocation_solve (symbolic.collocation_kernel,
    compiled) against SuperLU on scipy's assembly, with and without unknowns, C- and
    Fortran-ordered blocks."""
    from collocation_cases import elimination_against_superlu, random_collocation_blocks

    compiled = _auto_base().active
    for k in (0, 2):
        n, m, k, h, *blocks = random_collocation_blocks(k, n=8, m=40)
        fortran = [None if b is None else np.asfortranarray(b) for b in blocks]
        for case in (blocks, fortran):
            difference, growth = elimination_against_superlu(compiled, n, m, k, h, *case)
            assert difference <= 1e-12 and 0 < growth < 1e3


@needs_numba
def test_the_estimate_at_a_switch_state_with_compiled_kernels_is_its_true_error(monkeypatch):
    """With the compiled elimination, solve_bvp's line search on the halved mesh stopped short
    of convergence at this state (estimate 5.1e-9, true error 6.9e-9); the fixed-mesh Newton
    converges (test_error_estimates: the same with numpy)."""
    from collocation_cases import switch_state_estimate

    _auto_base()
    monkeypatch.setenv("SHELLBVP_KERNELS", "numba")
    s, estimate, true = switch_state_estimate()
    assert s.system.kernels.status == "numba"
    assert abs(estimate / true - 1) < 0.02, (estimate, true)


@needs_numba
def test_a_solve_on_compiled_kernels_matches_numpy(monkeypatch):
    _auto_base()
    scene = SCENES["base"]
    monkeypatch.setenv("SHELLBVP_KERNELS", "numpy")
    ref = sb.solve(scene, delta=0.3)
    monkeypatch.setenv("SHELLBVP_KERNELS", "auto")
    got = sb.solve(scene, delta=0.3)
    assert got.system.kernels.status == "numba" and ref.system.kernels.status == "numpy"
    assert got.status == ref.status == 0
    assert got.force == pytest.approx(ref.force, rel=1e-9)


@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(SCENES) - {"base"}))
def test_compiled_kernels_equal_numpy(name, monkeypatch):
    monkeypatch.setenv("SHELLBVP_KERNELS", "numba")  # compiled in this process
    scene = SCENES[name]
    t0 = time.perf_counter()
    ks = sk.kernel_set(scene.model(), scene.structure)
    assert ks.status == "numba" and time.perf_counter() - t0 < 120
    worst = compare_with_numpy(scene, ks.active)
    assert max(worst.values()) <= RTOL, worst


def _join_kernel_threads():
    for t in threading.enumerate():
        if t.name.startswith("shellbvp-kernels-"):
            t.join(10)


@pytest.mark.parametrize("compiled", [True, False])
def test_start_now_loads_compiled_kernels_of_a_counting_set_once(compiled, monkeypatch):
    scene = SCENES["base"]
    ks = sk.KernelSet(scene.model(), "auto")
    started = []
    monkeypatch.setattr(ks, "_background", lambda: started.append(1))
    monkeypatch.setattr(sk, "holds_key", lambda src, key: True)
    monkeypatch.setattr(sk, "_compiled", lambda src: compiled)
    ks.start_now()  # not counting yet: nothing to start
    assert ks.status == "numpy" and not started
    monkeypatch.setattr(sk, "_numba_version", lambda: "0.0")
    ks.start(scene.structure)
    assert ks.status == "counting"
    ks.start_now()
    ks.start_now()  # once only
    _join_kernel_threads()
    if compiled:
        assert started == [1] and ks.status == "waiting" and ks.active is ks.numpy
    else:  # compiling is left to the threshold: beside a whole curve it slows the curve
        assert not started and ks.status == "counting"
        with sb.options(compile_in_background=True):
            ks._charge(sk.START_AFTER_S)  # the threshold starts them where background compiles are allowed
        _join_kernel_threads()
        assert started == [1] and ks.status == "waiting"


def test_by_default_a_command_never_compiles_kernels(monkeypatch):
    """Past the threshold a structure not compiled stays on numpy (no background compile: it
    cannot repay within one command); compiled ones are loaded."""
    scene = SCENES["base"]
    for compiled in (False, True):
        ks = sk.KernelSet(scene.model(), "auto")
        started = []
        monkeypatch.setattr(ks, "_background", lambda: started.append(1))
        monkeypatch.setattr(sk, "_numba_version", lambda: "0.0")
        monkeypatch.setattr(sk, "holds_key", lambda src, key: True)
        monkeypatch.setattr(sk, "_compiled", lambda src: compiled)
        ks.start(scene.structure)
        ks._charge(sk.START_AFTER_S)
        _join_kernel_threads()
        if compiled:
            assert started == [1] and ks.status == "waiting"
        else:
            assert not started and ks.status == "numpy" and "shellbvp compile" in ks.reason
            assert ks.settled.is_set() and ks.active is ks.numpy


@needs_numba
def test_the_compile_command_readies_a_scenes_kernels():
    _auto_base()  # compiled once for this module
    r = subprocess.run([sys.executable, "-m", "shellbvp", "compile", "--preset", "base"], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "scene: kernels loaded" in r.stdout and "1 structure(s) ready" in r.stdout


def test_the_compile_command_without_numba_says_how_to_get_it(monkeypatch, capsys):
    from shellbvp.cli import main

    monkeypatch.setattr(sk, "_numba_version", lambda: None)
    assert main(["compile", "--preset", "base"]) == 2
    assert "pip install 'shellbvp[fast]'" in capsys.readouterr().err


@pytest.mark.parametrize("kw, starts", [({}, True), ({"deltas": np.linspace(0.01, 0.5, sk.LONG_CURVE_POINTS)}, True),
                                        ({"deltas": np.linspace(0.01, 0.5, sk.LONG_CURVE_POINTS - 1)}, False)])
def test_a_long_curve_starts_the_compiled_kernels_at_once(kw, starts, monkeypatch):
    import shellbvp.continuation as sc

    calls = []

    class Recorder:
        def start_now(self):
            calls.append(1)

    monkeypatch.setattr(sc, "kernel_set", lambda model, structure: Recorder())
    monkeypatch.setattr(sc, "adaptive", lambda *a: iter(()))  # the decision only: legs with no state
    monkeypatch.setattr(sc, "natural", lambda *a: iter(()))
    sb.curve(SCENES["base"], **kw)
    assert calls == ([1] if starts else [])
