"""How a scan runs: the run itself (``runner``), a chunk's task (``tasks``) and its points and
outputs (``chunk``), the plan the core folds a chunk by (``core_plan``), the chunks on a Dask
cluster (``dask_backend``), a design's readout modes (``readout_modes``) and the points written
as Parquet (``parquet``).
"""
