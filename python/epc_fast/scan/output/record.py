"""The first record of a scan's manifest (:mod:`epc_fast.jobs.output.manifest`): what is about
to run."""

from __future__ import annotations

from ...jobs.output.manifest import FORMAT, now_utc

__all__ = ["new_manifest"]


def new_manifest(config, overrides: dict, points: int) -> dict:
    """The manifest of a scan about to start (state ``running``, no point done)."""
    from ... import __version__, _core

    return {"format": FORMAT, "epc_fast_version": __version__, "core_isa": _core.isa,
            "config_source": config.source, "config": config.text, "overrides": overrides,
            "seed": config.seed, "points_requested": points, "points_done": 0,
            "chunk_points": config.chunk_points, "partial": True, "state": "running",
            "stopped_by": None, "parquet": config.parquet, "files": [],
            "started_utc": now_utc(), "updated_utc": now_utc()}
