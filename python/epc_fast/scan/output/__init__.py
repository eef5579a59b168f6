"""What a scan writes: the output directory and its policy (:mod:`~epc_fast.scan.output.directory`),
its one writer (:mod:`~epc_fast.scan.output.lock`) and the files named before the first point
(:mod:`~epc_fast.scan.output.plan`)."""

from __future__ import annotations

from .directory import PARQUET_BYTES_PER_VALUE, TABLE_BYTES, OutputDirectory
from .lock import LOCK_NAME, OutputLock
from .plan import TABLE_KINDS, plan_outputs

__all__ = ["OutputDirectory", "TABLE_BYTES", "PARQUET_BYTES_PER_VALUE", "plan_outputs",
           "TABLE_KINDS", "OutputLock", "LOCK_NAME"]
