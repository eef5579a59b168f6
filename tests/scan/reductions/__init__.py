"""A scan's reductions (epc_fast.scan.reductions): a file per module."""
