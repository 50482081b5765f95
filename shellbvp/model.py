"""Generated code for a scene's structure: derive once, cache, load.

The cache key is a SHA-256 of the structure description (material and bending
family or formula, xi, shell and tip shapes), the codegen version, a fingerprint of
the ``symbolic/`` sources and the SymPy version.  Cached modules live in ``$SHELLBVP_CACHE_DIR``, else
``$XDG_CACHE_HOME/shellbvp``, else ``~/.cache/shellbvp``; they are written
atomically (temporary file + rename) and checked on load (their ``KEY`` must
match), so a concurrent or interrupted writer never leaves a module that is
used half-written.  A warm load imports neither SymPy nor the derivation.

Cached modules are code that is imported, so a cache directory or file that
another user owns or may write is never imported from: the module is
regenerated, into a private temporary directory if the directory itself is
not trusted (a warning says so).
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import logging
import os
import stat
import sys
import tempfile
import time
from pathlib import Path

from symbolic.version import CODEGEN_VERSION, description_key, source_fingerprint

__all__ = ["cache_dir", "structure_description", "description_key", "load_module", "module_path",
           "untrusted_reason"]

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


def structure_description(material, xi: int, shell, tip, bending=None, pressurised=False) -> dict:
    """Everything the generated code depends on, as JSON-able data (``pressurised``: the
    pressure's terms and parameters are generated; descriptions without it are unchanged)."""
    return {**({"pressurised": True} if pressurised else {}),
        "bending": bending.description() if bending is not None else {"family": "trace"},
        "codegen": CODEGEN_VERSION,
        "source": source_fingerprint(),
        "sympy": importlib.metadata.version("sympy"),
        "material": material.description(),
        "xi": int(xi),
        "shell": shell.description(),
        "tip": tip.description(),
    }


def module_path(desc: dict) -> Path:
    return cache_dir() / f"model_{description_key(desc)[:20]}.py"


def _import_file(path: Path, key: str):
    name = f"shellbvp_generated_{key[:20]}"
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
        st = path.stat()
    except OSError as exc:
        return f"cannot stat it ({exc.strerror})"
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        return f"it belongs to another user (uid {st.st_uid})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"it is writable by other users (mode {stat.filemode(st.st_mode)})"
    return None


def _private_dir() -> Path:
    global _private
    if _private is None:
        _private = Path(tempfile.mkdtemp(prefix="shellbvp-"))  # 0700, ours
    return _private


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.chmod(tmp, 0o644)  # mkstemp makes 0600; never group- or world-writable
        os.replace(tmp, path)
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
    path = module_path(desc)
    if path.parent.exists() and (why := untrusted_reason(path.parent)):
        log.warning("not using the code cache %s: %s; generating into a private directory", path.parent, why)
        path = _private_dir() / path.name
    elif path.exists() and (why := untrusted_reason(path)):
        log.warning("not importing the cached module %s: %s; regenerating it", path, why)
        regenerate = True
    mod = None
    if path.exists() and not regenerate:
        try:
            mod = _import_file(path, key)
        except Exception as exc:  # corrupt or foreign file: derive again
            log.warning("ignoring unusable cached module %s (%s); regenerating", path, exc)
    if mod is None:
        from symbolic.build import generate_source

        t0 = time.perf_counter()
        src = generate_source(desc)
        log.info("derived and generated %s in %.2f s", path.name, time.perf_counter() - t0)
        try:
            _write_atomic(path, src)
        except OSError as exc:  # read-only cache: keep the module in a private temp dir
            log.warning("cannot write the code cache %s (%s); using a temporary directory", path, exc)
            path = _private_dir() / path.name
            _write_atomic(path, src)
        mod = _import_file(path, key)
    _loaded[key] = mod
    return mod
