"""Scans over a design space (epc_fast.scan): a file per module or concern."""
