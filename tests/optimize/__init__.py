"""The optimiser (epc_fast.optimize): a file per module."""
