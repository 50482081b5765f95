"""Compiled kernels (optional): a structure's hot functions compiled by numba.

A curve spends about 40 % of its time in the generated right-hand sides and
Jacobians, and 7-10 % in the regions' profiles (diagnosis and energy at every
state), most of it NumPy's fixed cost per array operation on a few hundred
nodes; and SuperLU, 20-30 %, on a matrix whose structure it does not know.
The code generator also prints them as loops over the nodes
(``symbolic.codegen_numba``, ``kernels_<key>.py`` beside the numpy module
``model_<key>.py``).  With numba installed (``pip install shellbvp[fast]``) they
are compiled once per structure, kept in numba's on-disk cache (``__pycache__``
beside the generated modules, so keyed the same way), and the solver
(:mod:`shellbvp.chain`) calls them in place of the numpy ones; the module also
holds the elimination that solves solve_bvp's collocation system in place of
SuperLU (:mod:`shellbvp.collocation`).  The numpy module
stays the reference and the fallback: without numba nothing changes.

The choice is the environment variable ``SHELLBVP_KERNELS``:

``auto`` (default)
    numba's kernels when numba is installed and they are compiled, never waited for.
    The numpy functions serve, timed, until they have taken ``START_AFTER_S`` (0.5 s) in
    this process, about what loading compiled kernels costs, so a single solve never pays
    for them and a curve is repaid; a curve of ``LONG_CURVE_POINTS`` or more (every
    adaptive curve) loads kernels already compiled at its start (waiting would only add its
    numpy time: loading in a thread holds the interpreter lock as the solve does).  The
    kernels are loaded from the cache in a background thread (~0.5 s) and the solver
    switches when they are ready.  A structure whose kernels are not compiled yet stays on
    numpy: compiling takes ~15-40 s on the other core of a 2-core machine, which no single
    curve, solve or fit repays (a curve's numpy time is ~1 s), and it competed with the
    user's own run.  ``shellbvp compile`` compiles them once, in the foreground (every
    preset's structure, or a scene's); with the option ``compile_in_background``
    (:func:`shellbvp.options`) a background process compiles them once the threshold is
    passed (a process, not a thread: compiling is Python work that would hold the
    interpreter lock and slow the solve it is meant to speed up; benchmarks/results/kernels.md).
``numpy``
    never compile; the numpy functions only.
``numba``
    compile (or load) the kernels before the first solve, in this process;
    ImportError if numba is missing.

Compilation is logged at INFO level ("compiling kernels for this scene, once:
~15 s"); ``kernels_<key>.ready`` records a finished compilation (numba and
Python versions, the source's time stamp and size), ``kernels_<key>.log`` the
background process's output.  numba's cache files are loaded code (pickles), so
they are used only from a directory that passes the code cache's trust checks
(:func:`shellbvp.model.untrusted_reason`); with ``NUMBA_CACHE_DIR`` set, numba
keeps them there instead, under the user's responsibility.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import json
import logging
import os
import subprocess
import sys
import threading
import time
import types
from pathlib import Path

from .config import OPTIONS
from .model import (description_key, holds_key, kernel_path, untrusted_bytecode, untrusted_reason, write_atomic,
                    write_bytecode)

__all__ = ["CHOICES", "ENV", "LONG_CURVE_POINTS", "KernelSet", "kernel_choice", "kernel_set", "compile_kernels",
           "compile_for"]

log = logging.getLogger(__name__)

ENV = "SHELLBVP_KERNELS"
CHOICES = ("auto", "numpy", "numba")
#: What the compile log line announces (derivation if needed + numba compile; measured in
#: benchmarks/results/kernels.md on the 2-core machine)
COMPILE_ESTIMATE_S = 15
#: auto starts the compiled kernels once the numpy ones have taken this long in this process:
#: loading them costs about as much (numba's start-up and cache; benchmarks/results/kernels.md),
#: so a single solve never pays it and a curve is repaid
START_AFTER_S = 0.5
#: A curve of at least this many points (adaptive curves: ~35) starts the compiled kernels at
#: once (:meth:`KernelSet.start_now`): ~30 ms of numpy per point against ~10 with the kernels
#: and ~0.6 s to load them (import numba included) repay from about 30 points
LONG_CURVE_POINTS = 30
_BUSY = 3  # exit status of the compile process when another process is compiling the same structure
_LOCK_STALE_S = 1800.0  # a lock older than this is from a compile that died
_WAIT_S = 1800.0  # how long a process waits for another one's compilation before giving up


def kernel_choice() -> str:
    """The value of ``SHELLBVP_KERNELS`` (default ``auto``); ValueError naming it if it is invalid."""
    raw = os.environ.get(ENV, "")
    value = raw.strip().lower() or "auto"
    if value not in CHOICES:
        raise ValueError(f"{ENV} must be one of {', '.join(CHOICES)}; got {raw!r}")
    return value


def _numba_version() -> str | None:
    try:
        return importlib.metadata.version("numba")
    except importlib.metadata.PackageNotFoundError:
        return None


# -- files beside the kernels module --------------------------------------------------------------
def _marker(src: Path) -> Path:
    return src.with_suffix(".ready")


def _stamp(src: Path) -> dict:
    st = src.stat()
    return {"numba": _numba_version(), "python": "{}.{}".format(*sys.version_info[:2]),
            "source_mtime_ns": st.st_mtime_ns, "source_size": st.st_size}


def _compiled(src: Path) -> bool:
    """numba's cache holds the kernels of ``src`` as it is now (per the marker of the last compile)."""
    try:
        mark = json.loads(_marker(src).read_text())
        return isinstance(mark, dict) and all(mark.get(k) == v for k, v in _stamp(src).items())
    except (OSError, ValueError):
        return False


def _ready(src: Path, key: str) -> bool:
    """``src`` holds the kernels of ``key`` and numba's cache holds them compiled."""
    return holds_key(src, key) and _compiled(src)


def _untrusted_cache(src: Path) -> str | None:
    """Why the cache files of ``src`` (numba's, and the module's own bytecode) must not be
    loaded, or None.  With ``NUMBA_CACHE_DIR`` set numba's files are the user's choice of
    location, but the import still reads the module's bytecode beside it."""
    return untrusted_bytecode(src, every_cache_file=not os.environ.get("NUMBA_CACHE_DIR"))


def _import_kernels(src: Path, key: str):
    """Import the kernels module: numba compiles it now, or loads its cache."""
    if why := untrusted_reason(src) or _untrusted_cache(src):
        raise ImportError(f"not loading compiled kernels: {why}")
    (src.parent / "__pycache__").mkdir(mode=0o700, exist_ok=True)  # before numba makes it with the umask's
    write_bytecode(src)  # the module's own Python (numba's dispatchers): ~35 ms to compile from source
    name = f"shellbvp_kernels_{key[:20]}"
    spec = importlib.util.spec_from_file_location(name, src)
    mod = importlib.util.module_from_spec(spec)
    # registered first: numba records the module by name in its cache, and imports it by that
    # name when it loads the cache
    sys.modules[name] = mod
    try:
        spec.loader.exec_module(mod)
        if getattr(mod, "KEY", None) != key:
            raise ImportError(f"{src} does not hold the kernels of key {key}")
    except BaseException:
        sys.modules.pop(name, None)
        raise
    return mod


def _discard_compiled(src: Path) -> None:
    """Remove numba's cache files of ``src`` and its marker (they failed to load: damaged or
    from another numba), so that the next compile rebuilds them and later runs read them as
    not compiled rather than warn again."""
    for f in [_marker(src), *(src.parent / "__pycache__").glob(src.stem + ".*.nb[ic]")]:
        try:
            f.unlink()
        except FileNotFoundError:
            pass


def _load_compiled(src: Path, key: str, desc: dict):
    """Import the compiled kernels of ``src``; where numba's cache of them fails to load (a
    damaged file: UnpicklingError, EOFError, ...), one warning, the cache discarded and the
    kernels compiled again.  ``(module, seconds compiling)``: 0 when loaded."""
    if why := untrusted_reason(src) or _untrusted_cache(src):
        raise ImportError(f"not loading compiled kernels: {why}")
    try:
        return _import_kernels(src, key), 0.0
    except Exception as exc:  # numba's loader raises what unpickling a damaged file raises
        log.warning("the compiled kernels of %s could not be loaded (%s: %s); compiling them again",
                    src.name, type(exc).__name__, " ".join(str(exc).split())[:200])
    _discard_compiled(src)
    return _compile_here(src, key, desc)


def _compile_here(src: Path, key: str, desc: dict):
    """Generate the source if need be, compile it in this process and mark it compiled."""
    if not holds_key(src, key):
        from symbolic.build import generate_sources

        write_atomic(src, generate_sources(desc)[1])
    t0 = time.perf_counter()
    mod = _import_kernels(src, key)
    seconds = time.perf_counter() - t0
    write_atomic(_marker(src), json.dumps(dict(_stamp(src), compile_s=round(seconds, 2))) + "\n")
    return mod, seconds


# -- the background compile process ------------------------------------------------------------------
def _acquire(lock: Path) -> bool:
    """Create ``lock`` (holding our pid) unless a live process holds it."""
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600)
        except FileExistsError:
            if not _stale(lock):
                return False
            lock.unlink(missing_ok=True)
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(str(os.getpid()))
        return True
    return False


def _stale(lock: Path) -> bool:
    try:
        if time.time() - lock.stat().st_mtime > _LOCK_STALE_S:
            return True
        pid = int(lock.read_text() or "0")
    except (OSError, ValueError):
        return True
    if os.name != "posix" or pid <= 0:
        return False  # only the age tells (os.kill(pid, 0) would end the process on Windows)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False


def compile_kernels(src: Path, desc: dict) -> int:
    """Compile the kernels of ``desc`` at ``src`` (the body of the background process).

    Returns 0 when they are compiled (or already were), ``_BUSY`` when another process
    is compiling them.
    """
    key = description_key(desc)
    if src.name != f"kernels_{key[:20]}.py":
        raise ValueError(f"{src} is not the kernels module of key {key[:20]}")
    lock = src.with_suffix(".lock")
    if not _acquire(lock):
        return _BUSY
    try:
        if not _ready(src, key):
            _, seconds = _compile_here(src, key, desc)
            log.info("compiled %s in %.1f s", src.name, seconds)
    finally:
        lock.unlink(missing_ok=True)
    return 0


_COMPILER = "import sys; from shellbvp.kernels import main; sys.exit(main(sys.argv[1:]))"


def _spawn_compiler(src: Path, desc: dict) -> int:
    """Run :func:`compile_kernels` in a new process of this interpreter; its exit status."""
    env = dict(os.environ)
    here = str(Path(__file__).resolve().parents[1])  # this shellbvp, whatever sys.path says
    env["PYTHONPATH"] = here + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    with open(src.with_suffix(".log"), "w") as out:  # a file, not a pipe: it may outlive us
        proc = subprocess.Popen([sys.executable, "-c", _COMPILER, str(src)], stdin=subprocess.PIPE,
                                stdout=out, stderr=subprocess.STDOUT, env=env, start_new_session=True)
    proc.stdin.write(json.dumps(desc).encode())
    proc.stdin.close()
    return proc.wait()


# -- the set the solver calls ------------------------------------------------------------------------
class KernelSet:
    """The generated functions of one structure as the solver calls them.

    ``active`` has the numpy module's functions, and, once the compiled kernels are
    loaded, the compiled ones in place of those it has (same names, same values to
    rounding; they take 1-D ``S`` and 2-D ``y`` arrays of float64).  ``status`` says
    which: ``numpy``; ``counting`` (auto: numpy, timing the hot calls until they have
    taken ``START_AFTER_S``); ``waiting`` (compiling or loading in the background);
    ``numba``; or ``failed`` (numpy, with the reason logged).  ``settled`` is set once
    it is final.
    """

    def __init__(self, model, choice: str):
        self.numpy = self.active = model
        self.compiled = None
        self.choice = choice
        self.status = "numpy"
        self.reason = ""
        self.numpy_seconds = 0.0  # time the hot numpy functions took while counting
        self.settled = threading.Event()
        self.pid = os.getpid()
        self._structure = None
        self._lock = threading.Lock()

    def __repr__(self):
        return f"KernelSet({self.numpy.KEY[:20]}, choice={self.choice!r}, status={self.status!r})"

    def _namespace(self, replace: dict):
        names = {n: getattr(self.numpy, n) for n in dir(self.numpy) if not n.startswith("_")}
        names.update(replace)
        return types.SimpleNamespace(**names)  # assigned to ``active`` at once: a caller sees old or new

    def _use(self, mod):
        self.compiled = mod
        self.active = self._namespace({n: getattr(mod, n) for n in mod.KERNELS})
        self.status = "numba"

    def _fail(self, reason: str):
        self.status, self.reason = "failed", reason
        log.warning("compiled kernels not used (%s); the numpy functions serve", reason)

    def start(self, structure):
        """Settle the choice: at once (numpy, numba) or after enough work, in the background (auto)."""
        if self.choice == "numpy":
            self.settled.set()
            return
        if self.choice == "auto" and _numba_version() is None:
            self.reason = "numba is not installed"
            self.settled.set()
            return
        if self.choice == "numba":
            try:
                self._load(structure(), foreground=True)
            finally:
                self.settled.set()
            return
        self._structure = structure
        self.status = "counting"
        self.active = self._namespace({n: self._timed(getattr(self.numpy, n)) for n in self.numpy.KERNELS})

    def _timed(self, fn):
        def timed(*args):
            t0 = time.perf_counter()
            try:
                return fn(*args)
            finally:
                self._charge(time.perf_counter() - t0)
        return timed

    def _charge(self, seconds):
        """Count time in the numpy kernels; past ``START_AFTER_S`` start the compiled ones
        (where they are compiled already, or compiling in the background is allowed)."""
        self.numpy_seconds += seconds
        if self.numpy_seconds >= START_AFTER_S and self.status == "counting":
            if OPTIONS.compile_in_background or _ready(kernel_path(self._structure()), self.numpy.KEY):
                self._begin()
            else:
                self._not_compiled()

    def _not_compiled(self):
        """Counting ends with numpy: this structure's kernels are not compiled, and one command
        does not repay compiling them (``shellbvp compile`` does it once)."""
        with self._lock:
            if self.status != "counting":
                return
            self.status, self.active = "numpy", self.numpy
            self.reason = "kernels not compiled for this structure (run `shellbvp compile` once)"
        log.info("compiled kernels not used: %s", self.reason)
        self.settled.set()

    def start_now(self):
        """auto: load compiled kernels now, not after ``START_AFTER_S`` of numpy work -- for a
        run known to repay them, a curve of :data:`LONG_CURVE_POINTS` or more.  Loading in a
        thread does not overlap the solve (both hold the interpreter lock), so for such a run
        the wait only adds its numpy time (default base curve in a fresh process: 1.95 s with
        the kernels loaded after ``START_AFTER_S``, 1.10-1.22 s from the start, 1.46-1.56 s
        numpy only; docs/benchmarking.md).  Kernels not compiled yet are left to the
        threshold: compiling from the start, beside the whole curve, made it slower than
        numpy (1.67 s against 1.56 s)."""
        if self.status != "counting":
            return
        if _ready(kernel_path(self._structure()), self.numpy.KEY):
            self._begin()

    def _begin(self):
        """Counting ends: load (or compile, in a process) the kernels in a background thread."""
        with self._lock:
            if self.status != "counting":
                return
            self.status = "waiting"
            self.active = self.numpy  # stop counting
        threading.Thread(target=self._background, daemon=True,
                         name=f"shellbvp-kernels-{self.numpy.KEY[:8]}").start()

    def _load(self, desc, foreground):
        key = self.numpy.KEY
        src = kernel_path(desc)
        if foreground:
            if _numba_version() is None:
                raise ImportError(f"{ENV}=numba needs numba: pip install 'shellbvp[fast]' (or numba)")
            fresh = not _ready(src, key)
            if fresh:
                log.info("compiling kernels for this scene, once: ~%d s", COMPILE_ESTIMATE_S)
                mod, seconds = _compile_here(src, key, desc)
                log.info("compiled kernels %s in %.1f s", src.name, seconds)
            else:
                mod, seconds = _load_compiled(src, key, desc)
                if seconds:
                    log.info("compiled kernels %s in %.1f s", src.name, seconds)
            self._use(mod)
            return
        if not _ready(src, key):
            log.info("compiling kernels for this scene, once: ~%d s, in the background (numpy meanwhile)",
                     COMPILE_ESTIMATE_S)
            lock, deadline = src.with_suffix(".lock"), time.monotonic() + _WAIT_S
            rc = _spawn_compiler(src, desc)
            while rc == _BUSY and not _compiled(src) and time.monotonic() < deadline:
                time.sleep(0.5)  # another process compiles this structure: wait for its marker
                if not lock.exists() and not _compiled(src):
                    rc = _spawn_compiler(src, desc)  # it ended without success: try ourselves
            if not _compiled(src):
                raise RuntimeError(f"the compile process failed (exit {rc}); its output: "
                                   f"{src.with_suffix('.log')}")
        t0 = time.perf_counter()
        try:
            mod = _import_kernels(src, key)
        except Exception as exc:  # a damaged cache: discarded, so later runs read "not compiled", no warning
            if isinstance(exc, ImportError) and str(exc).startswith("not loading"):
                raise
            _discard_compiled(src)
            raise RuntimeError(f"numba's cache of them failed to load ({type(exc).__name__}: {exc}); it is "
                               f"discarded: `shellbvp compile` builds it again") from None
        self._use(mod)
        log.info("compiled kernels %s loaded in %.2f s; the solver uses them from now on", src.name,
                 time.perf_counter() - t0)

    def _background(self):
        try:
            self._load(self._structure(), foreground=False)
        except Exception as exc:  # numba missing, broken or incompatible; a failed compile
            self._fail(f"{type(exc).__name__}: {exc}")
        finally:
            self.settled.set()


_sets: dict[tuple, KernelSet] = {}
_sets_lock = threading.Lock()


def kernel_set(model, structure) -> KernelSet:
    """The process's :class:`KernelSet` of a generated numpy module.

    Parameters
    ----------
    model : module
        The structure's generated numpy module (``Scene.model()``).
    structure : callable
        Returns the structure description (``Scene.structure``), called only when the
        set is first made.
    """
    choice = kernel_choice()
    k = (model.KEY, choice)
    with _sets_lock:
        ks = _sets.get(k)
        if ks is None or ks.pid != os.getpid():  # a forked child has none of our threads
            ks = _sets[k] = KernelSet(model, choice)
            try:
                ks.start(structure)
            except BaseException:
                del _sets[k]
                raise
    return ks


def compile_for(scene) -> tuple[str, float]:
    """Compile ``scene``'s kernels in this process, or load them if compiled already:
    ``("compiled" | "loaded", seconds)``.  ImportError without numba."""
    if _numba_version() is None:
        raise ImportError("compiled kernels need numba: pip install 'shellbvp[fast]'")
    model = scene.model()
    src = kernel_path(scene.structure())
    marked = _marker_time(src)
    t0 = time.perf_counter()
    KernelSet(model, "numba").start(scene.structure)
    compiled = marked is None or _marker_time(src) != marked  # a damaged cache is compiled again
    return ("compiled" if compiled else "loaded"), time.perf_counter() - t0


def _marker_time(src: Path) -> int | None:
    """When the kernels of ``src`` were last marked compiled (None: not compiled)."""
    try:
        return _marker(src).stat().st_mtime_ns if _compiled(src) else None
    except OSError:
        return None


def main(argv=None) -> int:
    """The background compile process: ``main([SRC])`` with the structure description (JSON) on stdin."""
    argv = sys.argv[1:] if argv is None else argv
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    if len(argv) != 1:
        print("usage: main([KERNELS_SOURCE]) with the description (JSON) on stdin", file=sys.stderr)
        return 2
    desc = json.loads(sys.stdin.read())
    if not isinstance(desc, dict):
        print("the description on stdin must be a JSON object", file=sys.stderr)
        return 2
    return compile_kernels(Path(argv[0]), desc)

