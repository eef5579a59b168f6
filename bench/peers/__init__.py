"""Pure-Python peers of the core, for the benchmarks only (Numba, SciPy)."""
