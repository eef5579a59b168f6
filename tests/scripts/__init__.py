"""The repository's scripts that are not package modules: bench/ and tools/."""
