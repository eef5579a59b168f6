"""A scan's manifest, ``manifest.json`` in its output directory: what ran and how far it got.

It records the config (its TOML text and the command line's overrides), the seed, the epc_fast
version and core build, the points asked for and done, ``partial``, the state (``running``
while the scan runs, updated after every merged chunk; then ``complete``, ``interrupted`` or
``failed``) and the files written. A directory whose manifest still says ``running`` and
whose lock no run holds (:mod:`~epc_fast.scan.output.lock`) was left by a scan that was killed.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from .atomic import atomic_write

__all__ = ["MANIFEST_NAME", "FORMAT", "new_manifest", "write_manifest", "read_manifest",
           "describe"]

MANIFEST_NAME = "manifest.json"
FORMAT = "epc_fast scan manifest 1"


def _now() -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())


def new_manifest(config, overrides: dict, points: int) -> dict:
    """The manifest of a scan about to start (state ``running``, no point done)."""
    from .. import __version__, _core

    return {"format": FORMAT, "epc_fast_version": __version__, "core_isa": _core.isa,
            "config_source": config.source, "config": config.text, "overrides": overrides,
            "seed": config.seed, "points_requested": points, "points_done": 0,
            "chunk_points": config.chunk_points, "partial": True, "state": "running",
            "stopped_by": None, "parquet": config.parquet, "files": [],
            "started_utc": _now(), "updated_utc": _now()}


def write_manifest(directory, manifest: dict) -> Path:
    """Write ``manifest`` (its ``updated_utc`` set now) atomically into ``directory``."""
    manifest["updated_utc"] = _now()
    text = json.dumps(manifest, indent=1) + "\n"
    return atomic_write(Path(directory) / MANIFEST_NAME, lambda p: p.write_text(text))


def read_manifest(directory) -> dict | None:
    """The manifest in ``directory``, or None when there is none or it is not one of ours."""
    path = Path(directory) / MANIFEST_NAME
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > 2**26:
            return None
        manifest = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return manifest if isinstance(manifest, dict) and manifest.get("format") == FORMAT else None


def describe(manifest: dict) -> str:
    """What a manifest says of its scan, in a few words, for a directory whose lock no run
    holds (a live run's directory is refused naming that run before its manifest is read)."""
    done = f"{manifest.get('points_done', 0):,} of {manifest.get('points_requested', 0):,} points"
    state = manifest.get("state")
    if state == "running":
        return (f"a scan that did not finish ({done} merged, last recorded "
                f"{manifest.get('updated_utc')}): it was killed (no run holds this "
                "directory's lock)")
    if state == "complete":
        return f"a complete scan ({done})"
    return f"a partial scan ({state}, {done}, stopped by {manifest.get('stopped_by')})"
