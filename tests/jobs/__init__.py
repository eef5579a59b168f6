"""What every command's job shares (epc_fast.jobs): a file per module."""
