"""What a scan writes: the files named before its first point (:mod:`~epc_fast.scan.output.plan`)
and its manifest's first record (:mod:`~epc_fast.scan.output.record`), in the output directory
of :mod:`epc_fast.jobs.output`."""

from __future__ import annotations

from .plan import TABLE_KINDS, plan_outputs
from .record import new_manifest

__all__ = ["plan_outputs", "TABLE_KINDS", "new_manifest"]
