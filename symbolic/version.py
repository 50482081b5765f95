"""Version of the derivation and of the generated interface.

Part of every generated module's cache key: bump it whenever the derivation
(symbolic/equations.py), the printer or the generated functions' signatures
change, so that stale cached modules are never loaded.  Kept free of imports
so that reading it does not import SymPy.
"""

CODEGEN_VERSION = "12"


def source_fingerprint(*formula_dirs) -> str:
    """SHA-256 of this package's source files and of those in ``formula_dirs`` (the modules
    that register energies with ``symbolic.energies``): part of the cache key.

    Any edit of the derivation, the printer or a formula changes it, so a stale cached
    module is never loaded even if CODEGEN_VERSION was not bumped.
    """
    import hashlib
    from pathlib import Path

    h = hashlib.sha256()
    for folder in (Path(__file__).parent, *map(Path, formula_dirs)):
        for path in sorted(folder.glob("*.py")):
            h.update(path.name.encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def canonical_json(description: dict) -> str:
    """Deterministic text of a structure description (sorted keys, no spaces)."""
    import json

    return json.dumps(description, sort_keys=True, separators=(",", ":"))


def description_key(description: dict) -> str:
    """SHA-256 of the canonical description: the generated module's identity."""
    import hashlib

    return hashlib.sha256(canonical_json(description).encode()).hexdigest()
