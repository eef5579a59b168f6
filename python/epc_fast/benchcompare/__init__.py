"""Benchmark regression runs that a busy machine can trust (``epc-fast bench compare``).

- ``worker``: the workloads, run in the Python of the install measured.
- ``sides``: a side's command line and its worker session: its answers checked, a side
  that stops answering killed after a timeout.
- ``compare``: paired, alternating rounds of both sides in blocks of fresh processes.
- ``ratios``: each workload's time ratio, its 95% interval and the verdict.
- ``report``: the Markdown and JSON reports.
- ``refbuild``: a git commit built into a cached venv (``--ref``).
- ``cli``: the sub-commands' arguments and runs.
"""
