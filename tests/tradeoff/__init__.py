"""Speed against accuracy (epc_fast.tradeoff, epc-fast bench): a file per module."""
