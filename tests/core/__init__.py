"""The C++ core's pieces, through the _core probes and the kernels' results: f50's starts and
solvers, the exposure stage, polynomials, streaming stores, float32, the per-level builds."""
