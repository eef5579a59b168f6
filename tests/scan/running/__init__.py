"""How a scan runs (epc_fast.scan.running): a file per module."""
