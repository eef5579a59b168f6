"""How a scan draws its points (epc_fast.scan.sampling): a file per module."""
