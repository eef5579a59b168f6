"""The command line: the main job and each epc-fast command (epc_fast.commands)."""
