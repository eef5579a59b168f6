"""A command's output directory: its policy (:mod:`~epc_fast.jobs.output.directory`), its one
writer (:mod:`~epc_fast.jobs.output.lock`) and the manifest a scan keeps in it
(:mod:`~epc_fast.jobs.output.manifest`)."""

from __future__ import annotations

from .directory import (COMMAND_FILES, PARQUET_BYTES_PER_VALUE, STAGING_PREFIX, TABLE_BYTES,
                        OutputDirectory)
from .lock import LOCK_NAME, OutputLock

__all__ = ["OutputDirectory", "TABLE_BYTES", "PARQUET_BYTES_PER_VALUE", "COMMAND_FILES",
           "STAGING_PREFIX", "OutputLock", "LOCK_NAME"]
