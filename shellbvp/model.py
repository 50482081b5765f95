"""Generated code for a scene's structure: derive once, cache, load.

The cache key is a SHA-256 of the structure description (material and bending
family or formula, xi, shell and tip shapes), the codegen version, a fingerprint of
the ``symbolic/`` sources and the SymPy version.  Cached modules live in ``$SHELLBVP_CACHE_DIR``, else
``$XDG_CACHE_HOME/shellbvp``, else ``~/.cache/shellbvp``; they are written
atomically (temporary file + rename) and checked on load (their ``KEY`` must
match), so a concurrent or interrupted writer never leaves a module that is
used half-written; a process meeting a structure that another is deriving waits for
that one's module (a lock file beside it) instead of deriving it too.  A warm load
imports neither SymPy nor the derivation.

Beside each module ``model_<key>.py`` lies ``kernels_<key>.py``, the same structure's
loop-over-nodes kernels for numba (``symbolic.codegen_numba``; imported only by
``shellbvp.kernels``), written by the same derivation; numba keeps its compiled code in
``__pycache__`` beside it.

Cached modules are code that is imported, so a cache directory or file that
another user owns or may write is never imported from: the module is
regenerated, into a private temporary directory if the directory itself is
not trusted (a warning says so).  The same holds for their bytecode
(``__pycache__`` beside them), which is written when a module is first imported
even under ``PYTHONDONTWRITEBYTECODE``: it is part of this cache, and compiling a
structure's numpy module from source costs ~0.1 s of every process's start
(``benchmarks/results/kernels.md``).
"""

from __future__ import annotations

import contextlib
import functools
import importlib.metadata
import importlib.util
import logging
import os
import py_compile
import stat
import sys
import tempfile
import time
from pathlib import Path

from symbolic.version import CODEGEN_VERSION, description_key, source_fingerprint

__all__ = ["cache_dir", "structure_description", "description_key", "load_module", "load_stability_module",
           "stability_description", "module_path", "lower_structure",
           "kernel_path", "kernel_source_path", "holds_key", "write_atomic", "untrusted_reason",
           "untrusted_bytecode", "write_bytecode"]

log = logging.getLogger(__name__)
_loaded: dict[str, object] = {}
_private: Path | None = None  # this process's own cache when the shared one is not to be trusted


def cache_dir() -> Path:
    """Directory of generated modules (created on demand)."""
    env = os.environ.get("SHELLBVP_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "shellbvp"


@functools.cache
def _code_inputs() -> tuple[str, str]:
    """(fingerprint of the derivation's source, SymPy version), read once per process: hashing
    the files and reading package metadata cost ~2 ms, and every solve asks (``Scene.model()``,
    ~80 times on the default base curve: 6 % of its time).  The derivation imported in this
    process is the one that generates, so its files are read once, like an import.  The
    materials' modules hold their formulas: they are part of the derivation's source."""
    return source_fingerprint(Path(__file__).parent / "materials"), importlib.metadata.version("sympy")


def structure_description(material, xi: int, shell, tip, bending=None, pressurised=False, substrate=False,
                          thickness=None) -> dict:
    """Everything the generated code depends on, as JSON-able data (``pressurised``: the
    pressure's terms and parameters are generated; ``substrate``: a closed shell's contact with
    the plane it rests on; ``thickness``: a wall's profile, ``ThicknessProfile.description``;
    descriptions without them are unchanged)."""
    return {**({"pressurised": True} if pressurised else {}), **({"substrate": True} if substrate else {}),
        **({"thickness": thickness} if thickness is not None else {}),
        "bending": bending.description() if bending is not None else {"family": "trace"},
        "codegen": CODEGEN_VERSION,
        "source": _code_inputs()[0],
        "sympy": _code_inputs()[1],
        "material": material.description(),
        "xi": int(xi),
        "shell": shell.description(),
        "tip": tip.description(),
    }


def module_path(desc: dict) -> Path:
    return cache_dir() / f"model_{description_key(desc)[:20]}.py"


def _import_file(path: Path, key: str):
    name = f"shellbvp_generated_{key[:20]}"
    write_bytecode(path)
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    if getattr(mod, "KEY", None) != key:
        raise ImportError(f"{path} does not hold the module for key {key}")
    sys.modules[name] = mod
    return mod


def untrusted_reason(path: Path) -> str | None:
    """Why a cached file or directory must not be imported from, or None.

    Generated modules are code that gets imported: a file or directory that
    another user owns or may write could hold anything.
    """
    try:
        st = path.lstat()
        if stat.S_ISLNK(st.st_mode):
            if not path.is_dir():  # a file's link could be pointed anywhere; a linked cache folder is a choice
                return "it is a symbolic link (imported code must be a file of its own)"
            st = path.stat()
    except OSError as exc:
        return f"cannot stat it ({exc.strerror})"
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        return f"it belongs to another user (uid {st.st_uid})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"it is writable by other users (mode {stat.filemode(st.st_mode)})"
    return None


def untrusted_bytecode(path: Path, every_cache_file: bool = False) -> str | None:
    """Why the bytecode beside the generated module ``path`` (``__pycache__``, which the import
    reads when it is current) must not be used, or None.  ``every_cache_file``: every file
    there named after the module (numba's index and data files too), not only the import's."""
    pycache = path.parent / "__pycache__"
    if not pycache.exists():
        return None
    if why := untrusted_reason(pycache):
        return f"{pycache}: {why}"
    files = (pycache.glob(path.stem + ".*") if every_cache_file
             else [Path(importlib.util.cache_from_source(str(path)))])
    for f in files:
        if f.exists() and (why := untrusted_reason(f)):
            return f"{f}: {why}"
    return None


def write_bytecode(path: Path) -> None:
    """Compile the generated module ``path`` into its ``__pycache__`` unless that holds a file
    as new as the source (the import checks the source's time stamp and size itself); atomic
    (py_compile), never fatal: without it the import compiles from source."""
    pyc = Path(importlib.util.cache_from_source(str(path)))
    try:
        if pyc.exists() and pyc.stat().st_mtime_ns >= path.stat().st_mtime_ns:
            return
        pyc.parent.mkdir(mode=0o700, exist_ok=True)
        py_compile.compile(str(path), cfile=str(pyc), doraise=True)
    except (OSError, py_compile.PyCompileError) as exc:
        log.debug("no bytecode written for %s: %s", path, exc)


def _private_dir() -> Path:
    global _private
    if _private is None:
        _private = Path(tempfile.mkdtemp(prefix="shellbvp-"))  # 0700, ours
    return _private


def write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.chmod(tmp, 0o644)  # mkstemp makes 0600; never group- or world-writable
        os.replace(tmp, path)
    except OSError as exc:  # a full disk: one error naming the file
        Path(tmp).unlink(missing_ok=True)
        raise OSError(exc.errno, f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def load_module(desc: dict, *, regenerate: bool = False):
    """The generated module of a structure: from memory, the cache, or a derivation.

    Derivation (cold start) takes a few seconds and logs at INFO level.
    """
    key = description_key(desc)
    if not regenerate and key in _loaded:
        return _loaded[key]

    def generate():
        from symbolic.build import generate_sources

        return generate_sources(desc)

    def write_kernels(path, kernel_src):
        kpath = _kernel_path(path.parent, key)
        if not holds_key(kpath, key):  # never rewritten when current: numba's cache stamps the file
            write_atomic(kpath, kernel_src)

    mod = _cached_or_generated(module_path(desc), key, generate, regenerate, write_kernels)
    _loaded[key] = mod
    return mod


def stability_description(desc: dict) -> dict:
    """The description of a structure's generated second variation (its own key)."""
    return {**desc, "generated": "second_variation"}


def load_stability_module(desc: dict):
    """The generated second variation of a structure (``symbolic.second_variation``): the form's
    entries and the reference shell, from memory, the cache, or a derivation (~5-10 s once)."""
    sdesc = stability_description(desc)
    key = description_key(sdesc)
    if key in _loaded:
        return _loaded[key]

    def generate():
        from symbolic.build import structure_from_description
        from symbolic.second_variation import form_module_source
        from symbolic.version import canonical_json

        return form_module_source(structure_from_description(desc), canonical_json(sdesc)), None

    mod = _cached_or_generated(cache_dir() / f"stability_{key[:20]}.py", key, generate)
    _loaded[key] = mod
    return mod


def _cached_or_generated(path: Path, key: str, generate, regenerate=False, write_extra=None):
    """The module of ``key`` at ``path`` in the code cache if it is there and trusted, else
    ``generate()`` -> (source, extra) written there (or to a private directory) and imported;
    ``write_extra(path, extra)`` writes what comes with it."""
    if path.parent.exists() and (why := untrusted_reason(path.parent) or untrusted_bytecode(path)):
        log.warning("not using the code cache %s: %s; generating into a private directory", path.parent, why)
        path = _private_dir() / path.name
    elif path.exists() and (why := untrusted_reason(path)):
        log.warning("not importing the cached module %s: %s; regenerating it", path, why)
        regenerate = True
    if path.exists() and not regenerate:
        try:
            return _import_file(path, key)
        except Exception as exc:  # corrupt or foreign file: derive again
            log.warning("ignoring unusable cached module %s (%s); regenerating", path, exc)
            regenerate = True
    with _generation_lock(path):
        if path.exists() and not regenerate:  # another process derived it while this one waited
            try:
                return _import_file(path, key)
            except Exception as exc:
                log.warning("ignoring unusable cached module %s (%s); regenerating", path, exc)
        return _generated(path, key, generate, write_extra)


#: A process waits at most this long for another deriving the same structure, then derives it too.
LOCK_WAIT = 600.0


@contextlib.contextmanager
def _generation_lock(path: Path):
    """Held while the module ``path`` is derived: a second process (a parallel batch, a test
    worker) meeting the same new structure waits and reads the first's module instead of
    deriving it again.  An advisory ``flock`` on ``<module>.lock`` beside it, released when its
    process ends however it ends; none where ``fcntl`` does not exist (Windows) or the lock
    file cannot be opened (a read-only cache), and none after ``LOCK_WAIT`` seconds."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        fd = os.open(path.with_name(path.name + ".lock"), os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o600)
    except OSError:
        yield
        return
    try:
        deadline, said = time.monotonic() + LOCK_WAIT, False
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() > deadline:
                    log.warning("another process has been deriving %s for %.0f s; deriving it here too",
                                path.name, LOCK_WAIT)
                    break
                if not said:
                    log.info("another process is deriving %s; waiting for it", path.name)
                    said = True
                time.sleep(0.05)
        yield
    finally:
        os.close(fd)  # releases the lock


def _generated(path: Path, key: str, generate, write_extra=None):
    """``generate()`` -> (source, extra) written to ``path`` (or a private directory) and imported."""
    t0 = time.perf_counter()
    log.info("deriving the equations of a new structure and generating their code, once (%s in %s) ...",
             path.name, path.parent)
    src, extra = generate()
    log.info("derived and generated %s in %.2f s", path.name, time.perf_counter() - t0)
    try:
        write_atomic(path, src)
    except OSError as exc:  # read-only cache: keep the module in a private temp dir
        log.warning("cannot write the code cache %s (%s); using a temporary directory", path, exc)
        path = _private_dir() / path.name
        write_atomic(path, src)
    if write_extra is not None:
        write_extra(path, extra)
    return _import_file(path, key)


def kernel_path(desc: dict) -> Path:
    """Where the kernels module of a structure lies (beside its numpy module; not generated here)."""
    mod = load_module(desc)  # its directory is the trusted one chosen for this structure
    return _kernel_path(Path(mod.__file__).parent, mod.KEY)


def _kernel_path(directory: Path, key: str) -> Path:
    return directory / f"kernels_{key[:20]}.py"


def holds_key(path: Path, key: str) -> bool:
    """``path`` is a generated kernel module of ``key`` (read as text: importing it compiles)."""
    try:
        with open(path, encoding="utf-8") as fh:
            head = fh.read(4096)
    except (OSError, UnicodeDecodeError):
        return False
    return f"\nKEY = {key!r}\n" in head


def kernel_source_path(desc: dict) -> Path:
    """The kernels module of a structure (``kernels_<key>.py`` beside its numpy module).

    Generated (a derivation, a few seconds) if it is missing, belongs to another key, or is
    not to be trusted; an existing current file is never rewritten, since numba's on-disk
    cache of its compiled code is keyed by the file's time stamp.
    """
    key = description_key(desc)
    path = kernel_path(desc)
    untrusted = path.exists() and (why := untrusted_reason(path))
    if untrusted:
        log.warning("not importing the cached kernels %s: %s; regenerating them", path, why)
    if untrusted or not holds_key(path, key):  # replaced by a rename: ours afterwards
        from symbolic.build import generate_sources

        t0 = time.perf_counter()
        write_atomic(path, generate_sources(desc)[1])
        log.info("derived and generated %s in %.2f s", path.name, time.perf_counter() - t0)
    return path


def lower_structure(scene) -> dict | None:
    """The structure of a closed shell's lower half where its meridian is its own
    (``UserShell.closed_halves``, both halves solved; else None): the scene's, with that
    meridian.  Both halves' modules take the same run-time parameters."""
    lower = getattr(scene.shell, "lower", None)
    if lower is None or not scene.two_contacts:
        return None
    return structure_description(scene.material, scene.xi, lower, scene.tip, scene.bending,
                                 pressurised=scene.pressurised, substrate=True)
